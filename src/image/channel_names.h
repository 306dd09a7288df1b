/* Colour channels by name: "R", "G", "B" (and "A"), or one layer's "<layer>.R", ... as
 * multi-layer OpenEXR files name them. Used by the EXR reader to order channels and by
 * `atmos compare` to pair them. */
#ifndef ATMOS_IMAGE_CHANNEL_NAMES_H
#define ATMOS_IMAGE_CHANNEL_NAMES_H

/* Finds R, G and B among names[0..count-1] (entries may not be NULL): the plain names
 * when all three exist, else the channels of the only layer that has all three. idx[0..2]
 * get their indices and idx[3] that of the same layer's alpha (or -1). Returns 1 if found,
 * 0 otherwise (also when two layers both have R, G and B: ambiguous). */
int atmos__rgb_channels(const char *const *names, int count, int idx[4]);

/* 1 if the name is an alpha channel: "A" or "<layer>.A". */
int atmos__is_alpha_channel(const char *name);

#endif
