/* EXR channel names of one wavelength each (exr_names.h). */
#include "exr_names.h"

#include <stdio.h>
#include <string.h>

void cli_exr_wavelength_name(char *buf, size_t cap, const char *layer, double nm)
{
    char num[32];
    snprintf(num, sizeof num, "%.6g", nm);
    char *dot = strchr(num, '.');
    if (dot) *dot = ',';
    snprintf(buf, cap, "%s.%snm", layer, num);
}
