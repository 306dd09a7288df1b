/* The volume as a participating medium for the path tracer: a per-cell (one cell per
 * 8^3 brick of the volume) minorant and majorant of every field's interpolated density,
 * traversed by a 3D DDA; free flights by delta tracking with spectral-tracking weights;
 * transmittance by residual ratio tracking.
 *
 * Everything runs in the grid's index space (voxel (i,j,k) covers [i, i+1)...), with the
 * ray parameter t in metres along the unit world direction, so extinction coefficients
 * stay in m^-1. The density is the volume's own trilinear interpolant (volume_sample.c's
 * convention: voxel centres at i + 0.5, indices clamped at the faces, zero outside),
 * evaluated here in single precision.
 *
 * Bounds: the interpolant inside cell c is a convex combination of the voxels whose index
 * is in [8c - 1, 8c + 8] (clamped to the grid), so their minimum and maximum bound it
 * everywhere in the cell. The majorant of the extinction at wavelength k is
 * sum_f max_f sigma_f,k, the minorant (control) sum_f min_f sigma_f,k.
 */
#include "render/path_internal.h"

#include <stdlib.h>
#include <string.h>

void atmos__path_medium_free(path_medium *m)
{
    if (!m) return;
    free(m->mm);
    memset(m, 0, sizeof *m);
}

static float voxel_or_zero(const atmos_volume *v, const vol_field *fl, int i, int j, int k)
{
    if (i < 0) i = 0;
    if (j < 0) j = 0;
    if (k < 0) k = 0;
    if (i > v->desc.dims[0] - 1) i = v->desc.dims[0] - 1;
    if (j > v->desc.dims[1] - 1) j = v->desc.dims[1] - 1;
    if (k > v->desc.dims[2] - 1) k = v->desc.dims[2] - 1;
    return vol_voxel(v, fl, i, j, k);
}

atmos_status atmos__path_medium_build(atmos_context *ctx, const atmos_volume *v, double scale, const double offset[3],
                                      const atmos_volume_optics *o, int nwl, path_medium *m)
{
    memset(m, 0, sizeof *m);
    m->v = v;
    m->nf = v->nfields;
    m->scale = (float)scale;
    m->empty = 1;
    for (int a = 0; a < 3; a++) {
        m->n[a] = v->desc.dims[a];
        m->nb[a] = v->nb[a];
        m->org[a] = v->desc.origin_m[a] + offset[a];
    }
    memcpy(m->R, v->desc.rotation, sizeof m->R);
    m->inv_vs = 1.0 / v->desc.voxel_size_m;
    for (int f = 0; f < m->nf; f++)
        for (int k = 0; k < nwl; k++) {
            double se, ss;
            atmos_phase_table_cross_sections(o->phase[f], k, &se, &ss);
            m->sig[f][k] = (float)se;
            m->sca[f][k] = (float)ss;
        }
    const uint64_t nc = v->nbricks;
    m->mm = calloc((size_t)nc * m->nf * 2, sizeof(float));
    if (!m->mm) return atmos__error(ctx, ATMOS_E_NOMEM, "render path: out of memory for the majorant grid");
    int clo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, chi[3] = {-1, -1, -1};
    /* Majorants rounded up (and minorants down) by a relative 1e-5 so that the
     * single-precision interpolant never leaves [min, max]. */
    const float up = 1.00001f, dn = 0.99999f;
    for (int cz = 0; cz < m->nb[2]; cz++)
        for (int cy = 0; cy < m->nb[1]; cy++)
            for (int cx = 0; cx < m->nb[0]; cx++) {
                uint64_t c = ((uint64_t)cz * m->nb[1] + cy) * m->nb[0] + cx;
                int any = 0;
                for (int f = 0; f < m->nf; f++) {
                    const vol_field *fl = &v->field[f];
                    float mx = fl->majorant ? fl->majorant[c] : 0.0f;
                    float mn = 0.0f;
                    if (mx > 0) {
                        /* minimum over the voxels the cell's interpolant reads; stops at 0 */
                        mn = INFINITY;
                        for (int k = cz * VOL_BRICK - 1; k <= cz * VOL_BRICK + VOL_BRICK && mn > 0; k++)
                            for (int j = cy * VOL_BRICK - 1; j <= cy * VOL_BRICK + VOL_BRICK && mn > 0; j++)
                                for (int i = cx * VOL_BRICK - 1; i <= cx * VOL_BRICK + VOL_BRICK; i++) {
                                    float val = voxel_or_zero(v, fl, i, j, k);
                                    if (val < mn) mn = val;
                                    if (!(mn > 0)) break;
                                }
                        if (!(mn > 0)) mn = 0;
                        any = 1;
                    }
                    m->mm[(c * m->nf + f) * 2] = mn * m->scale * dn;
                    m->mm[(c * m->nf + f) * 2 + 1] = mx * m->scale * up;
                }
                if (any) {
                    int cc[3] = {cx, cy, cz};
                    for (int a = 0; a < 3; a++) {
                        if (cc[a] < clo[a]) clo[a] = cc[a];
                        if (cc[a] > chi[a]) chi[a] = cc[a];
                    }
                }
            }
    if (chi[0] >= 0 && scale > 0) {
        m->empty = 0;
        for (int a = 0; a < 3; a++) {
            m->box_lo[a] = (double)clo[a] * VOL_BRICK;
            double hi = (double)(chi[a] + 1) * VOL_BRICK;
            m->box_hi[a] = hi < m->n[a] ? hi : m->n[a];
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
    const double *r = m->R;
    double e[3] = {p[0] - m->org[0], p[1] - m->org[1], p[2] - m->org[2]};
    for (int a = 0; a < 3; a++) {
        q[a] = (r[a] * e[0] + r[3 + a] * e[1] + r[6 + a] * e[2]) * m->inv_vs;
        qd[a] = (r[a] * d[0] + r[3 + a] * d[1] + r[6 + a] * d[2]) * m->inv_vs;
    }
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

/* Single-precision trilinear interpolation of every field at index point (x, y, z). */
void atmos__path_density(const path_medium *m, double x, double y, double z, float *dens)
{
    const atmos_volume *v = m->v;
    const int nf = m->nf;
    if (!(x >= 0 && y >= 0 && z >= 0 && x <= m->n[0] && y <= m->n[1] && z <= m->n[2])) {
        for (int f = 0; f < nf; f++) dens[f] = 0;
        return;
    }
    float px = (float)x - 0.5f, py = (float)y - 0.5f, pz = (float)z - 0.5f;
    float fx = floorf(px), fy = floorf(py), fz = floorf(pz);
    float wx = px - fx, wy = py - fy, wz = pz - fz;
    int i0 = (int)fx, j0 = (int)fy, k0 = (int)fz, i1 = i0 + 1, j1 = j0 + 1, k1 = k0 + 1;
    const int nx = m->n[0] - 1, ny = m->n[1] - 1, nz = m->n[2] - 1;
    if (i0 < 0) i0 = 0;
    if (j0 < 0) j0 = 0;
    if (k0 < 0) k0 = 0;
    if (i1 > nx) i1 = nx;
    if (j1 > ny) j1 = ny;
    if (k1 > nz) k1 = nz;
    if (i0 > nx) i0 = nx;
    if (j0 > ny) j0 = ny;
    if (k0 > nz) k0 = nz;
    const int same = (i0 >> VOL_BRICK_LOG2) == (i1 >> VOL_BRICK_LOG2) && (j0 >> VOL_BRICK_LOG2) == (j1 >> VOL_BRICK_LOG2) &&
                     (k0 >> VOL_BRICK_LOG2) == (k1 >> VOL_BRICK_LOG2);
    const uint64_t b = vol_brick_index(v, i0, j0, k0);
    for (int f = 0; f < nf; f++) {
        const vol_field *fl = &v->field[f];
        float c[8];
        if (same) {
            uint32_t s = fl->table[b];
            if (!s) {
                dens[f] = 0;
                continue;
            }
            const float *p = fl->bricks[s - 1];
            const int M = VOL_BRICK - 1;
            const int a0 = i0 & M, a1 = i1 & M, b0 = (j0 & M) * VOL_BRICK, b1 = (j1 & M) * VOL_BRICK,
                      c0 = (k0 & M) * VOL_BRICK * VOL_BRICK, c1 = (k1 & M) * VOL_BRICK * VOL_BRICK;
            c[0] = p[c0 + b0 + a0], c[1] = p[c0 + b0 + a1], c[2] = p[c0 + b1 + a0], c[3] = p[c0 + b1 + a1];
            c[4] = p[c1 + b0 + a0], c[5] = p[c1 + b0 + a1], c[6] = p[c1 + b1 + a0], c[7] = p[c1 + b1 + a1];
        } else {
            for (int q = 0; q < 8; q++)
                c[q] = vol_voxel(v, fl, q & 1 ? i1 : i0, q & 2 ? j1 : j0, q & 4 ? k1 : k0);
        }
        float x00 = c[0] + wx * (c[1] - c[0]), x10 = c[2] + wx * (c[3] - c[2]);
        float x01 = c[4] + wx * (c[5] - c[4]), x11 = c[6] + wx * (c[7] - c[6]);
        float y0 = x00 + wy * (x10 - x00), y1 = x01 + wy * (x11 - x01);
        float d = (y0 + wz * (y1 - y0)) * m->scale;
        dens[f] = d > 0 ? d : 0;
    }
}

/* 3D DDA over the majorant cells (Amanatides & Woo 1987). */
typedef struct {
    int c[3], st[3];
    double tn[3], dt[3];
    uint64_t idx;
    int64_t sidx[3];
} path_dda;

static void dda_init(const path_medium *m, const double q[3], const double qd[3], double t0, path_dda *g)
{
    for (int a = 0; a < 3; a++) {
        double x = q[a] + t0 * qd[a];
        int c = (int)floor(x * (1.0 / VOL_BRICK));
        if (c < 0) c = 0;
        if (c > m->nb[a] - 1) c = m->nb[a] - 1;
        g->c[a] = c;
        if (qd[a] > 0) {
            g->st[a] = 1;
            g->dt[a] = VOL_BRICK / qd[a];
            g->tn[a] = ((double)(c + 1) * VOL_BRICK - q[a]) / qd[a];
        } else if (qd[a] < 0) {
            g->st[a] = -1;
            g->dt[a] = -VOL_BRICK / qd[a];
            g->tn[a] = ((double)c * VOL_BRICK - q[a]) / qd[a];
        } else {
            g->st[a] = 0;
            g->dt[a] = INFINITY;
            g->tn[a] = INFINITY;
        }
    }
    g->sidx[0] = g->st[0];
    g->sidx[1] = (int64_t)g->st[1] * m->nb[0];
    g->sidx[2] = (int64_t)g->st[2] * m->nb[0] * m->nb[1];
    g->idx = ((uint64_t)g->c[2] * m->nb[1] + g->c[1]) * m->nb[0] + g->c[0];
}

/* End of the current cell (t) and step to the next; returns 0 when leaving the grid. */
static inline int dda_step(const path_medium *m, path_dda *g)
{
    int a = g->tn[0] < g->tn[1] ? (g->tn[0] < g->tn[2] ? 0 : 2) : (g->tn[1] < g->tn[2] ? 1 : 2);
    g->c[a] += g->st[a];
    if (g->c[a] < 0 || g->c[a] >= m->nb[a]) return 0;
    g->tn[a] += g->dt[a];
    g->idx += (uint64_t)g->sidx[a];
    return 1;
}

static inline double dda_tend(const path_dda *g)
{
    double t = g->tn[0] < g->tn[1] ? g->tn[0] : g->tn[1];
    return t < g->tn[2] ? t : g->tn[2];
}

/* The majorant of the carried wavelengths in the current cell. */
static inline double cell_majorant(const path_medium *m, const path_dda *g, const path_bundle *b)
{
    const float *mm = m->mm + g->idx * (uint64_t)m->nf * 2;
    double mu = 0;
    for (int i = 0; i < b->m; i++) {
        double s = 0;
        for (int f = 0; f < m->nf; f++) s += (double)mm[2 * f + 1] * m->sig[f][b->k[i]];
        if (s > mu) mu = s;
    }
    return mu;
}

int atmos__path_majorant_point(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                               const path_bundle *b, double tau_max, double u0, double u, double *tout, double *pdf)
{
    path_dda g;
    double total = 0;
    dda_init(m, q, qd, t0, &g);
    for (double t = t0;;) {
        double te = dda_tend(&g);
        if (te > t1) te = t1;
        if (te > t) total += cell_majorant(m, &g, b) * (te - t);
        if (te >= t1) break;
        t = te;
        if (!dda_step(m, &g)) break;
    }
    if (!(total > 0) || total > tau_max) return 0;
    /* the majorant optical depth from t0 to the point: the first tentative collision forced
     * into the crossing, or uniform in optical depth */
    const double A = -expm1(-total);
    const double target = u0 < 0.5 ? -log1p(-u * A) : u * total;
    double acc = 0;
    dda_init(m, q, qd, t0, &g);
    for (double t = t0;;) {
        double te = dda_tend(&g);
        if (te > t1) te = t1;
        const double mu = te > t ? cell_majorant(m, &g, b) : 0;
        if (mu > 0 && acc + mu * (te - t) > target) {
            double x = t + (target - acc) / mu;
            *tout = x < te ? x : te;
            *pdf = 0.5 * mu * exp(-target) / A + 0.5 * mu / total;
            return 1;
        }
        acc += mu * (te - t);
        if (te >= t1 || !dda_step(m, &g)) break;
        t = te;
    }
    return 0; /* rounding: the target beyond the sum of the second pass */
}

int atmos__path_free_flight(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                            const path_bundle *b, double *w, atmos__stream *r, double *tout, float *dens, long long *tentative)
{
    const int nf = m->nf, nb = b->m;
    path_dda g;
    dda_init(m, q, qd, t0, &g);
    double t = t0;
    double tau = -log(1.0 - atmos__stream_u(r)); /* optical depth (of the majorant) to the next tentative collision */
    long long tc = 0;
    int res = 0;
    for (;;) {
        double te = dda_tend(&g);
        if (te > t1) te = t1;
        const float *mm = m->mm + g.idx * (uint64_t)nf * 2;
        double mu = 0;
        for (int i = 0; i < nb; i++) {
            double s = 0;
            for (int f = 0; f < nf; f++) s += (double)mm[2 * f + 1] * m->sig[f][b->k[i]];
            if (s > mu) mu = s;
        }
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
            tau = -log(1.0 - atmos__stream_u(r));
        }
        if (te >= t1) break;
        t = te;
        if (!dda_step(m, &g)) break;
    }
out:
    *tentative += tc;
    return res;
}

void atmos__path_transmittance(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                               const path_bundle *b, atmos__stream *r, double *T)
{
    const int nf = m->nf, nb = b->m;
    double tauc[PATH_B];
    for (int i = 0; i < nb; i++) T[i] = 1, tauc[i] = 0;
    path_dda g;
    dda_init(m, q, qd, t0, &g);
    double t = t0;
    float dens[PATH_F];
    for (;;) {
        double te = dda_tend(&g);
        if (te > t1) te = t1;
        const float *mm = m->mm + g.idx * (uint64_t)nf * 2;
        double muc[PATH_B], mur = 0;
        int occupied = 0;
        for (int f = 0; f < nf; f++) occupied |= mm[2 * f + 1] > 0;
        if (occupied && te > t) {
            for (int i = 0; i < nb; i++) {
                double c = 0, rr = 0;
                for (int f = 0; f < nf; f++) {
                    c += (double)mm[2 * f] * m->sig[f][b->k[i]];
                    rr += (double)(mm[2 * f + 1] - mm[2 * f]) * m->sig[f][b->k[i]];
                }
                muc[i] = c;
                tauc[i] += c * (te - t);
                if (rr > mur) mur = rr;
            }
            if (mur > 0) {
                double s = t;
                for (;;) {
                    s += -log(1.0 - atmos__stream_u(r)) / mur;
                    if (s >= te) break;
                    atmos__path_density(m, q[0] + s * qd[0], q[1] + s * qd[1], q[2] + s * qd[2], dens);
                    double tmax = 0;
                    for (int i = 0; i < nb; i++) {
                        double st = 0;
                        for (int f = 0; f < nf; f++) st += (double)dens[f] * m->sig[f][b->k[i]];
                        double fac = 1.0 - (st - muc[i]) / mur;
                        T[i] *= fac < 0 ? 0 : (fac > 1 ? 1 : fac);
                        if (T[i] > tmax) tmax = T[i];
                    }
                    if (!(tmax > 0)) return;
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
                    return;
                }
                for (int i = 0; i < nb; i++) T[i] *= 4;
            }
        }
        if (te >= t1) break;
        t = te;
        if (!dda_step(m, &g)) break;
    }
    for (int i = 0; i < nb; i++) T[i] *= exp(-tauc[i]);
}
