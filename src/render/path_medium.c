/* The volume as a participating medium for the path tracer: free flights by delta
 * tracking with spectral-tracking weights, transmittance by residual ratio tracking and
 * forced points, all over the bricks of the volume walked by the accessor's DDA
 * (volume/volume_access.h: Amanatides & Woo 1987) against each brick's bounds of the
 * interpolated density, which the volume built at finalize (volume/volume_range.c).
 *
 * This file adds the optics: cross-sections per field and wavelength, their truncation,
 * and per brick the majorant (and minorant) of the extinction of the carried
 * wavelengths, sum_f max_f sigma_f,k (sum_f min_f sigma_f,k).
 *
 * Everything runs in the grid's index space (voxel (i,j,k) covers [i, i+1)...), with the
 * ray parameter t in metres along the unit world direction, so extinction coefficients
 * stay in m^-1. The density is the volume's trilinear interpolant evaluated in single
 * precision (the accessor's float sampler) times the density scale.
 */
#include "render/path_internal.h"

#include <stddef.h>
#include <string.h>

/* The volume's bounds hold for the exact interpolant; scaled and rounded outwards by a
 * relative 1e-5 in single precision they also hold for atmos__path_density's float
 * arithmetic. Computed per brick visit, in this order, so that the bounds (and with
 * them every free flight) are exactly those of a grid scaled at build time. */
#define BOUND_UP 1.00001f
#define BOUND_DN 0.99999f

/* path_medium.h's union: the named fields are the transform's. */
_Static_assert(offsetof(path_medium, org) == offsetof(path_medium, x.org) &&
                   offsetof(path_medium, R) == offsetof(path_medium, x.R) &&
                   offsetof(path_medium, inv_vs) == offsetof(path_medium, x.inv_vs),
               "path_medium: org, R, inv_vs must alias the transform");

void atmos__path_medium_free(path_medium *m)
{
    if (!m) return;
    memset(m, 0, sizeof *m);
}

atmos_status atmos__path_medium_build(atmos_context *ctx, const atmos_volume *v, double scale, const double offset[3],
                                      const atmos_volume_optics *o, int nwl, path_medium *m)
{
    (void)ctx;
    memset(m, 0, sizeof *m);
    m->v = v;
    m->nf = v->nfields;
    m->scale = (float)scale;
    m->empty = 1;
    atmos__vol_xform_init(v, offset, &m->x);
    for (int f = 0; f < m->nf; f++)
        for (int k = 0; k < nwl; k++) {
            double se, ss;
            atmos_phase_table_cross_sections(o->phase[f], k, &se, &ss);
            m->sig[f][k] = (float)se;
            m->sca[f][k] = (float)ss;
        }
    int clo[3], chi[3];
    if (atmos__vol_range_box(v, clo, chi) && scale > 0) {
        m->empty = 0;
        for (int a = 0; a < 3; a++) {
            m->box_lo[a] = (double)clo[a] * VOL_BRICK;
            double hi = (double)(chi[a] + 1) * VOL_BRICK;
            m->box_hi[a] = hi < v->desc.dims[a] ? hi : v->desc.dims[a];
        }
    }
    return ATMOS_OK;
}

void atmos__path_medium_truncate(path_medium *m, int nwl, const float trunc[][ATMOS_MAX_WAVELENGTHS])
{
    for (int f = 0; f < m->nf; f++)
        for (int k = 0; k < nwl; k++) {
            const double t = trunc[f][k], sca = m->sca[f][k], se = m->sig[f][k];
            if (!(t > 0)) continue;
            double se2 = se - t * sca;
            m->sca[f][k] = (float)(sca * (1.0 - t));
            m->sig[f][k] = (float)(se2 > m->sca[f][k] ? se2 : m->sca[f][k]);
        }
}

void atmos__path_to_index(const path_medium *m, const double p[3], const double d[3], double q[3], double qd[3])
{
    atmos__vol_point_to_index(&m->x, p, q);
    atmos__vol_dir_to_index(&m->x, d, qd);
}

int atmos__path_clip(const path_medium *m, const double q[3], const double qd[3], double tmax, double *t0, double *t1)
{
    if (m->empty) return 0;
    double a0 = 0, a1 = tmax;
    for (int a = 0; a < 3; a++) {
        if (qd[a] == 0) {
            if (q[a] < m->box_lo[a] || q[a] > m->box_hi[a]) return 0;
            continue;
        }
        double inv = 1.0 / qd[a];
        double ta = (m->box_lo[a] - q[a]) * inv, tb = (m->box_hi[a] - q[a]) * inv;
        if (ta > tb) {
            double x = ta;
            ta = tb, tb = x;
        }
        if (ta > a0) a0 = ta;
        if (tb < a1) a1 = tb;
    }
    if (!(a0 < a1)) return 0;
    *t0 = a0, *t1 = a1;
    return 1;
}

/* Scaled densities of every field at index point (x, y, z): the accessor's float sampler. */
void atmos__path_density(const path_medium *m, double x, double y, double z, float *dens)
{
    const atmos_volume *v = m->v;
    const int nf = m->nf;
    const double q[3] = {x, y, z};
    if (!atmos__vol_inside(v, q)) {
        for (int f = 0; f < nf; f++) dens[f] = 0;
        return;
    }
    atmos__vol_corners c;
    float w[3];
    atmos__vol_setup_f(v, q, &c, w);
    for (int f = 0; f < nf; f++) {
        const float d = atmos__vol_sample_f(v, f, &c, w) * m->scale;
        dens[f] = d > 0 ? d : 0;
    }
}

/* The majorant of the carried wavelengths in the DDA's current brick: max over them of
 * sum_f hi_f sigma_f,k with hi_f the field's scaled upper bound. Fields outer, wavelengths
 * inner: each bound is computed once, and each wavelength's sum still runs over the fields
 * in order (the same sums as a wavelength-outer loop). */
static inline double cell_majorant(const path_medium *m, const atmos__vol_dda *g, const path_bundle *b)
{
    if (atmos__vol_dda_empty(m->v, g)) return 0; /* all-zero bounds */
    const float *rg = atmos__vol_dda_range(m->v, g);
    double s[PATH_B] = {0};
    for (int f = 0; f < m->nf; f++) {
        const float hi = rg[2 * f + 1] * m->scale * BOUND_UP;
        for (int i = 0; i < b->m; i++) s[i] += (double)hi * m->sig[f][b->k[i]];
    }
    double mu = 0;
    for (int i = 0; i < b->m; i++)
        if (s[i] > mu) mu = s[i];
    return mu;
}

int atmos__path_majorant_point(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                               const path_bundle *b, double tau_max, double u0, double u, double *tout, double *pdf)
{
    atmos__vol_dda g;
    double total = 0;
    atmos__vol_dda_init(m->v, q, qd, t0, &g);
    for (double t = t0;;) {
        double te = atmos__vol_dda_tend(&g);
        if (te > t1) te = t1;
        if (te > t) total += cell_majorant(m, &g, b) * (te - t);
        if (te >= t1) break;
        t = te;
        if (!atmos__vol_dda_step(m->v, &g)) break;
    }
    if (!(total > 0) || total > tau_max) return 0;
    /* the majorant optical depth from t0 to the point: the first tentative collision forced
     * into the crossing, or uniform in optical depth */
    const double A = -expm1(-total);
    const double target = u0 < 0.5 ? -log1p(-u * A) : u * total;
    double acc = 0;
    atmos__vol_dda_init(m->v, q, qd, t0, &g);
    for (double t = t0;;) {
        double te = atmos__vol_dda_tend(&g);
        if (te > t1) te = t1;
        const double mu = te > t ? cell_majorant(m, &g, b) : 0;
        if (mu > 0 && acc + mu * (te - t) > target) {
            double x = t + (target - acc) / mu;
            *tout = x < te ? x : te;
            *pdf = 0.5 * mu * exp(-target) / A + 0.5 * mu / total;
            return 1;
        }
        acc += mu * (te - t);
        if (te >= t1 || !atmos__vol_dda_step(m->v, &g)) break;
        t = te;
    }
    return 0; /* rounding: the target beyond the sum of the second pass */
}

/* Every PATH_WALK_RR steps of one walk (tentative collisions of a free flight, steps of a
 * ratio-tracked shadow ray) the walk plays Russian roulette: it goes on with probability 1/2
 * and doubled weights, else ends (weights 0). Unbiased; it bounds the expected steps of a
 * walk that would otherwise take ~ its majorant optical depth in steps, which in an optically
 * huge medium (a density scale of 1e12, voxels of 1e20 m) is more than a render can take, or
 * never ends when the steps fall below the position's precision. In the media of the
 * gallery a walk never takes that many steps (no image changes). *res = -2 when it ends. */
static _Thread_local long long walks_ended; /* walks ended so, for atmos__path_walks_ended */

static int walk_roulette(double *w, int nb, atmos__stream *r, int *res)
{
    if (atmos__stream_u(r) < 0.5) {
        for (int i = 0; i < nb; i++) w[i] *= 2;
        return 1;
    }
    for (int i = 0; i < nb; i++) w[i] = 0;
    *res = -2;
    walks_ended++;
    return 0;
}

long long atmos__path_walks_ended(void)
{
    const long long n = walks_ended;
    walks_ended = 0;
    return n;
}

int atmos__path_free_flight(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                            const path_bundle *b, double *w, atmos__stream *r, double *tout, float *dens, long long *tentative)
{
    const int nf = m->nf, nb = b->m;
    atmos__vol_dda g;
    atmos__vol_dda_init(m->v, q, qd, t0, &g);
    double t = t0;
    double tau = -log(1.0 - atmos__stream_u(r)); /* optical depth (of the majorant) to the next tentative collision */
    long long tc = 0;
    int res = 0;
    for (;;) {
        double te = atmos__vol_dda_tend(&g);
        if (te > t1) te = t1;
        const double mu = cell_majorant(m, &g, b);
        while (mu > 0 && te > t) {
            double dtau = mu * (te - t);
            if (tau >= dtau) {
                tau -= dtau;
                break;
            }
            t += tau / mu;
            tc++;
            atmos__path_density(m, q[0] + t * qd[0], q[1] + t * qd[1], q[2] + t * qd[2], dens);
            double ss[PATH_B], sn[PATH_B], ns = 0, nn = 0;
            for (int i = 0; i < nb; i++) {
                double st = 0, sc = 0;
                for (int f = 0; f < nf; f++) {
                    st += (double)dens[f] * m->sig[f][b->k[i]];
                    sc += (double)dens[f] * m->sca[f][b->k[i]];
                }
                ss[i] = sc;
                sn[i] = mu - st > 0 ? mu - st : 0;
                ns += w[i] * ss[i];
                nn += w[i] * sn[i];
            }
            if (!(ns + nn > 0)) {
                res = -1;
                goto out;
            }
            const double ps = ns / (ns + nn);
            if (atmos__stream_u(r) < ps) {
                for (int i = 0; i < nb; i++) w[i] *= ss[i] / (mu * ps);
                *tout = t;
                res = 1;
                goto out;
            }
            for (int i = 0; i < nb; i++) w[i] *= sn[i] / (mu * (1.0 - ps));
            if ((tc & (PATH_WALK_RR - 1)) == 0 && !walk_roulette(w, nb, r, &res)) goto out;
            tau = -log(1.0 - atmos__stream_u(r));
        }
        if (te >= t1) break;
        t = te;
        if (!atmos__vol_dda_step(m->v, &g)) break;
    }
out:
    *tentative += tc;
    return res;
}

int atmos__path_transmittance(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                              const path_bundle *b, atmos__stream *r, double *T)
{
    const int nf = m->nf, nb = b->m;
    long long steps = 0;
    double tauc[PATH_B];
    for (int i = 0; i < nb; i++) T[i] = 1, tauc[i] = 0;
    atmos__vol_dda g;
    atmos__vol_dda_init(m->v, q, qd, t0, &g);
    double t = t0;
    float dens[PATH_F];
    for (;;) {
        double te = atmos__vol_dda_tend(&g);
        if (te > t1) te = t1;
        /* per carried wavelength the control muc = sum_f lo_f sigma_f,k and the residual
         * sum_f (hi_f - lo_f) sigma_f,k of this brick (fields outer, as in cell_majorant) */
        double muc[PATH_B] = {0}, res[PATH_B] = {0}, mur = 0;
        int occupied = 0;
        if (!atmos__vol_dda_empty(m->v, &g) && te > t) {
            const float *rg = atmos__vol_dda_range(m->v, &g);
            for (int f = 0; f < nf; f++) {
                const float lo = rg[2 * f] * m->scale * BOUND_DN, hi = rg[2 * f + 1] * m->scale * BOUND_UP;
                occupied |= hi > 0;
                for (int i = 0; i < nb; i++) {
                    muc[i] += (double)lo * m->sig[f][b->k[i]];
                    res[i] += (double)(hi - lo) * m->sig[f][b->k[i]];
                }
            }
        }
        if (occupied) {
            for (int i = 0; i < nb; i++) {
                tauc[i] += muc[i] * (te - t);
                if (res[i] > mur) mur = res[i];
            }
            if (mur > 0) {
                double s = t;
                for (;;) {
                    s += -log(1.0 - atmos__stream_u(r)) / mur;
                    if (s >= te) break;
                    int dead = 0;
                    if ((++steps & (PATH_WALK_RR - 1)) == 0 && !walk_roulette(T, nb, r, &dead)) return 1;
                    atmos__path_density(m, q[0] + s * qd[0], q[1] + s * qd[1], q[2] + s * qd[2], dens);
                    double tmax = 0;
                    for (int i = 0; i < nb; i++) {
                        double st = 0;
                        for (int f = 0; f < nf; f++) st += (double)dens[f] * m->sig[f][b->k[i]];
                        double fac = 1.0 - (st - muc[i]) / mur;
                        T[i] *= fac < 0 ? 0 : (fac > 1 ? 1 : fac);
                        if (T[i] > tmax) tmax = T[i];
                    }
                    if (!(tmax > 0)) return 0;
                }
            }
            /* Russian roulette once the transmittance is certainly small. */
            double tmax = 0, cmin = INFINITY;
            for (int i = 0; i < nb; i++) {
                if (T[i] > tmax) tmax = T[i];
                if (tauc[i] < cmin) cmin = tauc[i];
            }
            if (tmax * exp(-cmin) < 1e-2) {
                if (atmos__stream_u(r) >= 0.25) {
                    for (int i = 0; i < nb; i++) T[i] = 0;
                    return 0;
                }
                for (int i = 0; i < nb; i++) T[i] *= 4;
            }
        }
        if (te >= t1) break;
        t = te;
        if (!atmos__vol_dda_step(m->v, &g)) break;
    }
    for (int i = 0; i < nb; i++) T[i] *= exp(-tauc[i]);
    return 0;
}
