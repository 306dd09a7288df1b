/* Meshes placed for the beam renderer's tests (test_beams_primary, test_beams_sun_dark,
 * test_beams_surface_shadow): a mesh moved to (x, y, z), scaled by (sx, sy, sz) and turned ry
 * degrees about the vertical; a failure is a failed check. Header-only. */
#ifndef ATMOS_TEST_MESH_H
#define ATMOS_TEST_MESH_H

#include "atmos/atmos.h"
#include "test.h"

static atmos_mesh *test_mesh_place(atmos_context *ctx, atmos_mesh *m, double x, double y, double z, double sx,
                                   double sy, double sz, double ry)
{
    atmos_mesh_transform t;
    atmos_mesh_transform_identity(&t);
    t.position_m[0] = x, t.position_m[1] = y, t.position_m[2] = z;
    t.scale[0] = sx, t.scale[1] = sy, t.scale[2] = sz, t.rotation_deg[1] = ry;
    CHECK_OK(atmos_mesh_apply_transform(ctx, m, &t));
    return m;
}

#endif
