/* The library's two angle grids, and integration over the sphere on a grid.
 *
 * Phase tables (phase_table.c) and Ams_n tables (msphase.c) are tabulated on different grids,
 * both read through angle_table.h. They differ on purpose. A phase table has one row per
 * wavelength and must resolve single-scattering detail (rainbow and glory fringes) everywhere,
 * so it keeps 0.05° steps out to 180°. An Ams table has a row per order and wavelength
 * (hundreds of orders for cloud droplets, and the slice renderer keeps a per-pixel copy), and
 * Ams_n for n >= 2, a convolution of the phase function with itself, is smooth on the 0.1°
 * scale beyond 20°: 0.1° steps there halve it (its order 1 is the phase table resampled, as
 * Riley et al.'s 0.18° tables were). Near the forward direction the Ams grid is finer
 * (0.001° to 0.5°), because the diffraction peak of a 1 mm drop, ~0.013° wide, widens only
 * as sqrt(n). Both grids are baked into cached tables (a phase table's key holds a checksum
 * of its grid; a cached Ams table is compared with today's grid when loaded) and into
 * rendered images.
 */
#include "optics/angle_table.h"
#include "optics/optics_internal.h"

#include <math.h>

/* Segments [from, to) in degrees with their step: fine near 0° where the diffraction
 * peak of a 1 mm drop is ~0.01° wide (lambda / 2r rad), 0.05° over most of the range
 * (finer than the 0.1° of Riley et al.'s MiePlot tables). */
static const atmos__angle_segment phase_segments[] = {
    {0.0, 0.1, 0.0005}, {0.1, 1.0, 0.002}, {1.0, 10.0, 0.01}, {10.0, 180.0, 0.05}};

/* Ams_n: 0.001° near the forward direction, 0.1° at most anywhere (docs/msphase.md). */
static const atmos__angle_segment msphase_segments[] = {
    {0.0, 0.1, 0.0005}, {0.1, 0.5, 0.001}, {0.5, 2.0, 0.01}, {2.0, 20.0, 0.05}, {20.0, 180.0, 0.1}};

static atmos__angle_grid phase_grid, msphase_grid;
static int built;

static void build_grid(atmos__angle_grid *g, const atmos__angle_segment *seg, int count)
{
    static double deg[ATMOS__ANGLE_MAX];
    int n = atmos__angle_segments(seg, count, deg, ATMOS__ANGLE_MAX);
    /* Constant segments that fit: cannot fail (tests/unit/test_angle_table.c). */
    atmos__angle_grid_init(g, deg, n);
}

/* Built on first use, under a lock, before any caller sees them; from then on read-only. */
static void build_grids(void)
{
#pragma omp critical(atmos_angle_grids)
    {
        if (!built) {
            build_grid(&phase_grid, phase_segments, (int)(sizeof phase_segments / sizeof *phase_segments));
            build_grid(&msphase_grid, msphase_segments, (int)(sizeof msphase_segments / sizeof *msphase_segments));
            built = 1;
        }
    }
}

const atmos__angle_grid *atmos__phase_angle_grid(void)
{
    build_grids();
    return &phase_grid;
}

const atmos__angle_grid *atmos__msphase_angle_grid(void)
{
    build_grids();
    return &msphase_grid;
}

/* No lock: a pointer to a grid's angles exists only once the grid was built. */
const atmos__angle_grid *atmos__angle_grid_known(const double *deg, int n)
{
    if (deg == phase_grid.deg && n == phase_grid.n) return &phase_grid;
    if (deg == msphase_grid.deg && n == msphase_grid.n) return &msphase_grid;
    return NULL;
}

int atmos_phase_grid(const double **theta_deg)
{
    const atmos__angle_grid *g = atmos__phase_angle_grid();
    if (theta_deg) *theta_deg = g->deg;
    return g->n;
}

double atmos__sphere_integral(int n, const double *theta_deg, const double *f)
{
    const double d2r = 3.14159265358979323846 / 180.0;
    double s = 0.0;
    for (int i = 0; i + 1 < n; i++) {
        double t0 = theta_deg[i] * d2r, t1 = theta_deg[i + 1] * d2r;
        s += 0.5 * (f[i] * sin(t0) + f[i + 1] * sin(t1)) * (t1 - t0);
    }
    return 2.0 * 3.14159265358979323846 * s;
}
