/* The private temporary directory a fuzz target writes its inputs into: made under $TMPDIR (or
 * /tmp) on first use and removed, with the files in it, when the process exits normally (a
 * target that aborts on a broken promise leaves it, with the input that broke it). Included by
 * one target each; not a library header. */
#ifndef ATMOS_FUZZ_TMPDIR_H
#define ATMOS_FUZZ_TMPDIR_H
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

static char fuzz_tmpdir_path[256];

static void fuzz_tmpdir_remove(void)
{
    DIR *d = opendir(fuzz_tmpdir_path);
    if (d) {
        struct dirent *e;
        char p[512];
        while ((e = readdir(d)) != NULL) {
            if (e->d_name[0] == '.') continue;
            snprintf(p, sizeof p, "%s/%s", fuzz_tmpdir_path, e->d_name);
            remove(p);
        }
        closedir(d);
    }
    rmdir(fuzz_tmpdir_path);
}

/* The directory's path, or NULL if it cannot be made. */
static const char *fuzz_tmpdir(void)
{
    if (fuzz_tmpdir_path[0]) return fuzz_tmpdir_path;
    const char *t = getenv("TMPDIR");
    snprintf(fuzz_tmpdir_path, sizeof fuzz_tmpdir_path, "%s/atmos-fuzz-XXXXXX", t && *t ? t : "/tmp");
    if (!mkdtemp(fuzz_tmpdir_path)) return NULL;
    atexit(fuzz_tmpdir_remove);
    return fuzz_tmpdir_path;
}

#endif
