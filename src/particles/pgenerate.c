/* Particle clouds made as Harris's notes describe them (§1.1.1: "clouds as particle systems
 * ... ellipsoids filled with particles"): a cumulus is a cluster of ellipsoids over a flat base
 * (a large body, smaller turrets on its top and shoulders), each filled with particles on a
 * jittered lattice whose density falls off toward the ellipsoid's surface; a field scatters
 * such cumuli over an area, small ones more often, none overlapping (pcloud.h). */
#include "particles/pcloud.h"
#include "core/internal.h"
#include "core/rng.h"
#include "volume/generator.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define ETA 1e8           /* droplets per m^3 in a cloud's core (the volume generators' value) */
/* A field's clouds (docs/clouds.md "Against observations": the particle field's outlines): */
#define FIELD_H 42.0      /* particles this far apart (m) in every cloud, whatever its width */
#define SEP 0.9           /* cloud centres at least this times their summed widths apart */
#define WIDE 1.12         /* the outline's smooth ellipse this times the body's base ellipse */
#define REACH 1.4         /* no column kept beyond this times the smooth ellipse */
#define CORE 0.5          /* the columns where the smooth ellipse's 1 - rho^2 is above this never cut */
#define SKIRT 0.08        /* the skirt, out of the body within the outline, this times the width deep */
#define SKIRT_IN 0.2      /* its particles' depth inside (1 at a core, 0 on a surface: sqrt of the density) */

static const char *const names[] = {"harris_cumulus", "harris_field", NULL};
const char *const *atmos__pcloud_generator_names(void) { return names; }

typedef struct ellipsoid {
    double c[3], r[3];
} ellipsoid;

static double u01(uint64_t *s) { return atmos__u01(atmos__splitmix64(s)); }

/* The ellipsoids of a cumulus of width w on a base at height b, centred at (x, z): a broad,
 * flattened body, turrets on its top and shoulders, and smaller turrets on theirs (the
 * cauliflower of a growing cumulus); at most 32. */
static int cumulus_shape(uint64_t *rng, double x, double z, double b, double w, ellipsoid *e)
{
    const double R = 0.5 * w, H = 0.26 * w;
    int n = 0;
    e[n++] = (ellipsoid){{x, b + 0.4 * H, z}, {R, H, 0.8 * R}};
    const int turrets = 4 + (int)(4 * u01(rng));
    for (int i = 0; i < turrets; i++) {
        const double a = 2 * ATMOS_PI * u01(rng), d = 0.55 * R * sqrt(u01(rng)), rr = (0.25 + 0.2 * u01(rng)) * R;
        const double cy = b + (0.8 + 0.7 * u01(rng) * (1.0 - d / R)) * H;
        e[n++] = (ellipsoid){{x + d * cos(a), cy, z + 0.8 * d * sin(a)}, {rr, 0.9 * rr, rr}};
        const int subs = 1 + (int)(3 * u01(rng));
        for (int k = 0; k < subs && n < 32; k++) {
            const double sa = 2 * ATMOS_PI * u01(rng), sr = (0.4 + 0.2 * u01(rng)) * rr;
            e[n++] = (ellipsoid){{x + d * cos(a) + 0.6 * rr * cos(sa), cy + 0.6 * rr, z + 0.8 * d * sin(a) + 0.6 * rr * sin(sa)},
                                 {sr, 0.9 * sr, sr}};
        }
    }
    return n;
}

/* Fills the cluster with particles of spacing h above the base b. A field's cloud (f given: its
 * outline's noise, centre and ellipses) only in the columns of its fractal outline joined to its
 * core (atmos__pfootprint_make), and where those lie outside the ellipsoids a skirt SKIRT w deep
 * on the base: seen from above the outline is rough at every scale down to the spacing, seen
 * from the side the cumulus keeps its rounded body over a thin ragged foot. */
static atmos_status fill(atmos__pcloud *pc, uint64_t *rng, const ellipsoid *e, int ne, double b, double h,
                         const atmos__pfootprint_desc *f)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int k = 0; k < ne; k++)
        for (int a = 0; a < 3; a++) lo[a] = fmin(lo[a], e[k].c[a] - e[k].r[a]), hi[a] = fmax(hi[a], e[k].c[a] + e[k].r[a]);
    const double s = 0.6 * h, unit = atmos__pcloud_peak(1.0, h, s);
    atmos__pfootprint fp = {0, 0, NULL};
    if (f) { /* the lattice over the outline's reach */
        lo[0] = fmin(lo[0], f->cx - f->reach_a), hi[0] = fmax(hi[0], f->cx + f->reach_a);
        lo[2] = fmin(lo[2], f->cz - f->reach_b), hi[2] = fmax(hi[2], f->cz + f->reach_b);
        atmos__pfootprint_desc d = *f;
        d.x0 = lo[0] + 0.5 * h, d.z0 = lo[2] + 0.5 * h, d.h = h;
        d.nx = (int)ceil((hi[0] - lo[0]) / h - 0.5), d.nz = (int)ceil((hi[2] - lo[2]) / h - 0.5);
        if (atmos__pfootprint_make(&d, &fp) != ATMOS_OK) return ATMOS_E_NOMEM;
    }
    atmos_status st = ATMOS_OK;
    for (double y = fmax(lo[1], b) + 0.5 * h; y < hi[1] && st == ATMOS_OK; y += h)
        for (int kz = 0; lo[2] + (kz + 0.5) * h < hi[2] && st == ATMOS_OK; kz++)
            for (int ix = 0; lo[0] + (ix + 0.5) * h < hi[0] && st == ATMOS_OK; ix++) {
                const double x = lo[0] + (ix + 0.5) * h, z = lo[2] + (kz + 0.5) * h;
                const double p[3] = {x + 0.3 * h * (u01(rng) - 0.5), y + 0.3 * h * (u01(rng) - 0.5),
                                     z + 0.3 * h * (u01(rng) - 0.5)};
                if (p[1] < b) continue;
                double inside = 0; /* the deepest: 1 at an ellipsoid's centre, 0 on its surface */
                for (int k = 0; k < ne; k++) {
                    double q = 0;
                    for (int a = 0; a < 3; a++) q += (p[a] - e[k].c[a]) * (p[a] - e[k].c[a]) / (e[k].r[a] * e[k].r[a]);
                    inside = fmax(inside, 1.0 - q);
                }
                if (fp.phi) { /* outside the outline nothing; inside it, out of the body, the skirt */
                    if (ix >= fp.nx || kz >= fp.nz || fp.phi[(size_t)kz * fp.nx + ix] < 0) continue;
                    if (inside <= 0 && p[1] - b < SKIRT * f->w) inside = SKIRT_IN;
                }
                if (inside <= 0) continue;
                const double rho = ETA * sqrt(inside) * (0.7 + 0.3 * u01(rng));
                st = atmos__pcloud_add(pc, p[0], p[1], p[2], s, rho * unit, 0);
            }
    atmos__pfootprint_free(&fp);
    return st;
}

/* Cumuli over a half x half square about the origin, widths 300..1200 m (small ones more
 * often), thrown as darts kept SEP of their summed widths apart (their skirts must not join);
 * per_width > 0: particles that many lattice cells across each cloud, else FIELD_H apart. */
static atmos_status field(atmos__pcloud *pc, uint64_t *rng, double scale, int count, double half, double per_width,
                          double spacing, double *h_out)
{
    double cx[256], cz[256], cw[256];
    int n = 0;
    const double base = 1500;
    *h_out = INFINITY;
    for (int attempt = 0; attempt < 20000 && n < count; attempt++) {
        const double w = (count == 1 ? 1100 : 300 + 900 * pow(u01(rng), 2)) * scale;
        const double lim = fmax(0.0, half - 0.6 * w);
        const double x = count == 1 ? 0 : (2 * u01(rng) - 1) * lim, z = count == 1 ? 0 : (2 * u01(rng) - 1) * lim;
        int ok = 1;
        for (int m = 0; m < n && ok; m++) ok = hypot(x - cx[m], z - cz[m]) >= (count > 1 ? SEP : 0.6) * (w + cw[m]);
        if (!ok) continue;
        cx[n] = x, cz[n] = z, cw[n] = w, n++;
        ellipsoid e[32];
        const int ne = cumulus_shape(rng, x, z, base * scale, w, e);
        /* lattice cells across the cloud's width, or the given spacing; a given spacing fills
         * from a stream of its own, so that the clouds' places and shapes do not depend on it */
        const double h = spacing > 0 ? spacing : per_width > 0 ? w / per_width : FIELD_H * scale;
        *h_out = fmin(*h_out, h);
        /* a field's cloud: its outline (the body's base ellipse is R by 0.8 R) */
        const double R = 0.5 * w;
        const atmos__pfootprint_desc fd = {.seed = count > 1 ? atmos__splitmix64(rng) : 0, .cx = x, .cz = z, .w = w,
                                           .a = R * WIDE, .b = 0.8 * R * WIDE, .reach_a = REACH * R * WIDE,
                                           .reach_b = 0.8 * REACH * R * WIDE, .core = CORE};
        uint64_t own = *rng ^ 0xA5A5A5A5DEADBEEFull;
        atmos_status st = fill(pc, spacing > 0 ? &own : rng, e, ne, base * scale, h, count > 1 ? &fd : NULL);
        if (st != ATMOS_OK) return st;
    }
    return ATMOS_OK;
}

/* The finest spacing the generators take (m, times the scale): 1.2 million particles are 18 m apart. */
#define PGEN_SPACING_MIN_M 1.0

atmos_status atmos__pcloud_generate(atmos_context *ctx, const char *preset, uint64_t seed, double scale,
                                    double spacing_m, atmos__pcloud *out, double *voxel_m)
{
    memset(out, 0, sizeof *out);
    out->nfields = 1;
    snprintf(out->field_name[0], sizeof out->field_name[0], "cloud");
    snprintf(out->particle[0], sizeof out->particle[0], "cloud");
    if (!(scale > 0)) scale = 1.0;
    if (spacing_m != 0 && !(spacing_m >= PGEN_SPACING_MIN_M * scale)) /* the columns' int indices, the memory */
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "particles: spacing %g m under the generators' least, %g m (0: "
                            "their own lattice)", spacing_m, PGEN_SPACING_MIN_M * scale);
    uint64_t rng = seed * 0x9E3779B97F4A7C15ull + 0x1234567ull;
    double h = 0;
    atmos_status st;
    if (!strcmp(preset, "harris_cumulus")) st = field(out, &rng, scale, 1, 0, 24, spacing_m, &h);
    else if (!strcmp(preset, "harris_field")) st = field(out, &rng, scale, 120, 15000 * scale, 0, spacing_m, &h);
    else return atmos__error(ctx, ATMOS_E_INVALID_ARG, "particles: no preset \"%s\" (known: harris_cumulus, harris_field)", preset);
    if (st != ATMOS_OK) {
        atmos__pcloud_free(out);
        return atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory generating \"%s\"", preset);
    }
    /* world positions, as a generated volume's: the field about x = z = 0, the bases at 1.5 km */
    double lo[3], hi[3];
    atmos__pcloud_bounds(out, lo, hi);
    /* half the finest spacing, but no more than 640 voxels across (a field of 30 km: 47 m) */
    *voxel_m = fmax(0.5 * h, fmax(hi[0] - lo[0], hi[2] - lo[2]) / 640.0);
    return ATMOS_OK;
}
