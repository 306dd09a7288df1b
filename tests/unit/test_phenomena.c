/* Optical phenomena in rendered images (Riley et al. 2004 Figs. 4-6): the slice renderer
 * draws the rainbow of rain, the 22° halo of ice and the glory of cloud droplets where
 * the particles' phase tables put them.
 *
 * Each case renders a uniform slab of one particle type (optical depth 0.3 along the
 * axis, so that single scattering dominates) in a vacuum (black background, no air),
 * lit by the sun straight behind the camera (rainbow, glory: the camera looks at the
 * antisolar point) or straight in front of it (halo: the camera looks at the sun). The
 * radiance of every pixel is binned by the angle psi between its ray and the camera axis,
 * which is 180° minus the scattering angle (antisolar) or the scattering angle (halo).
 * Dividing by the slab's single-scattering path factor G (sunlight and eye attenuation
 * through the slab along that ray, computed here) leaves a profile proportional to the
 * phase function. The same binning and smoothing are applied to the phase table itself,
 * and the peaks are compared:
 *   rainbow: primary maximum per channel within 0.5° of the table's, red outside blue;
 *   halo: 22° maximum per channel within 0.5° of the table's, red inside blue (the inner
 *         edge, where the profile first reaches half its peak above the inner minimum);
 *   glory: the profile has a maximum at the antisolar point and its first ring lies
 *          within 0.3° of the table's;
 *   control: a Henyey-Greenstein particle (g = 0.7) in the rainbow and halo geometries
 *            gives no bump, so the measure can tell a bow from a smooth profile.
 * Each case is rendered with the do field (the default) and with the P1 field.
 * Fast-quality particle tables (docs/optics.md: bows and glory placed to 0.15°), small
 * images and 64 slices keep it quick. The sanitizer build skips the rain (its Mie table
 * and Ams take minutes there; the control still runs) and traces fewer ice rays. */
#include "atmos/atmos.h"
#include "test.h"

#if defined(__SANITIZE_ADDRESS__)
#define SANITIZED 1
#else
#define SANITIZED 0
#endif

#define PI 3.14159265358979323846
#define W 160
#define H 160
#define DEPTH 1000.0  /* slab thickness along z, m */
#define TAU 0.3       /* optical depth of the slab along z (green) */
#define MAXBINS 800

static char cache_dir[1024];
/* the slice renderer's field of the orders >= 2 (atmos_slice_field): every case is rendered with
 * the do field (the default: its first order in the delta-M scaled medium, the phase toward the
 * eye the full table's) and with the P1 field (Eq. 24/25 and Ams) */
static int field_kind = ATMOS_SLICE_FIELD_DO;
/* the slab's optical depth along its axis (green): TAU, or a dense cloud's (test_glory_dense) */
static double slab_tau = TAU;

static atmos_context *make_ctx(void)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.cache_dir = cache_dir;
    d.log = NULL;
    atmos_context *ctx = NULL;
    if (atmos_context_create(&d, &ctx) != ATMOS_OK) exit(1);
    return ctx;
}

typedef struct {
    atmos_phase_table *t;
    atmos_msphase *m;
    atmos_volume_optics o;
} optics;

static void build_optics(atmos_context *ctx, const atmos_particle_desc *p, optics *op)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_phase_table_desc td = {1};
    CHECK_OK(atmos_phase_table_build(ctx, p, &wl, &td, &op->t));
    atmos_msphase_desc md = {4, 0, 1}; /* tau = 0.3: n + 1 stays below 2 */
    CHECK_OK(atmos_msphase_build(ctx, op->t, &md, &op->m));
    memset(&op->o, 0, sizeof op->o);
    op->o.count = 1;
    op->o.phase[0] = op->t;
    op->o.ms[0] = op->m;
}

static void free_optics(optics *op)
{
    atmos_msphase_destroy(op->m);
    atmos_phase_table_destroy(op->t);
}

static void preset(atmos_context *ctx, const char *name, atmos_particle_desc *p)
{
    CHECK_OK(atmos_particle_preset(ctx, name, p));
    p->fast = 1;
}

static void hg(atmos_particle_desc *p)
{
    memset(p, 0, sizeof *p);
    snprintf(p->name, sizeof p->name, "hg07");
    p->kind = ATMOS_PARTICLE_ANALYTIC;
    p->analytic.count = 1;
    p->analytic.kind[0] = ATMOS_PHASE_HG;
    p->analytic.g[0] = 0.7;
    p->analytic.weight[0] = 1;
    p->sigma_ext_m2 = 1e-6;
    p->albedo = 1;
}

/* Sun 5° above the horizon in the south. front = 0: the camera looks at the antisolar
 * point (north, 5° down) and the slab lies north of it; front = 1: the camera looks at
 * the sun and the slab lies south. The slab is DEPTH thick along z, starting 100 m from
 * the camera, and 6.4 km wide, so that every ray of the image crosses its whole depth. */
typedef struct {
    atmos_scene s;
    atmos_volume *v;
    double axis[3]; /* camera axis */
    double l[3];    /* direction the sunlight travels */
    int front;
} setup;

static void make_setup(atmos_context *ctx, int front, double fov_deg, double sigma_ext, setup *u)
{
    memset(u, 0, sizeof *u);
    u->front = front;
    atmos_scene *s = &u->s;
    atmos_scene_defaults(s);
    s->width = W, s->height = H;
    s->samples_per_pixel = 1;
    s->atmosphere.kind = ATMOS_ATMOSPHERE_VACUUM;
    s->wavelengths = ATMOS_WAVELENGTHS_RGB;
    s->sun.from_time = 0;
    s->sun.elevation_deg = 5;
    s->sun.azimuth_deg = 180;
    double sun[3];
    atmos_direction_from_angles(5, 180, sun);
    for (int k = 0; k < 3; k++) u->l[k] = -sun[k], u->axis[k] = front ? sun[k] : -sun[k];
    double pos[3] = {0, 3000, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    for (int k = 0; k < 3; k++) s->camera.look_at[k] = pos[k] + 1000 * u->axis[k];
    s->camera.fov_deg = fov_deg;

    /* 32 x 32 x 5 voxels of 200 m: 6.4 km x 6.4 km x 1 km. */
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = 32, vd.dims[1] = 32, vd.dims[2] = 5;
    vd.voxel_size_m = DEPTH / 5;
    vd.origin_m[0] = -3200, vd.origin_m[1] = 3000 - 3200;
    vd.origin_m[2] = front ? 100 : -100 - DEPTH;
    CHECK_OK(atmos_volume_create(ctx, &vd, &u->v));
    int f = -1;
    CHECK_OK(atmos_volume_add_field(ctx, u->v, "slab", "slab", &f));
    static float buf[32 * 32 * 5];
    float eta = (float)(slab_tau / DEPTH / sigma_ext);
    for (int i = 0; i < 32 * 32 * 5; i++) buf[i] = eta;
    int off[3] = {0, 0, 0}, size[3] = {32, 32, 5};
    CHECK_OK(atmos_volume_set_dense(ctx, u->v, f, off, size, buf, 1.0f));
    CHECK_OK(atmos_volume_finalize(ctx, u->v));
}

/* Single scattering from a slab of optical depth tau (along z) seen along d: the
 * integral over the slab of (sunlight transmittance) x (eye transmittance) x beta ds,
 * by the midpoint rule. Only the shape in psi matters. */
static double path_factor(const setup *u, const double d[3], double tau)
{
    double dz = fabs(d[2]), lz = fabs(u->l[2]);
    const int n = 400;
    double sum = 0;
    for (int i = 0; i < n; i++) {
        double s = (i + 0.5) / n;                   /* depth fraction from the camera's side */
        double sun_path = u->front ? (1 - s) / lz : s / lz; /* in units of the slab thickness */
        double eye_path = s / dz;
        sum += exp(-tau * (sun_path + eye_path));
    }
    return sum / n * tau / dz;
}

typedef struct {
    double bin_deg;
    int nb;
    double v[3][MAXBINS];
    int cnt[MAXBINS];
} profile;

/* Radiance / path factor per channel, averaged in bins of psi. */
static void image_profile(atmos_context *ctx, const setup *u, const atmos_image *img, double bin_deg, profile *p)
{
    memset(p, 0, sizeof *p);
    p->bin_deg = bin_deg;
    p->nb = MAXBINS;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(ctx, &u->s.camera, W, H, &cam));
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            double d[3];
            if (!atmos_camera_ray(&cam, i + 0.5, j + 0.5, d)) continue;
            double c = d[0] * u->axis[0] + d[1] * u->axis[1] + d[2] * u->axis[2];
            double psi = acos(c > 1 ? 1 : c) * 180 / PI;
            int b = (int)(psi / bin_deg);
            if (b >= MAXBINS) continue;
            double g = path_factor(u, d, slab_tau);
            for (int k = 0; k < 3; k++) p->v[k][b] += img->pixels[((size_t)j * W + i) * img->channels + k] / g;
            p->cnt[b]++;
        }
    for (int b = 0; b < MAXBINS; b++)
        for (int k = 0; k < 3; k++) p->v[k][b] = p->cnt[b] ? p->v[k][b] / p->cnt[b] : NAN;
}

/* The phase table binned the same way: psi = 180 - theta (antisolar) or theta (front). */
static void table_profile(const atmos_phase_table *t, int front, double bin_deg, profile *p)
{
    memset(p, 0, sizeof *p);
    p->bin_deg = bin_deg;
    p->nb = MAXBINS;
    for (int b = 0; b < MAXBINS; b++) {
        p->cnt[b] = 1;
        for (int k = 0; k < 3; k++) {
            double sum = 0;
            const int sub = 16; /* average over the bin */
            for (int q = 0; q < sub; q++) {
                double psi = (b + (q + 0.5) / sub) * bin_deg;
                double theta = front ? psi : 180 - psi;
                if (theta < 0 || theta > 180) {
                    sum = NAN;
                    break;
                }
                sum += atmos_phase_table_eval(t, k, cos(theta * PI / 180));
            }
            p->v[k][b] = sum / sub;
        }
    }
}

/* 3-bin moving average value at bin b (NaN bins excluded). */
static double smooth(const profile *p, int k, int b)
{
    double s = 0;
    int n = 0;
    for (int q = b - 1; q <= b + 1; q++)
        if (q >= 0 && q < p->nb && isfinite(p->v[k][q])) s += p->v[k][q], n++;
    return n ? s / n : NAN;
}

/* psi (degrees) of the largest smoothed value in [lo, hi], refined by a parabola. */
static double peak(const profile *p, int k, double lo, double hi)
{
    int b0 = (int)(lo / p->bin_deg), b1 = (int)(hi / p->bin_deg);
    int best = -1;
    double bv = -1;
    for (int b = b0; b <= b1 && b < p->nb; b++) {
        double v = smooth(p, k, b);
        if (isfinite(v) && v > bv) bv = v, best = b;
    }
    if (best < 0) return NAN;
    double x = 0;
    if (best > b0 && best < b1) {
        double ym = smooth(p, k, best - 1), y0 = smooth(p, k, best), yp = smooth(p, k, best + 1);
        double den = ym - 2 * y0 + yp;
        if (den < 0) x = 0.5 * (ym - yp) / den;
    }
    return (best + 0.5 + x) * p->bin_deg;
}

/* Bump of the profile at psi: its value over the mean of the values `off` degrees on
 * either side (1 for a straight line; a bow or halo gives more). */
static double bump(const profile *p, int k, double psi, double off)
{
    int b = (int)(psi / p->bin_deg), d = (int)(off / p->bin_deg + 0.5);
    return smooth(p, k, b) / (0.5 * (smooth(p, k, b - d) + smooth(p, k, b + d)));
}

/* psi where the smoothed profile, rising from its minimum in [lo, pk], first reaches
 * half-way between that minimum and its value at pk (the halo's inner edge). */
static double inner_edge(const profile *p, int k, double lo, double pk)
{
    int b0 = (int)(lo / p->bin_deg), b1 = (int)(pk / p->bin_deg);
    double mn = INFINITY;
    int bmin = b0;
    for (int b = b0; b <= b1; b++) {
        double v = smooth(p, k, b);
        if (v < mn) mn = v, bmin = b;
    }
    double half = 0.5 * (mn + smooth(p, k, b1));
    for (int b = bmin; b < b1; b++) {
        double v0 = smooth(p, k, b), v1 = smooth(p, k, b + 1);
        if (v0 < half && v1 >= half) return (b + 0.5 + (half - v0) / (v1 - v0)) * p->bin_deg;
    }
    return NAN;
}

static atmos_image *render(atmos_context *ctx, const setup *u, const optics *op)
{
    atmos_slice_settings ss;
    atmos_slice_defaults(&ss);
    ss.optics = &op->o;
    atmos_scene s = u->s;
    s.slice.slices = 64;
    s.slice.light_size = 64;
    s.slice.field = field_kind;
    atmos_image *img = NULL;
    atmos_status st = atmos_render_slice(ctx, &s, u->v, &ss, &img, NULL);
    CHECK_MSG(st == ATMOS_OK, "render slice: %s", atmos_context_error(ctx));
    return img;
}

static const char *chan[3] = {"red", "green", "blue"};

static void test_rainbow(atmos_context *ctx, const optics *hgop)
{
    profile *im = malloc(sizeof *im), *tb = malloc(sizeof *tb);
    if (!SANITIZED) { /* rain's Mie table and Ams take minutes under the sanitizers */
        atmos_particle_desc p;
        preset(ctx, "rain", &p);
        optics op;
        build_optics(ctx, &p, &op);
        setup u;
        make_setup(ctx, 0, 100, atmos_phase_table_sigma_ext(op.t, 1), &u);
        atmos_image *img = render(ctx, &u, &op);
        image_profile(ctx, &u, img, 0.25, im);
        table_profile(op.t, 0, 0.25, tb);
        double pk[3];
        for (int k = 0; k < 3; k++) {
            double pred = peak(tb, k, 36, 46), meas = peak(im, k, 36, 46);
            pk[k] = meas;
            double b = bump(im, k, meas, 4);
            printf("rainbow %-5s (%.0f nm): primary bow at %.2f deg from the antisolar point (table %.2f), bump %.2f\n",
                   chan[k], atmos_phase_table_wavelength_nm(op.t, k), meas, pred, b);
            CHECK_NEAR(meas, pred, 0.5);
            CHECK(b > 1.15);
        }
        CHECK(pk[0] > pk[2] + 0.5); /* red outside */
        atmos_image_destroy(img);
        atmos_volume_destroy(u.v);
        free_optics(&op);
    }

    /* Control: the same geometry with an HG particle shows no bow. */
    setup uc;
    make_setup(ctx, 0, 100, atmos_phase_table_sigma_ext(hgop->t, 1), &uc);
    atmos_image *img = render(ctx, &uc, hgop);
    image_profile(ctx, &uc, img, 0.25, im);
    double worst = 0;
    for (double psi = 36; psi <= 46; psi += 0.25) {
        double b = bump(im, 1, psi, 4);
        if (b > worst) worst = b;
    }
    printf("rainbow control (HG g = 0.7): largest bump in 36-46 deg %.3f\n", worst);
    CHECK(worst < 1.05);
    atmos_image_destroy(img);
    atmos_volume_destroy(uc.v);
    free(im), free(tb);
}

static void test_halo(atmos_context *ctx, const optics *hgop)
{
    atmos_particle_desc p;
    preset(ctx, "ice", &p);
    if (SANITIZED) p.rays = 100000;
    optics op;
    build_optics(ctx, &p, &op);
    setup u;
    make_setup(ctx, 1, 70, atmos_phase_table_sigma_ext(op.t, 1), &u);
    atmos_image *img = render(ctx, &u, &op);
    profile *im = malloc(sizeof *im), *tb = malloc(sizeof *tb);
    image_profile(ctx, &u, img, 0.25, im);
    table_profile(op.t, 1, 0.25, tb);
    double edge[3];
    for (int k = 0; k < 3; k++) {
        double pred = peak(tb, k, 19, 26), meas = peak(im, k, 19, 26);
        double epred = inner_edge(tb, k, 17, pred), emeas = inner_edge(im, k, 17, meas);
        edge[k] = emeas;
        double b = bump(im, k, meas, 3);
        printf("halo %-5s (%.0f nm): maximum at %.2f deg from the sun (table %.2f), inner edge %.2f (table %.2f), bump %.2f\n",
               chan[k], atmos_phase_table_wavelength_nm(op.t, k), meas, pred, emeas, epred, b);
        CHECK_NEAR(meas, pred, 0.5);
        CHECK_NEAR(emeas, epred, 0.5);
        CHECK(b > 1.15);
    }
    CHECK(edge[0] < edge[2]); /* red inside */
    atmos_image_destroy(img);

    setup uc;
    make_setup(ctx, 1, 70, atmos_phase_table_sigma_ext(hgop->t, 1), &uc);
    img = render(ctx, &uc, hgop);
    image_profile(ctx, &uc, img, 0.25, im);
    double worst = 0;
    for (double psi = 19; psi <= 26; psi += 0.25) {
        double b = bump(im, 1, psi, 3);
        if (b > worst) worst = b;
    }
    printf("halo control (HG g = 0.7): largest bump in 19-26 deg %.3f\n", worst);
    CHECK(worst < 1.05);
    atmos_image_destroy(img);
    atmos_volume_destroy(uc.v);
    atmos_volume_destroy(u.v);
    free(im), free(tb);
    free_optics(&op);
}

/* First local maximum of the smoothed profile beyond its first local minimum, searching
 * outwards from lo (the glory's first bright ring). */
static double first_ring(const profile *p, int k, double lo, double hi)
{
    int b0 = (int)(lo / p->bin_deg) + 1, b1 = (int)(hi / p->bin_deg);
    int b = b0;
    while (b < b1 && !(smooth(p, k, b) < smooth(p, k, b - 1) && smooth(p, k, b) <= smooth(p, k, b + 1))) b++;
    while (b < b1 && !(smooth(p, k, b) > smooth(p, k, b - 1) && smooth(p, k, b) >= smooth(p, k, b + 1))) b++;
    if (b >= b1) return NAN;
    double ym = smooth(p, k, b - 1), y0 = smooth(p, k, b), yp = smooth(p, k, b + 1), den = ym - 2 * y0 + yp;
    return (b + 0.5 + (den < 0 ? 0.5 * (ym - yp) / den : 0)) * p->bin_deg;
}

/* A narrow droplet distribution (8 um, sigma 0.1, as in thin altocumulus): the glory's rings. */
static void build_narrow_droplets(atmos_context *ctx, optics *op)
{
    atmos_particle_desc p;
    memset(&p, 0, sizeof p);
    snprintf(p.name, sizeof p.name, "droplets");
    p.kind = ATMOS_PARTICLE_WATER;
    p.size.kind = ATMOS_SIZE_LOGNORMAL;
    p.size.r_m = 8e-6;
    p.size.sigma = 0.1;
    p.fast = 1;
    build_optics(ctx, &p, op);
}

static void test_glory(atmos_context *ctx)
{
    /* A narrow droplet distribution (as in thin altocumulus): the broad cloud preset
     * keeps the central glory maximum but washes out the rings. */
    optics op;
    build_narrow_droplets(ctx, &op);
    setup u;
    make_setup(ctx, 0, 24, atmos_phase_table_sigma_ext(op.t, 1), &u);
    atmos_image *img = render(ctx, &u, &op);
    profile *im = malloc(sizeof *im), *tb = malloc(sizeof *tb);
    image_profile(ctx, &u, img, 0.2, im);
    table_profile(op.t, 0, 0.2, tb);
    for (int k = 0; k < 3; k++) {
        double centre = smooth(im, k, 1), pred = first_ring(tb, k, 0.2, 10), meas = first_ring(im, k, 0.2, 10);
        /* the darkest point between the centre and the ring */
        double mn = INFINITY;
        for (int b = 1; b * im->bin_deg < meas; b++) mn = fmin(mn, smooth(im, k, b));
        printf("glory %-5s (%.0f nm): first ring at %.2f deg (table %.2f); centre / darkest inside the ring %.2f\n",
               chan[k], atmos_phase_table_wavelength_nm(op.t, k), meas, pred, centre / mn);
        CHECK_NEAR(meas, pred, 0.3);
        CHECK(centre > 1.1 * mn);
    }
    atmos_image_destroy(img);
    atmos_volume_destroy(u.v);
    free(im), free(tb);
    free_optics(&op);
}

/* The glory on a dense slab (optical depth 10, the multiple scattering as bright as the first
 * order): the blue over red of rings 0.25 degrees wide, 0-4 degrees from the antisolar point,
 * swings about its mean by (max - min) / 2 / mean. The do field's first order draws the rings
 * with the full phase table on the light that the droplets' forward peak has not turned, the
 * rest with a smooth phase (slice_do.c): 0.160 against the P1 field's 0.174 (whose rings match
 * the path tracer's on Fig. 4, docs/lightfield.md "The phenomena"); with the whole delta-M
 * direct beam drawn sharp (before 2026-12-06) 0.306. Wanted: within 30 % of the P1 field's.
 * No absolute band: the path tracer's measured swing (±12.5 % at 64 spp, ±12.9 % at 16 spp) is
 * Fig. 4's geometry, not this slab's, and no path tracer run of this slab is kept, so a band
 * around the 0.160 printed here would come from the renderer under test. The P1 field is the
 * reference instead because its rings match the path tracer's where both were measured. */
static double ring_swing(const profile *im)
{
    const int nb = (int)(4.0 / im->bin_deg + 0.5);
    double mn = INFINITY, mx = -INFINITY, sum = 0;
    for (int b = 0; b < nb; b++) {
        const double r = im->v[2][b] / im->v[0][b];
        mn = fmin(mn, r), mx = fmax(mx, r), sum += r;
    }
    return (mx - mn) / 2 / (sum / nb);
}

static void test_glory_dense(atmos_context *ctx)
{
    optics op;
    build_narrow_droplets(ctx, &op);
    slab_tau = 10;
    setup u;
    make_setup(ctx, 0, 24, atmos_phase_table_sigma_ext(op.t, 1), &u);
    profile *im = malloc(sizeof *im);
    const int fields[] = {ATMOS_SLICE_FIELD_DO, ATMOS_SLICE_FIELD_P1};
    double sw[2];
    for (int f = 0; f < 2; f++) {
        field_kind = fields[f];
        atmos_image *img = render(ctx, &u, &op);
        image_profile(ctx, &u, img, 0.25, im);
        sw[f] = ring_swing(im);
        atmos_image_destroy(img);
    }
    printf("glory on a dense slab (tau %.0f): the rings' blue / red swings +-%.3f with the do field, "
           "+-%.3f with the p1 field\n", slab_tau, sw[0], sw[1]);
    CHECK(sw[0] < 1.3 * sw[1] && sw[0] > sw[1] / 1.3);
    slab_tau = TAU;
    atmos_volume_destroy(u.v);
    free(im);
    free_optics(&op);
}

int main(void)
{
    test_tmp_path(cache_dir, sizeof cache_dir, "cache");
    atmos_context *ctx = make_ctx();
    atmos_particle_desc p;
    hg(&p);
    optics hgop;
    build_optics(ctx, &p, &hgop);
    const int fields[] = {ATMOS_SLICE_FIELD_DO, ATMOS_SLICE_FIELD_P1};
    for (int f = 0; f < 2; f++) {
        field_kind = fields[f];
        printf("== the %s field\n", f ? "p1" : "do");
        test_rainbow(ctx, &hgop);
        test_halo(ctx, &hgop);
        test_glory(ctx);
    }
    test_glory_dense(ctx);
    free_optics(&hgop);
    atmos_context_destroy(ctx);
    return test_summary("test_phenomena");
}
