/* Replays fuzz inputs without libFuzzer: every regular file in the directories
 * (or the files) named on the command line goes through LLVMFuzzerTestOneInput
 * once, so CI can run the corpus and the crasher files under the sanitizers
 * with any compiler. Exits nonzero if an argument cannot be read or names an
 * empty directory (a corpus that silently vanished must not pass). */
#define _POSIX_C_SOURCE 200809L /* opendir, stat */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Inputs larger than this are skipped: libFuzzer's own default -max_len is far
 * smaller, and the replay must not need unbounded memory. */
#define REPLAY_MAX_BYTES ((size_t)64 << 20)

static int run_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        return -1;
    }
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0 || (size_t)sb.st_size > REPLAY_MAX_BYTES) {
        fprintf(stderr, "%s: cannot stat or larger than %zu bytes\n", path, REPLAY_MAX_BYTES);
        fclose(f);
        return -1;
    }
    size_t size = (size_t)sb.st_size;
    /* An exact-size buffer (malloc(0) may return NULL; ask for at least 1) so
     * AddressSanitizer sees any read past the input's end. */
    uint8_t *buf = malloc(size ? size : 1);
    if (!buf || fread(buf, 1, size, f) != size) {
        fprintf(stderr, "%s: cannot read\n", path);
        free(buf);
        fclose(f);
        return -1;
    }
    fclose(f);
    LLVMFuzzerTestOneInput(buf, size);
    free(buf);
    return 0;
}

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Files in sorted order so that runs are reproducible. */
static int run_dir(const char *dir, int *count)
{
    DIR *d = opendir(dir);
    if (!d) {
        perror(dir);
        return -1;
    }
    char **names = NULL;
    size_t n = 0, cap = 0;
    struct dirent *e;
    int rc = 0;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.') continue;
        if (n == cap) {
            cap = cap ? cap * 2 : 64;
            char **nn = realloc(names, cap * sizeof *names);
            if (!nn) {
                rc = -1;
                break;
            }
            names = nn;
        }
        size_t len = strlen(dir) + strlen(e->d_name) + 2;
        names[n] = malloc(len);
        if (!names[n]) {
            rc = -1;
            break;
        }
        snprintf(names[n], len, "%s/%s", dir, e->d_name);
        n++;
    }
    closedir(d);
    if (n) qsort(names, n, sizeof *names, cmp_names);
    for (size_t i = 0; i < n; i++) {
        struct stat sb;
        if (rc == 0 && stat(names[i], &sb) == 0 && S_ISREG(sb.st_mode)) {
            if (run_file(names[i]) != 0) rc = -1;
            else (*count)++;
        }
        free(names[i]);
    }
    free(names);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s DIR_OR_FILE...\n", argv[0]);
        return 2;
    }
    int status = 0;
    for (int i = 1; i < argc; i++) {
        struct stat sb;
        int count = 0;
        if (stat(argv[i], &sb) != 0) {
            perror(argv[i]);
            status = 1;
            continue;
        }
        if (S_ISDIR(sb.st_mode)) {
            if (run_dir(argv[i], &count) != 0) status = 1;
            if (count == 0) {
                fprintf(stderr, "%s: no input files\n", argv[i]);
                status = 1;
            }
        } else {
            if (run_file(argv[i]) != 0) status = 1;
            else count = 1;
        }
        printf("%s: %d inputs replayed\n", argv[i], count);
    }
    return status;
}
