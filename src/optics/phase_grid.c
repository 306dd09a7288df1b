/* The angular grid shared by every phase table, and integration over the sphere on it. */
#include "optics/optics_internal.h"

#include <math.h>

/* Segments [from, to) in degrees with their step: fine near 0° where the diffraction
 * peak of a 1 mm drop is ~0.01° wide (lambda / 2r rad), 0.05° over most of the range
 * (finer than the 0.1° of Riley et al.'s MiePlot tables). */
static const struct {
    double from, to, step;
} segments[] = {{0.0, 0.1, 0.0005}, {0.1, 1.0, 0.002}, {1.0, 10.0, 0.01}, {10.0, 180.0, 0.05}};

#define GRID_MAX 6000
static double grid[GRID_MAX];
static int grid_n;

static void build_grid(void)
{
    int n = 0;
    for (size_t s = 0; s < sizeof segments / sizeof *segments; s++) {
        int steps = (int)lround((segments[s].to - segments[s].from) / segments[s].step);
        for (int i = 0; i < steps; i++) grid[n++] = segments[s].from + i * segments[s].step;
    }
    grid[n++] = 180.0;
    grid_n = n;
}

int atmos_phase_grid(const double **theta_deg)
{
    /* Built on first use; the values are the same on every call, so a race between
     * two first calls only writes the same numbers twice. */
#pragma omp critical(atmos_phase_grid)
    {
        if (!grid_n) build_grid();
    }
    if (theta_deg) *theta_deg = grid;
    return grid_n;
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
