/* Internals of the path tracer: its parts. Not part of the API. */
#ifndef ATMOS_PATH_INTERNAL_H
#define ATMOS_PATH_INTERNAL_H

#include "render/path_common.h"
#include "render/path_env.h"
#include "render/path_medium.h"
#include "render/path_phase.h"

#endif
