/* The planet's ground (planet.h): a uniform Lambertian reflectance and no light of its own. */
#include "atmosphere/planet.h"

double atmos__planet_ground_albedo(const atmos__planet *pl, const double g[3], int k)
{
    (void)g, (void)k;
    return pl->albedo;
}

double atmos__planet_ground_emission(const atmos__planet *pl, const double g[3], int k)
{
    (void)pl, (void)g, (void)k;
    return 0.0;
}
