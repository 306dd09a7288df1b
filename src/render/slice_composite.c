/* The §5 composite of the slice renderer (Riley et al. 2004): the volume's radiance and
 * transparency from the eye buffer over the sky image, with the air in front of the
 * volume's halfway plane in front of it and the rest behind. */
#include "atmosphere/atmosphere_ops.h"
#include "core/vec.h"
#include "render/slice_internal.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

/* §5 composite of one image pixel along direction dw (world): the air from the eye
 * to the halfway plane at distance th is in front of the volume, the rest (with the
 * ground and the sun's disk) behind it. px holds the sky image B (= front + T_front *
 * back) and receives front + T_front * L_vol + T_vol * (B - front). */
static void composite_pixel(const atmos_atmosphere *atm, const atmos__aerial *ap, const atmos_camera *cam,
                            const double dw[3], double th, const double sun_w[3], int n, const float *Lv,
                            const float *Tv, const float *Df, float *px)
{
    if (!(th > 0)) th = 0;
    double front[ATMOS_MAX_WAVELENGTHS], Tf[ATMOS_MAX_WAVELENGTHS];
    double tg = atmos_atmosphere_ground_distance(atm, cam->position, dw);
    if (th > tg) th = tg;
    if (!ap || !atmos__aerial_eval(ap, dw, th, front, Tf)) {
        atmos_atmosphere_inscatter(atm, cam->position, dw, th, sun_w, front);
        atmos_atmosphere_transmittance(atm, cam->position, dw, th, Tf);
    }
    if (Df) /* the volume's shadow on that air (slice_shadow.c; px has lost it already) */
        for (int c = 0; c < n; c++) front[c] = front[c] > Df[c] ? front[c] - Df[c] : 0.0;
    for (int c = 0; c < n; c++) {
        double B = px[c], L = Lv[c], T = Tv[c];
        double r = front[c] + Tf[c] * L + T * (B - front[c]);
        px[c] = (float)(isfinite(r) && r > 0 ? r : 0.0);
    }
}

/* The two eye-buffer pixels (of n) around fractional eye coordinate f (pixel centres at
 * integers) and the weight of the second; clamped at the edges. */
static void eye_taps(double f, int n, int t[2], float *w)
{
    if (!(f > 0)) f = 0;
    if (f > n - 1) f = n - 1;
    int i = (int)f;
    if (i > n - 2) i = n - 2 < 0 ? 0 : n - 2;
    t[0] = i, t[1] = i + 1 < n ? i + 1 : i;
    *w = t[1] == t[0] ? 0.0f : (float)(f - i);
}

/* The frame's aerial-perspective volume (a kind whose answers are closed forms is asked
 * directly: NULL): over the directions of the volume's box as the camera sees it (its
 * corners projected, widened by the bilinear taps of a reduced eye buffer and cut to the
 * image; the whole image when the eye is in front of no corner), from the box's nearest point
 * to its farthest corner (slices crowded at the near end, or at the far end when the eye is
 * above the box). It depends on neither the region rendered nor the thread count. */
static const atmos__aerial *frame_aerial(const sjob *j, const atmos_atmosphere *atm, const atmos_camera *cam,
                                         const double sun_w[3], const atmos__vol_xform *xf, atmos__aerial *ap,
                                         int threads)
{
    if (!ap || !atmos__aerial_wanted(atm) || cam->type != ATMOS_CAMERA_PINHOLE) return NULL;
    atmos__aerial_grid g;
    memset(&g, 0, sizeof g);
    memcpy(g.eye, cam->position, sizeof g.eye), memcpy(g.sun, sun_w, sizeof g.sun);
    memcpy(g.fwd, cam->forward, sizeof g.fwd), memcpy(g.right, cam->right, sizeof g.right);
    memcpy(g.up, cam->up, sizeof g.up);
    double f[3], rt[3], up[3];
    atmos__vol_dir_to_frame(xf, cam->forward, f);
    atmos__vol_dir_to_frame(xf, cam->right, rt);
    atmos__vol_dir_to_frame(xf, cam->up, up);
    const double W = cam->width, H = cam->height, tn = cam->tan_half_fov;
    const double ui[2] = {-W / H * tn, W / H * tn}, vi[2] = {-tn, tn};
    const sgrid *b = j->g;
    double far = 0, u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
    int behind = 0;
    for (int c = 0; c < 8; c++) {
        const double dd[3] = {(c & 1 ? b->box_hi[0] : b->box_lo[0]) - j->eye[0],
                              (c & 2 ? b->box_hi[1] : b->box_lo[1]) - j->eye[1],
                              (c & 4 ? b->box_hi[2] : b->box_lo[2]) - j->eye[2]};
        far = fmax(far, sqrt(atmos__dot3(dd, dd)));
        const double z = atmos__dot3(dd, f);
        if (!(z > 0)) {
            behind = 1;
            continue;
        }
        const double u = atmos__dot3(dd, rt) / z, v = atmos__dot3(dd, up) / z;
        u0 = fmin(u0, u), u1 = fmax(u1, u), v0 = fmin(v0, v), v1 = fmax(v1, v);
    }
    const double m = (2.0 * fmax(j->sx, j->sy) + 1.0) * 2.0 * tn / H; /* the taps' reach, in u and v */
    g.u0 = behind ? ui[0] : fmax(u0 - m, ui[0]), g.u1 = behind ? ui[1] : fmin(u1 + m, ui[1]);
    g.v0 = behind ? vi[0] : fmax(v0 - m, vi[0]), g.v1 = behind ? vi[1] : fmin(v1 + m, vi[1]);
    if (!(g.u1 > g.u0 && g.v1 > g.v0)) return NULL; /* the box is out of view */
    double near2 = 0; /* the box's nearest point (0: the eye is inside) */
    for (int a = 0; a < 3; a++) {
        const double e = j->eye[a] < b->box_lo[a] ? b->box_lo[a] - j->eye[a] : (j->eye[a] > b->box_hi[a] ? j->eye[a] - b->box_hi[a] : 0);
        near2 += e * e;
    }
    g.tmin = fmax(0.0, sqrt(near2) - 1.0);
    g.tmax = far + 0.01 * (far - g.tmin) + 1.0;
    /* looking down at the box from above it, the air thickens with distance: slices crowd far */
    double top = -INFINITY;
    for (int c = 0; c < 8; c++) {
        const double p[3] = {c & 1 ? b->box_hi[0] : b->box_lo[0], c & 2 ? b->box_hi[1] : b->box_lo[1],
                             c & 4 ? b->box_hi[2] : b->box_lo[2]};
        double w[3];
        atmos__vol_frame_to_point(xf, p, w);
        top = fmax(top, w[1]);
    }
    g.crowd_far = cam->position[1] > top;
    g.nd = ATMOS__AERIAL_SLICES;
    atmos__aerial_nodes(atm, &g);
    return atmos__aerial_build(ap, atm, &g, threads) ? ap : NULL;
}

void atmos__slice_composite(const sjob *j, const atmos_atmosphere *atm, const atmos_camera *cam, const double sun_w[3],
                            const atmos__vol_xform *xf, const atmos__rect *r, atmos__aerial *aerial, atmos_image *img,
                            int threads)
{
    const atmos__aerial *ap = frame_aerial(j, atm, cam, sun_w, xf, aerial, threads);
    /* §5: air from the eye to the volume's halfway plane is in front of the volume,
     * the rest (with the ground and the sun's disk, §4.2.4) behind it. With B the sky
     * image (= front + T_front * back), the pixel is
     *   front + T_front * L_vol + T_vol * (B - front).
     * Pixels the volume does not touch keep B exactly. */
    {
        const sgrid *g = j->g;
        double cen[3] = {0.5 * (g->box_lo[0] + g->box_hi[0]), 0.5 * (g->box_lo[1] + g->box_hi[1]),
                         0.5 * (g->box_lo[2] + g->box_hi[2])};
        const double hc = atmos__dot3(j->h, cen);
        const int C = img->channels;
        if (j->sx == 1.0 && j->sy == 1.0) {
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
            for (int y = 0; y < j->H; y++)
                for (int x = j->erow[y].x0; x <= j->erow[y].x1; x++) {
                    size_t p = (size_t)y * j->W + x;
                    int touched = 0;
                    for (int c = 0; c < j->n; c++)
                        touched |= j->L_eye[c * j->pst + p] != 0.0f || j->T_eye[c * j->pst + p] != 1.0f;
                    if (!touched) continue;
                    double dw[3];
                    atmos_camera_ray(cam, x + 0.5, y + 0.5, dw);
                    double th = j->pinv[p] != 0.0f ? (hc - j->he) * j->pinv[p] : 0.0;
                    float Lv[ATMOS_MAX_WAVELENGTHS], Tv[ATMOS_MAX_WAVELENGTHS];
                    for (int c = 0; c < j->n; c++) Lv[c] = j->L_eye[c * j->pst + p], Tv[c] = j->T_eye[c * j->pst + p];
                    composite_pixel(atm, ap, cam, dw, th, sun_w, j->n, Lv, Tv, j->air_front ? j->air_front + p * j->n : NULL,
                                    img->pixels + p * C);
                }
        } else {
            /* Eye buffer smaller than the image (or twice its size: the taps then fall
             * midway, the 2 x 2 box): L_vol and T_vol bilinear between the
             * four eye pixels around the image pixel's centre (both are premultiplied by
             * the volume's coverage, so this blurs the silhouette by one eye pixel but
             * does not tint it). Eye pixels outside their row's union of spans were
             * never reached (L = 0, T = 1). An image pixel whose four eye pixels are all
             * untouched keeps the sky image exactly; the halfway plane is met along the
             * image pixel's own ray. */
            const int W = cam->width;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
            for (int y = r->y0; y < r->y1; y++) {
                int ey[2];
                float wy;
                eye_taps((y + 0.5) / j->sy - 0.5, j->H, ey, &wy);
                int xa = INT32_MAX, xb = -1;
                for (int t = 0; t < 2; t++) {
                    const sspan e = j->erow[ey[t]];
                    if (e.x0 > e.x1) continue;
                    int a = (int)floor((e.x0 - 0.5) * j->sx), b = (int)ceil((e.x1 + 1.5) * j->sx);
                    xa = a < xa ? a : xa, xb = b > xb ? b : xb;
                }
                xa = xa < r->x0 ? r->x0 : xa, xb = xb > r->x1 - 1 ? r->x1 - 1 : xb;
                for (int x = xa; x <= xb; x++) {
                    int ex[2];
                    float wx;
                    eye_taps((x + 0.5) / j->sx - 0.5, j->W, ex, &wx);
                    /* edge_aa outside the edges: eye pixel (2x, 2y) alone, the image pixel's centre ray */
                    const int one = j->edge && !j->edge[(size_t)y * W + x];
                    const float vx = one ? 0.0f : wx, vy = one ? 0.0f : wy;
                    const float wt[4] = {(1 - vx) * (1 - vy), vx * (1 - vy), (1 - vx) * vy, vx * vy};
                    float Lv[ATMOS_MAX_WAVELENGTHS], Tv[ATMOS_MAX_WAVELENGTHS];
                    for (int c = 0; c < j->n; c++) Lv[c] = 0.0f, Tv[c] = 0.0f;
                    int touched = 0;
                    for (int q = 0; q < 4; q++) {
                        const int tx = ex[q & 1], ty = ey[q >> 1];
                        const size_t p = (size_t)ty * j->W + tx;
                        const int in = tx >= j->erow[ty].x0 && tx <= j->erow[ty].x1;
                        for (int c = 0; c < j->n; c++) {
                            const float L = in ? j->L_eye[c * j->pst + p] : 0.0f, T = in ? j->T_eye[c * j->pst + p] : 1.0f;
                            touched |= L != 0.0f || T != 1.0f;
                            Lv[c] += wt[q] * L, Tv[c] += wt[q] * T;
                        }
                    }
                    if (!touched) continue;
                    double dw[3], d[3];
                    atmos_camera_ray(cam, x + 0.5, y + 0.5, dw);
                    atmos__vol_dir_to_frame(xf, dw, d);
                    const double hd = atmos__dot3(j->h, d);
                    double th = fabs(hd) >= SLICE_HD_EPS ? (hc - j->he) / hd : 0.0;
                    if (one) { /* as the full-size eye buffer meets the halfway plane */
                        const float pv = j->pinv[(size_t)ey[0] * j->W + ex[0]];
                        th = pv != 0.0f ? (hc - j->he) * pv : 0.0;
                    }
                    const size_t q = (size_t)y * W + x;
                    composite_pixel(atm, ap, cam, dw, th, sun_w, j->n, Lv, Tv, j->air_front ? j->air_front + q * j->n : NULL,
                                    img->pixels + q * C);
                }
            }
        }
    }
}
