/* The fast eye and light passes of the slice renderer (Riley et al. 2004 Eq. 21, 24-26; see
 * slice_frame.c and docs/slice.md). They process a span in chunks of structure-of-arrays
 * samples so that the compiler vectorises the interpolation, the optics and the exponentials
 * (built for AVX2 as well as the baseline, chosen at run time), and compute the same
 * quantities in the same order as the reference passes of slice_pass_ref.c; they use a
 * polynomial exp (relative error < 1e-7) instead of libm's, and a polynomial log for the
 * thick-slab power of Eq. 25. Eq. 24's light update uses the reference code in both. */
#include "render/slice_internal.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "core/fastmath.h"

#define CH 64 /* samples per chunk: the SoA scratch stays in L1 */

#define SLICE_CLONES ATMOS_CLONES


/* ln x for x > 0: x = 2^e m with m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(s),
 * s = (m - 1)/(m + 1), |s| < 0.172, by its series to s^9 (error < 1e-9). Subnormal x
 * are taken as FLT_MIN. Branch-free for vectorisation. */
ATMOS_CLONE_HELPER float log_pos(float x)
{
    x = atmos__select_f(x < 1.17549435e-38f, 1.17549435e-38f, x);
    union {
        int32_t i;
        float f;
    } b = {.f = x};
    int32_t e = ((b.i >> 23) & 0xff) - 127;
    b.i = (b.i & 0x007fffff) | 0x3f800000; /* m in [1, 2) */
    float m = b.f;
    const int big = m > 1.41421356f;
    m = atmos__select_f(big, 0.5f * m, m);
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
ATMOS_CLONE_HELPER void trilinear_soa(const sgrid *g, int m, const int32_t *restrict vox, const float *restrict fu,
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
ATMOS_CLONE_HELPER void fields_live(int nf, int m, const float *dens, int *live)
{
    for (int f = 0; f < nf; f++) {
        const float *d = dens + f * CH;
        int any = 0;
        for (int q = 0; q < m; q++) any |= d[q] != 0.0f;
        live[f] = any;
    }
}

/* Samples at which every field is zero change neither the eye nor the light buffer (their
 * sums are exact zeros, their transmittance exactly 1), so they may be kept or dropped
 * without changing a bit: when more than a quarter of the m samples are empty they are
 * dropped (branch-free packing), otherwise kept (computing them costs less than packing).
 * Returns the new count (0: all empty). */
ATMOS_CLONE_HELPER int drop_empty(int nf, int m, float *dens, int *id)
{
    int nz[CH], live = 0;
    for (int q = 0; q < m; q++) nz[q] = 0;
    for (int f = 0; f < nf; f++)
        for (int q = 0; q < m; q++) nz[q] |= dens[f * CH + q] != 0.0f;
    for (int q = 0; q < m; q++) live += nz[q];
    if (live == 0 || 4 * live >= 3 * m) return live ? m : 0;
    int o = 0;
    for (int q = 0; q < m; q++) {
        for (int f = 0; f < nf; f++) dens[f * CH + o] = dens[f * CH + q];
        id[o] = id[q];
        o += nz[q];
    }
    return o;
}

/* Pads the compacted samples m..mv-1 (mv: m rounded up to 8) with copies of the last,
 * so that the vector loops run whole vectors only; results of the copies are never
 * stored. */
ATMOS_CLONE_HELPER int pad_samples(int m, int *id, int32_t *vox, float *fu, float *fv, float *fw)
{
    const int mv = (m + 7) & ~7;
    for (int q = m; q < mv; q++)
        id[q] = id[m - 1], vox[q] = vox[m - 1], fu[q] = fu[m - 1], fv[q] = fv[m - 1], fw[q] = fw[m - 1];
    return mv;
}

ATMOS_CLONE_HELPER int pad_dens(int nf, int m, float *dens, int *id)
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
 * and in an occupied block, as the reference's trilinear lookup decides. Returns how many;
 * id[] holds their chunk positions. The tests, lower corners and fractions run as one
 * vector loop over all points (rejected ones clamped to voxel 0, so that the occupancy
 * gather stays inside the grid); a branch-free scalar loop then packs the kept ones. */
ATMOS_CLONE_HELPER int compact(const sgrid *g, int cnt, const float *restrict u, const float *restrict v,
                               const float *restrict w, const int32_t *restrict ok, int *restrict id,
                               int32_t *restrict vox, float *restrict fu, float *restrict fv, float *restrict fw)
{
    const int c0 = g->c[0], c1 = g->c[1], ob0 = g->ob[0], ob1 = g->ob[1], nf = g->nf;
    const float u1 = (float)(c0 - 1), v1 = (float)(c1 - 1), w1 = (float)(g->c[2] - 1);
    const int32_t *restrict occ = g->occ;
    int32_t keep[CH], vx[CH];
    float a[CH], b[CH], c[CH];
    for (int q = 0; q < cnt; q++) {
        const float uq = u[q], vq = v[q], wq = w[q];
        /* 0 <= floor(x) <= c - 2, i.e. 0 <= x < c - 1 (NaN fails) */
        const int in = ok[q] & (uq >= 0.0f) & (vq >= 0.0f) & (wq >= 0.0f) & (uq < u1) & (vq < v1) & (wq < w1);
        const int i = in ? (int)uq : 0, jj = in ? (int)vq : 0, kk = in ? (int)wq : 0;
        const int32_t ob = (kk / SLICE_OCC_B * ob1 + jj / SLICE_OCC_B) * ob0 + i / SLICE_OCC_B;
        keep[q] = in & (occ[ob] != 0);
        vx[q] = ((kk * c1 + jj) * c0 + i) * nf;
        a[q] = uq - (float)i, b[q] = vq - (float)jj, c[q] = wq - (float)kk;
    }
    for (int q = cnt; q < ((cnt + 7) & ~7); q++) keep[q] = 0;
    /* Points come in runs (a span's ends, empty blocks), so groups of eight that are all
     * rejected are skipped and groups all kept are copied whole. */
    int m = 0;
    for (int g0 = 0; g0 < cnt; g0 += 8) {
        const int32_t *kq = keep + g0;
        const int kept = (kq[0] + kq[1]) + (kq[2] + kq[3]) + ((kq[4] + kq[5]) + (kq[6] + kq[7]));
        if (!kept) continue;
        if (kept == 8) {
            for (int i = 0; i < 8; i++) {
                const int q = g0 + i;
                id[m + i] = q, vox[m + i] = vx[q], fu[m + i] = a[q], fv[m + i] = b[q], fw[m + i] = c[q];
            }
            m += 8;
            continue;
        }
        const int g1 = g0 + 8 < cnt ? g0 + 8 : cnt;
        for (int q = g0; q < g1; q++) {
            id[m] = q, vox[m] = vx[q], fu[m] = a[q], fv[m] = b[q], fw[m] = c[q];
            m += keep[q];
        }
    }
    return m;
}

/* One chunk of eye samples (pixels x of one row on one slice) as structure of arrays. */
typedef struct {
    int m, mv;  /* samples, and that count padded to whole vectors */
    int contig; /* the samples are points 0..m-1 of the chunk (id[q] = q): their per-point
                   data is read and written without indices (see lane) */
    int id[CH];
    int32_t vox[CH], lt[CH], oi[CH], ai[ATMOS_VOLUME_MAX_FIELDS][CH];
    float fu[CH], fv[CH], fw[CH], dens[ATMOS_VOLUME_MAX_FIELDS * CH];
    float w00[CH], w10[CH], w01[CH], w11[CH], fo[CH], del[CH], nsc[CH], aw[ATMOS_VOLUME_MAX_FIELDS][CH];
    float pt[3][CH]; /* eye chunks: the points' render-voxel coordinates, by chunk position */
    int live[ATMOS_VOLUME_MAX_FIELDS];
} echunk;

/* Of a chunk's cnt candidate points (render-voxel coordinates u, v, w; ok[q] = 0 for
 * points already rejected), the ones that meet occupied blocks and a non-zero density, with
 * their densities. Returns the number of points looked up in the grid (e->m: kept). */
ATMOS_CLONE_HELPER int chunk_lookup(const sgrid *g, int cnt, const float *u, const float *v, const float *w,
                                    const int32_t *ok, echunk *e)
{
    e->m = compact(g, cnt, u, v, w, ok, e->id, e->vox, e->fu, e->fv, e->fw);
    const int looked = e->m;
    if (!e->m) return 0;
    e->mv = pad_samples(e->m, e->id, e->vox, e->fu, e->fv, e->fw);
    trilinear_soa(g, e->mv, e->vox, e->fu, e->fv, e->fw, e->dens);
    e->m = drop_empty(g->nf, e->m, e->dens, e->id);
    if (!e->m) return looked;
    e->mv = pad_dens(g->nf, e->m, e->dens, e->id);
    fields_live(g->nf, e->m, e->dens, e->live);
    e->contig = e->id[e->m - 1] == e->m - 1; /* ids increase from 0 */
    return looked;
}

/* The chunk point of sample q: id[q], which for a contiguous chunk is q itself, or for its
 * padded lanes (q >= m) the last sample's, as pad_samples made them (so a computed index
 * lets the loops read the per-point arrays without the indirection). */
ATMOS_CLONE_HELPER int lane(const echunk *e, int q) { return e->contig ? (q < e->m ? q : e->m - 1) : e->id[q]; }

/* The chunk of pixels p0.. (cnt of them) on slice k: chunk_lookup of their samples. */
ATMOS_CLONE_HELPER int eye_samples(const sjob *j, int k, size_t p0, int cnt, echunk *e)
{
    const float kf = (float)k;
    float *restrict u = e->pt[0], *restrict v = e->pt[1], *restrict w = e->pt[2];
    int32_t ok[CH];
    const float *restrict U0 = j->pU0[0] + p0, *restrict V0 = j->pU0[1] + p0, *restrict W0 = j->pU0[2] + p0;
    const float *restrict dU = j->pdU[0] + p0, *restrict dV = j->pdU[1] + p0, *restrict dW = j->pdU[2] + p0;
    const int *restrict k0 = j->pk0 + p0, *restrict k1 = j->pk1 + p0;
    for (int q = 0; q < cnt; q++) {
        u[q] = U0[q] + kf * dU[q];
        v[q] = V0[q] + kf * dV[q];
        w[q] = W0[q] + kf * dW[q];
        ok[q] = k >= k0[q] && k <= k1[q];
    }
    return chunk_lookup(j->g, cnt, u, v, w, ok, e);
}

/* The samples' light-buffer texel (lt, the row-major offset of the lower-left one) and
 * bilinear weights, and their slab lengths. */
ATMOS_CLONE_HELPER void eye_texels(const sjob *j, int k, size_t p0, echunk *e)
{
    const int L = j->L;
    const int32_t ns = j->n + 1;
    const float kf = (float)k, lim = (float)(L - 1);
    for (int q = 0; q < e->mv; q++) {
        const size_t p = p0 + (size_t)lane(e, q);
        float a = j->pF0[0][p] + kf * j->pdF[0][p], b = j->pF0[1][p] + kf * j->pdF[1][p];
        a = a < 0.0f ? 0.0f : (a > lim ? lim : a);
        b = b < 0.0f ? 0.0f : (b > lim ? lim : b);
        int ia = (int)a, ib = (int)b;
        ia = ia > L - 2 ? L - 2 : ia;
        ib = ib > L - 2 ? L - 2 : ib;
        const float wa = a - (float)ia, wb = b - (float)ib;
        e->w00[q] = (1 - wa) * (1 - wb), e->w10[q] = wa * (1 - wb), e->w01[q] = (1 - wa) * wb, e->w11[q] = wa * wb;
        e->lt[q] = (ib * L + ia) * ns;
        e->del[q] = j->pdelta[p];
    }
}

/* Bilinear light-buffer value at the samples: component c of the texels ([texel + c]). */
ATMOS_CLONE_HELPER void eye_bilinear(const echunk *e, const float *restrict B, int32_t ns, int32_t LN, float *restrict out)
{
    for (int q = 0; q < e->mv; q++) {
        const int32_t t00 = e->lt[q];
        out[q] = e->w00[q] * B[t00] + e->w10[q] * B[t00 + ns] + e->w01[q] * B[t00 + LN] + e->w11[q] * B[t00 + LN + ns];
    }
}

/* The Ams order (one more scattering than the light has had turns it to the eye, Eq. 26)
 * and each live field's Ams row and angle weight. */
ATMOS_CLONE_HELPER void eye_orders(const sjob *j, size_t p0, echunk *e)
{
    const int n = j->n, nf = j->nf, no = j->t->no;
    const float fno = (float)no;
    for (int q = 0; q < e->mv; q++) {
        const float mo = j->low_albedo ? 1.0f : e->nsc[q] + 1.0f;
        const float mm = mo < 1.0f ? 1.0f : (mo > fno ? fno : mo);
        int o = (int)(mm - 1.0f);
        o = o > no - 2 ? no - 2 : o;
        e->oi[q] = o;
        e->fo[q] = mm - 1.0f - (float)o;
    }
    /* the do field's loops: the count and the constants in locals and the eye's transmittance
       gathered first, so that each is one vector loop */
    const int mv = e->mv & ~7; /* e->mv itself: whole vectors */
    if (j->two_pop) { /* the do field back to front: the turned light's share (slice_do.c) */
        const float sd = j->share_dm;
        for (int q = 0; q < mv; q++) e->oi[q] = 2, e->fo[q] = 1.0f - atmos__expf_poly(-sd * e->nsc[q]);
    }
    if (j->sharp_eye) { /* the do field: its first order's smooth share (slice_do.c) */
        const int c = j->n / 2;
        const float km = j->kap[c] - 1.0f, sh = j->share, *restrict T0 = j->T_eye + c * j->pst + p0;
        float t0[CH];
        for (int q = 0; q < mv; q++) t0[q] = T0[lane(e, q)];
        for (int q = 0; q < mv; q++) e->fo[q] = 1.0f - atmos__expf_poly(km * log_pos(t0[q]) - sh * e->nsc[q]);
    }
    for (int f = 0; f < nf; f++) {
        if (!e->live[f]) continue;
        const int32_t *restrict pa = j->pa + p0 * nf + f;
        const float *restrict pw = j->pw + p0 * nf + f;
        for (int q = 0; q < e->mv; q++) {
            const int x = lane(e, q);
            e->ai[f][q] = pa[x * nf] + e->oi[q] * n;
            e->aw[f][q] = pw[x * nf];
        }
    }
}

/* Extinction and source (sum over fields of beta_sca (Ams + xi)) of wavelength c. */
ATMOS_CLONE_HELPER void eye_optics(const sjob *j, const echunk *e, int c, float *restrict bext, float *restrict src)
{
    const stables *t = j->t;
    const int n = j->n;
    const int32_t an = t->no * n; /* Ams: next angle (next order: + n) */
    const float xi = j->xi;
    for (int q = 0; q < e->mv; q++) bext[q] = 0.0f, src[q] = 0.0f;
    for (int f = 0; f < j->nf; f++) {
        if (!e->live[f]) continue;
        const float sg = t->sig[f][c], sa = t->sca[f][c];
        const float *restrict A = t->ams[f] + c;
        const float *restrict d = e->dens + f * CH;
        for (int q = 0; q < e->mv; q++) {
            const float dq = d[q] > 0.0f ? d[q] : 0.0f;
            bext[q] += dq * sg;
            const float bs = dq * sa;
            const int32_t ix = e->ai[f][q];
            const float lo = A[ix] + e->fo[q] * (A[ix + n] - A[ix]);
            const float hi = A[ix + an] + e->fo[q] * (A[ix + an + n] - A[ix + an]);
            const float val = lo + e->aw[f][q] * (hi - lo);
            src[q] += bs > 0.0f ? bs * (val + xi) : 0.0f;
        }
    }
}

/* The diffuse field's cells at a chunk's samples: per sample the offset of the lower
 * corner cell in the per-frame view (j->fview) and the trilinear weights, as
 * atmos__lfield_sample finds them (the cells' centres at render voxel (i + 1/2) s - 1/2,
 * clamped to the outer ones). One vector loop over the chunk. */
typedef struct {
    int32_t cell[CH];
    float w[8][CH];
    int32_t st[3]; /* the view's strides to the next cell along each axis (0: an axis of one cell) */
} fchunk;

/* One axis of the field's cells for mv samples (a multiple of 8) at render-voxel coordinate x:
 * the lower cell i and the fraction t. Written without a branch, so that it is one vector loop
 * (the fraction is taken whatever c; an axis of one cell sets it to 0 afterwards). */
ATMOS_CLONE_HELPER void field_axis(int mv, const float *restrict x, float off, float is, int c, int32_t *restrict i,
                                   float *restrict t)
{
    const float lim = (float)(c - 1); /* >= 0: the two clamps one after the other clamp alike */
    for (int q = 0; q < mv; q++) {
        float y = (x[q] - off) * is;
        y = y < 0.0f ? 0.0f : y;
        y = y > lim ? lim : y;
        int a = (int)y;
        a = a > c - 2 ? c - 2 : a;
        a = a < 0 ? 0 : a;
        i[q] = a, t[q] = y - (float)a;
    }
    if (c <= 1)
        for (int q = 0; q < mv; q++) t[q] = 0.0f;
}

ATMOS_CLONE_HELPER void eye_field_cells(const sjob *j, const echunk *e, fchunk *fc)
{
    const atmos__lfield *f = j->field;
    const int cx = f->c[0], cy = f->c[1], cz = f->c[2];
    const int32_t m = j->nf * j->fvq;
    const float off = 0.5f * (float)(f->s - 1), is = 1.0f / (float)f->s;
    fc->st[0] = cx > 1 ? m : 0, fc->st[1] = cy > 1 ? cx * m : 0, fc->st[2] = cz > 1 ? cx * cy * m : 0;
    /* the samples' points gathered first (eye_samples' own, by chunk position), then the cells and
       weights in vector loops (the gather and the clamps in one loop took more instructions:
       docs/lightfield.md) */
    const int mv = e->mv & ~7; /* e->mv itself: whole vectors */
    float pt[3][CH], ft[3][CH];
    int32_t it[3][CH];
    for (int q = 0; q < mv; q++) {
        const int x = lane(e, q);
        for (int a = 0; a < 3; a++) pt[a][q] = e->pt[a][x];
    }
    field_axis(mv, pt[0], off, is, cx, it[0], ft[0]);
    field_axis(mv, pt[1], off, is, cy, it[1], ft[1]);
    field_axis(mv, pt[2], off, is, cz, it[2], ft[2]);
    for (int q = 0; q < mv; q++) {
        const int32_t i = it[0][q], jj = it[1][q], kk = it[2][q];
        const float a = ft[0][q], b = ft[1][q], c = ft[2][q];
        fc->cell[q] = ((kk * cy + jj) * cx + i) * m;
        fc->w[0][q] = (1 - a) * (1 - b) * (1 - c), fc->w[1][q] = a * (1 - b) * (1 - c);
        fc->w[2][q] = (1 - a) * b * (1 - c), fc->w[3][q] = a * b * (1 - c);
        fc->w[4][q] = (1 - a) * (1 - b) * c, fc->w[5][q] = a * (1 - b) * c;
        fc->w[6][q] = (1 - a) * b * c, fc->w[7][q] = a * b * c;
    }
}

/* The diffuse field scattered toward the eye at the chunk's samples, wavelength c in
 * ds[c * CH + q]: sum over the live fields of density times the view's sca (L + g A)
 * (trilinear), not below 0. */
ATMOS_CLONE_HELPER void eye_field(const sjob *j, const echunk *e, float *restrict ds)
{
    fchunk fc;
    eye_field_cells(j, e, &fc);
    const int n = j->n, nf = j->nf, fq = j->fvq;
    const int32_t sx = fc.st[0], sy = fc.st[1], sz = fc.st[2];
    const int32_t o8[8] = {0, sx, sy, sx + sy, sz, sx + sz, sy + sz, sx + sy + sz};
    for (int c = 0; c < n; c++)
        for (int q = 0; q < e->mv; q++) ds[c * CH + q] = 0.0f;
    for (int f = 0; f < nf; f++) {
        if (!e->live[f]) continue;
        const float *restrict d = e->dens + f * CH;
        for (int c = 0; c < n; c++) {
            const float *restrict V = j->fview + f * fq + c;
            float *restrict o = ds + c * CH;
            for (int q = 0; q < e->mv; q++) {
                const float *p = V + fc.cell[q];
                float v = 0.0f;
                for (int x = 0; x < 8; x++) v += fc.w[x][q] * p[o8[x]];
                o[q] += (d[q] > 0.0f ? d[q] : 0.0f) * v;
            }
        }
    }
    for (int c = 0; c < n; c++)
        for (int q = 0; q < e->mv; q++) ds[c * CH + q] = ds[c * CH + q] > 0.0f ? ds[c * CH + q] : 0.0f;
}

/* Eq. 26 for wavelength c: the slab's transmittance and in-scattered light, composited
 * into the eye buffer over (back to front) or under (front to back); ds (or NULL): the
 * diffuse field's in-scattering added to the beam's; I1 (or NULL): the light leaving the slab
 * at the samples, Ic's attenuation across it (atmos__slice_beam_len). */
ATMOS_CLONE_HELPER void eye_blend(const sjob *j, size_t p0, const echunk *e, int c, const float *restrict Ic,
                                  const float *restrict bext, const float *restrict src, const float *restrict ds,
                                  const float *restrict I1)
{
    float Tq[CH], Cq[CH], S0[CH], Lq[CH], Eq[CH];
    /* the in-scattering: the field's, or zeros chosen before the loop (a test of ds inside the
     * loop became a masked load from the null pointer, whose every lane masked off still cost a
     * microcode assist per vector: a quarter of the eye pass without the field) */
    const float *restrict Sq = ds;
    if (!ds) {
        for (int q = 0; q < e->mv; q++) S0[q] = 0.0f;
        Sq = S0;
    }
    for (int q = 0; q < e->mv; q++) {
        const float be = bext[q], tau = be * e->del[q];
        const float T = atmos__expf_poly(-tau);
        /* beta_sca Delta of Eq. 26, integrated over the slab with its own attenuation:
         * (1 - T)/beta_ext (-> Delta when thin). */
        Lq[q] = tau < 1e-4f ? e->del[q] * (1.0f - 0.5f * tau) : (1.0f - T) / be;
        Tq[q] = be > 0.0f ? T : 1.0f, Eq[q] = T;
    }
    float Bq[CH]; /* the beam's length: Lq, or with I1 its attenuation across the slab too */
    if (I1) {
        /* the beam's exponentials are the slab's T and the light's ratio r themselves: a
         * logarithm a sample, no exponential (two were taken here) */
        const int mv = e->mv & ~7; /* e->mv itself: whole vectors */
        if (j->btf)
            for (int q = 0; q < mv; q++) {
                const float r = atmos__slice_beam_ratio(Ic[q], I1[q]);
                Bq[q] = atmos__slice_beam_len(e->del[q], bext[q] * e->del[q], Eq[q], -log_pos(r), r, 1);
            }
        else
            for (int q = 0; q < mv; q++) {
                const float r = atmos__slice_beam_ratio(Ic[q], I1[q]);
                Bq[q] = atmos__slice_beam_len(e->del[q], bext[q] * e->del[q], Eq[q], -log_pos(r), r, 0);
            }
    } else
        for (int q = 0; q < e->mv; q++) Bq[q] = Lq[q];
    for (int q = 0; q < e->mv; q++) Cq[q] = bext[q] > 0.0f ? Sq[q] * Lq[q] + Ic[q] * src[q] * Bq[q] : 0.0f;
    float *restrict Lb = j->L_eye + c * j->pst + p0, *restrict Tb = j->T_eye + c * j->pst + p0;
    const int m = e->m;
    if (e->contig && j->btf)
        for (int q = 0; q < m; q++) Lb[q] = Lb[q] * Tq[q] + Cq[q], Tb[q] *= Tq[q]; /* back-to-front: over */
    else if (e->contig)
        for (int q = 0; q < m; q++) Lb[q] += Tb[q] * Cq[q], Tb[q] *= Tq[q]; /* front-to-back: under */
    else if (j->btf)
        for (int q = 0; q < m; q++) {
            const int x = e->id[q];
            Lb[x] = Lb[x] * Tq[q] + Cq[q];
            Tb[x] *= Tq[q];
        }
    else
        for (int q = 0; q < m; q++) {
            const int x = e->id[q];
            Lb[x] += Tb[x] * Cq[q];
            Tb[x] *= Tq[q];
        }
}

#if defined(__SSE2__)
#include <immintrin.h>
#define SLICE_RGB 1

/* RGB (n = 3): a texel's I_r, I_g, I_b and n are one 16-byte vector, and an Ams row's three
 * wavelengths at orders o and o + 1 are six consecutive floats, so the light buffer and the
 * Ams tables are read by whole-vector loads rather than one gathered lane per wavelength.
 * Lane c computes what eye_bilinear and eye_optics compute for wavelength c, with the same
 * operations in the same order (the same bits); four samples' vectors are transposed into
 * the per-wavelength arrays. */

/* A sample's bilinear read of a light buffer: the four texels at p, p + 4, p + LN, p + LN + 4
 * (each I_r, I_g, I_b, n), weighted and summed in that order. */
ATMOS_CLONE_HELPER __m128 texel_rgb(const float *p, int32_t LN, __m128 w00, __m128 w10, __m128 w01, __m128 w11)
{
    __m128 v = _mm_mul_ps(w00, _mm_loadu_ps(p));
    v = _mm_add_ps(v, _mm_mul_ps(w10, _mm_loadu_ps(p + 4)));
    v = _mm_add_ps(v, _mm_mul_ps(w01, _mm_loadu_ps(p + LN)));
    return _mm_add_ps(v, _mm_mul_ps(w11, _mm_loadu_ps(p + LN + 4)));
}

/* I3[c]: the light of wavelength c of buffer Ib (c = 3: n, also in nsc); Jb (or NULL): a second
 * buffer read at the same texels with the same weights (the light leaving the slab), its three
 * wavelengths into J3 (its n is not stored). */
ATMOS_CLONE_HELPER void eye_rgb_light(const sjob *j, echunk *e, const float *Ib, float (*restrict I3)[CH],
                                      const float *Jb, float (*restrict J3)[CH])
{
    const int32_t LN = j->L * 4;
    for (int q0 = 0; q0 < e->mv; q0 += 4) {
        __m128 r[4], s[4];
        for (int i = 0; i < 4; i++) {
            const int q = q0 + i;
            const __m128 w00 = _mm_set1_ps(e->w00[q]), w10 = _mm_set1_ps(e->w10[q]);
            const __m128 w01 = _mm_set1_ps(e->w01[q]), w11 = _mm_set1_ps(e->w11[q]);
            r[i] = texel_rgb(Ib + e->lt[q], LN, w00, w10, w01, w11);
            if (Jb) s[i] = texel_rgb(Jb + e->lt[q], LN, w00, w10, w01, w11);
        }
        _MM_TRANSPOSE4_PS(r[0], r[1], r[2], r[3]);
        for (int c = 0; c < 3; c++) _mm_storeu_ps(I3[c] + q0, r[c]);
        _mm_storeu_ps(e->nsc + q0, r[3]);
        if (Jb) {
            _MM_TRANSPOSE4_PS(s[0], s[1], s[2], s[3]);
            for (int c = 0; c < 3; c++) _mm_storeu_ps(J3[c] + q0, s[c]);
        }
    }
}

/* One sample's extinction and source vectors (lane c: wavelength c) over the live fields. */
ATMOS_CLONE_HELPER void eye_rgb_sample(const sjob *j, const echunk *e, int q, const __m128 *sg, const __m128 *sa,
                                       __m128 *bext, __m128 *src)
{
    const stables *t = j->t;
    const int32_t an = t->no * 3;
    const __m128 xi = _mm_set1_ps(j->xi), zero = _mm_setzero_ps(), fo = _mm_set1_ps(e->fo[q]);
    __m128 be = zero, sr = zero;
    for (int f = 0; f < j->nf; f++) {
        if (!e->live[f]) continue;
        const float d = e->dens[f * CH + q];
        const __m128 dq = _mm_set1_ps(d > 0.0f ? d : 0.0f);
        be = _mm_add_ps(be, _mm_mul_ps(dq, sg[f]));
        const __m128 bs = _mm_mul_ps(dq, sa[f]);
        const float *A = t->ams[f] + e->ai[f][q];
        const __m128 l0 = _mm_loadu_ps(A), l1 = _mm_loadu_ps(A + 3);
        const __m128 h0 = _mm_loadu_ps(A + an), h1 = _mm_loadu_ps(A + an + 3);
        const __m128 lo = _mm_add_ps(l0, _mm_mul_ps(fo, _mm_sub_ps(l1, l0)));
        const __m128 hi = _mm_add_ps(h0, _mm_mul_ps(fo, _mm_sub_ps(h1, h0)));
        const __m128 val = _mm_add_ps(lo, _mm_mul_ps(_mm_set1_ps(e->aw[f][q]), _mm_sub_ps(hi, lo)));
        const __m128 s = _mm_mul_ps(bs, _mm_add_ps(val, xi));
        sr = _mm_add_ps(sr, _mm_and_ps(_mm_cmpgt_ps(bs, zero), s));
    }
    *bext = be, *src = sr;
}

ATMOS_CLONE_HELPER void eye_rgb_optics(const sjob *j, const echunk *e, float (*restrict be3)[CH], float (*restrict src3)[CH])
{
    const stables *t = j->t;
    __m128 sg[ATMOS_VOLUME_MAX_FIELDS], sa[ATMOS_VOLUME_MAX_FIELDS];
    for (int f = 0; f < j->nf; f++) {
        sg[f] = _mm_setr_ps(t->sig[f][0], t->sig[f][1], t->sig[f][2], 0.0f);
        sa[f] = _mm_setr_ps(t->sca[f][0], t->sca[f][1], t->sca[f][2], 0.0f);
    }
    for (int q0 = 0; q0 < e->mv; q0 += 4) {
        __m128 be[4], sr[4];
        for (int i = 0; i < 4; i++) eye_rgb_sample(j, e, q0 + i, sg, sa, &be[i], &sr[i]);
        _MM_TRANSPOSE4_PS(be[0], be[1], be[2], be[3]);
        _MM_TRANSPOSE4_PS(sr[0], sr[1], sr[2], sr[3]);
        for (int c = 0; c < 3; c++) _mm_storeu_ps(be3[c] + q0, be[c]), _mm_storeu_ps(src3[c] + q0, sr[c]);
    }
}

/* eye_field for RGB: a cell's view of a field is one 16-byte vector (fvq 4), so a sample's
 * three wavelengths are 8 vector loads per live field. (eye_field's vector loop, a gather per
 * corner in the AVX2 clone, took 4 % fewer instructions in the eye pass but 5-10 % more CPU a
 * frame where measured: docs/lightfield.md.) */
ATMOS_CLONE_HELPER void eye_rgb_field(const sjob *j, const echunk *e, float (*restrict ds3)[CH])
{
    fchunk fc;
    eye_field_cells(j, e, &fc);
    const int nf = j->nf;
    const int32_t sx = fc.st[0], sy = fc.st[1], sz = fc.st[2];
    const int32_t o8[8] = {0, sx, sy, sx + sy, sz, sx + sz, sy + sz, sx + sy + sz};
    const __m128 zero = _mm_setzero_ps();
    /* the fields outside, the samples inside: a field's test once a chunk (each sample's sum over
       the fields in the same order) */
    __m128 acc[CH];
    for (int q = 0; q < e->mv; q++) acc[q] = zero;
    for (int f = 0; f < nf; f++) {
        if (!e->live[f]) continue;
        const float *restrict V = j->fview + f * 4, *restrict d = e->dens + f * CH;
        for (int q = 0; q < e->mv; q++) {
            const float *p = V + fc.cell[q];
            __m128 v = _mm_mul_ps(_mm_set1_ps(fc.w[0][q]), _mm_loadu_ps(p));
            for (int x = 1; x < 8; x++) v = _mm_add_ps(v, _mm_mul_ps(_mm_set1_ps(fc.w[x][q]), _mm_loadu_ps(p + o8[x])));
            acc[q] = _mm_add_ps(acc[q], _mm_mul_ps(_mm_set1_ps(d[q] > 0.0f ? d[q] : 0.0f), v));
        }
    }
    for (int q0 = 0; q0 < e->mv; q0 += 4) {
        __m128 r[4];
        for (int i = 0; i < 4; i++) r[i] = _mm_max_ps(acc[q0 + i], zero);
        _MM_TRANSPOSE4_PS(r[0], r[1], r[2], r[3]);
        for (int c = 0; c < 3; c++) _mm_storeu_ps(ds3[c] + q0, r[c]);
    }
}

/* The light, the optics and the blend of an RGB chunk. */
ATMOS_CLONE_HELPER void eye_rgb(const sjob *j, size_t p0, echunk *e, const float *Ib, const float *In)
{
    float I3[4][CH], be3[3][CH], src3[3][CH], ds3[3][CH], J3[3][CH];
    if (j->low_albedo) /* and the light leaving the slab, read at the same texels */
        eye_rgb_light(j, e, Ib, I3, In, J3);
    else
        eye_rgb_light(j, e, Ib, I3, NULL, J3);
    eye_orders(j, p0, e);
    eye_rgb_optics(j, e, be3, src3);
    if (j->field) eye_rgb_field(j, e, ds3);
    for (int c = 0; c < 3; c++)
        eye_blend(j, p0, e, c, I3[c], be3[c], src3[c], j->field ? ds3[c] : NULL, j->low_albedo ? J3[c] : NULL);
}
#else
#define SLICE_RGB 0
#endif

SLICE_CLONES
long long atmos__slice_eye_span(const sjob *j, int k, int y, int x0, int x1, const float *Ib, const float *nb,
                                const float *In)
{
    const int n = j->n;
    const int32_t ns = n + 1, LN = j->L * ns; /* texels interleave I per wavelength and n */
    echunk e;
    float Ic[CH], I1[CH], bext[CH], src[CH];
    float ds[CH * ATMOS_MAX_WAVELENGTHS]; /* the diffuse field's in-scattering at the samples */
    long long count = 0;
    for (int xs = x0; xs <= x1; xs += CH) {
        const int cnt = x1 - xs + 1 < CH ? x1 - xs + 1 : CH;
        const size_t p0 = (size_t)y * j->W + xs;
        count += eye_samples(j, k, p0, cnt, &e);
        if (!e.m) continue;
        eye_texels(j, k, p0, &e);
#if SLICE_RGB
        if (n == 3) {
            eye_rgb(j, p0, &e, Ib, In);
            continue;
        }
#endif
        eye_bilinear(&e, nb, ns, LN, e.nsc);
        eye_orders(j, p0, &e);
        if (j->field) eye_field(j, &e, ds);
        for (int c = 0; c < n; c++) {
            eye_bilinear(&e, Ib + c, ns, LN, Ic);
            if (j->low_albedo) eye_bilinear(&e, In + c, ns, LN, I1);
            eye_optics(j, &e, c, bext, src);
            eye_blend(j, p0, &e, c, Ic, bext, src, j->field ? ds + c * CH : NULL, j->low_albedo ? I1 : NULL);
        }
    }
    return count;
}

/* The light of wavelength c leaving the chunk's samples (Eq. 25; the light pass's
 * per-wavelength part): I' = I (T + (1 - T) keep). Accumulates beta_sca Delta into dn. */
ATMOS_CLONE_HELPER void light_wavelength(const sjob *j, int c, const echunk *e, const float *restrict Iw,
                                         const float *restrict n0, float *restrict dn, float *restrict Io)
{
    const stables *t = j->t;
    const size_t ns = (size_t)j->n + 1;
    const float delta = j->ldelta;
    float be[CH], bs[CH], aF[CH], tq[CH], kp[CH], lg[CH], Iq[CH], out[CH];
    int32_t fi[CH];
    for (int q = 0; q < e->mv; q++)
        be[q] = 0.0f, bs[q] = 0.0f, aF[q] = 0.0f, Iq[q] = Iw[(size_t)lane(e, q) * ns];
    for (int f = 0; f < j->nf; f++) {
        if (!e->live[f]) continue;
        const float sg = t->sig[f][c], sa = t->sca[f][c];
        const float *restrict d = e->dens + f * CH;
        for (int q = 0; q < e->mv; q++) be[q] += d[q] * sg, bs[q] += d[q] * sa;
    }
    for (int q = 0; q < e->mv; q++) {
        dn[q] += bs[q] * delta;
        tq[q] = be[q] * delta;
        /* Eq. 25's order: floor(n + 1 + beta Delta) */
        const float idx = floorf(n0[q] + 1.0f + tq[q]);
        fi[q] = !(idx > 0.0f) ? 0 : (idx >= (float)SLICE_F_ORDERS ? SLICE_F_ORDERS : (int)idx);
    }
    if (j->low_albedo) { /* keep is 0: the light's plain attenuation (no log, no power) */
        for (int q = 0; q < e->mv; q++) {
            const float T = atmos__expf_poly(-tq[q]);
            out[q] = be[q] > 0.0f ? Iq[q] * T : Iq[q]; /* T + (1 - T) 0: the same bits */
        }
        for (int q = 0; q < e->m; q++) Io[(size_t)lane(e, q) * ns] = out[q];
        return;
    }
    for (int f = 0; f < j->nf; f++) {
        if (!e->live[f]) continue;
        const float sa = t->sca[f][c];
        const float *restrict Ft = t->F[f] + (size_t)c * (SLICE_F_ORDERS + 1);
        const float *restrict d = e->dens + f * CH;
        for (int q = 0; q < e->mv; q++) {
            const float fq = Ft[fi[q]], dq = d[q] > 0.0f ? d[q] : 0.0f;
            aF[q] += dq * sa * fq;
        }
    }
    for (int q = 0; q < e->mv; q++) {
        const float a = aF[q] / be[q];
        /* keep: the fraction of the scattered light (1 - T) still going forward,
         * Eq. 25's (alpha F)^{max(1, beta Delta)} (docs/slice.md); 0 in low albedo. */
        kp[q] = !j->low_albedo && bs[q] > 0.0f && a > 0.0f ? a : 0.0f;
        lg[q] = log_pos(kp[q]);
    }
    for (int q = 0; q < e->mv; q++) {
        const float tau = tq[q], T = atmos__expf_poly(-tau);
        const float pw = atmos__expf_poly(tau * lg[q]); /* thick slab: the power */
        const float keep = kp[q] > 0.0f && tau > 1.0f ? pw : kp[q];
        out[q] = be[q] > 0.0f ? Iq[q] * (T + (1.0f - T) * keep) : Iq[q];
    }
    for (int q = 0; q < e->m; q++) Io[(size_t)lane(e, q) * ns] = out[q];
}

SLICE_CLONES
long long atmos__slice_light_span(const sjob *j, int k, int b, int x0, int x1, int a0, int a1, const float *Ic_,
                                  const float *nc_, float *In_, float *nn_)
{
    if (j->eq24) return atmos__slice_light_span_ref(j, k, b, x0, x1, a0, a1, Ic_, nc_, In_, nn_);
    const int n = j->n, L = j->L;
    const size_t ns = (size_t)n + 1; /* texels interleave I per wavelength and n */
    const float *restrict Ic = Ic_, *restrict nc = nc_;
    float *restrict In = In_, *restrict nn = nn_;
    double base[3];
    for (int i = 0; i < 3; i++) base[i] = j->lA[i] + b * j->lEb[i] + k * j->lEk[i];
    const float bu = (float)base[0], bv = (float)base[1], bw = (float)base[2];
    const float eu = (float)j->lEa[0], ev = (float)j->lEa[1], ew = (float)j->lEa[2];
    float u[CH], v[CH], w[CH], n0[CH], dn[CH];
    int32_t ok[CH];
    echunk e;
    long long count = 0;
    for (int xs = x0; xs <= x1; xs += CH) {
        const int cnt = x1 - xs + 1 < CH ? x1 - xs + 1 : CH;
        const size_t q0 = (size_t)b * L + xs;
        /* Light that meets nothing passes unchanged. */
        memcpy(In + q0 * ns, Ic + q0 * ns, sizeof(float) * (size_t)cnt * ns);
        const int *restrict k0 = j->lk0 + q0, *restrict k1 = j->lk1 + q0;
        for (int q = 0; q < cnt; q++) {
            const int a = xs + q;
            const float af = (float)a;
            u[q] = bu + af * eu;
            v[q] = bv + af * ev;
            w[q] = bw + af * ew;
            ok[q] = a >= a0 && a <= a1 && k >= k0[q] && k <= k1[q];
        }
        count += chunk_lookup(j->g, cnt, u, v, w, ok, &e);
        if (!e.m) continue;
        for (int q = 0; q < e.mv; q++) n0[q] = nc[(q0 + (size_t)lane(&e, q)) * ns], dn[q] = 0.0f;
        for (int c = 0; c < n; c++) light_wavelength(j, c, &e, Ic + q0 * ns + c, n0, dn, In + q0 * ns + c);
        /* Eq. 21: n grows by alpha beta_ext Delta = beta_sca Delta (mean over wavelengths). */
        for (int q = 0; q < e.m; q++) nn[(q0 + (size_t)lane(&e, q)) * ns] = n0[q] + dn[q] / (float)n;
    }
    return count;
}
