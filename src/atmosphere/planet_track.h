/* Free flights and transmittances through the spherical planet's air for the Monte Carlo
 * reference (planet_track.c): delta tracking and ratio tracking with majorants that follow
 * the exponential profiles along the ray. Internal to src/atmosphere/. */
#ifndef ATMOS_PLANET_TRACK_H
#define ATMOS_PLANET_TRACK_H

#include "atmosphere/planet.h"

/* Distance from p to the top of the air along d (p at or below the top). */
double atmos__planet_exit_top(const atmos__planet *pl, const double p[3], const double d[3]);
/* Distance from p to the ground along d, INFINITY when the ray misses it or rises (p at or
 * above the ground: a point on the ground looking up does not meet it again). */
double atmos__planet_hit_ground(const atmos__planet *pl, const double p[3], const double d[3]);

/* Delta tracking of wavelength k's extinction along p + t d, t in [0, tmax]: the distance of
 * the first real collision, or tmax when the ray gets through (probability: the
 * transmittance). */
double atmos__planet_free_flight(const atmos__planet *pl, const double p[3], const double d[3], double tmax, int k,
                                 atmos__stream *r);
/* Ratio tracking: an unbiased estimate of the transmittance of p + t d, t in [0, tmax], at
 * wavelength k (draws no numbers where the air is absent). */
double atmos__planet_ratio_track(const atmos__planet *pl, const double p[3], const double d[3], double tmax, int k,
                                 atmos__stream *r);
/* An unbiased estimate of the transmittance of the sunlight reaching p (ratio tracking to
 * the top; 0 where the planet hides the sun's centre). */
double atmos__planet_sun_track(const atmos__planet *pl, const double p[3], const double sun[3], int k,
                               atmos__stream *r);

#endif
