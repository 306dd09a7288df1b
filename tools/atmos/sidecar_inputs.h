/* The data files of a raw volume's JSON sidecar: inputs too, which no output of a command may
 * replace (outputs.h's cli_outputs_check). */
#ifndef ATMOS_CLI_SIDECAR_INPUTS_H
#define ATMOS_CLI_SIDECAR_INPUTS_H

#include "outputs.h"

/* The data files a raw volume's sidecar (a source NAME.json) names, its "file" and each field's,
 * against the sidecar's folder as the reader takes them, as a command's inputs: their names stored
 * in names from *n on (at most cap), each appended to inputs at *ninputs. A file that is no such
 * sidecar (another format, unreadable, not JSON) adds none. */
void cli_sidecar_inputs(const char *path, char (*names)[CLI_OUTPUT_PATH_MAX], int cap, int *n, const char **inputs,
                        int *ninputs);

#endif
