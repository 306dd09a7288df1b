/* Geometric optics in a hexagonal ice prism: the crystal, projected areas, Fresnel
 * coefficients, and the Monte Carlo tracing of one ray (see crystal_internal.h).
 *
 * The method is the classic ray-tracing of randomly oriented hexagonal crystals
 * (Wendling, Wendling & Weickmann 1979, Appl. Opt. 18, 2663; Takano & Liou 1989,
 * J. Atmos. Sci. 46, 3-19; Macke, Mueller & Raschke 1996, J. Atmos. Sci. 53, 2813):
 * at every facet a ray splits into a reflected and a refracted part with the
 * unpolarised Fresnel weights; we record the part that leaves the crystal and keep
 * following the part that stays inside, so a ray never branches into a tree and its
 * energy is accounted for exactly (no Russian roulette noise in the energy balance).
 */
#include "optics/crystal_internal.h"
#include "core/vec.h"
#include "core/internal.h"

#include <math.h>

void atmos__crystal_init(atmos__crystal *c, double radius, double length)
{
    c->radius = radius;
    c->length = length;
    /* Prism faces: between vertices at 60k° and 60(k+1)°, outward normal at 60k + 30°,
     * at the apothem R cos 30° from the axis; each is a rectangle of width R (the side
     * of a regular hexagon equals its circumradius) and height L. */
    const double apothem = radius * sqrt(3.0) / 2.0;
    for (int k = 0; k < 6; k++) {
        double a = (60.0 * k + 30.0) * ATMOS_DEG2RAD;
        c->normal[k][0] = cos(a);
        c->normal[k][1] = sin(a);
        c->normal[k][2] = 0.0;
        c->dist[k] = apothem;
        c->area[k] = radius * length;
    }
    /* Basal faces: regular hexagons of area 3 sqrt(3) / 2 R^2. */
    const double hex = 1.5 * sqrt(3.0) * radius * radius;
    for (int k = 6; k < 8; k++) {
        c->normal[k][0] = 0.0;
        c->normal[k][1] = 0.0;
        c->normal[k][2] = k == 6 ? 1.0 : -1.0;
        c->dist[k] = 0.5 * length;
        c->area[k] = hex;
    }
    c->surface_area = 0.0;
    for (int k = 0; k < ATMOS_CRYSTAL_FACES; k++) c->surface_area += c->area[k];
}

double atmos__crystal_projected_area(const atmos__crystal *c, const double d[3])
{
    /* For a convex body the lit faces tile the shadow exactly once and so do the
     * unlit ones: the shadow is half the sum over all faces of area |n . d|. */
    double s = 0.0;
    for (int k = 0; k < ATMOS_CRYSTAL_FACES; k++) s += c->area[k] * fabs(atmos__dot3(c->normal[k], d));
    return 0.5 * s;
}

double atmos__fresnel(double n1, double n2, double cos_i, double *cos_t)
{
    if (cos_i > 1.0) cos_i = 1.0;
    if (cos_i < 0.0) cos_i = 0.0;
    double eta = n1 / n2;
    double sin_t2 = eta * eta * (1.0 - cos_i * cos_i);
    if (sin_t2 >= 1.0) {
        if (cos_t) *cos_t = 0.0;
        return 1.0;
    }
    double ct = sqrt(1.0 - sin_t2);
    if (cos_t) *cos_t = ct;
    /* Born & Wolf §1.5.2: amplitude ratios for the two polarisations; natural light
     * is the mean of the two reflectances. */
    double rs = (n1 * cos_i - n2 * ct) / (n1 * cos_i + n2 * ct);
    double rp = (n2 * cos_i - n1 * ct) / (n2 * cos_i + n1 * ct);
    double r = 0.5 * (rs * rs + rp * rp);
    return r > 1.0 ? 1.0 : r;
}

/* Angle between two unit vectors, accurate near 0 and pi (atan2 of |a x b| and a . b). */
static double angle_between(const double a[3], const double b[3])
{
    double cx = a[1] * b[2] - a[2] * b[1];
    double cy = a[2] * b[0] - a[0] * b[2];
    double cz = a[0] * b[1] - a[1] * b[0];
    return atan2(sqrt(cx * cx + cy * cy + cz * cz), atmos__dot3(a, b));
}

static void normalize3(double v[3])
{
    double l = sqrt(atmos__dot3(v, v));
    if (l > 0.0) {
        v[0] /= l;
        v[1] /= l;
        v[2] /= l;
    }
}

/* A facet normal tilted at random around the true one: tilt angle Rayleigh-distributed
 * with scale `tilt` (each of its two components is Gaussian with standard deviation
 * `tilt` for small tilts), azimuth uniform. The orthonormal basis around n follows
 * Duff et al. 2017, "Building an orthonormal basis, revisited" (JCGT 6(1)). */
static void tilted_normal(const double n[3], double tilt, atmos__rng *rng, double out[3])
{
    double u1 = atmos__rng_uniform(rng), u2 = atmos__rng_uniform(rng);
    double beta = tilt * sqrt(-2.0 * log(1.0 - u1)); /* 1 - u1 in (0, 1]: log finite */
    if (beta > 1.4) beta = 1.4;                       /* stay well inside the hemisphere */
    double phi = 2.0 * ATMOS_PI * u2;
    double sign = n[2] >= 0.0 ? 1.0 : -1.0;
    double a = -1.0 / (sign + n[2]);
    double b = n[0] * n[1] * a;
    double t1[3] = {1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]};
    double t2[3] = {b, sign + n[1] * n[1] * a, -n[1]};
    double cb = cos(beta), sb = sin(beta), cp = cos(phi), sp = sin(phi);
    for (int i = 0; i < 3; i++) out[i] = cb * n[i] + sb * (cp * t1[i] + sp * t2[i]);
    normalize3(out);
}

/* Direction refracted through a surface with unit normal m on the incident side
 * (m . d = -cos_i), relative index eta = n1 / n2 (Snell's law in vector form). */
static void refract(const double d[3], const double m[3], double eta, double cos_i, double cos_t, double out[3])
{
    double k = eta * cos_i - cos_t;
    for (int i = 0; i < 3; i++) out[i] = eta * d[i] + k * m[i];
    normalize3(out);
}

static void reflect(const double d[3], const double nrm[3], double out[3])
{
    double k = 2.0 * atmos__dot3(d, nrm);
    for (int i = 0; i < 3; i++) out[i] = d[i] - k * nrm[i];
    normalize3(out);
}

/* Uniform point on face f. */
static void sample_face_point(const atmos__crystal *c, int f, atmos__rng *rng, double p[3])
{
    double u = atmos__rng_uniform(rng), v = atmos__rng_uniform(rng);
    double R = c->radius;
    if (f < 6) {
        double a0 = 60.0 * f * ATMOS_DEG2RAD, a1 = 60.0 * (f + 1) * ATMOS_DEG2RAD;
        p[0] = R * (cos(a0) + u * (cos(a1) - cos(a0)));
        p[1] = R * (sin(a0) + u * (sin(a1) - sin(a0)));
        p[2] = (v - 0.5) * c->length;
    } else {
        /* One of the six equal triangles (centre, vertex k, vertex k+1), then a
         * uniform point in it by folding the unit square. */
        double w = atmos__rng_uniform(rng) * 6.0;
        int k = (int)w;
        if (k > 5) k = 5;
        if (u + v > 1.0) {
            u = 1.0 - u;
            v = 1.0 - v;
        }
        double a0 = 60.0 * k * ATMOS_DEG2RAD, a1 = 60.0 * (k + 1) * ATMOS_DEG2RAD;
        p[0] = R * (u * cos(a0) + v * cos(a1));
        p[1] = R * (u * sin(a0) + v * sin(a1));
        p[2] = f == 6 ? 0.5 * c->length : -0.5 * c->length;
    }
}

/* Tries to find a tilted normal for which the ray hits the tilted facet from the right
 * side, the reflected ray stays on the side of the true facet it came from and the
 * refracted ray (if any) crosses it; otherwise the tilt is redrawn, as Macke et al. 1996
 * do for their distorted crystals. `inside` tells which side the ray is on, `eta` is
 * n_incident / n_other. Falls back to the true normal after a few tries. */
static void facet_normal(const double n_true[3], const double d[3], int inside, double eta, double tilt,
                         atmos__rng *rng, double out[3])
{
    if (tilt > 0.0) {
        for (int attempt = 0; attempt < 8; attempt++) {
            tilted_normal(n_true, tilt, rng, out);
            double c = atmos__dot3(d, out);
            if (inside ? c <= 1e-6 : c >= -1e-6) continue;
            double r[3];
            reflect(d, out, r);
            double cr = atmos__dot3(r, n_true);
            if (inside ? cr >= -1e-9 : cr <= 1e-9) continue;
            double ci = fabs(c), sin_t2 = eta * eta * (1.0 - ci * ci);
            if (sin_t2 < 1.0) {
                double e[3], m[3];
                double sgn = inside ? -1.0 : 1.0; /* m: unit normal on the incident side */
                for (int i = 0; i < 3; i++) m[i] = sgn * out[i];
                refract(d, m, eta, ci, sqrt(1.0 - sin_t2), e);
                double ce = atmos__dot3(e, n_true);
                if (inside ? ce <= 1e-9 : ce >= -1e-9) continue;
            }
            return;
        }
    }
    out[0] = n_true[0];
    out[1] = n_true[1];
    out[2] = n_true[2];
}

void atmos__crystal_trace(const atmos__crystal *c, const atmos__crystal_optics *o, atmos__rng *rng,
                          atmos__crystal_ray *out)
{
    out->n_exit = 0;
    out->reflected = out->transmitted = out->absorbed = out->lost = 0.0;

    /* Incident direction: uniform on the sphere, accepted with probability
     * projected area / (S / 2). S / 2 bounds the projected area of a convex body, and
     * its mean is S / 4 (Cauchy), so about half the candidates are accepted. */
    double d[3];
    double proj;
    const double bound = 0.5 * c->surface_area;
    for (;;) {
        double z = 1.0 - 2.0 * atmos__rng_uniform(rng);
        double phi = 2.0 * ATMOS_PI * atmos__rng_uniform(rng);
        double s = sqrt(fmax(0.0, 1.0 - z * z));
        d[0] = s * cos(phi);
        d[1] = s * sin(phi);
        d[2] = z;
        proj = atmos__crystal_projected_area(c, d);
        if (atmos__rng_uniform(rng) * bound < proj) break;
    }

    /* Entry face: lit faces with probability area |n . d| / projected area (their
     * shadows tile the silhouette), then a uniform point on it (a uniform point on a
     * plane face projects to a uniform point on its shadow). */
    double u = atmos__rng_uniform(rng) * proj;
    int face = -1;
    for (int k = 0; k < ATMOS_CRYSTAL_FACES; k++) {
        double cn = atmos__dot3(c->normal[k], d);
        if (cn >= 0.0) continue;
        face = k;
        u -= c->area[k] * -cn;
        if (u < 0.0) break;
    }
    double p[3];
    sample_face_point(c, face, rng, p);

    /* External reflection and refraction into the crystal. */
    double nrm[3], t[3];
    facet_normal(c->normal[face], d, 0, 1.0 / o->n, o->tilt, rng, nrm);
    double cos_i = -atmos__dot3(d, nrm), cos_t;
    double R = atmos__fresnel(1.0, o->n, cos_i, &cos_t);
    double r[3];
    reflect(d, nrm, r);
    out->theta[0] = angle_between(d, r);
    out->weight[0] = R;
    out->n_exit = 1;
    out->reflected = R;
    refract(d, nrm, 1.0 / o->n, cos_i, cos_t, t);
    double w = 1.0 - R;
    int last = face;

    for (int hit = 0; hit < o->max_hits; hit++) {
        /* Nothing left worth following: at a few 1e-7 of the ray's energy this changes
         * the phase function far below the Monte Carlo noise and halves the cost
         * (partial internal reflections decay like 0.05^n). Counted as lost. */
        if (w < o->cutoff) break;
        /* Next facet: the nearest plane in front of the ray (the crystal is convex).
         * The facet just left is skipped: with tilted normals the ray may graze it. */
        double smin = INFINITY;
        int next = -1;
        for (int k = 0; k < ATMOS_CRYSTAL_FACES; k++) {
            if (k == last) continue;
            double cn = atmos__dot3(c->normal[k], t);
            if (cn <= 1e-12) continue;
            double s = (c->dist[k] - atmos__dot3(c->normal[k], p)) / cn;
            if (s < 0.0) s = 0.0;
            if (s < smin) {
                smin = s;
                next = k;
            }
        }
        if (next < 0) break; /* cannot happen in exact arithmetic; the energy counts as lost */
        for (int i = 0; i < 3; i++) p[i] += smin * t[i];
        if (o->alpha > 0.0) {
            double keep = exp(-o->alpha * smin);
            out->absorbed += w * (1.0 - keep);
            w *= keep;
        }

        facet_normal(c->normal[next], t, 1, o->n, o->tilt, rng, nrm);
        cos_i = atmos__dot3(t, nrm);
        R = atmos__fresnel(o->n, 1.0, cos_i, &cos_t);
        if (R < 1.0) {
            double e[3], m[3] = {-nrm[0], -nrm[1], -nrm[2]};
            refract(t, m, o->n, cos_i, cos_t, e);
            double we = w * (1.0 - R);
            out->theta[out->n_exit] = angle_between(d, e);
            out->weight[out->n_exit] = we;
            out->n_exit++;
            out->transmitted += we;
        }
        reflect(t, nrm, t);
        w *= R;
        last = next;
    }
    out->lost = w;
}
