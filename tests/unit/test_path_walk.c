/* The path tracer's walk and its clock:
 *  - an optically huge medium (a conservative slab of optical depth 1e12) renders in
 *    bounded time: the walks' roulettes and the default depth limit end every path, and
 *    the paths the limit stopped are counted (an alarm fails the test if a render hangs);
 *  - voxel sizes outside the documented range are refused;
 *  - the default depth limit's bias on a conservative slab of optical depth 1000
 *    (R + T against 1, measured from equirectangular renders above and below it, and the
 *    light lost against renders of the same samples with a 10 times higher limit);
 *  - the time budget stops a render inside a pass (wall time), and the image is then that
 *    of the whole passes completed: the same bytes as a render of that many samples
 *    without a budget, for 1 and 2 threads;
 *  - progress is reported at least every second during a pass longer than that;
 *  - the noise figures over the volume's pixels: their median and 90th percentile are
 *    those of the variance image over the pixels the volume covers. */
#define _POSIX_C_SOURCE 200809L
#include "atmos/atmos.h"
#include "test.h"
#include "test_optics.h"

#include <signal.h>
#include <time.h>
#include <unistd.h>

#define PI 3.14159265358979323846

static char cache_dir[1024];

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Progress calls of stage "render path": their times, the largest gap between them. */
typedef struct {
    double start, last, max_gap;
    int calls;
} progress_log;

static int on_progress(void *user, const char *stage, double f)
{
    (void)f;
    progress_log *p = user;
    if (!p || strcmp(stage, "render path") != 0) return 0;
    const double t = now_s();
    const double gap = t - (p->calls ? p->last : p->start);
    if (gap > p->max_gap) p->max_gap = gap;
    p->last = t;
    p->calls++;
    return 0;
}

static atmos_context *make_ctx(int threads, progress_log *prog)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = threads;
    d.cache_dir = cache_dir;
    d.log = NULL;
    d.progress = on_progress;
    d.progress_user = prog;
    atmos_context *ctx = NULL;
    if (atmos_context_create(&d, &ctx) != ATMOS_OK) exit(1);
    return ctx;
}

typedef test_optics optics;

/* One HG particle "hg" of extinction cross-section 1e-9 m^2. */
static void make_optics(atmos_context *ctx, double g, double albedo, optics *op)
{
    test_hg_optics(ctx, "hg", g, albedo, 0, op);
}

/* A slab of optical thickness tau, H = 100 m thick between y = SLAB_Y and SLAB_Y + H, nxz * H
 * wide, centred on x = z = 0: one voxel thick, uniform. */
#define SLAB_H 100.0
#define SLAB_Y 1000.0
static atmos_volume *slab(atmos_context *ctx, int nxz, double tau)
{
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = nxz, vd.dims[1] = 1, vd.dims[2] = nxz;
    vd.voxel_size_m = SLAB_H;
    vd.origin_m[0] = vd.origin_m[2] = -0.5 * nxz * SLAB_H;
    vd.origin_m[1] = SLAB_Y;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    int f = -1;
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "hg", &f));
    float *buf = malloc(sizeof(float) * (size_t)nxz * nxz);
    for (int i = 0; i < nxz * nxz; i++) buf[i] = (float)(tau / (1e-9 * SLAB_H));
    int off[3] = {0, 0, 0}, size[3] = {nxz, 1, nxz};
    CHECK_OK(atmos_volume_set_dense(ctx, v, f, off, size, buf, 1.0f));
    CHECK_OK(atmos_volume_finalize(ctx, v));
    free(buf);
    return v;
}

/* A vacuum, the sun 60 degrees high; a pinhole camera 3 km above the slab looking down. */
static void down_scene(atmos_scene *s, int w, int h, int spp)
{
    atmos_scene_defaults(s);
    s->atmosphere.kind = ATMOS_ATMOSPHERE_VACUUM;
    s->atmosphere.sun_diameter_deg = 0.5;
    s->sun.from_time = 0;
    s->sun.elevation_deg = 60;
    s->sun.azimuth_deg = 30;
    s->width = w, s->height = h;
    const double pos[3] = {0, SLAB_Y + 3000, 1};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    s->camera.look_at[0] = 0, s->camera.look_at[1] = SLAB_Y, s->camera.look_at[2] = 0;
    s->camera.fov_deg = 40;
    s->path.spp = spp;
    s->path.seed = 3;
}

static atmos_image *render(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v, const optics *op,
                           atmos_image **var, atmos_path_stats *st)
{
    atmos_path_settings ps;
    memset(&ps, 0, sizeof ps);
    ps.optics = &op->o;
    ps.variance = var;
    ps.stats = st;
    atmos_image *img = NULL;
    atmos_status status = atmos_render_path(ctx, s, v, &ps, &img, NULL);
    CHECK_MSG(status == ATMOS_OK, "render path: %s", atmos_context_error(ctx));
    if (status != ATMOS_OK) exit(1);
    return img;
}

static int all_finite(const atmos_image *img)
{
    for (size_t i = 0; i < (size_t)img->width * img->height * img->channels; i++)
        if (!isfinite(img->pixels[i])) return 0;
    return 1;
}

/* ------------------------------------------------------------------ optically huge media */

static void on_alarm(int sig)
{
    (void)sig;
    static const char msg[] = "FAIL: a render did not end (alarm)\n";
    if (write(2, msg, sizeof msg - 1) < 0) _exit(2);
    _exit(1);
}

/* A ball of nb^3 voxels of 25 m whose density falls smoothly from rho at its centre to 0
 * at its edge (so its bricks at the edge hold densities from 0 to near rho). */
static atmos_volume *ball(atmos_context *ctx, int nb, double rho)
{
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = vd.dims[1] = vd.dims[2] = nb;
    vd.voxel_size_m = 25;
    vd.origin_m[0] = vd.origin_m[2] = -0.5 * nb * 25;
    vd.origin_m[1] = SLAB_Y;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    int f = -1;
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "hg", &f));
    float *buf = malloc(sizeof(float) * (size_t)nb * nb * nb);
    for (int z = 0; z < nb; z++)
        for (int y = 0; y < nb; y++)
            for (int x = 0; x < nb; x++) {
                const double dx = (x + 0.5) / nb - 0.5, dy = (y + 0.5) / nb - 0.5, dz = (z + 0.5) / nb - 0.5;
                const double r = 2 * sqrt(dx * dx + dy * dy + dz * dz);
                buf[((size_t)z * nb + y) * nb + x] = (float)(r < 1 ? rho * (1 - r * r) : 0);
            }
    int off[3] = {0, 0, 0}, size[3] = {nb, nb, nb};
    CHECK_OK(atmos_volume_set_dense(ctx, v, f, off, size, buf, 1.0f));
    CHECK_OK(atmos_volume_finalize(ctx, v));
    free(buf);
    return v;
}

/* Renders s with v in bounded time (an alarm fails the test), finite pixels. */
static void render_ends(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v, const optics *op,
                        const char *what, atmos_path_stats *st)
{
    const double t0 = now_s();
    alarm(120);
    atmos_image *img = render(ctx, s, v, op, NULL, st);
    alarm(0);
    printf("  %s: %.2f s, %lld paths, %lld events, %lld stopped at the depth limit, %lld walks ended at their "
           "roulette\n",
           what, now_s() - t0, st->paths, st->events, st->cut_paths, st->walks_ended);
    CHECK_MSG(all_finite(img), "%s: pixels not finite", what);
    CHECK_MSG(st->events <= st->paths * 10000LL, "%s: events %lld over the depth limit for %lld paths", what, st->events,
              st->paths);
    atmos_image_destroy(img);
}

/* Optically huge media: a ball of droplet-cloud-like extinction times 1e12 (optical depth
 * ~1e13 across a voxel: ratio tracking through an edge brick would take ~1e14 steps), a
 * conservative slab of optical depth 1e12, voxels of 100 km. */
static void test_huge_tau(void)
{
    atmos_context *ctx = make_ctx(2, NULL);
    optics op;
    make_optics(ctx, 0.85, 1.0, &op);
    atmos_scene s;
    down_scene(&s, 12, 12, 2);
    atmos_path_stats st;
    atmos_volume *v = ball(ctx, 24, 1e8 * 1e12);
    render_ends(ctx, &s, v, &op, "ball, density 1e20 m^-3", &st);
    CHECK_MSG(st.walks_ended > 0, "walks in the ball's edge bricks must meet their roulette");
    atmos_volume_destroy(v);
    v = slab(ctx, 8, 1e12);
    render_ends(ctx, &s, v, &op, "slab, tau 1e12", &st);
    atmos_volume_destroy(v);
    /* the largest voxel allowed: a 1e5 m voxel slab of optical depth 1e4 seen from above */
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = vd.dims[1] = vd.dims[2] = 4;
    vd.voxel_size_m = 1e5;
    vd.origin_m[0] = vd.origin_m[2] = -2e5;
    vd.origin_m[1] = 0;
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    int f = -1;
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "hg", &f));
    float buf[64];
    for (int i = 0; i < 64; i++) buf[i] = (float)(1e4 / (1e-9 * 4e5));
    int off[3] = {0, 0, 0}, size[3] = {4, 4, 4};
    CHECK_OK(atmos_volume_set_dense(ctx, v, f, off, size, buf, 1.0f));
    CHECK_OK(atmos_volume_finalize(ctx, v));
    down_scene(&s, 12, 12, 2);
    s.camera.position[1] = 9e5;
    render_ends(ctx, &s, v, &op, "100 km voxels", &st);
    atmos_volume_destroy(v);
    /* an explicit max_depth is the user's: nothing counts as cut */
    v = slab(ctx, 8, 1e4);
    down_scene(&s, 12, 12, 2);
    s.path.max_depth = 50;
    render_ends(ctx, &s, v, &op, "slab, tau 1e4, max_depth 50", &st);
    CHECK(st.cut_paths == 0 && st.events > 0);
    atmos_volume_destroy(v);
    atmos_phase_table_destroy(op.t);
    atmos_context_destroy(ctx);
}

static void test_voxel_range(void)
{
    atmos_context *ctx = make_ctx(1, NULL);
    const double bad[4] = {1e20, 2e5, 1e-7, 1e300}, good[3] = {1e5, 1e-6, 0.25};
    for (int i = 0; i < 4; i++) {
        atmos_volume_desc vd;
        memset(&vd, 0, sizeof vd);
        vd.dims[0] = vd.dims[1] = vd.dims[2] = 4;
        vd.voxel_size_m = bad[i];
        atmos_volume *v = NULL;
        CHECK_MSG(atmos_volume_create(ctx, &vd, &v) == ATMOS_E_INVALID_ARG, "voxel size %g accepted", bad[i]);
        CHECK(strstr(atmos_context_error(ctx), "voxel size") != NULL);
        atmos_volume_destroy(v);
    }
    for (int i = 0; i < 3; i++) {
        atmos_volume_desc vd;
        memset(&vd, 0, sizeof vd);
        vd.dims[0] = vd.dims[1] = vd.dims[2] = 4;
        vd.voxel_size_m = good[i];
        atmos_volume *v = NULL;
        CHECK_MSG(atmos_volume_create(ctx, &vd, &v) == ATMOS_OK, "voxel size %g refused", good[i]);
        atmos_volume_destroy(v);
    }
    atmos_context_destroy(ctx);
}

/* The hemispherical flux of an equirectangular image's upper (down = 0) or lower half per unit
 * irradiance E (channel c), with its standard error from the variance image. */
static void hemi_flux(const atmos_image *img, const atmos_image *var, int c, int down, double E, double *flux,
                      double *se)
{
    const int W = img->width, H = img->height, C = img->channels;
    double f = 0, vv = 0;
    for (int y = 0; y < H; y++) {
        double ea = (90.0 - 180.0 * y / H) * PI / 180, eb = (90.0 - 180.0 * (y + 1) / H) * PI / 180;
        if (down ? ea > 1e-12 : eb < -1e-12) continue;
        double wgt = 0.5 * fabs(sin(ea) * sin(ea) - sin(eb) * sin(eb)) * 2 * PI / W / E;
        for (int x = 0; x < W; x++) {
            f += wgt * img->pixels[((size_t)y * W + x) * C + c];
            vv += wgt * wgt * var->pixels[((size_t)y * W + x) * C + c];
        }
    }
    *flux = f;
    *se = sqrt(vv);
}

/* R and T (per unit irradiance, channel G) of the conservative slab v (sun 60 degrees high),
 * from equirectangular renders just above and below it, with max_depth depth (0: the
 * default limit); the paths stopped by the default limit are added to *cut. */
static void slab_rt(atmos_context *ctx, const atmos_volume *v, const optics *op, int depth, int spp, double *F,
                    double *se, long long *cut, long long *paths, long long *events)
{
    atmos_scene s;
    down_scene(&s, 32, 16, spp);
    atmos_wavelengths wl;
    CHECK_OK(atmos_scene_wavelengths(ctx, &s, &wl));
    const double E = wl.sun_irradiance[1] * sin(60 * PI / 180);
    s.path.max_depth = depth;
    for (int side = 0; side < 2; side++) {
        const double pos[3] = {0, side == 0 ? SLAB_Y + SLAB_H + 0.05 : SLAB_Y - 0.05, 0};
        atmos_camera_defaults(ATMOS_CAMERA_EQUIRECT, pos, &s.camera);
        atmos_image *var = NULL;
        atmos_path_stats st;
        atmos_image *img = render(ctx, &s, v, op, &var, &st);
        hemi_flux(img, var, 1, side == 0, E, &F[side], &se[side]);
        *cut += st.cut_paths, *paths += st.paths, *events += st.events;
        atmos_image_destroy(img), atmos_image_destroy(var);
    }
}

/* The default depth limit (10000 events) on a conservative slab (g = 0.85) of optical depth
 * 1000: R + T must be 1. The light the limit loses is measured against renders of the same
 * samples with max_depth 100000 (the same paths up to the limit, so the difference has little
 * noise): the paths through the slab need ~1e5 events. ATMOS_PATH_LONG=1: 32x the samples, and
 * optical depths 100 and 3000. */
static void test_depth_bias(int long_run)
{
    atmos_context *ctx = make_ctx(0, NULL);
    optics op;
    make_optics(ctx, 0.85, 1.0, &op);
    const double taus[3] = {1000, 100, 3000};
    for (int i = 0; i < (long_run ? 3 : 1); i++) {
        atmos_volume *v = slab(ctx, 400, taus[i]);
        const int spp = long_run ? (taus[i] > 1000 ? 8 : 64) : 2;
        double F[2], se[2], G[2], sg[2];
        long long cut = 0, paths = 0, ev = 0, cut2 = 0, paths2 = 0, ev2 = 0;
        const double t0 = now_s();
        slab_rt(ctx, v, &op, 0, spp, F, se, &cut, &paths, &ev);
        const double t1 = now_s();
        slab_rt(ctx, v, &op, 100000, spp, G, sg, &cut2, &paths2, &ev2);
        const double t2 = now_s();
        const double sum = F[0] + F[1], e = sqrt(se[0] * se[0] + se[1] * se[1]), sum2 = G[0] + G[1];
        printf("  tau %g conservative slab, %d spp: default limit R %.4f +- %.4f, T %.4f +- %.4f, R + T %.4f +- %.4f, "
               "%lld of %lld paths stopped, %.1f events and %.3f ms per path; max_depth 100000: R + T %.4f, %.1f events "
               "and %.3f ms per path; lost to the default limit %.3f %%\n",
               taus[i], spp, F[0], se[0], F[1], se[1], sum, e, cut, paths, (double)ev / paths, 1e3 * (t1 - t0) / paths,
               sum2, (double)ev2 / paths2, 1e3 * (t2 - t1) / paths2, 100 * (sum2 - sum));
        if (i == 0) {
            CHECK_MSG(cut > 0, "no path met the depth limit at tau 1000");
            CHECK_MSG(sum < 1 + 3 * e && sum > 0.9, "R + T = %g +- %g", sum, e);
            CHECK_MSG(sum2 - sum >= 0 && sum2 - sum < 0.06, "the limit lost %g of the light", sum2 - sum);
        }
        atmos_volume_destroy(v);
    }
    atmos_phase_table_destroy(op.t);
    atmos_context_destroy(ctx);
}

/* ------------------------------------------------------------------ the clock */

static int same_bytes(const atmos_image *a, const atmos_image *b)
{
    return a->width == b->width && a->height == b->height && a->channels == b->channels &&
           !memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)a->width * a->height * a->channels);
}

/* A pass far longer than the budget (a conservative slab of optical depth 1e4: paths of up to
 * the depth limit's 10000 events) is stopped within the budget, with progress reports at least
 * every second. */
static void test_budget_in_pass(void)
{
    progress_log prog = {0};
    atmos_context *ctx = make_ctx(2, &prog);
    optics op;
    make_optics(ctx, 0.85, 1.0, &op);
    atmos_volume *v = slab(ctx, 8, 1e4);
    atmos_scene s;
    down_scene(&s, 48, 48, 64);
    s.path.time_budget_s = 2.5;
    atmos_path_stats st;
    prog.start = now_s();
    atmos_image *img = render(ctx, &s, v, &op, NULL, &st);
    const double el = now_s() - prog.start;
    if (prog.calls && now_s() - prog.last > prog.max_gap) prog.max_gap = now_s() - prog.last;
    printf("  budget 2.5 s: %.2f s, %d spp, %lld paths, %lld pixels without a sample, %d progress calls, largest gap "
           "%.2f s\n",
           el, st.spp, st.paths, st.empty_pixels, prog.calls, prog.max_gap);
    CHECK(all_finite(img));
    CHECK_MSG(el < 2.5 + 1.0, "the render took %.2f s with a 2.5 s budget", el);
    CHECK(st.budget_cut);
    CHECK_MSG(prog.calls >= 2 && prog.max_gap < 1.0, "%d progress calls, largest gap %.2f s", prog.calls, prog.max_gap);
    atmos_image_destroy(img);
    atmos_volume_destroy(v);
    atmos_phase_table_destroy(op.t);
    atmos_context_destroy(ctx);
}

/* A budget that ends several passes in: the image is that of the whole passes, the bytes of a
 * render of st.spp samples without a budget, with 1 thread as with 2. */
static void test_budget_whole_passes(void)
{
    atmos_context *c2 = make_ctx(2, NULL), *c1 = make_ctx(1, NULL);
    optics op;
    make_optics(c2, 0.85, 0.99, &op);
    atmos_volume *v = slab(c2, 8, 30);
    atmos_scene s;
    down_scene(&s, 24, 24, 1000000);
    s.path.time_budget_s = 0.6;
    atmos_path_stats st;
    const double t0 = now_s();
    atmos_image *a = render(c2, &s, v, &op, NULL, &st);
    const double el = now_s() - t0;
    printf("  budget 0.6 s: %.2f s, %d spp, budget cut in a pass: %d\n", el, st.spp, st.budget_cut);
    CHECK(st.spp >= 1 && st.empty_pixels == 0);
    CHECK_MSG(el < 0.6 + 0.5, "%.2f s with a 0.6 s budget", el);
    s.path.time_budget_s = 0;
    s.path.spp = st.spp;
    atmos_image *b = render(c1, &s, v, &op, NULL, &st);
    CHECK_MSG(same_bytes(a, b), "a budget's image differs from the render of its sample count");
    atmos_image_destroy(a), atmos_image_destroy(b);
    atmos_volume_destroy(v);
    atmos_phase_table_destroy(op.t);
    atmos_context_destroy(c1), atmos_context_destroy(c2);
}

/* ------------------------------------------------------------------ the noise figures */

/* The slab (optical depth 2) fills the middle of the view, a black vacuum around it: the
 * volume's pixels are those lit, and the median and 90th percentile of sqrt(variance.Y) / Y
 * recomputed here from the variance image over the lit pixels must be the stats'. */
static void test_noise_figures(void)
{
    atmos_context *ctx = make_ctx(2, NULL);
    optics op;
    make_optics(ctx, 0.85, 0.99, &op);
    atmos_volume *v = slab(ctx, 12, 2);
    atmos_scene s;
    down_scene(&s, 32, 32, 16);
    atmos_path_stats st;
    atmos_image *var = NULL;
    atmos_image *img = render(ctx, &s, v, &op, &var, &st);
    const int n = 3, C = n + 1;
    atmos_wavelengths wl;
    CHECK_OK(atmos_scene_wavelengths(ctx, &s, &wl));
    double *rel = malloc(sizeof(double) * 32 * 32);
    int m = 0;
    for (int p = 0; p < 32 * 32; p++) {
        double Y = 0;
        for (int k = 0; k < n; k++) Y += wl.to_xyz[k][1] * img->pixels[p * C + k];
        if (Y > 0) rel[m++] = sqrt(var->pixels[p * C + n]) / Y;
    }
    for (int i = 1; i < m; i++)
        for (int j = i; j > 0 && rel[j - 1] > rel[j]; j--) {
            const double t = rel[j];
            rel[j] = rel[j - 1], rel[j - 1] = t;
        }
    const double med = m % 2 ? rel[m / 2] : 0.5 * (rel[m / 2 - 1] + rel[m / 2]);
    const double p90 = rel[(int)ceil(0.9 * m) - 1];
    printf("  noise: %lld volume pixels (%d lit), mean %.4f median %.4f (%.4f) p90 %.4f (%.4f), all pixels %.4f\n",
           st.volume_pixels, m, st.volume_rel_error_mean, st.volume_rel_error_median, med, st.volume_rel_error_p90, p90,
           st.mean_rel_error);
    CHECK(st.volume_pixels > 32 * 32 / 8 && st.volume_pixels < 32 * 32);
    CHECK(st.volume_pixels == m);
    CHECK_REL(st.volume_rel_error_median, med, 1e-4);
    CHECK_REL(st.volume_rel_error_p90, p90, 1e-4);
    CHECK(st.volume_rel_error_median <= st.volume_rel_error_p90);
    free(rel);
    atmos_image_destroy(img), atmos_image_destroy(var);
    /* In the sky the air's pixels, many and with little noise, diluted the mean over all
     * pixels: the volume's figure is its own. */
    s.atmosphere.kind = ATMOS_ATMOSPHERE_RILEY;
    s.width = s.height = 16;
    img = render(ctx, &s, v, &op, NULL, &st);
    printf("  noise in the sky: %lld volume pixels, mean %.4f median %.4f p90 %.4f, all pixels %.4f\n", st.volume_pixels,
           st.volume_rel_error_mean, st.volume_rel_error_median, st.volume_rel_error_p90, st.mean_rel_error);
    CHECK(st.volume_pixels > 16 && st.volume_pixels < 16 * 16);
    CHECK(st.volume_rel_error_mean > 1.5 * st.mean_rel_error);
    atmos_image_destroy(img);
    atmos_volume_destroy(v);
    atmos_phase_table_destroy(op.t);
    atmos_context_destroy(ctx);
}

int main(void)
{
    test_tmp_path(cache_dir, sizeof cache_dir, "path_walk_cache");
    setvbuf(stdout, NULL, _IONBF, 0);
    signal(SIGALRM, on_alarm);
    test_voxel_range();
    test_noise_figures();
    test_budget_whole_passes();
    test_budget_in_pass();
    test_huge_tau();
    const char *lr = getenv("ATMOS_PATH_LONG");
    test_depth_bias(lr && *lr && *lr != '0');
    return test_summary("test_path_walk");
}
