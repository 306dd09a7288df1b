/* The Earth from space (docs/sky.md): the ground's maps looked up at known latitudes and
 * longitudes (synthetic maps whose halves differ), the night lights only on the night side,
 * the cloud spheres' attenuation against exp(-tau) in closed form, the brightness to
 * optical depth mapping against the two-stream reflectance it inverts; the scene keys: files
 * relative to the scene's folder, missing files refused, a world file placing a cloud image. */
#include "atmos/atmos.h"
#include "atmosphere/atmosphere_internal.h"
#include "atmosphere/planet_clouds.h"
#include "test.h"

#define PI 3.14159265358979323846
#define R_EARTH 6360e3

/* A w x h map; channel c of pixel (x, y) from f(lon, lat, c) at the pixel's centre. */
static atmos_image *make_map(int w, int h, int nc, float (*f)(double lon, double lat, int c))
{
    atmos_image *img = NULL;
    if (atmos_image_create(NULL, w, h, nc, &img) != ATMOS_OK) exit(2);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < nc; c++)
                img->pixels[((size_t)y * w + x) * nc + c] =
                    f(-180.0 + (x + 0.5) * 360.0 / w, 90.0 - (y + 0.5) * 180.0 / h, c);
    return img;
}

/* R: 1 east of Greenwich; G: 1 in the northern hemisphere; B: mid grey (128/255) */
static float halves(double lon, double lat, int c)
{
    if (c == 0) return lon > 0 ? 1.0f : 0.0f;
    if (c == 1) return lat > 0 ? 1.0f : 0.0f;
    return 128.0f / 255.0f;
}
static float white(double lon, double lat, int c) { (void)lon, (void)lat, (void)c; return 1.0f; }
static float grey_cloud(double lon, double lat, int c) { (void)lon, (void)lat, (void)c; return 0.6f; }

/* The spherical sky (SPHERICAL) where a check reads the sky (radiance, transmittance); where it
 * reads only the planet (the maps' look-ups, the geographic frame, the cloud spheres), DOBASHI:
 * the same planet (atmosphere_create.c's create_planet, whatever the kind) without the spherical
 * sky's multiple-scattering tables, which took most of this test's time (docs/architecture.md,
 * "The test suite's time"). */
static atmos_atmosphere *make_kind(atmos_atmosphere_kind kind, double lat0, double lon0, const atmos_image *ground,
                                   const atmos_image *night, const atmos_image *clouds, int spheres)
{
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    d.kind = kind;
    d.latitude_deg = lat0, d.longitude_deg = lon0;
    d.ground_map = ground, d.night_map = night;
    d.clouds.image = clouds;
    d.clouds.spheres = spheres;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &d, &wl, &a));
    return a;
}
static atmos_atmosphere *make(double lat0, double lon0, const atmos_image *ground, const atmos_image *night,
                              const atmos_image *clouds, int spheres)
{
    return make_kind(ATMOS_ATMOSPHERE_SPHERICAL, lat0, lon0, ground, night, clouds, spheres);
}
static atmos_atmosphere *make_planet(double lat0, double lon0, const atmos_image *ground, const atmos_image *night,
                                     const atmos_image *clouds, int spheres)
{
    return make_kind(ATMOS_ATMOSPHERE_DOBASHI, lat0, lon0, ground, night, clouds, spheres);
}

/* The ground point at angular distance arc_deg from the origin's ground point toward the
 * world direction (dx, dz) (unit, horizontal). */
static void ground_at(double arc_deg, double dx, double dz, double g[3])
{
    const double s = sin(arc_deg * PI / 180), c = cos(arc_deg * PI / 180);
    g[0] = R_EARTH * s * dx, g[1] = R_EARTH * c - R_EARTH, g[2] = R_EARTH * s * dz;
}

static void test_map_lookup(void)
{
    atmos_image *map = make_map(360, 180, 3, halves);
    double g[3], lat, lon;
    /* the origin at 30 N 100 E: north-east quadrant; 40 degrees north (-z): 70 N */
    atmos_atmosphere *a = make_planet(30, 100, map, NULL, NULL, 0);
    const atmos__planet *pl = a->planet;
    ground_at(0, 1, 0, g);
    atmos__planet_latlon(pl, g, &lat, &lon);
    CHECK_NEAR(lat, 30, 1e-9);
    CHECK_NEAR(lon, 100, 1e-9);
    CHECK_NEAR(atmos__planet_ground_albedo(pl, g, 0), 1.0, 1e-6);
    CHECK_NEAR(atmos__planet_ground_albedo(pl, g, 1), 1.0, 1e-6);
    /* 128/255 decoded by the sRGB transfer function: 0.2158605 (IEC 61966-2-1) */
    CHECK_NEAR(atmos__planet_ground_albedo(pl, g, 2), 0.2158605, 1e-6);
    ground_at(40, 0, -1, g);
    atmos__planet_latlon(pl, g, &lat, &lon);
    CHECK_NEAR(lat, 70, 1e-9);
    CHECK_NEAR(lon, 100, 1e-9);
    ground_at(60, 0, 1, g); /* 60 degrees south: 30 S */
    atmos__planet_latlon(pl, g, &lat, &lon);
    CHECK_NEAR(lat, -30, 1e-9);
    CHECK_NEAR(atmos__planet_ground_albedo(pl, g, 1), 0.0, 1e-6);
    atmos_atmosphere_destroy(a);
    /* on the equator at 5 W: 10 degrees east (+x) is 5 E, 10 west is 15 W */
    a = make_planet(0, -5, map, NULL, NULL, 0);
    pl = a->planet;
    ground_at(10, 1, 0, g);
    atmos__planet_latlon(pl, g, &lat, &lon);
    CHECK_NEAR(lon, 5, 1e-9);
    CHECK_NEAR(atmos__planet_ground_albedo(pl, g, 0), 1.0, 1e-6);
    ground_at(10, -1, 0, g);
    CHECK_NEAR(atmos__planet_ground_albedo(pl, g, 0), 0.0, 1e-6);
    atmos_atmosphere_destroy(a);
    /* across the date line: 175 E + 10 degrees east is 175 W */
    a = make_planet(0, 175, map, NULL, NULL, 0);
    ground_at(10, 1, 0, g);
    atmos__planet_latlon(a->planet, g, &lat, &lon);
    CHECK_NEAR(lon, -175, 1e-9);
    CHECK_NEAR(atmos__planet_ground_albedo(a->planet, g, 0), 0.0, 1e-6);
    /* the desc keeps no pointer to the caller's images */
    CHECK(atmos_atmosphere_get_desc(a)->ground_map == NULL);
    atmos_atmosphere_destroy(a);
    atmos_image_destroy(map);
}

/* a: the clear sky over 10 N 20 E with white night lights (shared with test_cloud_attenuation:
 * one spherical sky's tables fewer to build; the lights' look-ups here do not depend on where) */
static void test_night_lights(const atmos_atmosphere *a)
{
    const atmos__planet *pl = a->planet;
    const double g[3] = {0, 0, 0}, Ln = 5e-6; /* the default night_radiance */
    double sun[3];
    CHECK_NEAR(atmos__planet_ground_emission(pl, g, 1), Ln, 1e-12);
    const double elev[] = {60, 1, 0, -6, -12, -30, -90}, want[] = {0, 0, 0, 0.5, 1, 1, 1};
    for (int i = 0; i < 7; i++) {
        atmos_direction_from_angles(elev[i], 90, sun);
        CHECK_NEAR(atmos__planet_ground_lights(pl, g, sun, 1), want[i] * Ln, 1e-12);
    }
    /* seen from 500 km straight down: by day the lights are off, by night they shine
     * through the air (the air's own light is the sun's: none at midnight) */
    const double eye[3] = {0, 500e3, 0}, down[3] = {0, -1, 0};
    double L[3], T[3];
    atmos_direction_from_angles(-90, 0, sun);
    atmos_atmosphere_radiance(a, eye, down, sun, L, NULL);
    atmos_atmosphere_transmittance(a, eye, down, 500e3, T);
    /* (the production sky's view march and its segment transmittance agree to ~1e-3) */
    for (int k = 0; k < 3; k++) CHECK_REL(L[k], Ln * T[k], 2e-3);
}

/* The brightness mapping inverts the two-stream reflectance R = (1-g) tau / (2 + (1-g) tau),
 * g = 0.85 (planet_clouds.c). */
static void test_brightness_mapping(void)
{
    const double b0 = 0.04, bs[] = {0.1, 0.3, 0.6, 0.9};
    for (int i = 0; i < 4; i++) {
        const double tau = atmos__clouds_tau_from_brightness(bs[i], b0, 1e4);
        const double R = 0.15 * tau / (2 + 0.15 * tau);
        CHECK_NEAR(R, (bs[i] - b0) / (1 - b0), 1e-12);
    }
    CHECK(atmos__clouds_tau_from_brightness(0.03, b0, 1e4) == 0.0);
    CHECK(atmos__clouds_tau_from_brightness(0.999, b0, 50) == 50.0);
}

/* One uniform cloud sphere: the sunlight reaching the ground passes it with transmittance
 * exp(-tau / mu), mu the sun's cosine where the ray crosses the sphere (r sin = R sin:
 * the same ray); a view ray straight down sees the night lights dimmed by exp(-tau). */
static void test_cloud_attenuation(const atmos_atmosphere *clear, const atmos_image *night)
{
    atmos_image *cloud = make_map(72, 36, 1, grey_cloud);
    atmos_atmosphere *a = make(10, 20, NULL, night, cloud, 1);
    const atmos__planet *pl = a->planet;
    const double lin = pow((0.6 + 0.055) / 1.055, 2.4);
    const double tau = atmos__clouds_tau_from_brightness(lin, 0.04, 100);
    CHECK(tau > 1 && tau < 20);
    const double g[3] = {0, 0, 0};
    double sun[3];
    atmos_direction_from_angles(90, 0, sun);
    CHECK_NEAR(atmos__clouds_sun_attenuation(pl, g, sun, -1), exp(-tau), 1e-6 * exp(-tau));
    atmos_direction_from_angles(30, 45, sun); /* zenith angle 60 degrees at the ground */
    const double r = pl->clouds->r[0], mu = sqrt(1 - pow(R_EARTH / r * sin(60 * PI / 180), 2));
    CHECK_NEAR(atmos__clouds_sun_attenuation(pl, g, sun, -1), exp(-tau / mu), 1e-5 * exp(-tau / mu));
    CHECK(fabs(mu - 0.5) > 1e-5); /* the curvature is seen */
    /* the attenuation texture at the origin's column (lat 10, lon 20) and the sun overhead */
    float tex[36 * 18];
    atmos_direction_from_angles(90, 0, sun);
    atmos__clouds_attenuation_texture(pl, 0, sun, 36, 18, tex);
    CHECK_NEAR(tex[0], 1.0, 1e-12); /* the only sphere: nothing above it */
    atmos_direction_from_angles(-90, 0, sun);
    const double eye[3] = {0, 500e3, 0}, down[3] = {0, -1, 0};
    double L[3], L0[3];
    atmos_atmosphere_radiance(a, eye, down, sun, L, NULL);
    atmos_atmosphere_radiance(clear, eye, down, sun, L0, NULL);
    /* (the air's transmittance is integrated in two pieces with the cloud and, by the
     * production sky, in one march without it: ~1e-3) */
    for (int k = 0; k < 3; k++) CHECK_REL(L[k], L0[k] * exp(-tau), 2e-3);
    /* the sun's disk seen from the ground straight up through the cloud: dimmed by exp(-tau)
     * (the cloud's own light, ~E/pi, is ~1/200 of the dimmed disk's: 2 %) */
    const double ground[3] = {0, 1, 0}, up[3] = {0, 1, 0};
    atmos_direction_from_angles(90, 0, sun);
    double Ls[3], Lsun[3];
    atmos_atmosphere_sun_radiance(a, ground, sun, Lsun);
    atmos_atmosphere_radiance(a, ground, up, sun, Ls, NULL);
    for (int k = 0; k < 3; k++) CHECK_REL(Ls[k], Lsun[k] * exp(-tau), 0.02);
    atmos_atmosphere_destroy(a);
    /* five spheres carry the same column: the ground's shadow is the same */
    a = make_planet(10, 20, NULL, night, cloud, 5);
    atmos_direction_from_angles(90, 0, sun);
    CHECK_NEAR(atmos__clouds_sun_attenuation(a->planet, g, sun, -1), exp(-tau), 1e-6 * exp(-tau));
    atmos_atmosphere_destroy(a);
    atmos_image_destroy(cloud);
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) exit(2);
    fputs(text, f);
    fclose(f);
}

static void test_scene_keys(void)
{
    char scene[512], map[512], jgw[512];
    test_tmp_path(scene, sizeof scene, "earth.json");
    test_tmp_path(map, sizeof map, "earth_clouds.png");
    test_tmp_path(jgw, sizeof jgw, "earth_clouds.jgw");
    remove(map);
    remove(jgw);
    write_text(scene, "{\"atmosphere\": {\"model\": \"spherical\", \"latitude_deg\": 27, \"longitude_deg\": -117,"
                      " \"clouds\": {\"image\": \"earth_clouds.png\", \"world_file\": \"earth_clouds.jgw\"}}}");
    atmos_scene sc;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(NULL, &ctx));
    /* the image is missing: refused when the scene is read, naming the key */
    CHECK(atmos_scene_load(ctx, scene, &sc) == ATMOS_E_IO);
    CHECK(strstr(atmos_context_error(ctx), "clouds/image") != NULL);
    /* a 10 x 20 image, pixels 0.5 x 0.25 degrees, the top-left one centred at 119.75 W, 29.875 N:
     * it spans 120..115 W and 25..30 N */
    atmos_image *img = make_map(10, 20, 1, grey_cloud);
    CHECK_OK(atmos_write_png(NULL, img, map, 8));
    atmos_image_destroy(img);
    CHECK(atmos_scene_load(ctx, scene, &sc) == ATMOS_E_IO); /* the world file is missing */
    /* one that is there but wrong (a rotation): refused when the atmosphere is made, naming the
     * scene file, the key and the world file */
    write_text(jgw, "0.5\n0.1\n0\n-0.25\n-119.75\n29.875\n");
    CHECK_OK(atmos_scene_load(ctx, scene, &sc));
    atmos_wavelengths wl0;
    atmos_wavelengths_rgb(&wl0);
    atmos_atmosphere *a0 = NULL;
    CHECK(atmos_scene_atmosphere_create(ctx, &sc, &wl0, &a0) == ATMOS_E_FORMAT && a0 == NULL);
    CHECK_MSG(strstr(atmos_context_error(ctx), scene) && strstr(atmos_context_error(ctx), "/atmosphere/clouds/world_file: ") &&
                  strstr(atmos_context_error(ctx), jgw),
              "%s", atmos_context_error(ctx));
    write_text(jgw, "0.5\n0\n0\n-0.25\n-119.75\n29.875\n");
    CHECK_OK(atmos_scene_load(ctx, scene, &sc));
    CHECK(strcmp(sc.earth.cloud_image, map) == 0); /* resolved against the scene's folder */
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_scene_atmosphere_create(ctx, &sc, &wl, &a));
    if (a && a->planet->clouds) {
        const atmos__clouds *cl = a->planet->clouds;
        CHECK_NEAR(cl->lon_w, -120, 1e-12);
        CHECK_NEAR(cl->lon_e, -115, 1e-12);
        CHECK_NEAR(cl->lat_s, 25, 1e-12);
        CHECK_NEAR(cl->lat_n, 30, 1e-12);
        /* clouds over the origin (27 N 117 W), none at 10 degrees of arc west (outside) */
        CHECK(atmos__clouds_column_tau(cl, 27, -117) > 1);
        CHECK(atmos__clouds_column_tau(cl, 27, -127) == 0);
    }
    CHECK(a && a->planet->clouds);
    /* the same clouds as a volume: its vertical column's optical depth over the origin is the
     * cloud spheres' (-ln G of the sunlight from the zenith at the ground) */
    atmos_volume *v = NULL;
    const double centre[2] = {0, 0};
    CHECK_OK(atmos_scene_cloud_volume(ctx, &sc, centre, 5000, 500, &v));
    {   /* too many voxels across: refused with the count and the bound (8192 across: allowed) */
        atmos_volume *big = NULL;
        CHECK(atmos_scene_cloud_volume(ctx, &sc, centre, 5000, 1, &big) == ATMOS_E_INVALID_ARG && !big);
        CHECK(strstr(atmos_context_error(ctx), "gives 10000 voxels across (allowed 1..8192)") != NULL);
    }
    if (v && a) {
        atmos_particle_desc pd;
        CHECK_OK(atmos_particle_preset(NULL, "cloud", &pd));
        const atmos_volume_desc *vd = atmos_volume_get_desc(v);
        CHECK(vd->dims[0] == 20 && vd->dims[2] == 20);
        double col = 0;
        for (int j = 0; j < vd->dims[1]; j++) {
            const double p[3] = {250, vd->origin_m[1] + (j + 0.5) * 500, 250};
            col += atmos_volume_sample(v, 0, p) * pd.sigma_ext_m2 * 500;
        }
        double sun[3], g[3] = {250, 0, 250};
        atmos_direction_from_angles(90, 0, sun);
        const double spheres = -log(atmos__clouds_sun_attenuation(a->planet, g, sun, -1));
        CHECK(spheres > 1);
        CHECK_REL(col, spheres, 1e-3);
        /* outside the layer's heights: nothing */
        const double below[3] = {250, 1000, 250};
        CHECK(atmos_volume_sample(v, 0, below) == 0);
    }
    atmos_volume_destroy(v);
    atmos_atmosphere_destroy(a);
    /* a world file with a rotation is refused */
    write_text(jgw, "0.5\n0.1\n0\n-0.25\n-119.75\n29.875\n");
    a = NULL;
    CHECK(atmos_scene_atmosphere_create(ctx, &sc, &wl, &a) == ATMOS_E_FORMAT && !a);
    atmos_context_destroy(ctx);
}

/* A regional cloud image (10 x 20 degrees, 100 x 200 pixels, uniform grey) fades to no
 * cloud at its edges over 5 % of its shorter side (5 pixels; in reflectance: half way in,
 * half the reflectance, 0.41 of the optical depth for this grey), untouched inside. */
static void test_regional_edges(void)
{
    atmos_image *img = make_map(100, 200, 1, grey_cloud);
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    d.kind = ATMOS_ATMOSPHERE_DOBASHI; /* the planet's cloud spheres alone (make_kind) */
    d.clouds.image = img;
    d.clouds.lon_west_deg = 0, d.clouds.lon_east_deg = 10, d.clouds.lat_south_deg = 0, d.clouds.lat_north_deg = 20;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &d, &wl, &a));
    if (a) {
        const atmos__clouds *cl = a->planet->clouds;
        const double inner = atmos__clouds_column_tau(cl, 10, 5);
        CHECK(inner > 1);
        CHECK_NEAR(atmos__clouds_column_tau(cl, 10, 0.5), inner, 1e-9 * inner);  /* 5 pixels in */
        CHECK(atmos__clouds_column_tau(cl, 10, 0.001) < 0.01 * inner);            /* at the edge */
        const double half = atmos__clouds_column_tau(cl, 10, 0.25);               /* 2.5 pixels in */
        CHECK(half > 0.3 * inner && half < 0.7 * inner);
        CHECK(atmos__clouds_column_tau(cl, 19.999, 5) < 0.01 * inner);
    }
    atmos_atmosphere_destroy(a);
    atmos_image_destroy(img);
}

/* The texture look-ups' latitude and longitude (atmos__planet_latlon_fast) against the exact
 * ones: the arctangent of Abramowitz & Stegun 4.4.49 is within 2e-8 rad (1.15e-6 degrees) of
 * atan over [0, 1], so both angles stay within 1.2e-6 degrees of atmos__planet_latlon's
 * (longitudes compared across the date line), at any radius and origin, the poles included. */
static void test_latlon_fast(void)
{
    const double origins[3][2] = {{30, 100}, {-89.9, -179.9}, {0, 180}};
    double worst = 0.0;
    unsigned s = 12345u;
    for (int o = 0; o < 3; o++) {
        atmos_atmosphere *a = make_planet(origins[o][0], origins[o][1], NULL, NULL, NULL, 0);
        const atmos__planet *pl = a->planet;
        for (int i = 0; i < 20000; i++) {
            double x[3];
            for (int c = 0; c < 3; c++) {
                s = s * 1664525u + 1013904223u;
                x[c] = ((double)s / 4294967296.0 - 0.5) * 2.0e7;
            }
            if (i < 4) x[0] = 0, x[2] = 0, x[1] = i < 2 ? 7e6 : -7e6 - 2 * pl->r_ground; /* above the poles */
            double lat, lon, flat, flon;
            atmos__planet_latlon(pl, x, &lat, &lon);
            atmos__planet_latlon_fast(pl, x, &flat, &flon);
            double dl = fabs(flon - lon);
            dl = fmin(dl, 360.0 - dl);
            if (fabs(lat) > 90.0 - 1e-6) dl = 0; /* the pole's longitude is any */
            worst = fmax(worst, fmax(fabs(flat - lat), dl));
        }
        atmos_atmosphere_destroy(a);
    }
    CHECK(worst <= 1.2e-6);
}

int main(void)
{
    test_regional_edges();
    test_scene_keys();
    test_map_lookup();
    atmos_image *night = make_map(36, 18, 1, white);
    atmos_atmosphere *clear = make(10, 20, NULL, night, NULL, 0);
    test_night_lights(clear);
    test_brightness_mapping();
    test_cloud_attenuation(clear, night);
    atmos_atmosphere_destroy(clear);
    atmos_image_destroy(night);
    test_latlon_fast();
    return test_summary("test_earth");
}
