/* Light fields (DESIGN.md §13): a grid over a volume holding, per cell and wavelength, light
 * that a renderer's eye pass reads instead of computing it per sample. One container for
 * every solver: a plan product made once per sun direction (and sky) and reused by the eye
 * passes of every frame until the sun moves.
 *
 *   lfield.c      the container: the grid, its cells' values, the field turned toward an eye
 *                 (the trilinear read is inline below)
 *   lmedium.c     the medium on the field's grid (extinction, scattering, asymmetry per cell)
 *   sun_source.c  the sunlight a forward-lobe model (Riley et al. 2004 Eq. 24/25) drops at
 *                 each scattering: the source of the diffuse field
 *   diffusion.c   the diffuse light of all orders by a (flux-limited) diffusion solve
 *
 *   nishita_pattern.c, nishita_field.c, nishita_sky.c  Nishita et al. 1996's reference
 *                 patterns and sky elements (nishita.h)
 *
 * Kinds: ATMOS__LFIELD_DIFFUSION, ATMOS__LFIELD_NISHITA (docs/lightfield.md).
 * Not part of the API. */
#ifndef ATMOS_LIGHT_LFIELD_H
#define ATMOS_LIGHT_LFIELD_H

#include "core/internal.h"

#include <stddef.h>

typedef enum {
    ATMOS__LFIELD_NONE = 0,
    ATMOS__LFIELD_DIFFUSION = 1, /* mean radiance of the diffuse light, isotropic */
    ATMOS__LFIELD_NISHITA = 2,   /* Nishita et al. 1996: orders 2, 3 and sky light toward one eye direction */
} atmos__lfield_kind;

/* The medium on the field's grid: cell (i, j, k) is the box [i h, (i + 1) h) x ... in the
 * field's frame (metres from the grid's corner); per cell and wavelength ([cell * n + w]). */
typedef struct {
    int c[3], n;     /* cells per axis, wavelengths */
    double h;        /* cell edge, m */
    int periodic[3]; /* 1: the axis wraps around (a horizontally infinite layer); 0: vacuum beyond */
    float *sig_t;    /* extinction, m^-1 */
    float *sig_s;    /* scattering, m^-1 */
    float *g;        /* asymmetry parameter <cos theta> of the scattering */
    float *jin;      /* [face * n + w] or NULL: the diffuse light coming in through each non-periodic
                        face (-x, +x, -y, +y, -z, +z) from outside, the inward partial current
                        (irradiance), W m^-2 nm^-1: the sky and the ground as boundary sources */
} atmos__lmedium;

/* The field: cell (i, j, k) stands for the s^3 host voxels i s .. i s + s - 1 (host-voxel
 * centres at integer coordinates), its value at the centre of those, (i + (s - 1)/2 ...). */
typedef struct {
    int kind;
    int c[3], n; /* cells per axis, wavelengths */
    int s;       /* host voxels per cell edge */
    float *L;    /* [cell * n + w]: mean radiance of the diffuse light, W m^-2 sr^-1 nm^-1 */
    float *J;    /* [(cell * n + w) * 3 + axis]: its net flux (first moment), W m^-2 nm^-1, in the
                    grid's frame: the radiance toward unit direction d is L + 3/(4 pi) J . d */
    float *LA;   /* [cell * 2 n + w]: L, then [cell * 2 n + n + w]: A = 3/(4 pi) J . d toward one
                    eye (d from the cell's centre; the renderer's per-frame view of the field) */
    float *phi;  /* [cell * n + w]: its fluence (4 pi L), the solver's unknown (its warm start) */
    float *part; /* ATMOS__LFIELD_NISHITA: [(cell * n + w) * 4 + q], q = 0 the sunlight at the cell's
                    centre (W m^-2 nm^-1), 1 order 2, 2 order 3, 3 sky and ground light scattered
                    once (q = 1..3: radiance per unit scattering coefficient toward the eye,
                    W m^-2 sr^-1 nm^-1; L holds their sum). NULL for other kinds. */
    /* what it was computed for */
    int valid;
    double sun[3];
    int warm; /* 1: solved from an earlier sun's field (the viewer's frames); a frame that asks for
                 no warm start (a save: atmos render's image) solves it afresh */
    /* the last solve */
    int sweeps;
    double build_s, source_s, solve_s;
} atmos__lfield;

/* Fills f->LA for an eye at host-voxel coordinate eye (grid and host axes aligned, the host's
 * voxels cubes). */
void atmos__lfield_toward(atmos__lfield *f, const double eye[3], int threads);

size_t atmos__lmedium_cells(const atmos__lmedium *m);
int atmos__lmedium_alloc(atmos__lmedium *m, int cx, int cy, int cz, int n, double h);
void atmos__lmedium_free(atmos__lmedium *m);

/* Allocates a field of cells cx x cy x cz (s host voxels each) for n wavelengths, zero. */
int atmos__lfield_alloc(atmos__lfield *f, int kind, int cx, int cy, int cz, int n, int s);
void atmos__lfield_free(atmos__lfield *f);

/* Trilinear value at host-voxel coordinate (u, v, w) (clamped to the outer cells' centres)
 * of an array of m floats per cell (L: n, J: 3 n): out[m]. */
static inline void atmos__lfield_axis(float u, int s, int c, int *i, float *w)
{
    float x = (u - 0.5f * (float)(s - 1)) / (float)s;
    const float lim = (float)(c - 1);
    x = x < 0.0f ? 0.0f : (x > lim ? lim : x);
    int a = (int)x;
    if (a > c - 2) a = c - 2 < 0 ? 0 : c - 2;
    *i = a, *w = c > 1 ? x - (float)a : 0.0f;
}

static inline void atmos__lfield_sample(const atmos__lfield *f, const float *arr, int m, float u, float v, float w,
                                        float *out)
{
    int i, j, k;
    float a, b, c;
    atmos__lfield_axis(u, f->s, f->c[0], &i, &a);
    atmos__lfield_axis(v, f->s, f->c[1], &j, &b);
    atmos__lfield_axis(w, f->s, f->c[2], &k, &c);
    const size_t sx = f->c[0] > 1 ? (size_t)m : 0, sy = f->c[1] > 1 ? (size_t)f->c[0] * m : 0,
                 sz = f->c[2] > 1 ? (size_t)f->c[0] * f->c[1] * m : 0;
    const float *p = arr + (((size_t)k * f->c[1] + j) * f->c[0] + i) * m;
    const float w000 = (1 - a) * (1 - b) * (1 - c), w100 = a * (1 - b) * (1 - c), w010 = (1 - a) * b * (1 - c),
                w110 = a * b * (1 - c), w001 = (1 - a) * (1 - b) * c, w101 = a * (1 - b) * c, w011 = (1 - a) * b * c,
                w111 = a * b * c;
    for (int q = 0; q < m; q++)
        out[q] = w000 * p[q] + w100 * p[sx + q] + w010 * p[sy + q] + w110 * p[sx + sy + q] + w001 * p[sz + q] +
                 w101 * p[sx + sz + q] + w011 * p[sy + sz + q] + w111 * p[sx + sy + sz + q];
}

/* The forward-lobe model's kept fraction: the share F of the light scattered at cell `cell`
 * (wavelength w) that stays in the forward beam when the light has been scattered n times
 * before (Riley's F_{n+1}, Eq. 23; 0: all of it leaves the beam), and in *mu the mean cosine,
 * to the beam's direction of travel, of the dropped rest 1 - F (the diffuse source's
 * direction; 0: isotropic). */
typedef float (*atmos__lkeep_fn)(const void *user, size_t cell, int w, float n, float *mu);
/* The beam that keeps nothing (plain attenuation: F = 0, the dropped light isotropic). */
float atmos__lkeep_none(const void *user, size_t cell, int w, float n, float *mu);

/* The source of the diffuse field (sun_source.c): per cell and wavelength the power per unit
 * volume, W m^-3 nm^-1, that the forward beam loses to scattering out of its lobe,
 * Q = sig_s (1 - F) I, where I is the forward beam arriving at the cell's centre from the sun
 * (travel direction lt, a unit vector in the field's frame; sun[w] its irradiance where it
 * enters the grid) attenuated by sig_t - sig_s F along the way, the scattering count growing
 * by sig_s ds (mean over wavelengths, Riley's Eq. 21). Q1 (may be NULL) gets the source's
 * first moment, [(cell * n + w) * 3 + axis] = Q mu lt (W m^-3 nm^-1): the dropped light's net
 * direction. Ibeam (may be NULL) gets I. */
void atmos__lfield_sun_source(const atmos__lmedium *m, const double lt[3], const double *sun, atmos__lkeep_fn keep,
                              const void *user, float *Q, float *Q1, float *Ibeam, int threads);

/* A source of the diffuse field: per cell and wavelength its power per unit volume Q
 * ([cell * n + w]) and its first moment Q1 ([(cell * n + w) * 3 + axis], NULL: isotropic). */
typedef struct {
    const float *Q, *Q1;
} atmos__lsource;

typedef struct {
    int max_sweeps; /* 0: 2000 */
    double tol;     /* largest change of a sweep over the largest fluence; 0: 1e-4 */
    int limiter;    /* 1: flux-limited diffusion coefficient (Levermore-Pomraning sum limiter) */
    int cascade;    /* a cold start: up to this many coarser grids (cells of 2, 4 ... cells), each
                       solved from the next coarser one's solution, the coarsest from zero, then
                       the fine grid from the finest coarse one's (phi's content ignored); 0: none,
                       phi is the start (a warm start) */
} atmos__ldiffusion_opts;

/* Solves -div(D grad phi) + sig_a phi = Q - div(3 D Q1) on the medium's grid (diffusion.c), D =
 * 1/(3 sig_tr [+ |grad phi|/phi]), sig_tr = sig_t - g sig_s (the delta-Eddington /
 * similarity-scaled transport extinction), vacuum (Marshak) boundaries on the non-periodic
 * faces; phi holds the warm start on entry. Returns the sweeps used. */
int atmos__lfield_diffuse(const atmos__lmedium *m, const atmos__lsource *q, float *phi, const atmos__ldiffusion_opts *o,
                          int threads);

/* The cascade's coarse grids (diffusion_coarse.c). 1: m has a coarser grid (every axis of 4
 * cells or more, or a periodic axis of one). Coarsen: cm, its source *cq, *cq1 (NULL when q->Q1
 * is; the caller frees them) on cells twice as large, the means of the fine cells' (an odd
 * count padded with vacuum); 0 if out of memory. Prolong: wavelength w of phi on m from the
 * coarse solution cphi on cm (trilinear between the coarse cells' centres). */
int atmos__lmedium_can_coarsen(const atmos__lmedium *m);
int atmos__lmedium_coarsen(const atmos__lmedium *m, const atmos__lsource *q, atmos__lmedium *cm, float **cq,
                           float **cq1);
void atmos__lfield_prolong(const atmos__lmedium *cm, const float *cphi, const atmos__lmedium *m, float *phi, int w);

/* The net power leaving through each of the six faces (-x, +x, -y, +y, -z, +z), (outgoing
 * minus the incoming jin), summed over the face's cells, of wavelength w: out[6], W nm^-1. */
void atmos__lfield_leak(const atmos__lmedium *m, const atmos__lsource *q, const float *phi,
                        const atmos__ldiffusion_opts *o, int w, double out[6]);
/* The net flux J = -D grad phi + 3 D Q1 of the solution (central differences),
 * [(cell * n + w) * 3 + a]. */
void atmos__lfield_flux(const atmos__lmedium *m, const atmos__lsource *q, const float *phi,
                        const atmos__ldiffusion_opts *o, float *J, int threads);

#endif
