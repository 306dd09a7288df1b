/* The half-angle slicing renderer (Riley et al. 2004 §4.2-§5) against an independent
 * single-scattering ray marcher written here, and its invariants: no NaN/Inf, thread
 * independence, energy vs slice count, front-to-back vs back-to-front across 90°, an
 * empty volume renders exactly the sky, bad settings are rejected. Small volumes (32^3)
 * and 64x64 images keep it fast, also under ASan. */
#include "atmos/atmos.h"
#include "test.h"
#include "test_optics.h"

#define PI 3.14159265358979323846
#define N 32
#define VOX 20.0

static char cache_dir[1024];

static atmos_context *make_ctx(int threads)
{
    return test_context(threads, cache_dir);
}

/* A Gaussian blob of peak density peak (m^-3), zero at the edges, 640 m across,
 * centred 1000 m north of the origin at 1500 m. */
static atmos_volume *blob(atmos_context *ctx, float peak)
{
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = vd.dims[1] = vd.dims[2] = N;
    vd.voxel_size_m = VOX;
    vd.origin_m[0] = -N * VOX / 2, vd.origin_m[1] = 1500 - N * VOX / 2, vd.origin_m[2] = -1000 - N * VOX / 2;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    int f = -1;
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "cloud", &f));
    static float buf[N * N * N];
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                double x = (i + 0.5 - N / 2.0) / (N / 2.0), y = (j + 0.5 - N / 2.0) / (N / 2.0),
                       z = (k + 0.5 - N / 2.0) / (N / 2.0);
                double r2 = x * x + y * y + z * z;
                buf[(k * N + j) * N + i] = r2 < 0.8 ? (float)(peak * exp(-4 * r2) * (0.8 - r2) / 0.8) : 0.0f;
            }
    if (peak > 0) {
        int off[3] = {0, 0, 0}, size[3] = {N, N, N};
        CHECK_OK(atmos_volume_set_dense(ctx, v, f, off, size, buf, 1.0f));
    }
    CHECK_OK(atmos_volume_finalize(ctx, v));
    return v;
}

typedef test_optics optics;

/* An analytic Henyey-Greenstein particle (g = 0.7, sigma_ext 1e-9 m^2, albedo 0.95):
 * quick to build and exactly known to the ray marcher. */
static void make_optics(atmos_context *ctx, optics *op)
{
    test_hg_optics(ctx, "hg07", 0.7, 0.95, 1, op);
}

static void free_optics(optics *op)
{
    test_optics_free(op);
}

static void scene_for(atmos_scene *s, double sun_el, double sun_az)
{
    atmos_scene_defaults(s);
    s->width = s->height = 64;
    s->samples_per_pixel = 1;
    double pos[3] = {0, 1500, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    s->camera.look_at[0] = 0, s->camera.look_at[1] = 1500, s->camera.look_at[2] = -1000;
    s->camera.fov_deg = 45;
    s->sun.from_time = 0;
    s->sun.elevation_deg = sun_el;
    s->sun.azimuth_deg = sun_az;
    s->wavelengths = ATMOS_WAVELENGTHS_RGB;
}

/* What these tests vary: the scene's "slice" settings and the density scale (0: the
 * scene's; xi < 0: none), and the call's optics and reference passes. */
typedef struct {
    const atmos_volume_optics *optics;
    int slices, light_size, eq24, low_albedo, reference, diffuse;
    double xi, density_scale, eye_scale;
    double edge_aa; /* these tests take one eye ray per pixel unless this is set */
} sopts;

static atmos_status render_st(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *v, const sopts *o,
                              atmos_image **img)
{
    atmos_scene s = *scene;
    atmos_slice_settings ss;
    atmos_slice_defaults(&ss);
    s.slice.light_size = 96; /* plenty for a 32^3 volume; keeps the test fast */
    if (o) {
        ss.optics = o->optics;
        ss.reference = o->reference;
        if (o->slices) s.slice.slices = o->slices;
        if (o->light_size) s.slice.light_size = o->light_size;
        if (o->xi != 0) s.slice.xi = o->xi < 0 ? 0 : o->xi;
        s.slice.eq24 = o->eq24;
        s.slice.low_albedo = o->low_albedo;
        s.slice.diffuse = o->diffuse; /* these tests are Riley's path's: with or without the P1 field */
        s.slice.field = o->diffuse ? ATMOS_SLICE_FIELD_P1 : ATMOS_SLICE_FIELD_NONE;
        if (o->density_scale != 0) s.volume.density_scale = o->density_scale;
        if (o->eye_scale != 0) s.slice.eye_scale = o->eye_scale;
        s.slice.edge_aa = o->edge_aa;
    }
    return atmos_render_slice(ctx, &s, v, &ss, img, NULL);
}

static atmos_image *render(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v, const sopts *o)
{
    atmos_image *img = NULL;
    atmos_status st = render_st(ctx, s, v, o, &img);
    CHECK_MSG(st == ATMOS_OK, "render slice: %s", atmos_context_error(ctx));
    return img;
}

static int all_finite(const atmos_image *img)
{
    size_t n = (size_t)img->width * img->height * img->channels;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(img->pixels[i]) || img->pixels[i] < 0) return 0;
    return 1;
}

/* Sum over pixels and the 3 channels of |img - sky|: the volume's effect. */
static double volume_energy(const atmos_image *img, const atmos_image *sky)
{
    double e = 0;
    for (int p = 0; p < img->width * img->height; p++)
        for (int c = 0; c < 3; c++) e += fabs((double)img->pixels[p * 4 + c] - sky->pixels[p * 4 + c]);
    return e;
}

/* Independent single-scattering ray marcher: along each pixel's ray through the
 * volume, sunlight (Eq. 12) attenuated by the volume's optical depth towards the sun,
 * scattered by the HG phase function, attenuated by the volume to the eye; the sky
 * composited as Riley §5 (front air to the halfway plane, the rest behind). The
 * halfway plane is taken through the blob's centre perpendicular to the view ray,
 * which differs from the renderer's half-vector plane only in the tiny air path. */
static void march(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v, const atmos_image *sky,
                  double sigma_ext, double albedo, double g, atmos_image *out)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *air = NULL;
    CHECK_OK(atmos_atmosphere_create(ctx, &s->atmosphere, &wl, &air));
    const int vacuum = s->atmosphere.kind == ATMOS_ATMOSPHERE_VACUUM;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(ctx, &s->camera, s->width, s->height, &cam));
    double sun[3], el, az;
    CHECK_OK(atmos_scene_sun_direction(ctx, s, sun, &el, &az));
    double lo[3], hi[3];
    atmos_volume_bounds(v, lo, hi);
    double cen[3] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
    const double sig = sigma_ext;
    memcpy(out->pixels, sky->pixels, sizeof(float) * (size_t)s->width * s->height * 4);
    for (int y = 0; y < s->height; y++)
        for (int x = 0; x < s->width; x++) {
            double d[3];
            atmos_camera_ray(&cam, x + 0.5, y + 0.5, d);
            const int steps = 300;
            double t0 = 0, t1 = 2500, dt = (t1 - t0) / steps;
            double L[3] = {0, 0, 0}, tau = 0;
            double mu = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
            double P = (1 - g * g) / (4 * PI * pow(1 + g * g - 2 * g * mu, 1.5));
            for (int i = 0; i < steps; i++) {
                double t = t0 + (i + 0.5) * dt;
                double p[3] = {cam.position[0] + t * d[0], cam.position[1] + t * d[1], cam.position[2] + t * d[2]};
                double eta = atmos_volume_sample(v, 0, p);
                if (eta <= 0) continue;
                double be = eta * sig;
                double tl = atmos_volume_optical_depth(v, &sig, p, sun, 0, 1e5);
                double sl[3];
                if (vacuum) /* the sun unattenuated */
                    for (int c = 0; c < 3; c++) sl[c] = wl.sun_irradiance[c] * s->atmosphere.sun_scale;
                else
                    atmos_atmosphere_sunlight(air, p, sun, sl);
                /* exact slab integral of the source with its own attenuation */
                double Ts = exp(-be * dt);
                for (int c = 0; c < 3; c++) L[c] += exp(-tau) * sl[c] * exp(-tl) * albedo * P * (1 - Ts);
                tau += be * dt;
            }
            if (tau == 0) continue;
            double th = (cen[0] - cam.position[0]) * d[0] + (cen[1] - cam.position[1]) * d[1] +
                        (cen[2] - cam.position[2]) * d[2];
            double front[3], Tf[3];
            atmos_atmosphere_inscatter(air, cam.position, d, th, sun, front);
            atmos_atmosphere_transmittance(air, cam.position, d, th, Tf);
            if (vacuum)
                for (int c = 0; c < 3; c++) front[c] = 0, Tf[c] = 1;
            float *px = out->pixels + ((size_t)y * s->width + x) * 4;
            for (int c = 0; c < 3; c++) px[c] = (float)(front[c] + Tf[c] * L[c] + exp(-tau) * (px[c] - front[c]));
        }
    atmos_atmosphere_destroy(air);
}

enum { BG_SKY, BG_BLACK, BG_UNIFORM };
static int homogeneous_air; /* compare_with_marcher: a homogeneous layer instead of Riley's air */
static double marcher_sun[2] = {35, 200}; /* compare_with_marcher's sun: behind-left of the camera */
static int marcher_slices;                /* and its slice count (0: the renderer's choice) */

static void compare_with_marcher(atmos_context *ctx, float peak, int low_albedo, int background, double tol,
                                 const char *what);

/* As compare_with_marcher in a homogeneous layer of air (the renderer knows no kind's insides). */
static void compare_homogeneous(atmos_context *ctx, double tol)
{
    homogeneous_air = 1;
    compare_with_marcher(ctx, 1e4f, 0, BG_SKY, tol, "thin, homogeneous air");
    homogeneous_air = 0;
}

static void compare_with_marcher(atmos_context *ctx, float peak, int low_albedo, int background, double tol,
                                 const char *what)
{
    optics op;
    make_optics(ctx, &op);
    atmos_volume *v = blob(ctx, peak);
    atmos_scene s;
    scene_for(&s, marcher_sun[0], marcher_sun[1]); /* by default front-to-back */
    if (background != BG_SKY) s.atmosphere.kind = ATMOS_ATMOSPHERE_VACUUM;
    if (homogeneous_air) s.atmosphere.kind = ATMOS_ATMOSPHERE_HOMOGENEOUS, s.atmosphere.thickness_m = 1500;
    s.atmosphere.background_radiance = background == BG_UNIFORM ? 0.01 : 0.0;
    sopts ss = {0};
    ss.optics = &op.o;
    ss.xi = -1; /* no back-scatter term: pure single scattering in the thin limit */
    ss.low_albedo = low_albedo;
    ss.slices = marcher_slices;
    s.slice.air_shadows = 0; /* the marcher leaves the air unshadowed (test_slice_shafts checks the shadow) */
    atmos_image *img = render(ctx, &s, v, &ss);
    atmos_image *sky = NULL, *ref = NULL;
    CHECK_OK(atmos_render_sky(ctx, &s, &sky, NULL));
    CHECK_OK(atmos_image_create(ctx, s.width, s.height, 4, &ref));
    march(ctx, &s, v, sky, 1e-9, 0.95, 0.7, ref);
    double e_img = volume_energy(img, sky), e_ref = volume_energy(ref, sky), diff = volume_energy(img, ref);
    printf("%s: volume effect slice %.6g, marcher %.6g, |difference| %.3g%%\n", what, e_img, e_ref,
           100 * diff / e_ref);
    CHECK(e_ref > 0);
    CHECK_MSG(diff <= tol * e_ref, "%s: slice vs marcher differ by %.3g%% (tolerance %.3g%%)", what, 100 * diff / e_ref,
              100 * tol);
    CHECK(all_finite(img));
    atmos_image_destroy(img);
    atmos_image_destroy(sky);
    atmos_image_destroy(ref);
    atmos_volume_destroy(v);
    free_optics(&op);
}

static void test_thin_limit(void)
{
    atmos_context *ctx = make_ctx(2);
    /* peak 1e4 m^-3 * 1e-9 m^2 = 1e-5 m^-1: optical depth ~0.004 through the blob */
    compare_with_marcher(ctx, 1e4f, 0, BG_SKY, 0.02, "thin, Eq. 25");
    /* low-albedo mode is plain single scattering at any thickness (peak tau ~ 2) */
    compare_with_marcher(ctx, 5e6f, 1, BG_SKY, 0.03, "low albedo, thick");
    /* vacuum backgrounds: no air in front, the sun unattenuated */
    compare_with_marcher(ctx, 1e4f, 0, BG_BLACK, 0.02, "thin, black background");
    compare_with_marcher(ctx, 5e6f, 1, BG_UNIFORM, 0.03, "low albedo, uniform background");
    compare_homogeneous(ctx, 0.02);
    atmos_context_destroy(ctx);
}

/* Single scattering in a dense blob with coarse slices (peak optical depth ~1 a slab): the light
 * buffer's beam decays across each slab as the light pass attenuates it, toward the sun
 * (back to front, 20 degrees from the view: a cloud's sunlit edges seen toward the sun) and
 * away from it (front to back). Counted at the slab's entry alone, the beam made the blob's
 * light 6.7 % (toward the sun) and 9.8 % (away) off the marcher's at these slabs; now 0.2-0.3 %. */
static void test_low_albedo_coarse_slices(void)
{
    atmos_context *ctx = make_ctx(2);
    const double suns[2][2] = {{20, 0}, {35, 200}};
    const char *what[2] = {"low albedo, dense, 24 slices, sun ahead", "low albedo, dense, 24 slices, sun behind"};
    marcher_slices = 24;
    for (int i = 0; i < 2; i++) {
        marcher_sun[0] = suns[i][0], marcher_sun[1] = suns[i][1];
        compare_with_marcher(ctx, 3e7f, 1, BG_BLACK, 0.02, what[i]);
    }
    marcher_sun[0] = 35, marcher_sun[1] = 200, marcher_slices = 0;
    atmos_context_destroy(ctx);
}

static void test_threads_and_finite(void)
{
    optics op;
    atmos_context *c1 = make_ctx(1), *c2 = make_ctx(2);
    make_optics(c2, &op);
    atmos_volume *v = blob(c2, 3e6f);
    const double suns[][2] = {{35, 200}, {10, 0}, {-5, 180}, {90, 0}, {0.0, 0.0}};
    for (int i = 0; i < 5; i++) {
        atmos_scene s;
        scene_for(&s, suns[i][0], suns[i][1]);
        for (int u = 0; u < 3; u++) { /* eq25, eq24, eq25 with the diffuse light field */
            sopts ss = {0};
            ss.optics = &op.o;
            ss.slices = 64;
            ss.light_size = 64;
            ss.eq24 = u == 1;
            ss.diffuse = u == 2;
            atmos_image *a = render(c1, &s, v, &ss), *b = render(c2, &s, v, &ss);
            CHECK(a && b && all_finite(a) && all_finite(b));
            if (a && b)
                CHECK_MSG(memcmp(a->pixels, b->pixels, sizeof(float) * 64 * 64 * 4) == 0,
                          "1 vs 2 threads differ (sun %g/%g)", suns[i][0], suns[i][1]);
            atmos_image_destroy(a);
            atmos_image_destroy(b);
        }
    }
    /* optically huge, the camera inside the volume, the view straight at the sun */
    atmos_scene s;
    scene_for(&s, 0.0, 0.0);
    s.camera.position[2] = -1000;
    s.camera.look_at[2] = -2000;
    sopts ss = {0};
    ss.optics = &op.o;
    ss.slices = 32;
    ss.density_scale = 1e4;
    atmos_image *a = render(c2, &s, v, &ss);
    CHECK(a && all_finite(a));
    atmos_image_destroy(a);
    atmos_volume_destroy(v);
    free_optics(&op);
    atmos_context_destroy(c1);
    atmos_context_destroy(c2);
}

static void test_energy_vs_slices(void)
{
    atmos_context *ctx = make_ctx(2);
    optics op;
    make_optics(ctx, &op);
    atmos_volume *v = blob(ctx, 3e6f);
    atmos_scene s;
    scene_for(&s, 35, 200);
    atmos_image *sky = NULL;
    CHECK_OK(atmos_render_sky(ctx, &s, &sky, NULL));
    for (int u = 0; u < 2; u++) {
        sopts ss = {0};
        ss.optics = &op.o;
        ss.eq24 = u != 0;
        ss.slices = 64;
        atmos_image *a = render(ctx, &s, v, &ss);
        ss.slices = 256;
        atmos_image *b = render(ctx, &s, v, &ss);
        double ea = volume_energy(a, sky), eb = volume_energy(b, sky);
        printf("energy %s: 64 slices %.6g, 256 slices %.6g (%+.2f%%)\n", u ? "eq24" : "eq25", ea, eb,
               100 * (eb - ea) / ea);
        CHECK_MSG(eb <= ea * 1.03 && eb >= ea * 0.9, "energy 64 vs 256 slices: %g vs %g", ea, eb);
        atmos_image_destroy(a);
        atmos_image_destroy(b);
    }
    atmos_image_destroy(sky);
    atmos_volume_destroy(v);
    free_optics(&op);
    atmos_context_destroy(ctx);
}

/* The camera looks north (level); the light travels at 89° and at 91° from the view:
 * front-to-back and back-to-front slicing of nearly the same lighting. */
static void test_ftb_btf(void)
{
    atmos_context *ctx = make_ctx(2);
    optics op;
    make_optics(ctx, &op);
    atmos_volume *v = blob(ctx, 3e6f);
    double e[2];
    for (int i = 0; i < 2; i++) {
        double ang = i ? 91.0 : 89.0; /* angle between view (0,0,-1) and light travel -sun */
        double el = 30.0;
        double caz = -cos(ang * PI / 180) / cos(el * PI / 180); /* sun . view = cos(el) cos(az) */
        atmos_scene s;
        scene_for(&s, el, acos(-caz) * 180 / PI);
        atmos_image *sky = NULL;
        CHECK_OK(atmos_render_sky(ctx, &s, &sky, NULL));
        sopts ss = {0};
        ss.optics = &op.o;
        atmos_image *a = render(ctx, &s, v, &ss);
        e[i] = volume_energy(a, sky);
        atmos_image_destroy(a);
        atmos_image_destroy(sky);
    }
    printf("89 deg (front-to-back) %.6g, 91 deg (back-to-front) %.6g (%+.2f%%)\n", e[0], e[1],
           100 * (e[1] - e[0]) / e[0]);
    CHECK_REL(e[1], e[0], 0.05);
    atmos_volume_destroy(v);
    free_optics(&op);
    atmos_context_destroy(ctx);
}

static void test_empty_and_errors(void)
{
    atmos_context *ctx = make_ctx(2);
    optics op;
    make_optics(ctx, &op);
    atmos_volume *v = blob(ctx, 0.0f);
    atmos_scene s;
    scene_for(&s, 35, 200);
    sopts ss = {0};
    ss.optics = &op.o;
    atmos_image *a = render(ctx, &s, v, &ss), *sky = NULL;
    CHECK_OK(atmos_render_sky(ctx, &s, &sky, NULL));
    CHECK(a && memcmp(a->pixels, sky->pixels, sizeof(float) * 64 * 64 * 4) == 0);
    atmos_image_destroy(a);
    atmos_image_destroy(sky);

    atmos_image *img = NULL;
    ss.slices = -3;
    CHECK(render_st(ctx, &s, v, &ss, &img) == ATMOS_E_INVALID_ARG && img == NULL);
    CHECK(strstr(atmos_context_error(ctx), "/slice/slices") != NULL);
    ss.slices = 0;
    ss.xi = NAN;
    CHECK(render_st(ctx, &s, v, &ss, &img) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "/slice/xi") != NULL);
    ss.xi = 0;
    ss.eq24 = 7;
    CHECK(render_st(ctx, &s, v, &ss, &img) == ATMOS_E_INVALID_ARG);
    ss.eq24 = 0;
    s.camera.type = ATMOS_CAMERA_FISHEYE;
    s.volume.placed = 1;
    CHECK(render_st(ctx, &s, v, &ss, &img) != ATMOS_OK && img == NULL);
    CHECK(atmos_render_slice(ctx, &s, NULL, NULL, &img, NULL) == ATMOS_E_INVALID_ARG);
    atmos_scene d;
    atmos_scene_defaults(&d);
    CHECK(d.slice.slices == 0 && d.slice.light_size == 256 && fabs(d.slice.xi - 0.1 / (4 * PI)) < 1e-12);
    atmos_volume_destroy(v);
    free_optics(&op);
    atmos_context_destroy(ctx);
}

/* The fast passes (SoA chunks, polynomial exp/log) against the reference scalar passes
 * (libm expf/logf), thin and optically thick (slabs with beta Delta > 1, where Eq. 25
 * raises alpha F to a power), both compositing orders, Eq. 25, Eq. 24, low albedo, Eq. 25
 * with the diffuse light field: every pixel within 1e-5 of the image maximum. */
static void test_fast_vs_reference(void)
{
    optics op;
    atmos_context *ctx = make_ctx(2);
    make_optics(ctx, &op);
    atmos_volume *v = blob(ctx, 3e6f);
    const double suns[][2] = {{35, 200}, {20, 10}};
    double worst = 0;
    for (int i = 0; i < 2; i++)
        for (int mode = 0; mode < 4; mode++)
            for (int thick = TEST_SANITIZED; thick < 2; thick++) { /* the sanitizer copy: thick alone */
                atmos_scene s;
                scene_for(&s, suns[i][0], suns[i][1]);
                sopts ss = {0};
                ss.diffuse = mode == 3;
                ss.optics = &op.o;
                ss.slices = thick ? 61 : 64; /* 61: the last batch of slices is partial */
                ss.eq24 = mode == 1;
                ss.low_albedo = mode == 2;
                ss.density_scale = thick ? 40 : 1;
                atmos_image *a = render(ctx, &s, v, &ss);
                ss.reference = 1;
                atmos_image *b = render(ctx, &s, v, &ss);
                if (!a || !b) {
                    atmos_image_destroy(a);
                    atmos_image_destroy(b);
                    continue;
                }
                double mx = 0, d = 0;
                for (int p = 0; p < 64 * 64; p++)
                    for (int c = 0; c < 3; c++) {
                        mx = fmax(mx, b->pixels[p * 4 + c]);
                        d = fmax(d, fabs((double)a->pixels[p * 4 + c] - b->pixels[p * 4 + c]));
                    }
                CHECK_MSG(d <= 1e-5 * mx, "fast vs reference: %.3g of the maximum (sun %g/%g, mode %d, thick %d)",
                          d / mx, suns[i][0], suns[i][1], mode, thick);
                worst = fmax(worst, d / mx);
                atmos_image_destroy(a);
                atmos_image_destroy(b);
            }
    printf("slice: fast vs reference passes: max |difference| %.2g of the image maximum\n", worst);
    atmos_volume_destroy(v);
    free_optics(&op);
    atmos_context_destroy(ctx);
}

/* Eye buffer smaller than the image (eye_scale): scale 1 (or one that rounds to the
 * image size) is the full-resolution render exactly; 0.5 agrees with it on a smooth
 * blob within the tolerances below; image pixels farther than two pixels from anything
 * the full-resolution render touches keep the sky image bit for bit; 1 and 2 threads
 * give identical images; odd sizes and tiny scales stay finite. */
static void test_eye_scale(void)
{
    optics op;
    atmos_context *c1 = make_ctx(1), *c2 = make_ctx(2);
    make_optics(c2, &op);
    atmos_volume *v = blob(c2, 3e6f);
    const double suns[][2] = {{35, 200}, {20, 10}};
    for (int i = 0; i < 2 - TEST_SANITIZED; i++) { /* the sanitizer copy: front-to-back alone */
        atmos_scene s;
        scene_for(&s, suns[i][0], suns[i][1]);
        s.width = s.height = 128;
        const int W = 128, H = 128;
        atmos_image *sky = NULL;
        CHECK_OK(atmos_render_sky(c2, &s, &sky, NULL));
        sopts ss = {0};
        ss.optics = &op.o;
        ss.slices = 128;
        atmos_image *full = render(c2, &s, v, &ss);
        ss.eye_scale = 1.0;
        atmos_image *one = render(c2, &s, v, &ss);
        ss.eye_scale = 0.999; /* rounds to the image size */
        atmos_image *near1 = render(c2, &s, v, &ss);
        ss.eye_scale = 0.5;
        atmos_image *half = render(c2, &s, v, &ss), *half1 = render(c1, &s, v, &ss);
        if (!full || !one || !near1 || !half || !half1) {
            CHECK(0);
        } else {
            const size_t bytes = sizeof(float) * W * H * 4;
            CHECK_MSG(memcmp(full->pixels, one->pixels, bytes) == 0, "eye_scale 1 differs from the default");
            CHECK_MSG(memcmp(full->pixels, near1->pixels, bytes) == 0, "eye_scale 0.999 (64 -> 64) differs");
            CHECK_MSG(memcmp(half->pixels, half1->pixels, bytes) == 0, "eye_scale 0.5: 1 vs 2 threads differ");
            CHECK(all_finite(half));
            /* The volume's effect V = img - sky in both renders. */
            double ef = 0, eh = 0, dsum = 0, dmax = 0, vmax = 0;
            static unsigned char near_[128 * 128];
            memset(near_, 0, sizeof near_);
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++) {
                    const size_t p = (size_t)y * W + x;
                    int touched = 0;
                    for (int c = 0; c < 3; c++) {
                        double vf = (double)full->pixels[p * 4 + c] - sky->pixels[p * 4 + c];
                        double vh = (double)half->pixels[p * 4 + c] - sky->pixels[p * 4 + c];
                        ef += fabs(vf), eh += fabs(vh), dsum += fabs(vh - vf);
                        dmax = fmax(dmax, fabs(vh - vf)), vmax = fmax(vmax, fabs(vf));
                        touched |= full->pixels[p * 4 + c] != sky->pixels[p * 4 + c];
                    }
                    if (touched)
                        for (int dy = -2; dy <= 2; dy++)
                            for (int dx = -2; dx <= 2; dx++)
                                if (y + dy >= 0 && y + dy < H && x + dx >= 0 && x + dx < W)
                                    near_[(y + dy) * W + x + dx] = 1;
                }
            int sky_kept = 1;
            for (size_t p = 0; p < (size_t)W * H; p++)
                if (!near_[p] && memcmp(half->pixels + p * 4, sky->pixels + p * 4, sizeof(float) * 3) != 0) sky_kept = 0;
            printf("slice eye_scale 0.5 vs 1 (sun %g/%g): volume radiance %+.3f%%, mean |difference| %.2f%% of the "
                   "mean effect, max %.2f%% of the largest effect\n",
                   suns[i][0], suns[i][1], 100 * (eh - ef) / ef, 100 * dsum / ef, 100 * dmax / vmax);
            CHECK_MSG(fabs(eh - ef) <= 0.005 * ef, "eye_scale 0.5: volume radiance %g vs %g", eh, ef);
            CHECK_MSG(dsum <= 0.01 * ef, "eye_scale 0.5: mean difference %g of the effect", dsum / ef);
            CHECK_MSG(dmax <= 0.02 * vmax, "eye_scale 0.5: max difference %g of the largest effect", dmax / vmax);
            CHECK_MSG(sky_kept, "eye_scale 0.5: a pixel away from the volume is not the sky image");
        }
        atmos_image_destroy(full), atmos_image_destroy(one), atmos_image_destroy(near1);
        atmos_image_destroy(half), atmos_image_destroy(half1), atmos_image_destroy(sky);
    }
    /* odd sizes, tiny and odd scales, vacuum, back-to-front */
    atmos_scene s;
    scene_for(&s, 20, 10);
    s.width = 67, s.height = 45;
    s.atmosphere.kind = ATMOS_ATMOSPHERE_VACUUM;
    const double scales[] = {0.37, 0.02, 1e-9};
    for (int i = 0; i < 3; i++) {
        sopts ss = {0};
        ss.optics = &op.o;
        ss.slices = 32;
        ss.eye_scale = scales[i];
        atmos_image *a = render(c2, &s, v, &ss), *b = render(c1, &s, v, &ss);
        CHECK(a && b && all_finite(a) && memcmp(a->pixels, b->pixels, sizeof(float) * 67 * 45 * 4) == 0);
        atmos_image_destroy(a), atmos_image_destroy(b);
    }
    atmos_image *img = NULL;
    sopts bad = {0};
    bad.optics = &op.o;
    bad.eye_scale = 1.5;
    CHECK(render_st(c2, &s, v, &bad, &img) == ATMOS_E_INVALID_ARG && img == NULL);
    CHECK(strstr(atmos_context_error(c2), "eye_scale") != NULL);
    bad.eye_scale = -0.5;
    CHECK(render_st(c2, &s, v, &bad, &img) == ATMOS_E_INVALID_ARG);
    bad.eye_scale = NAN;
    CHECK(render_st(c2, &s, v, &bad, &img) == ATMOS_E_INVALID_ARG);
    atmos_volume_destroy(v);
    free_optics(&op);
    atmos_context_destroy(c1);
    atmos_context_destroy(c2);
}

/* eye_scale 2: two rays per pixel along each axis, averaged, as the path tracer spreads its
 * samples over the pixel's area. The image must be the 2 x 2 box average of the render at
 * twice the size (what the accuracy bench measured: docs/accuracy.md, "What the per-pixel
 * error is made of"), within what the sky's and the air's change across a pixel allows, and
 * nearer it than the one-ray image is. A dense blob of 48 x 48 pixels with the sun to the side,
 * seen from below. */
static void test_eye_scale_box(void)
{
    optics op;
    atmos_context *c2 = make_ctx(2);
    make_optics(c2, &op);
    atmos_volume *v = blob(c2, 3e7f);
    atmos_scene s;
    scene_for(&s, 20, 100);
    s.camera.position[1] = 900; /* looking up at it: no horizon in the image, whose step across a
                                   pixel the composite (one sky value per pixel) does not filter */
    const int W = 48, H = 48;
    sopts ss = {0};
    ss.optics = &op.o;
    ss.slices = 96;
    s.width = 2 * W, s.height = 2 * H;
    atmos_image *big = render(c2, &s, v, &ss), *sky = NULL, *sky2 = NULL;
    CHECK_OK(atmos_render_sky(c2, &s, &sky2, NULL));
    s.width = W, s.height = H;
    CHECK_OK(atmos_render_sky(c2, &s, &sky, NULL));
    atmos_image *one = render(c2, &s, v, &ss);
    ss.eye_scale = 2.0;
    atmos_image *two = render(c2, &s, v, &ss);
    if (!big || !one || !two || !sky || !sky2) {
        CHECK(0);
    } else {
        double d2 = 0, d1 = 0, m2 = 0, vmax = 0, eff = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                for (int c = 0; c < 3; c++) {
                    double box = 0;
                    for (int q = 0; q < 4; q++) {
                        const size_t b = ((size_t)(2 * y + (q >> 1)) * 2 * W + 2 * x + (q & 1)) * 4 + c;
                        box += 0.25 * ((double)big->pixels[b] - sky2->pixels[b]);
                    }
                    /* the volume's effects (image - sky): the sky's own curvature across a pixel cancels */
                    const size_t p = ((size_t)y * W + x) * 4 + c;
                    const double e2 = (double)two->pixels[p] - sky->pixels[p], e1 = (double)one->pixels[p] - sky->pixels[p];
                    d2 += fabs(e2 - box), d1 += fabs(e1 - box);
                    m2 = fmax(m2, fabs(e2 - box)), vmax = fmax(vmax, fabs(box)), eff += fabs(box);
                }
        printf("slice eye_scale 2 vs the 2x2 box of the double-size image: mean |difference| %.3f%% of the mean "
               "effect (1 ray per pixel: %.3f%%), max %.3f%% of the largest effect\n",
               100 * d2 / eff, 100 * d1 / eff, 100 * m2 / vmax);
        CHECK(all_finite(two));
        CHECK_MSG(d2 <= 0.002 * eff, "eye_scale 2: mean difference %g of the effect", d2 / eff);
        CHECK_MSG(m2 <= 0.01 * vmax, "eye_scale 2: max difference %g of the largest effect", m2 / vmax);
        CHECK_MSG(d2 <= 0.25 * d1, "eye_scale 2 is no nearer the box (%g) than one ray per pixel (%g)", d2, d1);
    }
    atmos_image_destroy(big), atmos_image_destroy(one), atmos_image_destroy(two), atmos_image_destroy(sky);
    atmos_image_destroy(sky2);
    atmos_volume_destroy(v);
    free_optics(&op);
    atmos_context_destroy(c2);
}

int main(void)
{
    test_tmp_path(cache_dir, sizeof cache_dir, "cache");
    test_thin_limit();
    test_low_albedo_coarse_slices();
    test_threads_and_finite();
    test_energy_vs_slices();
    test_ftb_btf();
    test_empty_and_errors();
    test_fast_vs_reference();
    test_eye_scale();
    test_eye_scale_box();
    return test_summary("test_slice");
}
