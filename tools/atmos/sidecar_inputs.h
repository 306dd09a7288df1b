/* The data files of a raw volume's JSON sidecar: inputs too, which no output of a command may
 * replace (outputs.h's cli_outputs_check). */
#ifndef ATMOS_CLI_SIDECAR_INPUTS_H
#define ATMOS_CLI_SIDECAR_INPUTS_H

#include "outputs.h"

/* The data files a raw volume's sidecar (a source NAME.json) names, its "file" and each field's,
 * against the sidecar's folder as the reader takes them, added to names from *n on (at most
 * cap). A file that is no such sidecar (another format, unreadable, not JSON) adds none. */
void cli_sidecar_files(const char *path, char (*names)[CLI_OUTPUT_PATH_MAX], int cap, int *n);

#endif
