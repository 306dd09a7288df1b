/* The sun's map along epipolar lines (render/beams_epipolar.h) against the map itself and a
 * brute-force march, on a fence of nine posts on a slab under a sun up to the right (its
 * 256-texel map) and the lines from an eye in front of it:
 *   - every fifth line's samples are the map's depth at their points (the four nearest texels'
 *     depths blended where all four hold an object, else the nearest texel's; beside the map
 *     INFINITY; read here with tent weights over the texel lattice and the nearest texel by
 *     rounding, not the code's index arithmetic), to 1e-5 relative, and a quarter of them at least are not at the next line's;
 *   - rays whose projections run exactly along those lines (three slopes in depth each): the
 *     lit length the line's tree walk gives against a march along the ray itself in steps of
 *     1/64 texel, each step lit where the ray is nearer the sun than the map's depth there:
 *     within 0.05 texel plus 0.6 texel for each edge the march crosses (the line holds a
 *     depth a texel, linear between: a shadow's edge may move by up to about half a texel
 *     along it); walked along the next line, an eighth of the shadowed rays at least miss so;
 *   - the fog's sunlight from the lines (atmos__beams_sun_airlight_lines) against the map's
 *     own steps at epsilon 1e-4 (atmos__beams_sun_airlight) on rays across the fence's
 *     shadows: within 2 % of the unshadowed whole a ray;
 *   - lines kept from one build to the next (the eye turning in place) are a fresh build's,
 *     and are made again when the map is (a post moved: the same epipole) or the eye moves;
 *   - the map, drawn band by band on 1, 2 and 3 threads, has the bits of every triangle drawn
 *     in order over the whole map, and so have its tiles. */
#include "atmos/atmos.h"
#include "render/beams_sun.h"
#include "render/beams_epipolar.h"
#include "render/beams_raster.h"
#include "core/vec.h"
#include "test.h"

#include <stdlib.h>
#include <string.h>

static atmos_context *ctx;

/* The map's depth at look-up coordinates (fx, fy), by the rule above. */
static double map_depth(const atmos__beams_sun *s, double fx, double fy)
{
    const int n = s->n;
    if (!(fx > -1 && fx < n && fy > -1 && fy < n)) return INFINITY;
    /* the texels of the lattice points around (fx, fy), tent weights 1 - |distance| per axis,
     * an index past the map's edge read at the edge */
    double sum = 0, nearest = INFINITY;
    int holes = 0;
    for (int c = 0; c < 4; c++) {
        const double x = floor(fx) + (c & 1), y = floor(fy) + (c >> 1);
        const double w = (1 - fabs(fx - x)) * (1 - fabs(fy - y));
        const double d = s->depth[(size_t)fmin(fmax(y, 0), n - 1) * n + (size_t)fmin(fmax(x, 0), n - 1)];
        holes += isinf(d);
        sum += isinf(d) ? 0 : w * d;
        if (x == floor(fx + 0.5) && y == floor(fy + 0.5)) nearest = d; /* the nearest, ties upward */
    }
    return holes ? nearest : sum;
}

static void add_length(void *u, double ra, double rb) { *(double *)u += rb - ra; }

/* 1 when a's lines are b's: the same epipole, lines and samples. */
static int same_lines(const atmos__beams_epi *a, const atmos__beams_epi *b)
{
    if (a->lines != b->lines || a->ex != b->ex || a->ey != b->ey || a->lines <= 0) return 0;
    const int L = a->lines;
    if (memcmp(a->k0, b->k0, sizeof(int) * L) || memcmp(a->cnt, b->cnt, sizeof(int) * L) ||
        memcmp(a->at, b->at, sizeof(size_t) * L) || memcmp(a->tat, b->tat, sizeof(size_t) * L))
        return 0;
    return !memcmp(a->m, b->m, sizeof(float) * (a->at[L - 1] + (size_t)a->cnt[L - 1])) &&
           !memcmp(a->lh, b->lh, sizeof(float) * 2 * a->tat[L - 1]);
}

/* Lines kept from the last build (the eye turning in place) only while they are what a fresh
 * build gives: the same eye and map; the map made again with a post moved (the same box, so the
 * same epipole: only the map's build tells); the eye moved; the bound on the samples lowered below
 * theirs (none, as a fresh build under it). */
static void test_kept_lines(atmos_mesh *post[10], atmos__beams_sun *s, const double sun[3], const double eye[3])
{
    atmos__beams_epi kept = {0}, fresh = {0};
    CHECK(atmos__beams_epi_build(&kept, s, eye, (size_t)1 << 24, 2) == 0);
    CHECK(atmos__beams_epi_build(&kept, s, eye, (size_t)1 << 24, 1) == 0);
    CHECK(atmos__beams_epi_build(&fresh, s, eye, (size_t)1 << 24, 1) == 0);
    CHECK_MSG(same_lines(&kept, &fresh), "the same eye and map: not a fresh build's lines");
    atmos__beams_epi_free(&fresh);
    const double ex = kept.ex, ey = kept.ey;
    atmos_mesh_transform t;
    atmos_mesh_transform_identity(&t);
    t.position_m[0] = 2.5;
    CHECK_OK(atmos_mesh_apply_transform(ctx, post[4], &t));
    CHECK_OK(atmos__beams_sun_build(ctx, s, sun, post, 10, 256));
    CHECK(atmos__beams_epi_build(&kept, s, eye, (size_t)1 << 24, 2) == 0);
    CHECK(atmos__beams_epi_build(&fresh, s, eye, (size_t)1 << 24, 1) == 0);
    CHECK(fresh.ex == ex && fresh.ey == ey); /* the same epipole */
    CHECK_MSG(same_lines(&kept, &fresh), "a post moved, the map made again: not a fresh build's lines");
    atmos__beams_epi_free(&fresh);
    const double moved[3] = {eye[0] + 0.5, eye[1], eye[2]};
    CHECK(atmos__beams_epi_build(&kept, s, moved, (size_t)1 << 24, 2) == 0);
    CHECK(atmos__beams_epi_build(&fresh, s, moved, (size_t)1 << 24, 1) == 0);
    CHECK_MSG(same_lines(&kept, &fresh), "the eye moved: not a fresh build's lines");
    const size_t few = kept.lines > 0 ? kept.at[kept.lines - 1] + (size_t)kept.cnt[kept.lines - 1] - 1 : 0;
    CHECK(atmos__beams_epi_build(&kept, s, moved, few, 2) == 0);
    CHECK(atmos__beams_epi_build(&fresh, s, moved, few, 1) == 0);
    CHECK_MSG(kept.lines == 0 && fresh.lines == 0, "max_samples lowered: %d lines kept, %d fresh", kept.lines,
              fresh.lines);
    atmos__beams_epi_free(&fresh), atmos__beams_epi_free(&kept);
}

/* Nine posts 1.5 m square and 30 m high, 6 m apart, 60 m away, on a slab 80 m by 40 (post[9]);
 * the sun's map of them. */
static int fence(atmos_mesh *post[10], atmos__beams_sun *s, const double sun[3])
{
    for (int i = 0; i < 10; i++) {
        post[i] = NULL;
        CHECK_OK(atmos_mesh_load(ctx, "builtin:box", 0, &post[i]));
        if (!post[i]) return 0;
        atmos_mesh_transform t;
        atmos_mesh_transform_identity(&t);
        t.position_m[0] = 6 * (i - 4), t.position_m[1] = 15, t.position_m[2] = -60;
        t.scale[0] = 1.5, t.scale[1] = 30, t.scale[2] = 1.5;
        if (i == 9) t.position_m[0] = 0, t.position_m[1] = -0.5, t.scale[0] = 80, t.scale[1] = 1, t.scale[2] = 40;
        CHECK_OK(atmos_mesh_apply_transform(ctx, post[i], &t));
    }
    memset(s, 0, sizeof *s);
    CHECK_OK(atmos__beams_sun_build(ctx, s, sun, post, 10, 256));
    return s->n == 256;
}

/* The map of s built again with 1, 2 and 3 threads against the fence's triangles drawn one
 * after the other into the whole map (the rasteriser alone), and its tiles. */
static void test_bands(atmos_mesh *post[10], const atmos__beams_sun *s, const double sun[3])
{
    const size_t nn = (size_t)s->n * s->n;
    float *ref = malloc(sizeof(float) * nn);
    if (!ref) return;
    for (size_t i = 0; i < nn; i++) ref[i] = INFINITY;
    for (int m = 0; m < 10; m++)
        for (int t = 0; t < post[m]->triangle_count; t++) {
            double x[3], y[3], z[3];
            for (int k = 0; k < 3; k++) {
                const float *p = post[m]->positions + 3 * post[m]->indices[3 * t + k];
                const double q[3] = {p[0], p[1], p[2]};
                x[k] = (atmos__dot3(q, s->right) - s->u0) / s->texel;
                y[k] = (atmos__dot3(q, s->up) - s->v0) / s->texel;
                z[k] = atmos__dot3(q, s->fwd);
            }
            atmos__beams_raster(ref, s->n, x, y, z, 0);
        }
    long lit = 0;
    for (size_t i = 0; i < nn; i++) lit += !isinf(ref[i]);
    CHECK(lit > (long)nn / 20); /* the fence covers the map, not a corner of it */
    for (int th = 1; th <= 3; th++) {
        atmos_context_desc d;
        memset(&d, 0, sizeof d);
        d.threads = th;
        atmos_context *c = NULL;
        CHECK_OK(atmos_context_create(&d, &c));
        atmos__beams_sun b;
        memset(&b, 0, sizeof b);
        CHECK_OK(atmos__beams_sun_build(c, &b, sun, post, 10, s->n));
        CHECK(b.n == s->n && b.depth && !memcmp(b.depth, ref, sizeof(float) * nn));
        CHECK(b.tiles.levels == s->tiles.levels && b.tiles.min &&
              !memcmp(b.tiles.min, s->tiles.min,
                      sizeof(float) * 2 * (s->tiles.level_at[s->tiles.levels - 1] + 1)));
        atmos__beams_sun_free(&b);
        atmos_context_destroy(c);
    }
    free(ref);
}

/* Each line's tree: a cell of the finest level holds the least and the greatest of its 4
 * segments' samples (the line's last cell fewer), a cell above those of the one or two cells
 * below it; lines of every length mod 4 are among them. */
static void test_trees(const atmos__beams_epi *e)
{
    int bad = 0, mods = 0;
    for (int j = 0; j < e->lines; j++) {
        const int nseg = e->cnt[j] - 1;
        if (nseg <= 0) continue;
        mods |= 1 << (nseg % 4);
        const float *m = e->m + e->at[j], *lh = e->lh + 2 * e->tat[j];
        int c = (nseg + 3) / 4;
        for (int i = 0; i < c; i++) {
            float lo = INFINITY, hi = -INFINITY;
            for (int k = 4 * i; k <= 4 * i + 4 && k <= nseg; k++) lo = fminf(lo, m[k]), hi = fmaxf(hi, m[k]);
            bad += lh[2 * i] != lo || lh[2 * i + 1] != hi;
        }
        for (; c > 1; lh += 2 * c, c = (c + 1) / 2)
            for (int i = 0; 2 * i < c; i++) {
                const float *a = lh + 4 * i, *b = 2 * i + 1 < c ? a + 2 : a, *up = lh + 2 * c + 2 * i;
                bad += up[0] != fminf(a[0], b[0]) || up[1] != fmaxf(a[1], b[1]);
            }
    }
    CHECK_MSG(bad == 0, "%d cells of the lines' trees not the least and greatest below them", bad);
    CHECK_MSG(mods == 15, "lines of lengths %#x mod 4 only", (unsigned)mods);
}

static void test_lit_length(const atmos__beams_sun *s, const atmos__beams_epi *e, const double eye[3])
{
    int rays = 0, shadowed = 0, fails = 0, off_fails = 0, samples = 0, samples_off = 0, sampled = 0;
    double worst = 0;
    for (int j = 0; j < e->lines; j += 5) {
        const double th = j * e->dth, th1 = (j + 1) * e->dth;
        /* the line's samples are the map's depths at its points (and not at the next line's) */
        for (int i = 0; i < e->cnt[j]; i++) {
            const double r = e->k0[j] + i, m = e->m[e->at[j] + i];
            const double want = map_depth(s, e->ex + r * cos(th), e->ey + r * sin(th));
            const double next = map_depth(s, e->ex + r * cos(th1), e->ey + r * sin(th1));
            sampled++;
            samples += !(fabs(m - want) <= 1e-5 * fabs(want) || m == want);
            samples_off += !(fabs(m - next) <= 1e-5 * fabs(next) || m == next);
        }
        for (int k = 0; k < 3; k++) {
            const double zs = 0.3 * (k - 1); /* depth per texel along the line */
            const double zc = atmos__dot3(eye, s->fwd) - s->bias, rT = e->k0[j] + e->cnt[j] + 5.0;
            double walked = 0, off = 0, marched = 0;
            atmos__beams_epi_walk(e, j, zc, zs, rT, add_length, &walked);
            atmos__beams_epi_walk(e, (j + 1) % e->lines, zc, zs, rT, add_length, &off);
            const double h = 1.0 / 64;
            int edges = 0, was = 1;
            for (double r = 0.5 * h; r < rT; r += h) {
                const int lit = zc + r * zs < map_depth(s, e->ex + r * cos(th), e->ey + r * sin(th));
                marched += h * lit, edges += lit != was, was = lit;
            }
            rays++;
            if (marched < rT - 1) {
                const double tol = 0.05 + 0.6 * edges;
                shadowed++;
                fails += fabs(walked - marched) > tol, off_fails += fabs(off - marched) > tol;
                worst = fmax(worst, fabs(walked - marched) / tol);
            }
        }
    }
    printf("epipolar lines: %d lines; %d of %d samples not the map's depth at their point (%d not at the next "
           "line's); %d rays, %d shadowed: %d with a lit length beyond 0.05 + 0.6 texel an edge of the march "
           "(at most %.2f of it), %d along the next line\n",
           e->lines, samples, sampled, samples_off, rays, shadowed, fails, worst, off_fails);
    CHECK(samples == 0);
    CHECK(samples_off > sampled / 4);
    CHECK(shadowed > 40);
    CHECK(fails == 0);
    CHECK(off_fails >= shadowed / 8);
}

static void test_airlight(const atmos__beams_sun *s, const atmos__beams_epi *e, const double eye[3])
{
    const atmos__beams_fog fog = {.sigma0 = 0.002, .albedo = 0.9, .g = 0.5};
    double worst = 0;
    int shadowed = 0;
    for (int r = 0; r < 41; r++)
        for (int k = 0; k < 3; k++) {
            double d[3] = {-0.6 + 0.03 * r, 0.1 + 0.15 * k, -1};
            atmos__normalize3(d);
            const double T = 200;
            const double lines = atmos__beams_sun_airlight_lines(s, e, &fog, eye, d, T, 0.01, 256);
            const double steps = atmos__beams_sun_airlight(s, &fog, eye, d, T, 1e-4, 10000);
            atmos__beams_sun empty = *s;
            empty.n = 0;
            const double whole = atmos__beams_sun_airlight(&empty, &fog, eye, d, T, 1e-4, 10000);
            shadowed += steps < 0.99 * whole;
            worst = fmax(worst, fabs(lines - steps) / whole);
        }
    printf("epipolar lines: the fog's sunlight within %.3f %% of the unshadowed whole of the map's steps "
           "(%d of 123 rays shadowed)\n", 100 * worst, shadowed);
    CHECK(shadowed > 10);
    CHECK(worst <= 0.02);
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    atmos_mesh *post[10];
    atmos__beams_sun s;
    double sun[3] = {0.4, 0.5, 0.6};
    atmos__normalize3(sun);
    if (fence(post, &s, sun)) {
        const double eye[3] = {3, 10, 0};
        atmos__beams_epi e = {0};
        CHECK(atmos__beams_epi_build(&e, &s, eye, (size_t)1 << 24, 2) == 0);
        CHECK(e.lines > 0);
        if (e.lines > 0) {
            test_trees(&e);
            test_lit_length(&s, &e, eye);
            test_airlight(&s, &e, eye);
        }
        atmos__beams_epi_free(&e);
        test_bands(post, &s, sun);
        test_kept_lines(post, &s, sun, eye); /* last: it moves a post */
    }
    atmos__beams_sun_free(&s);
    for (int i = 0; i < 10; i++) atmos_mesh_destroy(post[i]);
    atmos_context_destroy(ctx);
    return test_summary("test_beams_epipolar");
}
