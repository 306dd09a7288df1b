/* The sun's shadow map rectified along epipolar lines (docs/beams.md, *The sun* and
 * *Fourteenth round* under *Speed*; Chen, Baran, Kavan and Jensen 2011, "Real-time volumetric
 * shadows using 1D min-max mipmaps", whose rectification and trees this follows). For a
 * directional sun every eye ray o + t d projects into the sun's orthographic map onto a
 * half-line from the eye's own point there (the epipole), so the map is resampled once a frame
 * along half-lines from the epipole at even angles, and each line gets a 1-D min/max tree of
 * its depths. A ray then takes the line nearest its projection's angle and finds where it is
 * lit by walking that tree: its depth is linear along the line, the line's depth piecewise
 * linear between samples a texel apart, so the lit stretches come out in closed form, without
 * reading the map. Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_EPIPOLAR_H
#define ATMOS_RENDER_BEAMS_EPIPOLAR_H

#include <stddef.h>

typedef struct atmos__beams_sun atmos__beams_sun;

typedef struct atmos__beams_epi {
    int lines;          /* 0: none (each ray walks the map's own tiles) */
    double ex, ey;      /* the epipole: the eye in the map's look-up coordinates (texels) */
    double dth;         /* line j leaves the epipole at the angle j dth (2 pi / lines) */
    int *k0, *cnt;      /* line j: cnt samples at r = k0, k0 + 1, ... texels from the epipole */
    size_t *at, *tat;   /* line j's samples at m + at[j], its tree's cells at lh + 2 tat[j] */
    float *m, *lh;      /* depths along the lines (INFINITY beside every object); per tree cell its
                         * least and greatest depth, side by side */
    size_t cap_lines, cap_floats; /* the blocks' sizes, kept from frame to frame */
    const atmos__beams_sun *sun;  /* the map the lines were made of, and its build (gen) */
    unsigned long gen;
    size_t max_samples;           /* the bound on the samples they were made under */
} atmos__beams_epi;

/* The lines of the map s from the eye: their number such that neighbours lie at most a texel
 * apart where the map's objects end (their blocks kept from the last call where large enough).
 * Lines made by the last call of the same build of the same map from the same point (the eye
 * turning in place) are kept as they are: the same values.
 * 0 (e without lines when s has no map or they would take more than max_samples samples), or
 * -1 out of memory. Threads: threads lines at a time. */
int atmos__beams_epi_build(atmos__beams_epi *e, const atmos__beams_sun *s, const double eye[3], size_t max_samples,
                           int threads);
void atmos__beams_epi_free(atmos__beams_epi *e);

/* The lit stretches of a ray along line j (0 <= j < lines) over r in [0, rT] (rT may be
 * INFINITY), its depth zc + r zs (the bias taken off): lit where it is nearer the sun than the
 * line's depth. Each maximal lit stretch [ra, rb] is passed to lit(u, ra, rb) in increasing r. */
void atmos__beams_epi_walk(const atmos__beams_epi *e, int j, double zc, double zs, double rT,
                           void (*lit)(void *u, double ra, double rb), void *u);

#endif
