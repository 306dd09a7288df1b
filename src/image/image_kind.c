/* An image file's format by its first bytes (atmos/image.h): the magic numbers the readers
 * check, in one place. */
#include "atmos/image.h"

#include <stdio.h>
#include <string.h>

const char *atmos_image_kind(const void *bytes, size_t n)
{
    const unsigned char *b = bytes;
    if (!b) return NULL;
    if (n >= 4 && !memcmp(b, "\x76\x2f\x31\x01", 4)) return "OpenEXR";
    if (n >= 8 && !memcmp(b, "\x89PNG\r\n\x1a\n", 8)) return "PNG";
    if (n >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) return "JPEG";
    /* "PF" or "Pf" and the whitespace byte atmos_read_pfm takes after it ("PF\r\n" too) */
    if (n >= 3 && b[0] == 'P' && (b[1] == 'F' || b[1] == 'f') &&
        (b[2] == ' ' || b[2] == '\t' || b[2] == '\n' || b[2] == '\r'))
        return "PFM";
    return NULL;
}

const char *atmos_image_file_kind(const char *path)
{
    unsigned char b[8];
    FILE *f = path ? fopen(path, "rb") : NULL;
    if (!f) return NULL;
    const size_t n = fread(b, 1, sizeof b, f);
    fclose(f);
    return atmos_image_kind(b, n);
}
