/* The data files of a raw volume's JSON sidecar (sidecar_inputs.h). */
#include "sidecar_inputs.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <string.h>

/* The files into names (cli_sidecar_inputs). */
static void sidecar_files(const char *path, char (*names)[CLI_OUTPUT_PATH_MAX], int cap, int *n)
{
    const size_t len = strlen(path);
    FILE *f = len > 5 && !strcmp(path + len - 5, ".json") ? fopen(path, "rb") : NULL;
    if (!f) return;
    static char text[1 << 20];
    const size_t got = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[got] = '\0';
    cJSON *root = cJSON_Parse(text), *fields = cJSON_GetObjectItemCaseSensitive(root, "fields"), *it;
    const char *slash = strrchr(path, '/');
    const int dir = slash ? (int)(slash - path) + 1 : 0;
    const cJSON *files[64];
    int k = 0;
    files[k++] = cJSON_GetObjectItemCaseSensitive(root, "file");
    if (!cJSON_IsArray(fields)) fields = NULL;
    cJSON_ArrayForEach(it, fields) if (k < 64) files[k++] = cJSON_GetObjectItemCaseSensitive(it, "file");
    for (int i = 0; i < k && *n < cap; i++)
        if (cJSON_IsString(files[i]) && files[i]->valuestring[0])
            snprintf(names[(*n)++], CLI_OUTPUT_PATH_MAX, "%.*s%s", files[i]->valuestring[0] == '/' ? 0 : dir, path,
                     files[i]->valuestring);
    cJSON_Delete(root);
}

void cli_sidecar_inputs(const char *path, char (*names)[CLI_OUTPUT_PATH_MAX], int cap, int *n, const char **inputs,
                        int *ninputs)
{
    const int from = *n;
    sidecar_files(path, names, cap, n);
    for (int k = from; k < *n; k++) inputs[(*ninputs)++] = names[k];
}
