/* The beam renderer's triangle rasteriser for its depth maps (the spotlights' cube faces,
 * beams_shadow.c, and the sun's orthographic map, beams_sun.c). Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_RASTER_H
#define ATMOS_RENDER_BEAMS_RASTER_H

/* One triangle into an n x n depth map, keeping the least depth per texel whose centre it
 * covers: its vertices at texel coordinates (x[k], y[k]) with z[k] their depth (perspective 0:
 * the depth is affine across the map, an orthographic view) or its reciprocal (perspective 1:
 * 1/depth is affine, a pinhole view). */
void atmos__beams_raster(float *depth, int n, const double x[3], const double y[3], const double z[3], int perspective);
/* The same, its texels in rows row0..row1 alone (0 <= row0, row1 <= n - 1): each texel the
 * value and the order of comparisons of the whole triangle's, so a map drawn band by band,
 * every triangle in the same order into each band, has the same bits. */
void atmos__beams_raster_rows(float *depth, int n, const double x[3], const double y[3], const double z[3],
                              int perspective, int row0, int row1);

/* Clips a triangle (a view's frame, z forward) at z = near (Sutherland-Hodgman) into poly;
 * returns its vertex count, 0 or 3..4 (a fan from poly[0]). */
int atmos__beams_clip_near(const double in[3][3], double near, double poly[4][3]);

#endif
