/* The reference eye and light passes of the slice renderer (Riley et al. 2004 Eq. 21, 24-26;
 * see slice_frame.c and docs/slice.md): plain scalar code with libm's exp, one sample at a
 * time. slice_pass.c holds the fast versions, which compute the same quantities in the same
 * order; the reference decides what they must give. */
#include "render/slice_internal.h"

#include <math.h>

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

/* What a unit density of each field scatters toward the eye at (u, v, w), out[f * n + c], from
 * the field itself, not from the fast pass's per-cell view (which this checks): the diffuse
 * field's L and A = 3/(4 pi) J . d (atmos__lfield_toward, d per cell) read here, the do field's L. */
static void field_toward_eye(const sjob *j, float u, float v, float w, float *out)
{
    const atmos__lfield *F = j->field;
    const int n = j->n;
    float LA[2 * ATMOS_MAX_WAVELENGTHS];
    atmos__lfield_sample(F, j->fg ? F->LA : F->L, j->fg ? 2 * n : n, u, v, w, LA);
    const float *A = LA + n;
    for (int f = 0; f < j->nf; f++)
        for (int c = 0; c < n; c++) {
            const int i = f * ATMOS_MAX_WAVELENGTHS + c;
            out[f * n + c] = j->fsca[i] * (LA[c] + (j->fg ? j->fg[i] * A[c] : 0.0f));
        }
}

/* Reference eye pass (see slice_internal.h). */
long long atmos__slice_eye_span_ref(const sjob *j, int k, int y, int x0, int x1, const float *Ib, const float *nb,
                                    const float *In)
{
    const int n = j->n, nf = j->nf, no = j->t->no;
    const float kf = (float)k;
    float dens[ATMOS_VOLUME_MAX_FIELDS], I[ATMOS_MAX_WAVELENGTHS], I1[ATMOS_MAX_WAVELENGTHS], nsc, n1;
    long long count = 0;
    for (int x = x0; x <= x1; x++) {
        size_t p = (size_t)y * j->W + x;
        if (k < j->pk0[p] || k > j->pk1[p]) continue;
        float u = j->pU0[0][p] + kf * j->pdU[0][p], v = j->pU0[1][p] + kf * j->pdU[1][p],
              w = j->pU0[2][p] + kf * j->pdU[2][p];
        if (!sgrid_sample_u(j->g, u, v, w, dens)) continue;
        count++;
        const float lu = j->pF0[0][p] + kf * j->pdF[0][p], lv = j->pF0[1][p] + kf * j->pdF[1][p];
        light_lookup(j, Ib, nb, lu, lv, I, &nsc);
        if (j->low_albedo) light_lookup(j, In, In + n, lu, lv, I1, &n1); /* the light leaving the slab */
        const float delta = j->pdelta[p];
        /* One more scattering than the light has had turns it to the eye (Eq. 26):
         * Ams at fractional order m, linear between orders (and angles). */
        const float m = j->low_albedo ? 1.0f : nsc + 1.0f;
        const float mm = m < 1.0f ? 1.0f : (m > (float)no ? (float)no : m);
        int oi = (int)(mm - 1.0f);
        if (oi > no - 2) oi = no - 2;
        float fo = mm - 1.0f - (float)oi;
        if (j->two_pop) oi = 2, fo = 1.0f - expf(-j->share_dm * nsc); /* the do field back to front */
        if (j->sharp_eye) { /* the do field: its first order's smooth share (slice_do.c) */
            const float Tg = j->T_eye[(size_t)(n / 2) * j->pst + p];
            fo = 1.0f - expf((j->kap[n / 2] - 1.0f) * logf(Tg > 1e-30f ? Tg : 1e-30f) - j->share * nsc);
        }
        float fv[ATMOS_VOLUME_MAX_FIELDS * ATMOS_MAX_WAVELENGTHS];
        if (j->field) field_toward_eye(j, u, v, w, fv);
        for (int c = 0; c < n; c++) {
            float bext = 0, src = 0, dsrc = 0;
            for (int f = 0; f < nf; f++) {
                if (dens[f] <= 0.0f) continue;
                bext += dens[f] * j->t->sig[f][c];
                float bs = dens[f] * j->t->sca[f][c];
                if (bs > 0.0f) {
                    if (j->field) dsrc += dens[f] * fv[f * n + c];
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
            /* the light buffer's beam also attenuated across the slab where the light pass
               takes all its extinction (atmos__slice_beam_len) */
            const float rI = j->low_albedo ? atmos__slice_beam_ratio(I[c], I1[c]) : 1.0f;
            const float lenI = j->low_albedo ? atmos__slice_beam_len(delta, tau, Tslab, -logf(rI), rI, j->btf) : len;
            /* the diffuse field scattered toward the eye: beta_sca (L + g A), not below 0 */
            float contrib = I[c] * src * lenI + (j->field && dsrc > 0.0f ? dsrc * len : 0.0f);
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

