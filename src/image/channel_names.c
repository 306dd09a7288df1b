/* Colour channels by name (channel_names.h). */
#include "image/channel_names.h"

#include <string.h>

int atmos__is_alpha_channel(const char *name)
{
    size_t n = strlen(name);
    return strcmp(name, "A") == 0 || (n >= 2 && strcmp(name + n - 2, ".A") == 0);
}

/* The index of "<prefix><letter>" (prefix of length plen) or -1. */
static int find_in_layer(const char *const *names, int count, const char *prefix, size_t plen, char letter)
{
    for (int i = 0; i < count; i++)
        if (strlen(names[i]) == plen + 1 && strncmp(names[i], prefix, plen) == 0 && names[i][plen] == letter) return i;
    return -1;
}

/* The channels of the layer named by prefix[0..plen): 1 if it has R, G and B. */
static int layer_rgb(const char *const *names, int count, const char *prefix, size_t plen, int idx[4])
{
    static const char letters[4] = {'R', 'G', 'B', 'A'};
    for (int c = 0; c < 4; c++) idx[c] = find_in_layer(names, count, prefix, plen, letters[c]);
    return idx[0] >= 0 && idx[1] >= 0 && idx[2] >= 0;
}

int atmos__rgb_channels(const char *const *names, int count, int idx[4])
{
    if (layer_rgb(names, count, "", 0, idx)) return 1;
    int found = 0, best[4] = {-1, -1, -1, -1};
    for (int i = 0; i < count; i++) {
        size_t n = strlen(names[i]);
        if (n < 3 || strcmp(names[i] + n - 2, ".R") != 0) continue; /* each layer once, by its R */
        int cand[4];
        if (!layer_rgb(names, count, names[i], n - 1, cand)) continue;
        if (found++) return 0; /* two layers with colour: which one is meant is not ours to guess */
        memcpy(best, cand, sizeof best);
    }
    memcpy(idx, best, sizeof best);
    return found == 1;
}
