/* The on-disk table cache (DESIGN.md §7): file format and checks in cache.h. */
#define _POSIX_C_SOURCE 200809L /* mkdir, opendir, fstat */
#include "core/cache.h"
#include "atmos/cache.h"
#include "core/internal.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

static const unsigned char magic[8] = {'A', 'T', 'M', 'O', 'S', 'C', 'A', 0x1a};
#define HEADER_SIZE 32u

uint64_t atmos__cache_hash_key(const char *key)
{
    uint64_t h = 0xcbf29ce484222325ull; /* FNV-1a 64 offset basis and prime */
    for (const unsigned char *p = (const unsigned char *)key; *p; p++) {
        h ^= *p;
        h *= 0x100000001b3ull;
    }
    return h;
}

static uint64_t rotl64(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }

/* A word-at-a-time checksum so that multi-megabyte spectral tables verify in well
 * under a millisecond: each 8-byte word is multiplied by an odd constant, rotated and
 * folded in with another multiply (the round of xxHash64's design, written from its
 * published description), then the length and a final avalanche (SplitMix64's
 * finaliser). It detects corruption; it is not meant to resist deliberate forgery —
 * the full key comparison is what guards against returning the wrong entry. */
uint64_t atmos__cache_checksum(const void *data, size_t size)
{
    const uint64_t p1 = 0x9e3779b185ebca87ull, p2 = 0xc2b2ae3d27d4eb4full;
    const unsigned char *b = data;
    uint64_t h = 0x27d4eb2f165667c5ull ^ (uint64_t)size;
    size_t i = 0;
    for (; i + 8 <= size; i += 8) {
        uint64_t w;
        memcpy(&w, b + i, 8);
        h ^= rotl64(w * p2, 31) * p1;
        h = rotl64(h, 27) * p1 + 0x85ebca77c2b2ae63ull;
    }
    for (; i < size; i++) {
        h ^= (uint64_t)b[i] * p1;
        h = rotl64(h, 11) * p2;
    }
    h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
    h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
    return h ^ (h >> 31);
}

static void put_u32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}
static void put_u64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++) p[i] = (unsigned char)(v >> (8 * i));
}
static uint32_t get_u32(const unsigned char *p)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; i++) v |= (uint32_t)p[i] << (8 * i);
    return v;
}
static uint64_t get_u64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++) v |= (uint64_t)p[i] << (8 * i);
    return v;
}

int atmos__cache_entry_path(const atmos_context *ctx, const char *key, char *buf, size_t cap)
{
    int n = snprintf(buf, cap, "%s/%016llx%s", atmos_context_cache_dir(ctx),
                     (unsigned long long)atmos__cache_hash_key(key), ATMOS__CACHE_SUFFIX);
    return n > 0 && (size_t)n < cap;
}

/* Reports a bad entry, removes it so it is rebuilt, and returns 0 (a miss). */
static int reject(atmos_context *ctx, FILE *f, const char *path, const char *why)
{
    if (f) fclose(f);
    atmos__log(ctx, ATMOS_LOG_WARN, "cache: %s: %s; ignoring it and rebuilding", path, why);
    if (remove(path) != 0 && errno != ENOENT)
        atmos__log(ctx, ATMOS_LOG_WARN, "cache: %s: cannot remove: %s", path, strerror(errno));
    return 0;
}

/* Opens an entry for reading, or NULL (a miss). The descriptor is opened without
 * blocking and checked before anything is read: a FIFO in place of an entry would
 * block fopen until a writer appears, and a device or directory is not an entry. Such
 * a name is removed (a directory only if empty) so that the rebuilt entry can take it. */
static FILE *open_entry(atmos_context *ctx, const char *path)
{
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        if (errno != ENOENT) atmos__log(ctx, ATMOS_LOG_WARN, "cache: %s: cannot open: %s", path, strerror(errno));
        return NULL; /* a missing entry is the normal cold case: silent */
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        reject(ctx, NULL, path, "not a regular file");
        return NULL;
    }
    int fl = fcntl(fd, F_GETFL);
    FILE *f = fl == -1 || fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) == -1 ? NULL : fdopen(fd, "rb");
    if (!f) {
        atmos__log(ctx, ATMOS_LOG_WARN, "cache: %s: cannot open: %s", path, strerror(errno));
        close(fd);
    }
    return f;
}

int atmos__cache_load(atmos_context *ctx, const char *key, void **data, size_t *size)
{
    *data = NULL;
    *size = 0;
    char path[4096];
    size_t key_len = strlen(key);
    if (key_len == 0 || key_len > ATMOS__CACHE_MAX_KEY || !atmos__cache_entry_path(ctx, key, path, sizeof path))
        return 0;
    FILE *f = open_entry(ctx, path);
    if (!f) return 0;
    struct stat st;
    if (fstat(fileno(f), &st) != 0) return reject(ctx, f, path, "cannot stat");
    uint64_t file_size = (uint64_t)st.st_size;

    unsigned char h[HEADER_SIZE];
    if (file_size < HEADER_SIZE || fread(h, 1, HEADER_SIZE, f) != HEADER_SIZE)
        return reject(ctx, f, path, "truncated header");
    if (memcmp(h, magic, sizeof magic) != 0) return reject(ctx, f, path, "not an atmos cache file (bad magic)");
    uint32_t version = get_u32(h + 8);
    if (version != ATMOS__CACHE_FORMAT_VERSION) {
        char why[96];
        snprintf(why, sizeof why, "format version %u, expected %u", version, ATMOS__CACHE_FORMAT_VERSION);
        return reject(ctx, f, path, why);
    }
    uint32_t stored_key_len = get_u32(h + 12);
    uint64_t payload_size = get_u64(h + 16), checksum = get_u64(h + 24);
    /* Every size is checked against the limits and the file's real size before
     * anything is allocated, so a corrupt header cannot ask for gigabytes. */
    if (stored_key_len != key_len) return reject(ctx, f, path, "stale entry (key differs)");
    if (payload_size > ATMOS__CACHE_MAX_PAYLOAD) return reject(ctx, f, path, "payload size over the 1 GiB limit");
    if (file_size != HEADER_SIZE + (uint64_t)key_len + payload_size)
        return reject(ctx, f, path, file_size < HEADER_SIZE + (uint64_t)key_len + payload_size
                                        ? "truncated (file shorter than its header says)"
                                        : "trailing bytes after the payload");
    char *stored_key = malloc(key_len);
    void *payload = malloc(payload_size ? (size_t)payload_size : 1);
    if (!stored_key || !payload) {
        free(stored_key);
        free(payload);
        fclose(f);
        atmos__log(ctx, ATMOS_LOG_WARN, "cache: %s: out of memory reading it; rebuilding", path);
        return 0;
    }
    int ok = fread(stored_key, 1, key_len, f) == key_len;
    const char *why = "truncated key";
    if (ok && memcmp(stored_key, key, key_len) != 0) ok = 0, why = "stale entry (key differs)";
    if (ok && fread(payload, 1, (size_t)payload_size, f) != payload_size) ok = 0, why = "truncated payload";
    if (ok && atmos__cache_checksum(payload, (size_t)payload_size) != checksum)
        ok = 0, why = "payload checksum mismatch (corrupt)";
    free(stored_key);
    if (!ok) {
        free(payload);
        return reject(ctx, f, path, why);
    }
    fclose(f);
    *data = payload;
    *size = (size_t)payload_size;
    return 1;
}

/* mkdir -p with mode 0755. */
static int make_dirs(const char *dir)
{
    char buf[4096];
    size_t n = strlen(dir);
    if (n == 0 || n >= sizeof buf) return -1;
    memcpy(buf, dir, n + 1);
    for (size_t i = 1; i <= n; i++) {
        if (buf[i] != '/' && buf[i] != '\0') continue;
        char c = buf[i];
        buf[i] = '\0';
        if (mkdir(buf, 0755) != 0 && errno != EEXIST) return -1;
        buf[i] = c;
    }
    struct stat st;
    return stat(dir, &st) == 0 && S_ISDIR(st.st_mode) ? 0 : -1;
}

typedef struct {
    const char *key;
    const void *data;
    size_t size;
} store_job;

static atmos_status write_entry(atmos_context *ctx, const char *tmp_path, void *user)
{
    const store_job *job = user;
    size_t key_len = strlen(job->key);
    unsigned char h[HEADER_SIZE];
    memcpy(h, magic, sizeof magic);
    put_u32(h + 8, ATMOS__CACHE_FORMAT_VERSION);
    put_u32(h + 12, (uint32_t)key_len);
    put_u64(h + 16, (uint64_t)job->size);
    put_u64(h + 24, atmos__cache_checksum(job->data, job->size));
    FILE *f = fopen(tmp_path, "wb");
    if (!f) {
        atmos__log(ctx, ATMOS_LOG_WARN, "cache: %s: cannot create: %s", tmp_path, strerror(errno));
        return ATMOS_E_IO;
    }
    int ok = fwrite(h, 1, sizeof h, f) == sizeof h && fwrite(job->key, 1, key_len, f) == key_len &&
             (job->size == 0 || fwrite(job->data, 1, job->size, f) == job->size);
    if (fclose(f) != 0) ok = 0;
    if (!ok) {
        atmos__log(ctx, ATMOS_LOG_WARN, "cache: %s: write failed: %s", tmp_path, strerror(errno));
        return ATMOS_E_IO;
    }
    return ATMOS_OK;
}

atmos_status atmos__cache_store(atmos_context *ctx, const char *key, const void *data, size_t size)
{
    char path[4096];
    size_t key_len = strlen(key);
    if (key_len == 0 || key_len > ATMOS__CACHE_MAX_KEY || (uint64_t)size > ATMOS__CACHE_MAX_PAYLOAD ||
        !atmos__cache_entry_path(ctx, key, path, sizeof path)) {
        atmos__log(ctx, ATMOS_LOG_WARN, "cache: entry too large or path too long; not cached");
        return ATMOS_E_LIMIT;
    }
    const char *dir = atmos_context_cache_dir(ctx);
    if (make_dirs(dir) != 0) {
        atmos__log(ctx, ATMOS_LOG_WARN, "cache: cannot create directory %s: %s; not cached", dir, strerror(errno));
        return ATMOS_E_IO;
    }
    store_job job = {key, data, size};
    atmos_status st = atmos__write_atomic_unique(ctx, path, write_entry, &job);
    if (st != ATMOS_OK) atmos__log(ctx, ATMOS_LOG_WARN, "cache: %s: not cached (%s)", path, atmos_status_string(st));
    return st;
}

/* An entry name is exactly 16 lower-case hex digits + suffix; a leftover of an
 * interrupted atomic write is that followed by ".tmp" and digits. */
static int is_cache_file(const char *name)
{
    size_t sl = strlen(ATMOS__CACHE_SUFFIX);
    for (int i = 0; i < 16; i++)
        if (!((name[i] >= '0' && name[i] <= '9') || (name[i] >= 'a' && name[i] <= 'f'))) return 0;
    if (strncmp(name + 16, ATMOS__CACHE_SUFFIX, sl) != 0) return 0;
    const char *rest = name + 16 + sl;
    if (*rest == '\0') return 1;
    if (strncmp(rest, ".tmp", 4) != 0 || !rest[4]) return 0;
    for (rest += 4; *rest; rest++)
        if (*rest < '0' || *rest > '9') return 0;
    return 1;
}

atmos_status atmos_cache_clear(atmos_context *ctx, int *removed)
{
    if (removed) *removed = 0;
    const char *dir = atmos_context_cache_dir(ctx);
    DIR *d = opendir(dir);
    if (!d) {
        if (errno == ENOENT) return ATMOS_OK;
        return atmos__error(ctx, ATMOS_E_IO, "%s: cannot read the cache directory: %s", dir, strerror(errno));
    }
    atmos_status st = ATMOS_OK;
    int count = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (!is_cache_file(e->d_name)) continue;
        char path[4096];
        if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >= (int)sizeof path) continue;
        if (remove(path) == 0) count++;
        else if (errno != ENOENT)
            st = atmos__error(ctx, ATMOS_E_IO, "%s: cannot remove: %s", path, strerror(errno));
    }
    closedir(d);
    if (removed) *removed = count;
    return st;
}
