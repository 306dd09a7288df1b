/* Internals of the slice renderer: the plan (slice_plan.c: the render grid, the optics
 * tables, the buffers and the per-sun light frame kept between frames), the per-frame job
 * (slice_frame.c), the spans (slice_spans.c), the two passes (slice_pass.c) and the
 * composite (slice_composite.c). Not part of the API. */
#ifndef ATMOS_RENDER_SLICE_INTERNAL_H
#define ATMOS_RENDER_SLICE_INTERNAL_H

#include "atmosphere/atmosphere_ops.h"
#include "core/clones.h"
#include "core/fastmath.h"
#include "core/internal.h"
#include "light/lfield.h"
#include "render/dfield.h"
#include "render/plan_internal.h"
#include "render/slice_grid.h"
#include "render/slice_tables.h"

#include "volume/volume_access.h"

#define SLICE_HD_EPS 0.02 /* rays within ~89 degrees of the slice planes are not sliced */

/* Pixels x0..x1 of one image row, or texels of one light-buffer row, that a slice
 * touches (x0 > x1: none). */
typedef struct {
    int x0, x1;
} sspan;

typedef struct {
    int n, nf;
    int W, H, L;                 /* eye buffer (the image, or smaller: eye_scale), light buffer side */
    double sx, sy;               /* image pixels per eye-buffer pixel (1 = the image is the eye buffer) */
    int nslices;
    int btf;                     /* back-to-front */
    int low_albedo, eq24;
    float xi;
    double h[3], lt[3], e1[3], e2[3]; /* half vector, light propagation, light basis */
    double s0, ds;               /* slice planes s_k = s0 + (k + 0.5) ds along h */
    double eye[3], he;           /* eye in grid frame, h . eye */
    double u0, v0, du, dv;       /* light buffer: texel (a, b) centre at u0 + (a+0.5) du, ... */
    double hl;                   /* h . lt */
    const sgrid *g;
    const stables *t;
    /* with the do field, front to back (slice_do.c): the share of the first order's light that is
     * sharp, T_eye^(kap - 1) exp(-share n) (kap = sigma_t / sigma_t*, share = 1 - sigma_s* / sigma_s,
     * n the light's scattering depth from the sun), drawn with the full phase table, the rest with
     * the smooth phase (tab_dm's Ams order-2 rows, blended by the order weight) */
    int sharp_eye;
    float kap[ATMOS_MAX_WAVELENGTHS], share;
    /* with the do field, back to front (slice_do.c): the first order of two populations, the light
     * the delta-M peak has not turned (the share exp(-share_dm n)) with the full phase table (Ams
     * row 2), the rest with delta-M's scaled phase (row 3) */
    int two_pop;
    float share_dm;
    const atmos__lfield *field;  /* the diffuse light field (or the do field's cells, slice_do.c), or NULL */
    const float *fview;          /* the field toward the frame's eye as the fast eye pass reads it:
                                    [(cell * nf + f) * fvq + c] (atmos__dfield_view) */
    int fvq;                     /* floats per cell and field: 4 for RGB (the fourth 0), else n */
    /* the same from the field itself, for the reference eye pass: per unit density field f
     * scatters fsca_f (L + fg_f A) toward the eye (the field's L and A, atmos__lfield_toward; fg
     * NULL: L alone, the do field); [f * ATMOS_MAX_WAVELENGTHS + c] */
    const float *fsca, *fg;
    /* Per pixel. Slice planes are parallel, so the point where a pixel's ray meets
     * slice k is linear in k: render-voxel coordinate U0 + k dU, light-buffer
     * coordinate (texel units, centres at integers) F0 + k dF. */
    float *pU0[3], *pdU[3], *pF0[2], *pdF[2];
    float *pdelta;               /* eye-ray length of a slab */
    float *pinv;                 /* 1 / (h . d) */
    int *pk0, *pk1;              /* slices the ray crosses inside the box */
    int *pa;                     /* [pix * nf + f] Ams angle row offset (a * no * n) */
    float *pw;                   /* [pix * nf + f] weight of the next angle */
    float *L_eye, *T_eye;        /* [c * pst + pix] (pst: plane stride >= npix) */
    size_t pst;
    float *pixblock;             /* owns all the per-pixel planes */
    /* Per light texel; render-voxel coordinate of texel (a, b) on slice k:
     * lA + a lEa + b lEb + k lEk. */
    int *lk0, *lk1;
    double lA[3], lEa[3], lEb[3], lEk[3];
    float ldelta;                /* light-ray length of a slab */
    /* The light ring (see render): batch + 1 slots of L*L texels, each I per wavelength
     * then n ([texel * (n + 1) + c]); nsc[s] = I[s] + n. */
    int batch;
    float *ring, **I, **nsc;
    /* Per slice: the pixels of each row and the texels of each light row whose
     * samples may fall in occupied blocks ([k * H + y], [k * L + b]). */
    sspan *espan, *lspan, *wspan; /* wspan: union of the light spans of slices k - batch..k */
    /* Their union over the slices, per image row and per light row: the only pixels
     * and texels the render reads or writes (the rest keep the sky / are never read). */
    sspan *erow, *lrow;
    /* The volume's shadow on the air in front of the halfway plane, per image pixel
     * ([pixel * n + c], image width; slice_shadow.c), taken from the air in front in the
     * composite; NULL: none (the option off, or no air). */
    const float *air_front;
    /* edge_aa (slice_edges.c): per image pixel 1 where its four eye rays (the eye buffer twice
     * the image per axis) are traced and averaged, 0 where one ray through its centre (eye pixel
     * (2x, 2y)) stands for the four; NULL: every eye pixel is traced */
    const unsigned char *edge;
} sjob;

/* The light frame of one sun direction (everything of the light buffer that does not depend
 * on the camera): the light's travel lt and the buffer's axes e1, e2 in the grid frame, its
 * extent (texel (a, b) centre at u0 + (a + 0.5) du, v0 + (b + 0.5) dv), and per texel where
 * its ray crosses the box ([ta, tb], hit) and the sunlight entering there (float, n per
 * texel; texels that miss get the sunlight at the box's centre). */
typedef struct {
    int valid;
    double sun[3];
    int L;                       /* the buffer's side: the plan's, or a frame's smaller one */
    double lt[3], e1[3], e2[3];
    double u0, v0, du, dv;
    double *ta, *tb;
    unsigned char *hit;
    float *sl;
} slight;

/* The volume's shadow for the air (slice_shadow.c), kept until the sun moves: a deep
 * optical-depth map over a plane across the sun's light (the light frame's axes lt, e1, e2 in
 * the grid frame): per texel (a, b) of N x N over the box's projection (centre at
 * u0 + (a + 0.5) du, v0 + (b + 0.5) dv) and per depth node j at w = w0 + j dw along lt (D nodes
 * over the box's extent along the light), the volume's transmittance toward the sun from that
 * depth, exp(-tau) with tau the optical depth (each field's cross-section averaged over the
 * wavelengths) from the sun's side of the box. Stored with one texel of ones around
 * ((N + 2)^2 texels of D floats), so a bilinear tap outside the map reads 1; past the last
 * node a texel keeps its total (the shadow below and behind the box). */
typedef struct {
    int valid;
    double sun[3];
    int N, D;
    double lt[3], e1[3], e2[3];
    double u0, v0, du, dv, w0, dw;
    double lo[3], hi[3];     /* map coordinates (padded texel, node) where T < 1 can be read */
    float *T;
    double build_s;          /* the last build's time */
} sshadow;

struct atmos__slice_plan {
    sgrid g;                 /* g.v NULL: an empty volume, the sky alone */
    stables tab;
    int n, nf, L;
    int low_albedo, eq24, reference;
    float xi;
    double edge_aa;          /* the transmittance step between neighbours that marks an edge; 0 = off */
    unsigned char *edge;     /* sjob.edge's storage (grown to the largest image) */
    size_t edge_cap;
    atmos__vol_xform x;      /* the volume's transform, placed: world = org + R g in the grid frame */
    double prepare_s;        /* building the grid and the tables */
    int slices_used;         /* the last frame's slice count (the rule's when "slices" is 0) */
    atmos__aerial aerial;    /* the last frame's aerial-perspective volume (its storage kept) */
    double sunlight_s;       /* the last frame's time on the sunlight of the light frame (0: kept) */
    /* Buffers kept between frames, grown when a frame needs more. */
    float *pixblock;
    size_t pix_cap;          /* floats */
    sspan *spans;
    size_t span_cap;         /* sspans */
    int *lk;                 /* 2 L^2 */
    float *ring, **I, **nsc; /* the light ring: batch + 1 slots */
    int batch;
    slight light;
    /* The diffuse light field (dfield.c; "diffuse"). */
    int diffuse;
    atmos__dfield df;
    /* "do" (slice_do.c): the first order in the delta-M scaled medium (the passes read tab_dm, the
     * tables with sigma_t*, as in low albedo and without xi) and the orders >= 2 from the
     * discrete-ordinates field of dop (a Nishita plan of that field alone, on the same render
     * grid), turned toward the eye into do_view (the layout of df.view) */
    int do_field;
    atmos__nishita_plan *dop;
    stables tab_dm;          /* tab, its sig[][] sigma_t* (the pointers tab's: not freed) */
    float *do_view;
    float *do_ams;           /* tab_dm's Ams: tab's, the order-2 rows the smooth phase (slice_do.c) */
    float do_kap[ATMOS_MAX_WAVELENGTHS], do_share, do_share_dm; /* sjob's kap, share, share_dm (slice_do.c) */
    double do_sun[3];
    int do_valid;
    /* The volume's shadow on the air ("air_shadows"; slice_shadow.c): the map, kept per sun
     * direction, the per-frame aerial-perspective table over the shadowed pixels (storage kept)
     * and the per-pixel front part (sjob.air_front; grown to the largest image). */
    int air_shadows;
    sshadow shadow;
    atmos__aerial shadow_ap;
    float *air_front;
    size_t air_cap;
    double *air_lattice; /* the shadow evaluated at every other pixel (slice_shadow.c) */
    size_t air_lattice_cap;
};

/* The volume's shadow on the air's single scattering over the region r of img (which holds
 * the sky image): the map built when the sun moved, then per pixel the light the shadow takes
 * from the air, subtracted from the image, the part in front of the volume's halfway plane
 * kept in sp->air_front and set as j->air_front for the composite. Does nothing (j->air_front
 * NULL) for a vacuum or a sun that lights no air. *secs receives its time. */
atmos_status atmos__slice_air_shadow(atmos_context *ctx, atmos__slice_plan *sp, const atmos_atmosphere *atm,
                                     const atmos__view *v, const atmos__rect *r, sjob *j, atmos_image *img,
                                     double *secs);
void atmos__slice_shadow_free(atmos__slice_plan *sp);

/* edge_aa (slice_edges.c): 1 when the view takes four eye rays at the volume's edges only
 * (edge_aa > 0 with eye_scale 1: the eye buffer is then twice the image per axis). */
int atmos__slice_edge_mode(const atmos__slice_plan *sp, const atmos__view *v);
/* The edge pixels of the view (sets j->edge; sp->edge's storage): a pixel is an edge when the
 * volume's transmittance along its centre ray, exp(-tau) (tau at the middle wavelength),
 * differs by more than edge_aa from that of one of its eight neighbours. Depends only on the
 * view, not on the region rendered or the thread count: called after the spans are built,
 * before they are clipped to the region (it reads erow). 0 if out of memory. */
int atmos__slice_edges(atmos__slice_plan *sp, const atmos_atmosphere *atm, const atmos__view *v, sjob *j, int threads);

/* The discrete-ordinates field (slice_do.c): prepare once per plan (after the tables), update
 * per frame (a solve when the sun moved, none while held (hold_field), its view toward the eye;
 * sets j->field, j->fview, j->fvq and, when it solved, tm->field), free with the plan, and its
 * metadata line. */
atmos_status atmos__slice_do_prepare(atmos_plan *p, atmos__slice_plan *sp);
atmos_status atmos__slice_do_update(atmos_plan *p, atmos__slice_plan *sp, const atmos__view *v, sjob *j,
                                    atmos_slice_timing *tm);
void atmos__slice_do_free(atmos__slice_plan *sp);
void atmos__slice_do_describe(const atmos__slice_plan *sp, char *buf, size_t cap);

/* Slice indices k whose plane s_k = s0 + (k + 0.5) ds lies in [sa, sb] (k0 > k1: none). */
void atmos__slice_range(double sa, double sb, double s0, double ds, int nslices, int *k0, int *k1);
/* Fills the spans of j (espan, lspan, wspan, erow, lrow); 0 if out of memory. cf, cr, cu:
 * the camera's axes in the grid frame. */
int atmos__slice_build_spans(sjob *j, const atmos_camera *cam, const double cf[3], const double cr[3],
                             const double cu[3], int threads);
/* Restricts the eye spans to the eye-buffer pixels [x0, x1) x [y0, y1). */
void atmos__slice_clip_spans(sjob *j, int x0, int y0, int x1, int y1);
/* The §5 composite of the region r of the image img (which holds the sky); the air in front
 * of the volume from the aerial-perspective volume kept in `aerial` (rebuilt for the frame)
 * when the atmosphere's kind wants one, else asked of the atmosphere per pixel. */
void atmos__slice_composite(const sjob *j, const atmos_atmosphere *atm, const atmos_camera *cam, const double sun_w[3],
                            const atmos__vol_xform *xf, const atmos__rect *r, atmos__aerial *aerial, atmos_image *img,
                            int threads);
/* Sets up the per-frame job j of plan sp for the view (geometry, buffers, spans, pixels,
 * texels); r is the image region to render. */
atmos_status atmos__slice_frame_setup(atmos_context *ctx, atmos__slice_plan *sp, const atmos_atmosphere *atm,
                                      const atmos__view *v, const atmos__rect *r, sjob *j);
/* The slices, in batches; fills the eye buffer of j. Returns ATMOS_E_CANCELLED when the
 * progress callback asks to stop. */
atmos_status atmos__slice_passes(atmos_context *ctx, const atmos__slice_plan *sp, sjob *j, atmos_slice_timing *tm);

/* The beam's transmittance across a slab from the light arriving (i0) and leaving (i1) it, as the
 * light pass took it: i1 / i0, 1 where no light arrives or none is lost, at least e^-80 (a beam put
 * out within the slab): its -ln, the beam's optical depth, is then at most 80 in both eye passes,
 * the fast one's logarithm and the reference's libm one alike. */
#define ATMOS__SLICE_BEAM_MIN 1.80485e-35f /* e^-80 */
ATMOS_CLONE_HELPER float atmos__slice_beam_ratio(float i0, float i1)
{
    float r = atmos__select_f(i0 > 0.0f, i1 / i0, 1.0f);
    r = atmos__select_f(r < 1.0f, r, 1.0f); /* NaN: 1 */
    return atmos__select_f(r > ATMOS__SLICE_BEAM_MIN, r, ATMOS__SLICE_BEAM_MIN);
}

/* The eye-ray length by which the light arriving at a slab, I, times the slab's in-scattering
 * coefficient makes its in-scattered light: the integral over the slab of the light's own
 * attenuation in it (tl, the optical depth across the slab that the light pass took from that
 * light: -ln of the light leaving over the light arriving, read from the same texels; 0 where
 * the light pass keeps part of the scattered light, Eq. 24/25) times the eye's (te along the eye
 * ray, del its length). Front to back the light and the eye enter the slab by the same face:
 * del (1 - e^-(te + tl)) / (te + tl); back to front the light enters by the far one: del (e^-tl -
 * e^-te) / (te - tl). With tl = 0 both are the plain (1 - e^-te) del / te; with tl left out a
 * homogeneous medium's beam was counted too bright (back to front by (e^tl - 1) / tl: +37 % at
 * tl = te = 0.6 a slab, a dense cloud's 256 slices; front to back +29 % there). The exponentials
 * are the caller's: T = e^-te, the slab's transmittance along the eye, which Eq. 26 needs anyway,
 * and r = e^-tl, the ratio tl was taken from (atmos__slice_beam_ratio); e^-(te + tl) is T r. Both
 * sides are computed and one selected by its bits (atmos__select_f: a loop over it vectorises; a
 * division by 0 on the side not taken is not selected), as in atmos__slice_beam_ratio. */
ATMOS_CLONE_HELPER float atmos__slice_beam_len(float del, float te, float T, float tl, float r, int btf)
{
    const float y = btf ? te - tl : te + tl;
    const float e0 = btf ? r : 1.0f, e1 = btf ? T : T * r; /* the integrand at the two faces */
    const float near = del * e0 * (1.0f - 0.5f * y), far = del * (e0 - e1) / y;
    return atmos__select_f((y < 1e-3f) & (y > -1e-3f), near, far);
}

/* Eye pass of slice k over pixels x0..x1 of image row y (Eq. 26); light pass of slice k
 * over texels x0..x1 of light row b (Eq. 21, 25 / 24) where texels a0..a1 may meet
 * occupied blocks (the others of x0..x1 are copied from the arriving buffer). Each
 * returns the samples that fell in occupied blocks. Ib/nb (Ic/nc) are the light
 * arriving at slice k, In/nn the light leaving it (the eye pass reads In too, for the light's
 * attenuation across the slab: atmos__slice_beam_len). The fast versions process a span
 * in chunks of structure-of-arrays samples with vectorisable loops and a polynomial
 * exp; the reference versions are the plain scalar loops with libm's expf/logf
 * (atmos_slice_settings.reference). Both write only their own pixels/texels. */
long long atmos__slice_eye_span(const sjob *j, int k, int y, int x0, int x1, const float *Ib, const float *nb,
                                const float *In);
long long atmos__slice_light_span(const sjob *j, int k, int b, int x0, int x1, int a0, int a1, const float *Ic,
                                  const float *nc, float *In, float *nn);
long long atmos__slice_eye_span_ref(const sjob *j, int k, int y, int x0, int x1, const float *Ib, const float *nb,
                                    const float *In);
long long atmos__slice_light_span_ref(const sjob *j, int k, int b, int x0, int x1, int a0, int a1, const float *Ic,
                                      const float *nc, float *In, float *nn);

#endif
