/* A sweep of random valid scenes through every renderer (sky, slice, path): sun and camera
 * at the edges of their ranges, extreme atmospheres, generated volumes with extreme
 * densities, voxel sizes and extents, tiny images. Each scene runs in a child process
 * under a wall-clock limit, so that a crash or a hang is one failure among the others
 * rather than the end of the sweep. A scene fails when its image holds a NaN or an
 * infinity (the library refuses such an image: that error counts as "nonfinite"), when an
 * image channel's mean is negative beyond its noise, when the render runs past its budget,
 * when it is killed at the wall-clock limit, crashes, or fails with an error. A scene the
 * parser refuses, or whose volume exceeds a stated limit, is counted as "refused": a
 * failure of the sweep's own generator in --short mode, reported only in the full sweep.
 *
 *   atmos_sweep [--count N] [--first I] [--seed S] [--short] [--limit SECONDS] [-v] [--print]
 *
 * Scene i is made from (seed, i) alone: `--first I --count 1` replays it, -v prints its JSON,
 * --print prints the scenes' JSON without rendering them.
 * --short keeps to the ranges that work today (the test in `make test`); the full ranges
 * are those of docs/scene-format.md. One line per failing scene, then counts by kind;
 * exit status 1 if any scene failed. */
#define _POSIX_C_SOURCE 200809L
#include "atmos/atmos.h"

#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

enum { K_OK, K_REFUSED, K_NONFINITE, K_NEGATIVE, K_OVERTIME, K_TIMEOUT, K_CRASH, K_ERROR, K_COUNT };
static const char *const kind_names[K_COUNT] = {"ok",      "refused", "nonfinite", "negative",
                                                "overtime", "timeout", "crash",     "error"};

typedef struct {
    uint64_t s;
} rng;

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}
/* SplitMix64; each scene's stream starts at a hash of (seed, index), so that the streams
 * of neighbouring scenes do not overlap. */
static uint64_t next_u64(rng *r) { return mix64(r->s += 0x9e3779b97f4a7c15ull); }
static double uni(rng *r) { return (next_u64(r) >> 11) * (1.0 / 9007199254740992.0); }
static double range(rng *r, double a, double b) { return a + (b - a) * uni(r); }
static double log_range(rng *r, double a, double b) { return exp(range(r, log(a), log(b))); }
static int pick(rng *r, int n) { return (int)(uni(r) * n); }
/* One of the listed edge values with probability p, else the fallback. */
static double edge_or(rng *r, double p, const double *edges, int n, double fallback)
{
    return uni(r) < p ? edges[pick(r, n)] : fallback;
}

typedef struct {
    int renderer; /* 0 sky, 1 slice, 2 path */
    double budget_s; /* the render's own budget (path: its time_budget_s) */
    char json[4096];
} scene_text;

static void append(scene_text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void append(scene_text *t, const char *fmt, ...)
{
    size_t n = strlen(t->json);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(t->json + n, sizeof t->json - n, fmt, ap);
    va_end(ap);
}

/* Camera, sun, atmosphere, image: shared by all renderers. The slice renderer needs a
 * pinhole camera. */
static int make_view(rng *r, int full, int renderer, scene_text *t)
{
    static const char *const cams[3] = {"pinhole", "fisheye", "equirect"};
    const int cam = renderer == 1 ? 0 : pick(r, 3);
    static const double alt_edges[] = {0.0, 1e6, 700000.0, 1.0};
    double alt = full ? edge_or(r, 0.25, alt_edges, 4, log_range(r, 1.0, 1e6)) : log_range(r, 10.0, 20000.0);
    static const double el_edges[] = {-90.0, 90.0, 0.0, -0.001, 0.001};
    double vel = edge_or(r, 0.25, el_edges, 5, range(r, -90, 90)), vaz = range(r, 0, 359.999);
    double sel = edge_or(r, 0.3, el_edges, 5, range(r, -90, 90)), saz = range(r, 0, 359.999);
    if (!full) sel = range(r, -5, 90), vel = range(r, -60, 60);
    append(t, "{\"image\": {\"width\": %d, \"height\": %d, \"samples_per_pixel\": %d},\n", 16, 12, 1 + pick(r, 2));
    append(t, " \"camera\": {\"type\": \"%s\", \"position_m\": [%.17g, %.17g, %.17g]", cams[cam], range(r, -1e4, 1e4),
           alt, range(r, -1e4, 1e4));
    if (cam != 2) {
        /* a view straight up or down needs an up vector that is not parallel to it */
        append(t, ", \"view\": {\"elevation_deg\": %.17g, \"azimuth_deg\": %.17g}", vel, vaz);
        if (fabs(vel) > 89.9) append(t, ", \"up\": [0, 0, -1]");
        if (cam == 0) append(t, ", \"fov_deg\": %.17g", full ? log_range(r, 0.01, 179.9) : range(r, 10, 120));
        else append(t, ", \"fov_deg\": %.17g", range(r, 1, 360));
    }
    append(t, "},\n \"sun\": {\"elevation_deg\": %.17g, \"azimuth_deg\": %.17g},\n", sel, saz);
    static const double sd_edges[] = {1e-6, 20.0, 0.5};
    double sun_d = full ? edge_or(r, 0.3, sd_edges, 3, log_range(r, 1e-6, 20)) : log_range(r, 0.05, 5);
    double H = full ? log_range(r, 100, 1e5) : log_range(r, 2000, 20000);
    double beta = full ? log_range(r, 1e-9, 0.01) : log_range(r, 1e-6, 1e-4);
    append(t, " \"atmosphere\": {\"kind\": \"%s\", \"scale_height_m\": %.17g, \"beta_sl_550_per_m\": %.17g, "
              "\"ground_albedo\": %.17g, \"sun_diameter_deg\": %.17g, \"thickness_m\": %.17g},\n",
           pick(r, 4) == 0 ? "homogeneous" : "riley", H, beta, uni(r), sun_d, log_range(r, 1, full ? 1e6 : 2e4));
    if (pick(r, 8) == 0) append(t, " \"background\": \"black\",\n");
    if (pick(r, 4) == 0) append(t, " \"wavelengths\": {\"mode\": \"spectral\", \"samples\": %d},\n", 4);
    return cam;
}

/* A generated volume for the slice renderer and the path tracer. */
static void make_volume(rng *r, int full, int pinhole, scene_text *t)
{
    static const char *const presets[6] = {"cumulus", "cumulonimbus", "cumulus_field", "cirrus", "rain_shaft", "storm"};
    const char *preset = presets[full ? pick(r, 6) : pick(r, 2) * 3]; /* short: cumulus, cirrus */
    double dens = full ? log_range(r, 1e-6, 1e12) : log_range(r, 1e-2, 1e2);
    /* scale: the generators take [0.05, 20] (docs/scene-format.md states (0, 100]) */
    double scale = full ? log_range(r, 0.05, 20) : log_range(r, 0.2, 1);
    append(t, " \"volume\": {\"generate\": \"%s\", \"density_scale\": %.17g, \"scale\": %.17g, \"seed\": %d", preset,
           dens, scale, 1 + pick(r, 1000));
    /* short: always a voxel size, so that the volumes stay small (fast to generate) */
    if (!full || pick(r, 2)) append(t, ", \"voxel_size_m\": %.17g", full ? log_range(r, 100, 1e5) : log_range(r, 60, 400));
    if (!pinhole || pick(r, 2)) { /* the default placement needs a pinhole camera */
        /* near the camera, sometimes around it (a camera inside the cloud) */
        append(t, ", \"position_m\": [%.17g, %.17g, %.17g]", range(r, -3000, 3000), range(r, 0, 3000),
               range(r, -6000, 0));
    }
    append(t, "},\n");
    /* The rain preset's Mie table (size parameters to ~15 000) takes minutes to build; the
     * full sweep draws rain as an analytic forward-peaked stand-in, the other presets as they are. */
    if (full)
        append(t, " \"particles\": {\"rain\": {\"kind\": \"analytic\", \"lobes\": [{\"type\": \"hg\", \"g\": 0.88, "
                  "\"weight\": 1}], \"sigma_ext_m2\": 6e-6}},\n");
}

static void make_scene(uint64_t seed, int index, int full, scene_text *t)
{
    rng r = {mix64(mix64(seed) ^ mix64((uint64_t)index + 0x632be59bd9b4e019ull))};
    memset(t, 0, sizeof *t);
    t->renderer = pick(&r, 3);
    /* --short: the sky and the slice renderer take camera, sun and atmosphere from the full
     * ranges (they pass the full sweep); the path tracer and the volumes keep to the short ones. */
    const int cam = make_view(&r, full || t->renderer != 2, t->renderer, t);
    if (t->renderer > 0 && (t->renderer == 1 || pick(&r, 4) != 0)) make_volume(&r, full, cam == 0, t);
    if (t->renderer == 1) {
        t->budget_s = 10.0;
        append(t, " \"renderer\": \"slice\", \"slice\": {\"slices\": %d, \"light_size\": %d, \"grid_max_dim\": %d}}\n",
               1 + pick(&r, full ? 512 : 128), 8 + pick(&r, 56), 8 + pick(&r, 56));
    } else if (t->renderer == 2) {
        t->budget_s = 1.0;
        append(t, " \"renderer\": \"path\", \"path\": {\"spp\": %d, \"time_budget_s\": %g, \"seed\": %d}}\n",
               1 + pick(&r, 4), t->budget_s, 1 + pick(&r, 100));
    } else {
        t->budget_s = 5.0;
        append(t, " \"renderer\": \"sky\"}\n");
    }
}

typedef struct {
    int kind;
    double load_s, plan_s, render_s;
    long nonfinite, negative_px;
    double worst_mean; /* the most negative channel mean in units of its standard error */
    char msg[200];
} result;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* The child's work: parse, load, plan, render, inspect. */
static void run_scene(const scene_text *t, int limit_s, result *res)
{
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.threads = 1;
    cd.log = NULL;
    atmos_context *ctx = NULL;
    atmos_scene s;
    atmos_volume *vol = NULL;
    atmos_plan *p = NULL;
    atmos_image *img = NULL;
    atmos_frame f;
    atmos_render_info info = {0};
    memset(res, 0, sizeof *res);
    if (atmos_context_create(&cd, &ctx) != ATMOS_OK) { res->kind = K_ERROR; return; }
    atmos_status st = atmos_scene_parse(ctx, t->json, strlen(t->json), "sweep", &s);
    res->kind = K_REFUSED;
    double off[3], t0 = now();
    if (st == ATMOS_OK && s.volume.source[0]) st = atmos_scene_load_volume(ctx, &s, &vol, off);
    res->load_s = now() - t0;
    if (st == ATMOS_OK) {
        res->kind = K_ERROR;
        t0 = now();
        st = atmos_plan_create(ctx, &s, vol, NULL, &p);
        alarm((unsigned)limit_s); /* the plan (tables, first built once per cache) had its own */
    }
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, &s, &f);
    if (st == ATMOS_OK) st = atmos_plan_image_create(p, &f, &img);
    if (st == ATMOS_OK) {
        res->plan_s = now() - t0;
        st = atmos_plan_render(p, &f, NULL, img, &info);
        res->render_s = info.seconds;
    }
    if (st != ATMOS_OK) {
        snprintf(res->msg, sizeof res->msg, "%s", atmos_context_error(ctx));
        if (strstr(res->msg, "NaN or infinite")) res->kind = K_NONFINITE;
        else if (st == ATMOS_E_LIMIT && res->kind == K_ERROR) res->kind = K_REFUSED; /* a stated limit */
    } else {
        const int C = img->channels, n = img->width * img->height;
        res->kind = K_OK;
        res->worst_mean = 0;
        for (int c = 0; c < C - 1; c++) {
            double sum = 0, sum2 = 0;
            for (int i = 0; i < n; i++) {
                double v = img->pixels[(size_t)i * C + c];
                if (!isfinite(v)) { res->nonfinite++; continue; }
                res->negative_px += v < 0;
                sum += v, sum2 += v * v;
            }
            double mean = sum / n, sem = sqrt(fmax(sum2 / n - mean * mean, 0.0) / n);
            if (mean < 0 && sem > 0) res->worst_mean = fmin(res->worst_mean, mean / sem);
            if (mean < 0 && sem == 0) res->worst_mean = -INFINITY;
        }
        if (res->nonfinite) res->kind = K_NONFINITE;
        else if (res->worst_mean < -3.0) res->kind = K_NEGATIVE;
        else if (res->render_s > 2.0 * t->budget_s + 1.0) res->kind = K_OVERTIME;
    }
    atmos_image_destroy(img);
    atmos_plan_destroy(p);
    atmos_volume_destroy(vol);
    atmos_context_destroy(ctx);
}

/* Runs one scene in a child with a wall-clock limit. */
static void run_child(const scene_text *t, int limit_s, result *res)
{
    int fd[2];
    memset(res, 0, sizeof *res);
    if (pipe(fd) != 0) { res->kind = K_ERROR; snprintf(res->msg, sizeof res->msg, "pipe failed"); return; }
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        alarm((unsigned)(limit_s > 600 ? limit_s : 600)); /* loading, generating, building tables */
        result r;
        run_scene(t, limit_s, &r);
        ssize_t w = write(fd[1], &r, sizeof r);
        _exit(w == (ssize_t)sizeof r ? 0 : 3);
    }
    close(fd[1]);
    ssize_t got = pid > 0 ? read(fd[0], res, sizeof *res) : -1;
    close(fd[0]);
    int status = 0;
    if (pid > 0) waitpid(pid, &status, 0);
    if (got == (ssize_t)sizeof *res) return;
    memset(res, 0, sizeof *res);
    if (pid > 0 && WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) {
        res->kind = K_TIMEOUT;
        snprintf(res->msg, sizeof res->msg, "killed after %d s", limit_s);
    } else {
        res->kind = K_CRASH;
        snprintf(res->msg, sizeof res->msg, "child ended with %s %d", WIFSIGNALED(status) ? "signal" : "status",
                 WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status));
    }
}

int main(int argc, char **argv)
{
    int count = 1000, first = 0, full = 1, limit = 60, verbose = 0;
    uint64_t seed = 13;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--count") && i + 1 < argc) count = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--first") && i + 1 < argc) first = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--seed") && i + 1 < argc) seed = strtoull(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--limit") && i + 1 < argc) limit = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--short")) full = 0;
        else if (!strcmp(argv[i], "-v")) verbose = 1;
        else if (!strcmp(argv[i], "--print")) verbose = 2;
        else {
            fprintf(stderr, "usage: atmos_sweep [--count N] [--first I] [--seed S] [--short] [--limit SECONDS] [-v] [--print]\n");
            return 2;
        }
    }
    static const char *const rnames[3] = {"sky", "slice", "path"};
    int counts[K_COUNT][3] = {{0}};
    double worst_render[3] = {0};
    int some_negative[3] = {0}; /* scenes that passed with some negative pixel values */
    for (int i = first; i < first + count; i++) {
        scene_text t;
        result res;
        make_scene(seed, i, full, &t);
        if (verbose == 2) { /* --print: the scenes' JSON, nothing rendered */
            printf("scene %d %s\n%s", i, rnames[t.renderer], t.json);
            continue;
        }
        run_child(&t, limit, &res);
        counts[res.kind][t.renderer]++;
        if (res.kind == K_OK && res.negative_px > 0) {
            some_negative[t.renderer]++;
            printf("scene %d %s: ok with %ld negative pixel values (worst channel mean %.3g standard errors)\n", i,
                   rnames[t.renderer], res.negative_px, res.worst_mean);
        }
        if ((i - first + 1) % 50 == 0) fprintf(stderr, "sweep: %d of %d scenes\n", i - first + 1, count);
        if (res.render_s > worst_render[t.renderer]) worst_render[t.renderer] = res.render_s;
        if (res.kind != K_OK || verbose) {
            printf("scene %d %s: %s (volume %.2f s, plan %.2f s, render %.2f s, budget %g s, %ld negative pixels, "
                   "worst mean %.3g sigma) %s\n",
                   i, rnames[t.renderer], kind_names[res.kind], res.load_s, res.plan_s, res.render_s, t.budget_s,
                   res.negative_px,
                   res.worst_mean, res.msg);
            if (verbose) printf("%s\n", t.json);
        }
    }
    int failed = 0;
    printf("sweep: seed %llu, scenes %d..%d, %s ranges\n", (unsigned long long)seed, first, first + count - 1,
           full ? "full" : "short");
    for (int k = 0; k < K_COUNT; k++) {
        printf("  %-9s sky %4d  slice %4d  path %4d\n", kind_names[k], counts[k][0], counts[k][1], counts[k][2]);
        if (k != K_OK && (k != K_REFUSED || !full)) failed += counts[k][0] + counts[k][1] + counts[k][2];
    }
    printf("  longest render: sky %.2f s, slice %.2f s, path %.2f s\n", worst_render[0], worst_render[1], worst_render[2]);
    printf("  passed with some negative pixel values: sky %d, slice %d, path %d\n", some_negative[0], some_negative[1],
           some_negative[2]);
    return failed ? 1 : 0;
}
