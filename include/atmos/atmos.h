/* atmos — physically based rendering of atmospheric phenomena.
 *
 * Umbrella header: the base (atmos/base.h: version, status codes, the context object) and
 * every module header. Each module header also compiles on its own.
 *
 * Conventions (see docs/architecture.md):
 *  - SI units: metres, m^-1, m^2, particles/m^3; angles in degrees at the API surface
 *    unless a name says _rad.
 *  - Right-handed world frame, y up, y = 0 at sea level; x points east, z south, so
 *    north is -z. Azimuths are measured clockwise from north (north 0°, east 90°).
 *  - Objects come in create/destroy pairs; destroy(NULL) does nothing.
 *  - Fallible functions return atmos_status and report a message with context through
 *    the atmos_context they are given (atmos_context_error()).
 */
#ifndef ATMOS_ATMOS_H
#define ATMOS_ATMOS_H

#include "atmos/base.h"

#include "atmos/spectrum.h"
#include "atmos/camera.h"
#include "atmos/sun.h"
#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/optics.h"
#include "atmos/volume.h"
#include "atmos/scene.h"
#include "atmos/render.h"
#include "atmos/slice.h"
#include "atmos/path.h"
#include "atmos/plan.h"
#include "atmos/mesh.h"
#include "atmos/sim.h"
#include "atmos/cloudstats.h"

#endif
