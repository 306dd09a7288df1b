/* Compiled-in refractive-index tables (generated: src/optics/refractive_data.c). */
#ifndef ATMOS_REFRACTIVE_DATA_H
#define ATMOS_REFRACTIVE_DATA_H

extern const int atmos__water_hale_querry_count;
extern const double atmos__water_hale_querry[][3];
extern const int atmos__ice_warren_brandt_count;
extern const double atmos__ice_warren_brandt[][3];

#endif
