/* The eye and light passes of the slice renderer (Riley et al. 2004 Eq. 21, 24-26; see
 * slice_frame.c and docs/slice.md): a scalar reference version of each, and a fast version
 * that processes a span in chunks of structure-of-arrays samples so that the compiler
 * vectorises the interpolation, the optics and the exponentials (built for AVX2 as
 * well as the baseline, chosen at run time). Both compute the same quantities in the
 * same order; the fast one uses a polynomial exp (relative error < 1e-7) instead of
 * libm's, and a polynomial log for the thick-slab power of
 * Eq. 25. Eq. 24's light update uses the reference code in both. */
#include "render/slice_internal.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "core/fastmath.h"

/* Linear interpolation in a per-order table at fractional n >= 0; past the last order,
 * F is held (F_n -> 1/2) and S grows by ln F of the last order per order. */
static inline float order_lerp(const float *tab, float n, int extend)
{
    if (!(n > 0.0f)) return tab[0];
    if (n >= (float)SLICE_F_ORDERS) {
        if (!extend) return tab[SLICE_F_ORDERS];
        float slope = tab[SLICE_F_ORDERS] - tab[SLICE_F_ORDERS - 1];
        return tab[SLICE_F_ORDERS] + slope * (n - (float)SLICE_F_ORDERS);
    }
    int i = (int)n;
    float f = n - (float)i;
    return tab[i] + f * (tab[i + 1] - tab[i]);
}


/* Trilinear densities of all fields at render-voxel coordinate (u, v, w). Returns 0
 * if the point is outside the grid or in an empty occupancy block (dens untouched). */
static inline int sgrid_sample_u(const sgrid *g, float u, float v, float w, float *dens)
{
    if (!(u >= 0.0f && v >= 0.0f && w >= 0.0f)) return 0;
    int i = (int)u, j = (int)v, k = (int)w;
    if (i > g->c[0] - 2 || j > g->c[1] - 2 || k > g->c[2] - 2) return 0;
    if (!g->occ[((size_t)(k / SLICE_OCC_B) * g->ob[1] + j / SLICE_OCC_B) * g->ob[0] + i / SLICE_OCC_B]) return 0;
    float fu = u - i, fv = v - j, fw = w - k;
    const int nf = g->nf;
    const size_t sx = (size_t)nf, sy = (size_t)g->c[0] * nf, sz = (size_t)g->c[0] * g->c[1] * nf;
    const float *p = g->v + (((size_t)k * g->c[1] + j) * g->c[0] + i) * nf;
    float w000 = (1 - fu) * (1 - fv) * (1 - fw), w100 = fu * (1 - fv) * (1 - fw), w010 = (1 - fu) * fv * (1 - fw),
          w110 = fu * fv * (1 - fw), w001 = (1 - fu) * (1 - fv) * fw, w101 = fu * (1 - fv) * fw,
          w011 = (1 - fu) * fv * fw, w111 = fu * fv * fw;
    for (int f = 0; f < nf; f++)
        dens[f] = w000 * p[f] + w100 * p[sx + f] + w010 * p[sy + f] + w110 * p[sx + sy + f] + w001 * p[sz + f] +
                  w101 * p[sx + sz + f] + w011 * p[sy + sz + f] + w111 * p[sx + sy + sz + f];
    return 1;
}

/* Light buffer lookup at light-buffer coordinate (fu, fv): bilinear I per wavelength and n. */
static inline void light_lookup(const sjob *j, const float *Ib, const float *nb, float fu, float fv, float *I, float *n)
{
    const int L = j->L;
    const float lim = (float)(L - 1);
    fu = fu < 0.0f ? 0.0f : (fu > lim ? lim : fu);
    fv = fv < 0.0f ? 0.0f : (fv > lim ? lim : fv);
    int a = (int)fu, b = (int)fv;
    if (a > L - 2) a = L - 2;
    if (b > L - 2) b = L - 2;
    float wa = fu - (float)a, wb = fv - (float)b;
    size_t t00 = (size_t)b * L + a, t10 = t00 + 1, t01 = t00 + L, t11 = t01 + 1;
    float w00 = (1 - wa) * (1 - wb), w10 = wa * (1 - wb), w01 = (1 - wa) * wb, w11 = wa * wb;
    const size_t ns = (size_t)j->n + 1; /* texels interleave I per wavelength and n */
    t00 *= ns, t10 *= ns, t01 *= ns, t11 *= ns;
    for (int k = 0; k < j->n; k++) {
        const float *p = Ib + k;
        I[k] = w00 * p[t00] + w10 * p[t10] + w01 * p[t01] + w11 * p[t11];
    }
    *n = w00 * nb[t00] + w10 * nb[t10] + w01 * nb[t01] + w11 * nb[t11];
}

/* Reference eye pass (see slice_internal.h). */
long long atmos__slice_eye_span_ref(const sjob *j, int k, int y, int x0, int x1, const float *Ib, const float *nb)
{
    const int n = j->n, nf = j->nf, no = j->t->no;
    const float kf = (float)k;
    float dens[ATMOS_VOLUME_MAX_FIELDS], I[ATMOS_MAX_WAVELENGTHS], nsc;
    long long count = 0;
    for (int x = x0; x <= x1; x++) {
        size_t p = (size_t)y * j->W + x;
        if (k < j->pk0[p] || k > j->pk1[p]) continue;
        float u = j->pU0[0][p] + kf * j->pdU[0][p], v = j->pU0[1][p] + kf * j->pdU[1][p],
              w = j->pU0[2][p] + kf * j->pdU[2][p];
        if (!sgrid_sample_u(j->g, u, v, w, dens)) continue;
        count++;
        light_lookup(j, Ib, nb, j->pF0[0][p] + kf * j->pdF[0][p], j->pF0[1][p] + kf * j->pdF[1][p], I, &nsc);
        const float delta = j->pdelta[p];
        /* One more scattering than the light has had turns it to the eye (Eq. 26):
         * Ams at fractional order m, linear between orders (and angles). */
        const float m = j->low_albedo ? 1.0f : nsc + 1.0f;
        const float mm = m < 1.0f ? 1.0f : (m > (float)no ? (float)no : m);
        int oi = (int)(mm - 1.0f);
        if (oi > no - 2) oi = no - 2;
        const float fo = mm - 1.0f - (float)oi;
        for (int c = 0; c < n; c++) {
            float bext = 0, src = 0;
            for (int f = 0; f < nf; f++) {
                if (dens[f] <= 0.0f) continue;
                bext += dens[f] * j->t->sig[f][c];
                float bs = dens[f] * j->t->sca[f][c];
                if (bs > 0.0f) {
                    const float *q = j->t->ams[f] + ((size_t)j->pa[p * nf + f] + (size_t)oi * n + c);
                    const size_t an = (size_t)no * n; /* next angle; next order: + n */
                    float lo = q[0] + fo * (q[n] - q[0]);
                    float hi = q[an] + fo * (q[an + n] - q[an]);
                    src += bs * (lo + j->pw[p * nf + f] * (hi - lo) + j->xi);
                }
            }
            if (bext <= 0.0f) continue;
            float tau = bext * delta;
            float Tslab = expf(-tau);
            /* beta_sca Delta of Eq. 26, integrated over the slab with its own
             * attenuation: (1 - T)/beta_ext (-> Delta when thin). */
            float len = tau < 1e-4f ? delta * (1.0f - 0.5f * tau) : (1.0f - Tslab) / bext;
            float contrib = I[c] * src * len;
            float *Lp = j->L_eye + c * j->pst + p, *Tp = j->T_eye + c * j->pst + p;
            if (j->btf) *Lp = *Lp * Tslab + contrib; /* back-to-front: over */
            else *Lp += *Tp * contrib;               /* front-to-back: under */
            *Tp *= Tslab;
        }
    }
    return count;
}

/* Reference light pass of slice k over texels x0..x1 of light row b: reads
 * the light arriving at slice k, writes the light leaving it into the other buffer.
 * Texels a0..a1 may meet occupied blocks; the others of x0..x1 are copied (texels
 * outside x0..x1 are equal in both buffers, see render). */
long long atmos__slice_light_span_ref(const sjob *j, int k, int b, int x0, int x1, int a0, int a1, const float *Ic,
                                      const float *nc, float *In, float *nn)
{
    const int n = j->n, nf = j->nf, L = j->L;
    const size_t ns = (size_t)n + 1; /* texels interleave I per wavelength and n */
    const float delta = j->ldelta;
    float dens[ATMOS_VOLUME_MAX_FIELDS];
    long long count = 0;
    double base[3];
    for (int i = 0; i < 3; i++) base[i] = j->lA[i] + b * j->lEb[i] + k * j->lEk[i];
    const float bu = (float)base[0], bv = (float)base[1], bw = (float)base[2];
    const float eu = (float)j->lEa[0], ev = (float)j->lEa[1], ew = (float)j->lEa[2];
    for (int a = x0; a <= x1; a++) {
        size_t q = (size_t)b * L + a;
        const float n0 = nc[q * ns];
        nn[q * ns] = n0;
        int upd = a >= a0 && a <= a1 && k >= j->lk0[q] && k <= j->lk1[q];
        if (upd) {
            const float af = (float)a;
            upd = sgrid_sample_u(j->g, bu + af * eu, bv + af * ev, bw + af * ew, dens);
        }
        if (!upd) {
            for (int c = 0; c < n; c++) In[q * ns + c] = Ic[q * ns + c];
            continue;
        }
        count++;
        float dn = 0;
        for (int c = 0; c < n; c++) {
            float bext = 0, bsca = 0;
            for (int f = 0; f < nf; f++) {
                bext += dens[f] * j->t->sig[f][c];
                bsca += dens[f] * j->t->sca[f][c];
            }
            dn += bsca * delta;
            if (bext <= 0.0f) {
                In[q * ns + c] = Ic[q * ns + c];
                continue;
            }
            float tau = bext * delta, T = expf(-tau);
            float keep; /* fraction of the scattered light (1 - T) still going forward */
            if (j->low_albedo) {
                keep = 0.0f;
            } else {
                /* The number of scatterings in the slab, ceil(beta Delta) in Eq. 24, taken
                 * continuously as max(1, beta Delta); Eq. 25 raises its worst-case factor to
                 * the same power (see docs/slice.md). */
                float msl = tau > 1.0f ? tau : 1.0f;
                if (bsca <= 0.0f) {
                    keep = 0.0f;
                } else if (!j->eq24) {
                    /* Eq. 25: (alpha F_{floor(n + 1 + beta Delta)})^{beta Delta}. */
                    float idx = floorf(n0 + 1.0f + tau);
                    float aF = 0;
                    for (int f = 0; f < nf; f++)
                        if (dens[f] > 0.0f)
                            aF += dens[f] * j->t->sca[f][c] *
                                  order_lerp(j->t->F[f] + (size_t)c * (SLICE_F_ORDERS + 1), idx, 0);
                    aF /= bext;
                    keep = aF > 0.0f ? (tau > 1.0f ? expf(msl * logf(aF)) : aF) : 0.0f;
                } else {
                    /* Eq. 24: prod_{i=n+1}^{n+m} alpha F_i = alpha^m exp(S(n+m) - S(n)); fields
                     * mixed geometrically by their share of beta_sca. */
                    float lnk = msl * logf(bsca / bext);
                    for (int f = 0; f < nf; f++) {
                        float bs = dens[f] * j->t->sca[f][c];
                        if (bs <= 0.0f) continue;
                        const float *S = j->t->S[f] + (size_t)c * (SLICE_F_ORDERS + 1);
                        lnk += bs / bsca * (order_lerp(S, n0 + msl, 1) - order_lerp(S, n0, 1));
                    }
                    keep = expf(lnk);
                }
            }
            In[q * ns + c] = Ic[q * ns + c] * (T + (1.0f - T) * keep);
        }
        /* Eq. 21: n grows by alpha beta_ext Delta = beta_sca Delta (mean over wavelengths). */
        nn[q * ns] = n0 + dn / (float)n;
    }
    return count;
}

/* ------------------------------------------------------------------ fast passes */

#define CH 64 /* samples per chunk: the SoA scratch stays in L1 */

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define SLICE_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define SLICE_CLONES
#endif


/* ln x for x > 0: x = 2^e m with m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(s),
 * s = (m - 1)/(m + 1), |s| < 0.172, by its series to s^9 (error < 1e-9). Subnormal x
 * are taken as FLT_MIN. Branch-free for vectorisation. */
static inline float log_pos(float x)
{
    x = x < 1.17549435e-38f ? 1.17549435e-38f : x;
    union {
        int32_t i;
        float f;
    } b = {.f = x};
    int32_t e = ((b.i >> 23) & 0xff) - 127;
    b.i = (b.i & 0x007fffff) | 0x3f800000; /* m in [1, 2) */
    float m = b.f;
    const int big = m > 1.41421356f;
    m = big ? 0.5f * m : m;
    e += big;
    const float s = (m - 1.0f) / (m + 1.0f), s2 = s * s;
    float p = 1.0f / 9.0f;
    p = p * s2 + 1.0f / 7.0f;
    p = p * s2 + 1.0f / 5.0f;
    p = p * s2 + 1.0f / 3.0f;
    p = p * s2 + 1.0f;
    return (float)e * 0.693147180559945309f + 2.0f * s * p;
}

/* Trilinear densities of the compacted samples: vox[q] is the grid index of the lower
 * corner (times nf), (fu, fv, fw) the fractions. SoA out: dens[f * CH + q]. The grid
 * holds at most 2 GB, so 32-bit indices suffice. */
static inline void trilinear_soa(const sgrid *g, int m, const int32_t *restrict vox, const float *restrict fu,
                                 const float *restrict fv, const float *restrict fw, float *restrict dens)
{
    const int nf = g->nf;
    const int32_t sx = nf, sy = g->c[0] * nf, sz = g->c[0] * g->c[1] * nf;
    const float *restrict v = g->v;
    for (int f = 0; f < nf; f++) {
        float *restrict d = dens + f * CH;
        for (int q = 0; q < m; q++) {
            const float *p = v + vox[q] + f;
            float a = fu[q], b = fv[q], c = fw[q];
            float w000 = (1 - a) * (1 - b) * (1 - c), w100 = a * (1 - b) * (1 - c), w010 = (1 - a) * b * (1 - c),
                  w110 = a * b * (1 - c), w001 = (1 - a) * (1 - b) * c, w101 = a * (1 - b) * c,
                  w011 = (1 - a) * b * c, w111 = a * b * c;
            d[q] = w000 * p[0] + w100 * p[sx] + w010 * p[sy] + w110 * p[sx + sy] + w001 * p[sz] + w101 * p[sx + sz] +
                   w011 * p[sy + sz] + w111 * p[sx + sy + sz];
        }
    }
}

/* live[f]: whether field f is non-zero at any of the m samples. A field that is zero
 * everywhere in a chunk adds exact zeros to every sum, so its lookups are skipped. */
static inline void fields_live(int nf, int m, const float *dens, int *live)
{
    for (int f = 0; f < nf; f++) {
        const float *d = dens + f * CH;
        int any = 0;
        for (int q = 0; q < m; q++) any |= d[q] != 0.0f;
        live[f] = any;
    }
}

/* Drops the samples at which every field is zero (they change neither the eye nor the
 * light buffer: their sums are exact zeros). Returns the new count. */
static inline int drop_empty(int nf, int m, float *dens, int *id)
{
    int o = 0;
    for (int q = 0; q < m; q++) {
        int any = 0;
        for (int f = 0; f < nf; f++) any |= dens[f * CH + q] != 0.0f;
        if (!any) continue;
        for (int f = 0; f < nf; f++) dens[f * CH + o] = dens[f * CH + q];
        id[o++] = id[q];
    }
    return o;
}

/* Pads the compacted samples m..mv-1 (mv: m rounded up to 8) with copies of the last,
 * so that the vector loops run whole vectors only; results of the copies are never
 * stored. */
static inline int pad_samples(int m, int *id, int32_t *vox, float *fu, float *fv, float *fw)
{
    const int mv = (m + 7) & ~7;
    for (int q = m; q < mv; q++)
        id[q] = id[m - 1], vox[q] = vox[m - 1], fu[q] = fu[m - 1], fv[q] = fv[m - 1], fw[q] = fw[m - 1];
    return mv;
}

static inline int pad_dens(int nf, int m, float *dens, int *id)
{
    const int mv = (m + 7) & ~7;
    for (int q = m; q < mv; q++) {
        id[q] = id[m - 1];
        for (int f = 0; f < nf; f++) dens[f * CH + q] = dens[f * CH + m - 1];
    }
    return mv;
}

/* The compaction shared by both passes: of the chunk's candidate points (render-voxel
 * coordinates u, v, w; ok[q] = 0 for points already rejected), keeps those in the grid
 * and in an occupied block, as sgrid_sample_u decides. Returns how many; id[] holds
 * their chunk positions. */
static inline int compact(const sgrid *g, int cnt, const float *u, const float *v, const float *w,
                          const unsigned char *ok, int *id, int32_t *vox, float *fu, float *fv, float *fw)
{
    const int c0 = g->c[0], c1 = g->c[1], c2 = g->c[2], ob0 = g->ob[0], ob1 = g->ob[1];
    const int nf = g->nf;
    int m = 0;
    for (int q = 0; q < cnt; q++) {
        if (!ok[q]) continue;
        if (!(u[q] >= 0.0f && v[q] >= 0.0f && w[q] >= 0.0f)) continue;
        int i = (int)u[q], jj = (int)v[q], kk = (int)w[q];
        if (i > c0 - 2 || jj > c1 - 2 || kk > c2 - 2) continue;
        if (!g->occ[((size_t)(kk / SLICE_OCC_B) * ob1 + jj / SLICE_OCC_B) * ob0 + i / SLICE_OCC_B]) continue;
        id[m] = q;
        vox[m] = ((kk * c1 + jj) * c0 + i) * nf;
        fu[m] = u[q] - (float)i, fv[m] = v[q] - (float)jj, fw[m] = w[q] - (float)kk;
        m++;
    }
    return m;
}

SLICE_CLONES
long long atmos__slice_eye_span(const sjob *j, int k, int y, int x0, int x1, const float *Ib_, const float *nb_)
{
    const sgrid *g = j->g;
    const stables *t = j->t;
    const int n = j->n, nf = j->nf, no = t->no, L = j->L;
    const int32_t ns = n + 1, LN = L * ns; /* texels interleave I per wavelength and n */
    const int32_t an = no * n;             /* Ams: next angle (next order: + n) */
    const float kf = (float)k, lim = (float)(L - 1), xi = j->xi, fno = (float)no;
    const float *restrict Ib = Ib_, *restrict nb = nb_;
    float u[CH], v[CH], w[CH];
    unsigned char ok[CH];
    int id[CH];
    int32_t vox[CH], lt[CH], ai[ATMOS_VOLUME_MAX_FIELDS][CH];
    float fu[CH], fv[CH], fw[CH], dens[ATMOS_VOLUME_MAX_FIELDS * CH];
    float w00[CH], w10[CH], w01[CH], w11[CH], fo[CH], del[CH], aw[ATMOS_VOLUME_MAX_FIELDS][CH];
    float Ic[CH], bext[CH], src[CH], Tq[CH], Cq[CH];
    long long count = 0;
    for (int xs = x0; xs <= x1; xs += CH) {
        const int cnt = x1 - xs + 1 < CH ? x1 - xs + 1 : CH;
        const size_t p0 = (size_t)y * j->W + xs;
        {
            const float *restrict U0 = j->pU0[0] + p0, *restrict V0 = j->pU0[1] + p0, *restrict W0 = j->pU0[2] + p0;
            const float *restrict dU = j->pdU[0] + p0, *restrict dV = j->pdU[1] + p0, *restrict dW = j->pdU[2] + p0;
            const int *restrict k0 = j->pk0 + p0, *restrict k1 = j->pk1 + p0;
            for (int q = 0; q < cnt; q++) {
                u[q] = U0[q] + kf * dU[q];
                v[q] = V0[q] + kf * dV[q];
                w[q] = W0[q] + kf * dW[q];
                ok[q] = k >= k0[q] && k <= k1[q];
            }
        }
        int m = compact(g, cnt, u, v, w, ok, id, vox, fu, fv, fw);
        if (!m) continue;
        count += m;
        int mv = pad_samples(m, id, vox, fu, fv, fw);
        trilinear_soa(g, mv, vox, fu, fv, fw, dens);
        m = drop_empty(nf, m, dens, id);
        if (!m) continue;
        mv = pad_dens(nf, m, dens, id);
        int live[ATMOS_VOLUME_MAX_FIELDS];
        fields_live(nf, m, dens, live);
        /* Light buffer (bilinear I and n), the Ams order n + 1 and angle, slab length. */
        float nsc[CH];
        for (int q = 0; q < mv; q++) {
            const size_t p = p0 + (size_t)id[q];
            float a = j->pF0[0][p] + kf * j->pdF[0][p], b = j->pF0[1][p] + kf * j->pdF[1][p];
            a = a < 0.0f ? 0.0f : (a > lim ? lim : a);
            b = b < 0.0f ? 0.0f : (b > lim ? lim : b);
            int ia = (int)a, ib = (int)b;
            ia = ia > L - 2 ? L - 2 : ia;
            ib = ib > L - 2 ? L - 2 : ib;
            float wa = a - (float)ia, wb = b - (float)ib;
            w00[q] = (1 - wa) * (1 - wb), w10[q] = wa * (1 - wb), w01[q] = (1 - wa) * wb, w11[q] = wa * wb;
            lt[q] = (ib * L + ia) * ns;
            const int32_t t00 = lt[q];
            nsc[q] = w00[q] * nb[t00] + w10[q] * nb[t00 + ns] + w01[q] * nb[t00 + LN] + w11[q] * nb[t00 + LN + ns];
            del[q] = j->pdelta[p];
        }
        int32_t oi[CH];
        for (int q = 0; q < mv; q++) {
            /* One more scattering than the light has had turns it to the eye (Eq. 26). */
            const float mo = j->low_albedo ? 1.0f : nsc[q] + 1.0f;
            const float mm = mo < 1.0f ? 1.0f : (mo > fno ? fno : mo);
            int o = (int)(mm - 1.0f);
            o = o > no - 2 ? no - 2 : o;
            oi[q] = o;
            fo[q] = mm - 1.0f - (float)o;
        }
        for (int f = 0; f < nf; f++) {
            if (!live[f]) continue;
            const int32_t *restrict pa = j->pa + p0 * nf + f;
            const float *restrict pw = j->pw + p0 * nf + f;
            for (int q = 0; q < mv; q++) {
                ai[f][q] = pa[id[q] * nf] + oi[q] * n;
                aw[f][q] = pw[id[q] * nf];
            }
        }
        for (int c = 0; c < n; c++) {
            const float *restrict Iw = Ib + c;
            for (int q = 0; q < mv; q++) {
                const int32_t t00 = lt[q];
                Ic[q] = w00[q] * Iw[t00] + w10[q] * Iw[t00 + ns] + w01[q] * Iw[t00 + LN] + w11[q] * Iw[t00 + LN + ns];
                bext[q] = 0.0f, src[q] = 0.0f;
            }
            for (int f = 0; f < nf; f++) {
                if (!live[f]) continue;
                const float sg = t->sig[f][c], sa = t->sca[f][c];
                const float *restrict A = t->ams[f] + c; /* next order: + n, next angle: + an */
                const float *restrict d = dens + f * CH;
                for (int q = 0; q < mv; q++) {
                    const float dq = d[q] > 0.0f ? d[q] : 0.0f;
                    bext[q] += dq * sg;
                    const float bs = dq * sa;
                    const int32_t ix = ai[f][q];
                    const float lo = A[ix] + fo[q] * (A[ix + n] - A[ix]);
                    const float hi = A[ix + an] + fo[q] * (A[ix + an + n] - A[ix + an]);
                    const float val = lo + aw[f][q] * (hi - lo);
                    src[q] += bs > 0.0f ? bs * (val + xi) : 0.0f;
                }
            }
            for (int q = 0; q < mv; q++) {
                const float be = bext[q], tau = be * del[q];
                const float T = atmos__expf_poly(-tau);
                /* beta_sca Delta of Eq. 26, integrated over the slab with its own
                 * attenuation: (1 - T)/beta_ext (-> Delta when thin). */
                const float len = tau < 1e-4f ? del[q] * (1.0f - 0.5f * tau) : (1.0f - T) / be;
                const float contrib = Ic[q] * src[q] * len;
                Tq[q] = be > 0.0f ? T : 1.0f;
                Cq[q] = be > 0.0f ? contrib : 0.0f;
            }
            float *restrict Lb = j->L_eye + c * j->pst + p0, *restrict Tb = j->T_eye + c * j->pst + p0;
            if (j->btf)
                for (int q = 0; q < m; q++) {
                    const int x = id[q];
                    Lb[x] = Lb[x] * Tq[q] + Cq[q]; /* back-to-front: over */
                    Tb[x] *= Tq[q];
                }
            else
                for (int q = 0; q < m; q++) {
                    const int x = id[q];
                    Lb[x] += Tb[x] * Cq[q]; /* front-to-back: under */
                    Tb[x] *= Tq[q];
                }
        }
    }
    return count;
}

SLICE_CLONES
long long atmos__slice_light_span(const sjob *j, int k, int b, int x0, int x1, int a0, int a1, const float *Ic_,
                                  const float *nc_, float *In_, float *nn_)
{
    if (j->eq24) return atmos__slice_light_span_ref(j, k, b, x0, x1, a0, a1, Ic_, nc_, In_, nn_);
    const sgrid *g = j->g;
    const stables *t = j->t;
    const int n = j->n, nf = j->nf, L = j->L;
    const size_t ns = (size_t)n + 1; /* texels interleave I per wavelength and n */
    const float delta = j->ldelta;
    const float *restrict Ic = Ic_, *restrict nc = nc_;
    float *restrict In = In_, *restrict nn = nn_;
    double base[3];
    for (int i = 0; i < 3; i++) base[i] = j->lA[i] + b * j->lEb[i] + k * j->lEk[i];
    const float bu = (float)base[0], bv = (float)base[1], bw = (float)base[2];
    const float eu = (float)j->lEa[0], ev = (float)j->lEa[1], ew = (float)j->lEa[2];
    float u[CH], v[CH], w[CH];
    unsigned char ok[CH];
    int id[CH];
    int32_t vox[CH], fi[CH];
    float fu[CH], fv[CH], fw[CH], dens[ATMOS_VOLUME_MAX_FIELDS * CH];
    float n0[CH], dn[CH], Iq[CH], out[CH];
    long long count = 0;
    for (int xs = x0; xs <= x1; xs += CH) {
        const int cnt = x1 - xs + 1 < CH ? x1 - xs + 1 : CH;
        const size_t q0 = (size_t)b * L + xs;
        /* Light that meets nothing passes unchanged. */
        memcpy(In + q0 * ns, Ic + q0 * ns, sizeof(float) * (size_t)cnt * ns);
        {
            const int *restrict k0 = j->lk0 + q0, *restrict k1 = j->lk1 + q0;
            for (int q = 0; q < cnt; q++) {
                const int a = xs + q;
                const float af = (float)a;
                u[q] = bu + af * eu;
                v[q] = bv + af * ev;
                w[q] = bw + af * ew;
                ok[q] = a >= a0 && a <= a1 && k >= k0[q] && k <= k1[q];
            }
        }
        int m = compact(g, cnt, u, v, w, ok, id, vox, fu, fv, fw);
        if (!m) continue;
        count += m;
        int mv = pad_samples(m, id, vox, fu, fv, fw);
        trilinear_soa(g, mv, vox, fu, fv, fw, dens);
        m = drop_empty(nf, m, dens, id);
        if (!m) continue;
        mv = pad_dens(nf, m, dens, id);
        int live[ATMOS_VOLUME_MAX_FIELDS];
        fields_live(nf, m, dens, live);
        for (int q = 0; q < mv; q++) n0[q] = nc[(q0 + (size_t)id[q]) * ns], dn[q] = 0.0f;
        float be[CH], bs[CH], aF[CH], tq[CH], kp[CH], lg[CH];
        for (int c = 0; c < n; c++) {
            const float *restrict Iw = Ic + q0 * ns + c;
            for (int q = 0; q < mv; q++) be[q] = 0.0f, bs[q] = 0.0f, aF[q] = 0.0f, Iq[q] = Iw[(size_t)id[q] * ns];
            for (int f = 0; f < nf; f++) {
                if (!live[f]) continue;
                const float sg = t->sig[f][c], sa = t->sca[f][c];
                const float *restrict d = dens + f * CH;
                for (int q = 0; q < mv; q++) be[q] += d[q] * sg, bs[q] += d[q] * sa;
            }
            for (int q = 0; q < mv; q++) {
                dn[q] += bs[q] * delta;
                tq[q] = be[q] * delta;
                /* Eq. 25's order: floor(n + 1 + beta Delta) */
                const float idx = floorf(n0[q] + 1.0f + tq[q]);
                fi[q] = !(idx > 0.0f) ? 0 : (idx >= (float)SLICE_F_ORDERS ? SLICE_F_ORDERS : (int)idx);
            }
            if (!j->low_albedo)
                for (int f = 0; f < nf; f++) {
                    if (!live[f]) continue;
                    const float sa = t->sca[f][c];
                    const float *restrict Ft = t->F[f] + (size_t)c * (SLICE_F_ORDERS + 1);
                    const float *restrict d = dens + f * CH;
                    for (int q = 0; q < mv; q++) {
                        const float fq = Ft[fi[q]], dq = d[q] > 0.0f ? d[q] : 0.0f;
                        aF[q] += dq * sa * fq;
                    }
                }
            for (int q = 0; q < mv; q++) {
                const float a = aF[q] / be[q];
                /* keep: the fraction of the scattered light (1 - T) still going forward,
                 * Eq. 25's (alpha F)^{max(1, beta Delta)} (docs/slice.md); 0 in low albedo. */
                kp[q] = !j->low_albedo && bs[q] > 0.0f && a > 0.0f ? a : 0.0f;
                lg[q] = log_pos(kp[q]);
            }
            for (int q = 0; q < mv; q++) {
                const float tau = tq[q], T = atmos__expf_poly(-tau);
                const float pw = atmos__expf_poly(tau * lg[q]); /* thick slab: the power */
                const float keep = kp[q] > 0.0f && tau > 1.0f ? pw : kp[q];
                out[q] = be[q] > 0.0f ? Iq[q] * (T + (1.0f - T) * keep) : Iq[q];
            }
            float *restrict Io = In + q0 * ns + c;
            for (int q = 0; q < m; q++) Io[(size_t)id[q] * ns] = out[q];
        }
        /* Eq. 21: n grows by alpha beta_ext Delta = beta_sca Delta (mean over wavelengths). */
        for (int q = 0; q < m; q++) nn[(q0 + (size_t)id[q]) * ns] = n0[q] + dn[q] / (float)n;
    }
    return count;
}
