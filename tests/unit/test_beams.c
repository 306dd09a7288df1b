/* The beam renderer (Dobashi et al. 2002 §4) against closed forms:
 *   - the airlight of an isotropic point light in a homogeneous medium without shadows, the
 *     single-scattering integral in Sun, Ramamoorthi, Narasimhan and Nayar 2005 (Eq. 7-8):
 *       L = sigma_s I exp(-sigma d cos g) / (2 pi d sin g) [F(A1, xi_b) - F(A1, g / 2)],
 *       A1 = sigma d sin g, F(a, xi) = int_0^xi exp(-a tan z) dz,
 *     d the light's distance from the eye, g the angle between the ray and the light,
 *     xi_b = pi/4 + atan((t_end - d cos g) / (d sin g)) / 2; F by Simpson's rule here;
 *   - a shadow: a ray passing below a sphere lit from above loses exactly the light of the
 *     segment inside the sphere's shadow cone (its ends solved from the cone's quadric); also
 *     with coarse epsilon and fine planes, where a point light's small intervals share samples;
 *   - the sub-planes' samples summed through the shadow map's tiles (runs proven lit or dark
 *     not read) against each sample read alone, for a point light's cube map and a spot;
 *   - the pixels a spot's beam is left out of (its cone's hull on the screen): every pixel
 *     whose ray crosses the lit cone within the light's reach (found by marching the ray) is
 *     lit, for spots seen from the side, end on and from behind;
 *   - the same image with one thread and with two, byte for byte;
 *   - the units of a light's spectrum (its intensity is the integral over 380-780 nm).
 */
#include "atmos/atmos.h"
#include "render/beams_internal.h"
#include "test.h"

static atmos_context *ctx;

/* F(a, xi) by composite Simpson's rule (n even intervals). */
static double sun_F(double a, double xi)
{
    const int n = 20000;
    const double h = xi / n;
    double s = 0;
    for (int i = 0; i <= n; i++) {
        const double z = i * h, tz = tan(z);
        const double f = z >= 0.5 * ATMOS_PI - 1e-12 ? 0 : exp(-a * tz);
        s += f * (i == 0 || i == n ? 1 : i % 2 ? 4 : 2);
    }
    return s * h / 3;
}

/* Sun et al. 2005's airlight along [ta, tb] of the ray o + t dir (unit) from a light of
 * intensity I at lp, per unit of I. */
static double airlight(const double o[3], const double dir[3], const double lp[3], double sig_t, double sig_s,
                       double ta, double tb)
{
    const double Lp[3] = {lp[0] - o[0], lp[1] - o[1], lp[2] - o[2]};
    const double tq = Lp[0] * dir[0] + Lp[1] * dir[1] + Lp[2] * dir[2];
    const double dd = sqrt(Lp[0] * Lp[0] + Lp[1] * Lp[1] + Lp[2] * Lp[2]);
    const double v = sqrt(fmax(0, dd * dd - tq * tq));
    const double xa = 0.25 * ATMOS_PI + 0.5 * atan((ta - tq) / v);
    const double xb = isinf(tb) ? 0.5 * ATMOS_PI : 0.25 * ATMOS_PI + 0.5 * atan((tb - tq) / v);
    return sig_s * exp(-sig_t * tq) / (2 * ATMOS_PI * v) * (sun_F(sig_t * v, xb) - sun_F(sig_t * v, xa));
}

static void base_scene(atmos_scene *s, int w, int h)
{
    atmos_scene_defaults(s);
    s->renderer = ATMOS_RENDERER_BEAMS;
    s->width = w, s->height = h;
    s->atmosphere.kind = ATMOS_ATMOSPHERE_VACUUM;
    s->atmosphere.background_radiance = 0;
    s->fog.enabled = 1;
    s->fog.extinction_per_m = 0.05, s->fog.scattering_per_m = 0.04, s->fog.g = 0;
    s->beams.screen_step = 1; /* the airlight of every pixel (test_screen_step: the lattice) */
    s->light_count = 1;
    atmos_scene_light *l = &s->lights[0];
    memset(l, 0, sizeof *l);
    l->type = ATMOS_LIGHT_POINT;
    l->intensity_w_sr = 400, l->colour[0] = l->colour[1] = l->colour[2] = 1; /* 1 W sr^-1 nm^-1 */
    l->range_m = 2000;
    l->direction[1] = -1;
}

static atmos_image *render(atmos_context *c, const atmos_scene *s)
{
    atmos_image *img = NULL;
    const atmos_status st = atmos_render_scene(c, s, NULL, &img, NULL);
    CHECK_MSG(st == ATMOS_OK, "render: %s", atmos_context_error(c));
    return img;
}

static void test_airlight(void)
{
    atmos_scene s;
    base_scene(&s, 40, 30);
    const double eye[3] = {0, 2, 0}, lp[3] = {3, 4, -20};
    memcpy(s.camera.position, eye, sizeof eye);
    s.camera.look_at[0] = 1, s.camera.look_at[1] = 2.5, s.camera.look_at[2] = -10;
    s.camera.fov_deg = 50;
    memcpy(s.lights[0].position_m, lp, sizeof lp);
    atmos_image *img = render(ctx, &s);
    if (!img) return;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam));
    double worst = 0, lo = INFINITY, hi = 0;
    for (int y = 0; y < s.height; y++)
        for (int x = 0; x < s.width; x++) {
            double d[3];
            atmos_camera_ray(&cam, x + 0.5, y + 0.5, d);
            const double want = airlight(eye, d, lp, 0.05, 0.04, 0, INFINITY); /* x 1 W sr^-1 nm^-1 */
            for (int k = 0; k < 3; k++) {
                const double got = img->pixels[((size_t)y * s.width + x) * img->channels + k];
                worst = fmax(worst, fabs(got / want - 1));
            }
            lo = fmin(lo, want), hi = fmax(hi, want);
        }
    printf("airlight: %dx%d pixels from %.4g to %.4g W m^-2 sr^-1 nm^-1, worst relative error %.2e\n", s.width,
           s.height, lo, hi, worst);
    CHECK_MSG(worst <= 1e-4, "the airlight is off Sun et al.'s closed form by %.3g", worst);
    atmos_image_destroy(img);
}

/* The ends of the part of the ray o + t d (t > 0) inside the shadow cone of a sphere (centre
 * c, radius r) lit from lp, beyond the sphere: |(P - lp) x a| <= sin(al) |P - lp|, a toward c. */
static int shadow_span(const double o[3], const double d[3], const double lp[3], const double c[3], double r,
                       double *ta, double *tb)
{
    double a[3], w[3];
    const double dc = sqrt((c[0] - lp[0]) * (c[0] - lp[0]) + (c[1] - lp[1]) * (c[1] - lp[1]) + (c[2] - lp[2]) * (c[2] - lp[2]));
    for (int k = 0; k < 3; k++) a[k] = (c[k] - lp[k]) / dc, w[k] = o[k] - lp[k];
    const double cos2 = 1 - (r / dc) * (r / dc);
    /* ((w + t d).a)^2 - cos2 |w + t d|^2 = 0 */
    const double wa = w[0] * a[0] + w[1] * a[1] + w[2] * a[2], da = d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
    const double ww = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], wd = w[0] * d[0] + w[1] * d[1] + w[2] * d[2];
    const double A = da * da - cos2, B = 2 * (wa * da - cos2 * wd), C = wa * wa - cos2 * ww;
    const double disc = B * B - 4 * A * C;
    if (disc <= 0) return 0;
    double t1 = (-B - sqrt(disc)) / (2 * A), t2 = (-B + sqrt(disc)) / (2 * A);
    if (t1 > t2) {
        const double t = t1;
        t1 = t2, t2 = t;
    }
    *ta = t1, *tb = t2;
    return t2 > 0;
}

/* The light reaching the ray o + t d over [t0, t1] past the mesh itself (not the sphere it
 * approximates): the lit and shadowed spans found by casting rays toward the light (2000
 * steps, each change of visibility refined by bisection to 1e-12 m), the lit spans
 * integrated by Sun et al.'s closed form. */
static int lit(const atmos_mesh *m, const double o[3], const double d[3], const double lp[3], double t)
{
    const double p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
    double w[3] = {lp[0] - p[0], lp[1] - p[1], lp[2] - p[2]};
    const double r = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (int k = 0; k < 3; k++) w[k] /= r;
    return !atmos_mesh_intersect(m, p, w, 0, r, NULL);
}

static double airlight_past_mesh(const atmos_mesh *m, const double o[3], const double d[3], const double lp[3], double t0,
                                 double t1)
{
    const int n = 2000;
    double sum = 0, a = t0;
    int state = lit(m, o, d, lp, t0);
    for (int i = 1; i <= n; i++) {
        double b = t0 + (t1 - t0) * i / n;
        const int sb = lit(m, o, d, lp, b);
        if (sb != state || i == n) {
            double lo = t0 + (t1 - t0) * (i - 1) / n, hi = b;
            while (sb != state && hi - lo > 1e-12)
                if (lit(m, o, d, lp, 0.5 * (lo + hi)) == state) lo = 0.5 * (lo + hi);
                else hi = 0.5 * (lo + hi);
            const double e = sb != state ? 0.5 * (lo + hi) : t1;
            if (state) sum += airlight(o, d, lp, 0.05, 0.04, a, e);
            a = e, state = sb;
        }
    }
    return sum;
}

/* The point light over the sphere, at epsilon eps with planes spacing apart: every pixel of a
 * row within tol of the airlight past the mesh's own shadow. */
static void shadow_case(double eps, double spacing, double tol)
{
    atmos_scene s;
    base_scene(&s, 41, 3);
    const double eye[3] = {-15, 2, 0.4}, lp[3] = {0, 10, 0}, c[3] = {0, 5, 0};
    memcpy(s.camera.position, eye, sizeof eye);
    s.camera.look_at[0] = 0, s.camera.look_at[1] = 2, s.camera.look_at[2] = 0.4;
    s.camera.fov_deg = 1.4; /* about 19 degrees across */
    memcpy(s.lights[0].position_m, lp, sizeof lp);
    s.lights[0].range_m = 40;
    s.object_count = 1;
    atmos_scene_object *o = &s.objects[0];
    memset(o, 0, sizeof *o);
    snprintf(o->mesh, sizeof o->mesh, "builtin:sphere");
    memcpy(o->position_m, c, sizeof c);
    o->scale[0] = o->scale[1] = o->scale[2] = 1;
    s.beams.shadow_size = 1024, s.beams.epsilon = eps, s.beams.max_subplanes = 512, s.beams.plane_spacing_m = spacing;
    atmos_image *img = render(ctx, &s);
    if (!img) return;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam));
    double worst = 0, worst_part = 0, worst_mesh = 0, max_part = 0;
    int shadowed = 0;
    atmos_mesh *mesh = NULL;
    atmos_mesh_transform tr;
    atmos_mesh_transform_identity(&tr);
    memcpy(tr.position_m, c, sizeof c);
    CHECK_OK(atmos_mesh_load(ctx, "builtin:sphere", 0, &mesh));
    if (mesh) CHECK_OK(atmos_mesh_apply_transform(ctx, mesh, &tr));
    const double R = 40; /* the light's range: the renderer samples the air within it */
    for (int x = 0; x < s.width; x++) {
        double d[3], ta, tb;
        atmos_camera_ray(&cam, x + 0.5, 1.5, d);
        const double Lp[3] = {lp[0] - eye[0], lp[1] - eye[1], lp[2] - eye[2]};
        const double tq = Lp[0] * d[0] + Lp[1] * d[1] + Lp[2] * d[2];
        const double v2 = Lp[0] * Lp[0] + Lp[1] * Lp[1] + Lp[2] * Lp[2] - tq * tq, hh = sqrt(R * R - v2);
        const double t0 = fmax(0, tq - hh), t1 = tq + hh;
        double want = airlight(eye, d, lp, 0.05, 0.04, t0, t1), part = 0;
        if (shadow_span(eye, d, lp, c, 1.0, &ta, &tb)) {
            part = airlight(eye, d, lp, 0.05, 0.04, fmax(ta, t0), fmin(tb, t1));
            want -= part;
            shadowed++;
        }
        const double got = img->pixels[((size_t)1 * s.width + x) * img->channels + 1];
        const double exact = mesh ? airlight_past_mesh(mesh, eye, d, lp, t0, t1) : want;
        worst = fmax(worst, fabs(got / want - 1));
        worst_mesh = fmax(worst_mesh, fabs(got / exact - 1));
        max_part = fmax(max_part, part);
        if (part > 0) worst_part = fmax(worst_part, fabs(got - want));
        if (getenv("BEAMS_VERBOSE"))
            printf("x %d part %.4g want %.6g mesh %.6g got %.6g rel %.2e %.2e\n", x, part, want, exact, got, got / want - 1,
                   got / exact - 1);
    }
    worst_part /= max_part;
    printf("shadow (epsilon %g, planes %g m): %d of %d rays through the sphere's shadow; worst relative error against "
           "the mesh's own shadow %.2e; against the sphere's %.2e of the pixel, %.2e of the most light a ray loses\n",
           eps, spacing, shadowed, s.width, worst_mesh, worst, worst_part);
    CHECK(shadowed > s.width / 3);
    /* against the mesh's own shadow, what is left is the shadow map's and the sub-planes'
     * sampling and Eq. 6's product: within 1e-3 (epsilon) where the ray crosses the shadow,
     * 3.5e-3 where it grazes the shadow cone (a 1024 map per cube face, 2 mrad texels; 2048
     * gives 5.7e-4); the sphere's shadow differs besides by the tessellation (the polyhedron
     * is inside the unit sphere by up to 2.4e-3, more at grazing rays) */
    CHECK_MSG(worst_mesh <= tol, "pixels are off the mesh's shadow by %.3g (epsilon %g)", worst_mesh, eps);
    CHECK_MSG(worst_part <= 0.03, "the shadowed light is off the sphere's by %.3g of the most a ray loses", worst_part);
    atmos_mesh_destroy(mesh);
    atmos_image_destroy(img);
}

static void test_shadow(void)
{
    shadow_case(1e-3, 0.25, 5e-3);
    /* planes 5 cm apart, epsilon 0.02: most intervals hold less than a quarter of epsilon of the
     * pixel's airlight, and neighbours of them share one sample (beams_render.c, merged()),
     * which carries at most a quarter of epsilon: the sampling's error stays within epsilon */
    shadow_case(0.02, 0.05, 0.02);
}

/* A spotlight over a sphere and a floor, rendered with 1 and with 2 threads. */
/* A spotlight over a sphere and a floor in fog (Fig. 4 in small). */
static void spot_scene(atmos_scene *sp, int w, int h)
{
    atmos_scene s;
    base_scene(&s, w, h);
    s.camera.position[0] = 0, s.camera.position[1] = 6, s.camera.position[2] = 25;
    s.camera.look_at[0] = 0, s.camera.look_at[1] = 5, s.camera.look_at[2] = 0;
    s.lights[0].type = ATMOS_LIGHT_SPOT;
    s.lights[0].position_m[1] = 20;
    s.lights[0].cone_deg = 15, s.lights[0].edge_deg = 5;
    s.lights[0].range_m = 40;
    s.object_count = 2;
    for (int i = 0; i < 2; i++) {
        memset(&s.objects[i], 0, sizeof s.objects[i]);
        s.objects[i].scale[0] = s.objects[i].scale[1] = s.objects[i].scale[2] = i ? 30 : 2;
        s.objects[i].albedo[0] = s.objects[i].albedo[1] = s.objects[i].albedo[2] = 0.6;
    }
    snprintf(s.objects[0].mesh, sizeof s.objects[0].mesh, "builtin:sphere");
    s.objects[0].position_m[1] = 5;
    snprintf(s.objects[1].mesh, sizeof s.objects[1].mesh, "builtin:plane");
    s.beams.shadow_size = 256;
    *sp = s;
}

static void test_threads(void)
{
    atmos_scene s;
    spot_scene(&s, 48, 36);
    atmos_image *img[2] = {NULL, NULL};
    for (int t = 0; t < 2; t++) {
        atmos_context_desc d;
        memset(&d, 0, sizeof d);
        d.threads = t + 1;
        atmos_context *c = NULL;
        CHECK_OK(atmos_context_create(&d, &c));
        img[t] = render(c, &s);
        atmos_context_destroy(c);
    }
    if (img[0] && img[1]) {
        const size_t n = (size_t)s.width * s.height * img[0]->channels;
        CHECK_MSG(!memcmp(img[0]->pixels, img[1]->pixels, n * sizeof(float)), "1 and 2 threads differ");
        /* and the picture has what Fig. 4 has: a lit floor, a shadow below the sphere, a beam */
        const float *p = img[0]->pixels;
        double sum = 0;
        for (size_t i = 0; i < n; i++) sum += i % img[0]->channels < 3 ? p[i] : 0;
        printf("threads: colour sum %g\n", sum);
        CHECK(sum > 0);
    }
    atmos_image_destroy(img[0]);
    atmos_image_destroy(img[1]);
}

/* The Fig. 4 scene file, smaller: the picture has what the figure has. And objects from OBJ
 * files named relative to the scene's folder: a good one renders, a broken one is an error
 * naming the file. */
static void test_scene_files(void)
{
    const char *src = getenv("ATMOS_SOURCE_DIR");
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/dobashi_fig04_spotlight.json", src && *src ? src : ".");
    atmos_scene s;
    CHECK_OK(atmos_scene_load(ctx, path, &s));
    s.width = 60, s.height = 90;
    atmos_image *img = render(ctx, &s);
    if (img) {
        atmos_camera cam;
        CHECK_OK(atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam));
        /* the pixels looking at the sphere's lit top, through its shadow below, at the lit floor */
        const double top[3] = {0, 9.4, 0}, under[3] = {0, 4, 0}, floor_lit[3] = {5.5, 0, 0}, floor_dark[3] = {0, 0, 0};
        const double *pts[4] = {top, under, floor_lit, floor_dark};
        double val[4];
        for (int i = 0; i < 4; i++) {
            double d[3], best = -1;
            int bx = 0, by = 0;
            for (int y = 0; y < s.height; y++)
                for (int x = 0; x < s.width; x++) { /* the pixel whose ray passes nearest the point */
                    atmos_camera_ray(&cam, x + 0.5, y + 0.5, d);
                    double w[3], t = 0;
                    for (int k = 0; k < 3; k++) w[k] = pts[i][k] - s.camera.position[k], t += w[k] * d[k];
                    double e = 0;
                    for (int k = 0; k < 3; k++) e += (w[k] - t * d[k]) * (w[k] - t * d[k]);
                    if (best < 0 || e < best) best = e, bx = x, by = y;
                }
            val[i] = img->pixels[((size_t)by * s.width + bx) * img->channels + 1];
        }
        printf("fig04: sphere top %.4g, the air below it %.4g, lit floor %.4g, its shadow %.4g\n", val[0], val[1], val[2],
               val[3]);
        CHECK(val[0] > 2 * val[1] && val[2] > 3 * val[3] && val[1] > 0);
        atmos_image_destroy(img);
    }
    char obj[1024], scene[1024];
    test_tmp_path(obj, sizeof obj, "tri.obj");
    FILE *f = fopen(obj, "wb");
    if (f) fputs("v -1 0 -1\nv 1 0 -1\nv 0 0 1\nf 1 3 2\n", f), fclose(f);
    const char *text = "{\"renderer\": \"beams\", \"image\": {\"width\": 16, \"height\": 12}, \"background\": \"black\","
                       " \"camera\": {\"position_m\": [0, 3, 6], \"look_at_m\": [0, 0, 0]},"
                       " \"fog\": {\"extinction_per_m\": 0.1}, \"lights\": [{\"position_m\": [0, 4, 0]}],"
                       " \"objects\": [{\"mesh\": \"%s\", \"scale\": 2}]}";
    for (int broken = 0; broken < 2; broken++) {
        test_tmp_path(scene, sizeof scene, broken ? "broken_scene.json" : "obj_scene.json");
        f = fopen(scene, "wb");
        if (f) fprintf(f, text, broken ? "nothing_here.obj" : "tri.obj"), fclose(f);
        CHECK_OK(atmos_scene_load(ctx, scene, &s));
        atmos_image *im = NULL;
        const atmos_status st = atmos_render_scene(ctx, &s, NULL, &im, NULL);
        if (broken)
            CHECK_MSG(st == ATMOS_E_IO && strstr(atmos_context_error(ctx), "nothing_here.obj"), "broken OBJ: %s",
                      atmos_context_error(ctx));
        else
            CHECK_MSG(st == ATMOS_OK && im && im->pixels[((size_t)6 * 16 + 8) * im->channels + 1] > 0, "OBJ scene: %s",
                      atmos_context_error(ctx));
        atmos_image_destroy(im);
    }
}

/* Valid scenes at the ends of the ranges render, with finite pixels (the plan refuses a NaN or
 * an infinity), and nothing negative. */
static void test_extremes(void)
{
    for (int c = 0; c < 8; c++) {
        atmos_scene s;
        base_scene(&s, 16, 12);
        s.camera.position[0] = 0, s.camera.position[1] = 2, s.camera.position[2] = 10;
        s.camera.look_at[1] = 2;
        atmos_scene_light *l = &s.lights[0];
        l->position_m[1] = 4;
        s.object_count = 1;
        atmos_scene_object *o = &s.objects[0];
        memset(o, 0, sizeof *o);
        snprintf(o->mesh, sizeof o->mesh, "builtin:sphere");
        o->position_m[1] = 2, o->scale[0] = o->scale[1] = o->scale[2] = 1, o->albedo[0] = o->albedo[1] = o->albedo[2] = 1;
        switch (c) {
        case 0: l->type = ATMOS_LIGHT_SPOT, l->cone_deg = 0, l->edge_deg = 0; break; /* a beam of no width */
        case 1: l->type = ATMOS_LIGHT_SPOT, l->cone_deg = 89, l->edge_deg = 1; break; /* a half space: cube map */
        case 2: memcpy(l->position_m, s.camera.position, sizeof l->position_m); break; /* at the eye */
        case 3: l->position_m[1] = 2; break;                                           /* inside the sphere */
        case 4: s.fog.extinction_per_m = s.fog.scattering_per_m = 10, l->range_m = 1e6; break;
        case 5: s.fog.extinction_per_m = s.fog.scattering_per_m = 1e-9, l->range_m = 1e6; break;
        case 6: s.fog.g = 0.999, l->intensity_w_sr = 1e9; break;
        case 7: s.fog.enabled = 0; break; /* no fog: the lit sphere alone */
        }
        atmos_image *img = NULL;
        const atmos_status st = atmos_render_scene(ctx, &s, NULL, &img, NULL);
        CHECK_MSG(st == ATMOS_OK, "extreme case %d: %s", c, atmos_context_error(ctx));
        int negative = 0;
        for (size_t i = 0; img && i < (size_t)s.width * s.height * img->channels; i++) negative += img->pixels[i] < 0;
        CHECK_MSG(negative == 0, "extreme case %d: %d negative values", c, negative);
        atmos_image_destroy(img);
    }
}

/* A progress callback that asks to stop once the beams are being drawn. */
static int stop_beams(void *user, const char *stage, double fraction)
{
    (void)fraction;
    if (strcmp(stage, "render beams")) return 0;
    ++*(int *)user;
    return 1;
}

static void test_cancel(void)
{
    atmos_scene s;
    base_scene(&s, 32, 24);
    s.lights[0].position_m[2] = -20;
    atmos_context_desc d;
    memset(&d, 0, sizeof d);
    int calls = 0;
    d.progress = stop_beams, d.progress_user = &calls;
    d.threads = 1; /* progress comes from the calling thread: with one, from the first row on */
    atmos_context *c = NULL;
    CHECK_OK(atmos_context_create(&d, &c));
    atmos_image *img = NULL;
    const atmos_status st = atmos_render_scene(c, &s, NULL, &img, NULL);
    CHECK_MSG(st == ATMOS_E_CANCELLED && calls >= 1 && !img, "%s, %d calls: %s", atmos_status_string(st), calls, atmos_context_error(c));
    atmos_image_destroy(img);
    atmos_context_destroy(c);
}

/* The plan's shadow maps report progress ("beams shadow maps", rising to 1 before the frame's
 * "render beams") and can be cancelled there: a large scene spends seconds in them. */
typedef struct {
    int calls, rendering_after, stop;
    double last;
} plan_progress;

static int watch_maps(void *user, const char *stage, double fraction)
{
    plan_progress *w = user;
    if (!strcmp(stage, "render beams")) w->rendering_after += w->calls > 0;
    if (strcmp(stage, "beams shadow maps")) return 0;
    CHECK_MSG(fraction >= w->last && fraction <= 1, "shadow map progress %g after %g", fraction, w->last);
    w->last = fraction, w->calls++;
    return w->stop;
}

static void test_plan_progress(void)
{
    atmos_scene s;
    base_scene(&s, 16, 12);
    s.camera.position[0] = 0, s.camera.position[1] = 6, s.camera.position[2] = 25;
    s.light_count = 2; /* a point light (six cube faces) and a narrow spot (one map) */
    s.lights[1] = s.lights[0];
    s.lights[1].type = ATMOS_LIGHT_SPOT, s.lights[1].position_m[1] = 20, s.lights[1].cone_deg = 5;
    s.lights[0].position_m[0] = 8, s.lights[0].position_m[1] = 4;
    s.object_count = 1;
    memset(&s.objects[0], 0, sizeof s.objects[0]);
    snprintf(s.objects[0].mesh, sizeof s.objects[0].mesh, "builtin:sphere");
    s.objects[0].scale[0] = s.objects[0].scale[1] = s.objects[0].scale[2] = 2;
    s.objects[0].albedo[0] = s.objects[0].albedo[1] = s.objects[0].albedo[2] = 0.6;
    s.beams.shadow_size = 64;
    for (int stop = 0; stop < 2; stop++) {
        plan_progress w = {0, 0, stop, 0};
        atmos_context_desc d;
        memset(&d, 0, sizeof d);
        d.progress = watch_maps, d.progress_user = &w;
        atmos_context *c = NULL;
        CHECK_OK(atmos_context_create(&d, &c));
        atmos_image *img = NULL;
        const atmos_status st = atmos_render_scene(c, &s, NULL, &img, NULL);
        if (!stop)
            CHECK_MSG(st == ATMOS_OK && w.calls >= 2 && w.last == 1 && w.rendering_after > 0,
                      "%s: %d shadow map reports, the last %g, %d render reports after", atmos_context_error(c), w.calls,
                      w.last, w.rendering_after);
        else
            CHECK_MSG(st == ATMOS_E_CANCELLED && !img && w.rendering_after == 0, "cancelled in the shadow maps: %s (%s)",
                      atmos_status_string(st), atmos_context_error(c));
        atmos_image_destroy(img);
        atmos_context_destroy(c);
    }
}

static void test_spectrum(void)
{
    atmos_scene_light l;
    memset(&l, 0, sizeof l);
    l.intensity_w_sr = 250, l.colour_temperature_k = 3200;
    atmos_wavelengths wl;
    CHECK_OK(atmos_wavelengths_spectral(40, &wl));
    double sum = 0;
    for (int k = 0; k < wl.count; k++) sum += atmos__lamp_spectrum(&l, &wl, k) * wl.width_nm[k];
    CHECK_REL(sum, 250, 2e-3);
}

/* Mean relative difference of a's first three channels from the reference r's, over the
 * samples above 1e-3 of r's brightest. */
static double mean_rel(const atmos_image *a, const atmos_image *r)
{
    const size_t n = (size_t)r->width * r->height;
    double top = 0, sum = 0;
    long count = 0;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) top = fmax(top, r->pixels[i * r->channels + k]);
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            const double y = r->pixels[i * r->channels + k], x = a->pixels[i * a->channels + k];
            if (y > 1e-3 * top) sum += fabs(x - y) / y, count++;
        }
    return count ? sum / count : INFINITY;
}

/* Interleaved sampling (Keller and Heidrich 2001) instead of sub-planes: closer to the
 * converged image than the planes alone at the same count of samples, at a size where the
 * filter's blur costs less than it gains (docs/beams.md); a frame rendered in two
 * regions equals the whole one (the filter reads past a region's edge); 1 and 2 threads alike. */
static void test_interleave(void)
{
    atmos_scene s;
    spot_scene(&s, 256, 192);
    s.beams.plane_spacing_m = 2.0;
    atmos_scene ref = s;
    ref.beams.epsilon = 5e-4, ref.beams.max_subplanes = 2048, ref.beams.plane_spacing_m = 0.25;
    ref.beams.shadow_size = 1024;
    s.beams.max_subplanes = 1;
    atmos_scene il = s;
    il.beams.interleave = 2;
    atmos_image *r = render(ctx, &ref), *plain = render(ctx, &s), *inter = render(ctx, &il);
    if (!r || !plain || !inter) return;
    const double e_plain = mean_rel(plain, r), e_inter = mean_rel(inter, r);
    printf("interleave: planes alone %.4f, 2x2 interleaved %.4f (mean relative difference)\n", e_plain, e_inter);
    CHECK_MSG(e_inter < 0.75 * e_plain, "interleaved %g not below 3/4 of planes alone %g", e_inter, e_plain);
    /* two regions, and two threads */
    atmos_plan *plan = NULL;
    atmos_frame f;
    atmos_image *half = NULL;
    CHECK_OK(atmos_plan_create(ctx, &il, NULL, NULL, &plan));
    CHECK_OK(atmos_frame_from_scene(ctx, &il, &f));
    CHECK_OK(atmos_plan_image_create(plan, &f, &half));
    const atmos_region top = {0, 0, il.width, 77}, bottom = {0, 77, il.width, il.height};
    CHECK_OK(atmos_plan_render(plan, &f, &top, half, NULL));
    CHECK_OK(atmos_plan_render(plan, &f, &bottom, half, NULL));
    const size_t bytes = sizeof(float) * (size_t)il.width * il.height * inter->channels;
    CHECK_MSG(!memcmp(half->pixels, inter->pixels, bytes), "two regions differ from the whole frame");
    atmos_context_desc d;
    memset(&d, 0, sizeof d);
    d.threads = 1;
    atmos_context *c1 = NULL;
    CHECK_OK(atmos_context_create(&d, &c1));
    atmos_image *one = render(c1, &il);
    if (one) CHECK_MSG(!memcmp(one->pixels, inter->pixels, bytes), "1 and 2 threads differ (interleaved)");
    atmos_image_destroy(one);
    atmos_context_destroy(c1);
    atmos_image_destroy(half);
    atmos_plan_destroy(plan);
    atmos_image_destroy(r);
    atmos_image_destroy(plain);
    atmos_image_destroy(inter);
}

/* The built-in unit sphere moved to (x, y, 0); NULL (a failed check) if it cannot be made. */
static atmos_mesh *sphere_at(double x, double y)
{
    atmos_mesh *mesh = NULL;
    atmos_mesh_transform tr;
    atmos_mesh_transform_identity(&tr);
    tr.position_m[0] = x, tr.position_m[1] = y;
    CHECK_OK(atmos_mesh_load(ctx, "builtin:sphere", 0, &mesh));
    if (mesh) CHECK_OK(atmos_mesh_apply_transform(ctx, mesh, &tr));
    return mesh;
}

/* atmos__beams_ray_light_sum against atmos__beams_ray_light at every sample, on rays across a
 * sphere's shadow, for a point light (a cube map) and a spot (one face); and
 * atmos__beams_ray_light_sum_split (halved without its own test) on parts of the rays, the same
 * as the tested sum to the bit for the point light. */
static void test_light_sum(void)
{
    atmos_mesh *mesh = sphere_at(0, 5);
    if (!mesh) return;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_scene s;
    base_scene(&s, 8, 8);
    for (int kind = 0; kind < 2; kind++) {
        atmos_scene_light sl = s.lights[0];
        sl.position_m[1] = 10;
        if (kind) sl.type = ATMOS_LIGHT_SPOT, sl.cone_deg = 30, sl.edge_deg = 5;
        atmos__beams_light l;
        memset(&l, 0, sizeof l);
        atmos__lamp_make(&sl, &wl, &l.L);
        atmos__beams_progress pr = {0, 6, 0};
        CHECK_OK(atmos__beams_shadow_build(ctx, &l, &mesh, 1, 256, &pr));
        double worst = 0, dark = 0;
        int split_differs = 0;
        for (int r = 0; r < 60; r++) {
            const double o[3] = {-12, 0.5 + 0.1 * r, 0.3 - 0.01 * r};
            double d[3] = {1, 0.02 * (r % 5) - 0.04, 0.05};
            const double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int a = 0; a < 3; a++) d[a] /= n;
            atmos__beams_ray ray;
            atmos__beams_ray_init(&l, o, d, &ray);
            const int m = 400;
            const double step = 24.0 / m;
            double want = 0, all = 0;
            for (int k = 0; k < m; k++)
                want += atmos__beams_ray_light(&ray, (k + 0.5) * step), all += atmos__beams_ray_falloff(&ray, (k + 0.5) * step);
            const double got = atmos__beams_ray_light_sum(&ray, 0, step, 0.5, 0, m);
            worst = fmax(worst, fabs(got - want) / fmax(all, 1));
            for (int c = 0; c < 4; c++) { /* halved at once, as after a failed test of the whole span */
                const int s0 = c * 37, s1 = m - c * 91;
                double part = 0;
                for (int k = s0; k < s1; k++) part += atmos__beams_ray_light(&ray, (k + 0.5) * step);
                const double split = atmos__beams_ray_light_sum_split(&ray, 0, step, 0.5, s0, s1);
                worst = fmax(worst, fabs(split - part) / fmax(all, 1));
                if (!kind) split_differs += split != atmos__beams_ray_light_sum(&ray, 0, step, 0.5, s0, s1);
            }
            dark += want < all - 1;
        }
        printf("sub-plane samples through the tiles (%s): worst difference %.2e of the unshadowed samples, "
               "%g of 60 rays through the shadow\n", kind ? "spot" : "point light, cube map", worst, dark);
        CHECK(dark >= 10);
        CHECK(worst < 1e-12);
        CHECK_MSG(split_differs == 0, "the point light's sums halved at once differ from the tested ones %d times", split_differs);
        atmos__beams_shadow_free(&l);
    }
    atmos_mesh_destroy(mesh);
}

/* l: the base scene's light made a point light at (x, y, z) with its shadow maps of mesh, size
 * texels a face. */
static void point_light(atmos_mesh **mesh, double x, double y, double z, int size, atmos__beams_light *l)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_scene s;
    base_scene(&s, 8, 8);
    atmos_scene_light sl = s.lights[0];
    sl.type = ATMOS_LIGHT_POINT, sl.position_m[0] = x, sl.position_m[1] = y, sl.position_m[2] = z;
    memset(l, 0, sizeof *l);
    atmos__lamp_make(&sl, &wl, &l->L);
    atmos__beams_progress pr = {0, 6, 0};
    CHECK_OK(atmos__beams_shadow_build(ctx, l, mesh, 1, size, &pr));
}

/* A point light's runs of at most 32 samples (read without the tiles' test, each run's cube face
 * from its first and last sample) against every sample read alone, on rays that cross the edge
 * between two faces of the cube (x + y = 10 here) inside a sphere's shadow, which straddles it:
 * a run across the edge read on one face would be wrong on the other side. */
static void test_runs_across_faces(void)
{
    atmos_mesh *mesh = sphere_at(3.5, 6.5);
    if (!mesh) return;
    atmos__beams_light l;
    point_light(&mesh, 0, 10, 0, 256, &l);
    double worst = 0;
    long runs = 0, shadowed = 0;
    for (int r = 0; r < 25; r++) {
        double d[3] = {0.3, 0.3, 1};
        const double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int a = 0; a < 3; a++) d[a] /= n;
        const double P[3] = {6.36 + 0.12 * (r % 5 - 2), 3.64 + 0.12 * (r / 5 - 2), 0}; /* in the shadow, on the edge */
        const double o[3] = {P[0] - 6 * d[0], P[1] - 6 * d[1], P[2] - 6 * d[2]};
        atmos__beams_ray ray;
        atmos__beams_ray_init(&l, o, d, &ray);
        const int m = 400;
        const double step = 12.0 / m;
        for (int k = 2; k <= 32; k += k < 8 ? 1 : 8)
            for (int s0 = 0; s0 + k <= m; s0 += 3) {
                double want = 0;
                for (int q = s0; q < s0 + k; q++) want += atmos__beams_ray_light(&ray, (q + 0.5) * step);
                const double got = atmos__beams_ray_light_sum(&ray, 0, step, 0.5, s0, s0 + k);
                worst = fmax(worst, fabs(got - want)), runs++, shadowed += want < k - 0.5;
            }
    }
    printf("runs of 2-32 samples across a cube map's edge: %ld runs, %ld in the shadow, worst difference %.2e\n", runs,
           shadowed, worst);
    CHECK(shadowed > 100);
    CHECK_MSG(worst < 1e-12, "a run across the cube's faces differs from its samples by %.3g", worst);
    atmos__beams_shadow_free(&l);
    atmos_mesh_destroy(mesh);
}

/* atmos__beams_tiles_range's level found from the box's larger side against the search from level
 * 0 (the same cells, so the same bounds to the bit), and its bounds holding every texel the box's
 * tiles cover, on maps of 100 and 512 texels with tiles of 2 x 2 and 8 x 8. */
static void test_tiles_range(void)
{
    const int sizes[2] = {100, 512}, shifts[2] = {1, 3};
    long boxes = 0, differ = 0, loose = 0;
    for (int c = 0; c < 4; c++) {
        const int n = sizes[c / 2], sh = shifts[c % 2];
        float *depth = malloc(sizeof(float) * (size_t)n * n);
        if (!depth) continue;
        for (int i = 0; i < n * n; i++) depth[i] = (float)(1 + (i * 7919 % 1009) + (i / n) % 13);
        atmos__beams_tiles t;
        CHECK(atmos__beams_tiles_build(&t, depth, n, sh, 1 + (c / 2 + c) % 2) == 0);
        for (int b = 0; b < 4000 && t.min; b++, boxes++) {
            int x0 = (b * 37) % (n + 1) - 1, x1 = x0 + (b * 13) % (b % 3 ? 9 : n), y0 = (b * 53) % (n + 1) - 1;
            int y1 = y0 + (b * 29) % (b % 5 ? 40 : n);
            x1 = x1 > n - 1 ? n - 1 : x1, y1 = y1 > n - 1 ? n - 1 : y1;
            float lo, hi, rlo = INFINITY, rhi = -INFINITY;
            atmos__beams_tiles_range(&t, x0, x1, y0, y1, &lo, &hi);
            const int tx0 = x0 < 0 ? 0 : x0 >> sh, tx1 = x1 < 0 ? 0 : x1 >> sh, ty0 = y0 < 0 ? 0 : y0 >> sh;
            const int ty1 = y1 < 0 ? 0 : y1 >> sh;
            int k = 0;
            while (k + 1 < t.levels && ((tx1 >> k) - (tx0 >> k) > 1 || (ty1 >> k) - (ty0 >> k) > 1)) k++;
            for (int ty = ty0 >> k; ty <= ty1 >> k; ty++)
                for (int tx = tx0 >> k; tx <= tx1 >> k; tx++) {
                    const size_t i = t.level_at[k] + (size_t)ty * t.level_n[k] + tx;
                    rlo = fminf(rlo, t.min[i]), rhi = fmaxf(rhi, t.max[i]);
                }
            differ += lo != rlo || hi != rhi;
            for (int y = y0 < 0 ? 0 : y0; y <= y1; y++)
                for (int x = x0 < 0 ? 0 : x0; x <= x1; x++) loose += depth[(size_t)y * n + x] < lo || depth[(size_t)y * n + x] > hi;
        }
        atmos__beams_tiles_free(&t);
        free(depth);
    }
    printf("tiles' ranges: %ld boxes, %ld differ from the search from level 0, %ld texels outside\n", boxes, differ, loose);
    CHECK(boxes == 16000);
    CHECK_MSG(differ == 0 && loose == 0, "tiles' ranges: %ld differ, %ld texels outside", differ, loose);
}

/* A point light's ray in its cube map's six faces (atmos__beams_ray_init: the odd faces from the
 * even ones, two signs flipped) against each face's own dot products, to the bit. */
static void test_ray_faces(void)
{
    atmos_mesh *mesh = sphere_at(3.5, 6.5);
    if (!mesh) return;
    atmos__beams_light l;
    point_light(&mesh, 0.3, 10, -0.7, 64, &l);
    CHECK(l.nfaces == 6);
    int differ = 0;
    for (int r = 0; r < 50; r++) {
        double d[3] = {sin(0.7 * r), cos(1.3 * r), 0.2 * r - 5};
        const double nn = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int a = 0; a < 3; a++) d[a] /= nn;
        const double o[3] = {0.37 * r - 9, 1.1 * (r % 7), 4 - 0.3 * r};
        atmos__beams_ray ray;
        atmos__beams_ray_init(&l, o, d, &ray);
        double w0[3];
        for (int a = 0; a < 3; a++) w0[a] = o[a] - l.L.pos[a];
        for (int f = 0; f < l.nfaces; f++) {
            const double *ax[3] = {l.face[f].right, l.face[f].up, l.face[f].fwd};
            for (int a = 0; a < 3; a++)
                differ += ray.f0[f][a] != w0[0] * ax[a][0] + w0[1] * ax[a][1] + w0[2] * ax[a][2] ||
                          ray.f1[f][a] != d[0] * ax[a][0] + d[1] * ax[a][1] + d[2] * ax[a][2];
        }
    }
    printf("a point light's ray in its six faces: %d of 900 coordinates differ\n", differ);
    CHECK_MSG(differ == 0, "a point light's ray in its faces: %d coordinates differ", differ);
    atmos__beams_shadow_free(&l);
    atmos_mesh_destroy(mesh);
}

/* Spots seen from several places: every pixel whose ray meets the cone within its reach is lit. */
static void test_screen_spans(void)
{
    const double eyes[4][3] = {{-30, 15, 5}, {0, 15, 25}, {4, 0.5, 2}, {2, 42, -3}}, look[3] = {0, 12, 0};
    int missed = 0, crossing = 0;
    for (int e = 0; e < 4; e++)
        for (int kind = 0; kind < 2; kind++) {
            atmos_scene s;
            base_scene(&s, 64, 48);
            s.fog.extinction_per_m = 0.01, s.fog.scattering_per_m = 0.01;
            atmos_scene_light *l = &s.lights[0];
            l->type = ATMOS_LIGHT_SPOT, l->cone_deg = kind ? 25 : 6, l->edge_deg = 2, l->range_m = 15;
            l->position_m[0] = 0, l->position_m[1] = 20, l->position_m[2] = 0;
            l->direction[0] = 0.3, l->direction[1] = -1, l->direction[2] = 0.2;
            memcpy(s.camera.position, eyes[e], sizeof eyes[e]);
            memcpy(s.camera.look_at, look, sizeof look);
            s.camera.fov_deg = 50;
            atmos_image *img = render(ctx, &s);
            atmos_camera cam;
            CHECK_OK(atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam));
            if (!img) continue;
            double ax[3] = {0.3, -1, 0.2};
            const double n = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]), co = cos((l->cone_deg + l->edge_deg) * ATMOS_DEG2RAD);
            for (int a = 0; a < 3; a++) ax[a] /= n;
            for (int y = 0; y < s.height; y++)
                for (int x = 0; x < s.width; x++) {
                    double d[3];
                    atmos_camera_ray(&cam, x + 0.5, y + 0.5, d);
                    int inside = 0;
                    for (int k = 0; k < 4000 && !inside; k++) { /* the ray to 60 m, every 1.5 cm */
                        const double t = (k + 0.5) * 0.015;
                        const double w[3] = {eyes[e][0] + t * d[0], eyes[e][1] + t * d[1] - 20, eyes[e][2] + t * d[2]};
                        const double r = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
                        inside = r < 15 && w[0] * ax[0] + w[1] * ax[1] + w[2] * ax[2] > 1.0001 * co * r;
                    }
                    crossing += inside;
                    missed += inside && !(img->pixels[((size_t)y * s.width + x) * img->channels] > 0);
                }
            atmos_image_destroy(img);
        }
    printf("spots' screen spans: %d pixels cross a lit cone, %d of them left dark\n", crossing, missed);
    CHECK(crossing > 1000);
    CHECK(missed == 0);
}

/* A spot 20 m above a 60 m floor (albedo 0.6; cone 20 deg, edge 5 deg, pointing (0.3, -1, 0.2)),
 * in a fog that absorbs sig per metre and scatters nothing, seen from eye toward (3, 0, 2). */
static void spot_floor_scene(atmos_scene *s, int w, int h, const double eye[3], double range, double sig)
{
    base_scene(s, w, h);
    s->fog.extinction_per_m = sig, s->fog.scattering_per_m = 0;
    atmos_scene_light *l = &s->lights[0];
    l->type = ATMOS_LIGHT_SPOT, l->cone_deg = 20, l->edge_deg = 5, l->range_m = range;
    l->position_m[0] = 0, l->position_m[1] = 20, l->position_m[2] = 0;
    l->direction[0] = 0.3, l->direction[1] = -1, l->direction[2] = 0.2;
    s->object_count = 1;
    memset(&s->objects[0], 0, sizeof s->objects[0]);
    s->objects[0].scale[0] = s->objects[0].scale[1] = s->objects[0].scale[2] = 30;
    s->objects[0].albedo[0] = s->objects[0].albedo[1] = s->objects[0].albedo[2] = 0.6;
    snprintf(s->objects[0].mesh, sizeof s->objects[0].mesh, "builtin:plane");
    memcpy(s->camera.position, eye, 3 * sizeof *eye);
    s->camera.look_at[0] = 3, s->camera.look_at[1] = 0, s->camera.look_at[2] = 2;
    s->camera.fov_deg = 70;
}

/* A floor under a spot, seen from several places, no light scattered by the air: every pixel whose
 * floor point lies inside the spot's outer cone is lit, every other is dark — the surfaces' light
 * skipped outside the light's screen span must be zero there, also where the floor lies beyond the
 * light's reach (the spans cover the cone within the reach only; a surface is lit at any distance). */
static void test_surface_spans(void)
{
    const double eyes[3][3] = {{-30, 15, 5}, {0, 25, 28}, {6, 3, -9}}, ranges[2] = {12, 40};
    int lit = 0, dark = 0, wrong = 0;
    for (int e = 0; e < 3; e++)
        for (int k = 0; k < 2; k++) {
            atmos_scene s;
            spot_floor_scene(&s, 64, 48, eyes[e], ranges[k], 0.001);
            atmos_image *img = render(ctx, &s);
            atmos_camera cam;
            CHECK_OK(atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam));
            if (!img) continue;
            double ax[3] = {0.3, -1, 0.2};
            const double n = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]), co = cos(25 * ATMOS_DEG2RAD);
            for (int a = 0; a < 3; a++) ax[a] /= n;
            for (int y = 0; y < s.height; y++)
                for (int x = 0; x < s.width; x++) {
                    double d[3];
                    atmos_camera_ray(&cam, x + 0.5, y + 0.5, d);
                    if (!(d[1] < 0)) continue;
                    const double t = -eyes[e][1] / d[1], w[3] = {eyes[e][0] + t * d[0], -20, eyes[e][2] + t * d[2]};
                    if (fabs(w[0]) > 10 || fabs(w[2]) > 10) continue; /* well inside the floor */
                    const double c = (w[0] * ax[0] + w[1] * ax[1] + w[2] * ax[2]) / sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
                    const float v = img->pixels[((size_t)y * s.width + x) * img->channels];
                    if (c > co + 1e-3) lit++, wrong += !(v > 0);
                    else if (c < co - 1e-3) dark++, wrong += v != 0;
                }
            atmos_image_destroy(img);
        }
    printf("surfaces under a spot: %d floor pixels inside its cone, %d outside, %d wrong\n", lit, dark, wrong);
    CHECK(lit > 1000 && dark > 1000);
    CHECK(wrong == 0);
}

/* A floor under a spot, no airlight (no scattering), every floor pixel against the closed form
 * albedo / pi I f(c) cos / r^2 exp(-sigma r) exp(-sigma t) (f the smoothstep between the cone's
 * cosines), with the airlight subsampled (the surfaces' lights a row at a time) and per pixel:
 * the pixels at the cone's edge, where the falloff is barely above 0, lit as they should be
 * (the renderer skips a light whose cone surely leaves a point out before its falloff); the
 * black vacuum above the horizon 0 with alpha 1 (written without evaluating its rays). */
static void test_surface_closed_form(void)
{
    const double eyes[2][3] = {{-30, 15, 5}, {6, 3, -9}}, lp[3] = {0, 20, 0}, sig = 0.001;
    double worst = 0, ax[3] = {0.3, -1, 0.2};
    int edge = 0, pixels = 0, sky = 0, sky_wrong = 0, renders = 0;
    const double na = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    const double ci = cos(20 * ATMOS_DEG2RAD), co = cos(25 * ATMOS_DEG2RAD);
    for (int a = 0; a < 3; a++) ax[a] /= na;
    for (int e = 0; e < 2; e++)
        for (int step = 1; step <= 4; step += 3) {
            atmos_scene s;
            spot_floor_scene(&s, 160, 120, eyes[e], 40, sig);
            s.beams.screen_step = step;
            atmos_image *img = render(ctx, &s);
            atmos_camera cam;
            CHECK_OK(atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam));
            CHECK(img != NULL);
            if (!img) continue;
            renders++;
            for (int y = 0; y < s.height; y++)
                for (int x = 0; x < s.width; x++) {
                    double d[3];
                    atmos_camera_ray(&cam, x + 0.5, y + 0.5, d);
                    const float *px = img->pixels + ((size_t)y * s.width + x) * img->channels;
                    if (!(d[1] < 0)) { /* the black vacuum above: 0, alpha 1 */
                        sky++, sky_wrong += px[0] != 0 || px[1] != 0 || px[2] != 0 || px[3] != 1;
                        continue;
                    }
                    const double t = -eyes[e][1] / d[1];
                    const double w[3] = {eyes[e][0] + t * d[0] - lp[0], -lp[1], eyes[e][2] + t * d[2] - lp[2]};
                    if (fabs(w[0]) > 10 || fabs(w[2]) > 10) continue; /* well inside the floor */
                    const double r = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
                    const double c = (w[0] * ax[0] + w[1] * ax[1] + w[2] * ax[2]) / r;
                    const double q = c >= ci ? 1 : c <= co ? 0 : (c - co) / (ci - co), f = q * q * (3 - 2 * q);
                    const double want = 0.6 / ATMOS_PI * f * (lp[1] / r) / (r * r) * exp(-sig * (r + t));
                    const double got = px[0];
                    const double err = fabs(got - want) / (want > 0 ? want : 1);
                    pixels++, edge += f > 0 && f < 1e-3;
                    worst = err > worst ? err : worst;
                }
            atmos_image_destroy(img);
        }
    printf("surfaces under a spot, closed form: %d floor pixels (%d at the cone's edge, falloff below 1e-3), "
           "worst relative difference %.2g; %d sky pixels, %d not (0, 0, 0, alpha 1)\n",
           pixels, edge, worst, sky, sky_wrong);
    CHECK(renders == 4 && edge > 20 && sky > 1000);
    CHECK(sky_wrong == 0);
    CHECK(worst < 1e-5);
}

/* The sky behind, no fog or lights: with the airlight subsampled (screen_step 4) the sky too is
 * read from the sky renderer's grid of every 4th pixel, within 0.3 % of its every pixel's value
 * (the grid's tolerance: test_sky_step) and not the same image; screen_step 1: every pixel. */
static void test_sky_on_lattice(void)
{
    atmos_scene s;
    base_scene(&s, 256, 160);
    s.fog.enabled = 0; /* the point light lights nothing: no fog, no objects */
    s.atmosphere.kind = ATMOS_ATMOSPHERE_RILEY;
    s.sun.from_time = 0, s.sun.elevation_deg = 8, s.sun.azimuth_deg = 150; /* low, in view */
    s.camera.position[0] = 0, s.camera.position[1] = 1200, s.camera.position[2] = 0;
    s.camera.look_at[0] = 495, s.camera.look_at[1] = 1270, s.camera.look_at[2] = 857;
    s.camera.fov_deg = 60;
    atmos_image *exact = render(ctx, &s);
    s.beams.screen_step = 4;
    atmos_image *grid = render(ctx, &s);
    if (exact && grid) {
        const size_t n = (size_t)s.width * s.height * exact->channels;
        double worst = 0;
        long differ = 0;
        for (size_t i = 0; i < n; i++) {
            const double a = exact->pixels[i], b = grid->pixels[i];
            worst = fmax(worst, fabs(b - a) / fmax(a, 1e-30));
            differ += a != b;
        }
        printf("the sky behind on the lattice: %ld of %zu samples differ, worst relative difference %.2e\n", differ, n,
               worst);
        CHECK(differ > 0);
        CHECK(worst < 3e-3);
    }
    atmos_image_destroy(exact), atmos_image_destroy(grid);
}

/* The last render_counted's count of the evaluations handed their cell's corners' agreement, and
 * of their rays' stretches taken within a run of agreed ones (no W looked up), and of the stretches
 * a merged sample told lit or dark to the cells around. */
static long last_shared, last_unread, last_told;

/* One frame of s by a plan (on context c); *evaluated, *pixels: the renderer's count of the
 * pixels whose airlight it evaluated rather than interpolated, of all. */
static atmos_image *render_counted(atmos_context *c, const atmos_scene *s, long *evaluated, long *pixels)
{
    atmos_plan *plan = NULL;
    atmos_frame f;
    atmos_image *img = NULL;
    CHECK_OK(atmos_plan_create(c, s, NULL, NULL, &plan));
    if (!plan) return NULL;
    CHECK_OK(atmos_frame_from_scene(c, s, &f));
    CHECK_OK(atmos_plan_image_create(plan, &f, &img));
    if (img) CHECK_OK(atmos_plan_render(plan, &f, NULL, img, NULL));
    *evaluated = plan->beams->air_evaluated, *pixels = plan->beams->air_pixels, last_shared = plan->beams->air_shared;
    last_unread = plan->beams->air_unread, last_told = plan->beams->air_told;
    atmos_plan_destroy(plan);
    return img;
}

/* render_counted on a context of one thread (the same bytes as two: the tests compare). */
static atmos_image *render_counted_one_thread(const atmos_scene *s, long *evaluated, long *pixels)
{
    atmos_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.threads = 1;
    atmos_context *c1 = NULL;
    CHECK_OK(atmos_context_create(&cd, &c1));
    atmos_image *img = c1 ? render_counted(c1, s, evaluated, pixels) : NULL;
    atmos_context_destroy(c1);
    return img;
}

/* The images the screen_step tests compare: s at screen_step 1 (exact) and at step (sub; one, the
 * same on a context of one thread), the renderer's counts for sub (ev of n pixels evaluated) and
 * for one (ev1); nonzero if all three were made. */
typedef struct {
    atmos_image *exact, *sub, *one;
    long ev, n, ev1, shared; /* shared: of sub's evaluations, those handed their cell's corners' agreement */
    long unread;             /* sub's stretches taken within a run of agreed ones */
    long told;               /* sub's stretches a merged sample told lit or dark */
} stepped;

static int render_stepped(atmos_scene *s, int step, stepped *r)
{
    r->ev = 0, r->n = 1, r->ev1 = 0, r->shared = 0, r->unread = 0, r->told = 0;
    s->beams.screen_step = 1;
    r->exact = render_counted(ctx, s, &r->ev, &r->n);
    s->beams.screen_step = step;
    r->sub = render_counted(ctx, s, &r->ev, &r->n);
    r->shared = last_shared, r->unread = last_unread, r->told = last_told;
    r->one = render_counted_one_thread(s, &r->ev1, &r->n);
    return r->exact && r->sub && r->one;
}

/* 1 and 2 threads the same bytes and the same count of evaluated pixels (if all three images were
 * made), then the images freed. */
static void stepped_threads_free(stepped *r, int step)
{
    if (r->exact && r->sub && r->one) {
        const size_t bytes = sizeof(float) * (size_t)r->sub->width * r->sub->height * r->sub->channels;
        CHECK_MSG(r->ev1 == r->ev && !memcmp(r->one->pixels, r->sub->pixels, bytes),
                  "1 and 2 threads differ (screen step %d)", step);
    }
    atmos_image_destroy(r->one);
    atmos_image_destroy(r->exact);
    atmos_image_destroy(r->sub);
}

/* A plan keeps its frame's per-pixel buffers for the next frame (beams_kept.h): frames whose
 * camera moves, a region smaller than the frame, then the whole frame again, each the same to
 * the byte as a fresh plan's; and a kept buffer grows when asked for more, stays when asked for
 * less. */
static atmos_image *plan_frame(atmos_plan *plan, const atmos_frame *f, const atmos_region *r)
{
    atmos_image *img = NULL;
    CHECK_OK(atmos_plan_image_create(plan, f, &img));
    if (img) {
        memset(img->pixels, 0, sizeof(float) * (size_t)img->width * img->height * img->channels);
        CHECK_OK(atmos_plan_render(plan, f, r, img, NULL));
    }
    return img;
}

static void test_kept_frames(void)
{
    atmos__beams_kept k = {NULL, 0};
    void *a = atmos__beams_kept_get(&k, 100), *b = atmos__beams_kept_get(&k, 60);
    CHECK(a && a == b && k.size == 100);
    CHECK(atmos__beams_kept_get(&k, 1000) && k.size == 1000);
    atmos__beams_kept_free(&k);
    CHECK(!k.p && k.size == 0);

    atmos_scene s;
    spot_scene(&s, 96, 72);
    s.beams.screen_step = 4;
    atmos_frame f[2];
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f[0]));
    f[1] = f[0];
    f[1].camera.position[0] += 3, f[1].camera.position[1] -= 1;
    const atmos_region part = {10, 20, 60, 49};
    /* f[0]'s part (the buffers made small), f[0] (made larger), f[1], f[0] again (kept); not a
     * part right after its whole frame: the plan copies that frame's pixels (stats.reused) */
    const atmos_region *order[4] = {&part, NULL, NULL, NULL};
    const int which[4] = {0, 0, 1, 0};
    atmos_plan *kept = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, NULL, NULL, &kept));
    if (!kept) return;
    for (int i = 0; i < 4; i++) {
        const atmos_frame *fr = &f[which[i]];
        atmos_plan *fresh = NULL;
        CHECK_OK(atmos_plan_create(ctx, &s, NULL, NULL, &fresh));
        atmos_image *want = fresh ? plan_frame(fresh, fr, order[i]) : NULL, *got = plan_frame(kept, fr, order[i]);
        const size_t bytes = got ? sizeof(float) * (size_t)got->width * got->height * got->channels : 0;
        CHECK_MSG(want && got && !memcmp(want->pixels, got->pixels, bytes), "frame %d of a plan differs from a fresh plan's",
                  i);
        atmos_image_destroy(want), atmos_image_destroy(got);
        atmos_plan_destroy(fresh);
    }
    atmos_plan_destroy(kept);
}

/* The subsampled image sub against the exact one (green, over the pixels above 1e-3 of the
 * brightest): the worst relative difference at the edges (a neighbour differing by a fifth in
 * the exact image), their count, and the mean over the lit pixels (their count). */
static void exact_diff(const atmos_image *exact, const atmos_image *sub, int W, int H, double *worst_edge, long *edges,
                       double *mean, long *lit)
{
    const int C = exact->channels;
    double sum = 0, top = 0;
    *worst_edge = 0, *edges = 0, *lit = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) top = fmax(top, exact->pixels[i * C + 1]);
    for (int y = 1; y + 1 < H; y++)
        for (int x = 1; x + 1 < W; x++) {
            const float *e = exact->pixels + ((size_t)y * W + x) * C, *g = sub->pixels + ((size_t)y * W + x) * C;
            if (!(e[1] > 1e-3 * top)) continue; /* the pixels that show */
            const double rel = fabs(g[1] / e[1] - 1);
            sum += rel, ++*lit;
            int edge = 0;
            for (int k = 0; k < 4; k++) {
                const int dx = k == 0 ? -1 : k == 1 ? 1 : 0, dy = k == 2 ? -1 : k == 3 ? 1 : 0;
                edge |= fabs(e[(dy * W + dx) * C + 1] - e[1]) > 0.2 * e[1];
            }
            if (edge) ++*edges, *worst_edge = fmax(*worst_edge, rel);
        }
    *mean = *lit ? sum / *lit : 0;
}

/* The subsampled image of r against its exact one (exact_diff) printed under the label what, and
 * checked: more than min_edges pixels at the edges, the worst of them within edge_max, the mean
 * over the lit pixels within mean_max. */
static void check_exact_diff(const stepped *r, int W, int H, const char *what, long min_edges, double edge_max,
                             double mean_max)
{
    double worst_edge, mean;
    long edges, lit;
    exact_diff(r->exact, r->sub, W, H, &worst_edge, &edges, &mean, &lit);
    printf("%s: airlight evaluated %ld times over %ld pixels (%.1f %%); %ld edge pixels, worst relative difference "
           "there %.2e; mean over %ld lit pixels %.2e\n", what, r->ev, r->n, 100.0 * r->ev / r->n, edges, worst_edge,
           lit, mean);
    CHECK_MSG(edges > min_edges, "%s: %ld edge pixels", what, edges);
    CHECK_MSG(worst_edge <= edge_max, "%s: an edge pixel is off the exact one by %.3g", what, worst_edge);
    CHECK_MSG(mean <= mean_max, "%s: the subsampled image is off the exact one by %.3g on average", what, mean);
}

/* The airlight subsampled on a lattice of every 4th pixel (beams/screen_step 4): a point
 * light's smooth glow is interpolated over most pixels (the renderer's count of those it
 * evaluated at most half), within 1 % of Sun et al.'s closed form at the pixels between the
 * lattice's nodes; across a spot's beam, a sphere's shadow in it, on the floor and its
 * silhouette, the pixels at the edges (among those above 1e-3 of the brightest, a neighbour
 * differing by a fifth in the exact image) within 3 % of the exact image (step 1), the mean
 * within 0.1 %; 1 and 2 threads give the same bytes. */
static void test_screen_step(void)
{
    atmos_scene s;
    base_scene(&s, 160, 120);
    const double eye[3] = {0, 2, 0}, lp[3] = {3, 4, -20};
    memcpy(s.camera.position, eye, sizeof eye);
    s.camera.look_at[0] = 1, s.camera.look_at[1] = 2.5, s.camera.look_at[2] = -10;
    s.camera.fov_deg = 50;
    memcpy(s.lights[0].position_m, lp, sizeof lp);
    s.beams.screen_step = 4;
    long ev = 0, n = 1;
    atmos_image *img = render_counted(ctx, &s, &ev, &n);
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam));
    double worst = 0;
    for (int y = 1; img && y < s.height; y += 2)
        for (int x = y % 4 == 1 ? 1 : 2; x < s.width; x += 4) { /* inside the cells, and on their edges */
            double d[3];
            atmos_camera_ray(&cam, x + 0.5, y + 0.5, d);
            const double want = airlight(eye, d, lp, 0.05, 0.04, 0, INFINITY);
            worst = fmax(worst, fabs(img->pixels[((size_t)y * s.width + x) * img->channels + 1] / want - 1));
        }
    printf("screen step 4: a point light's glow, airlight evaluated at %ld of %ld pixels (%.1f %%), worst relative "
           "error %.2e between the nodes\n", ev, n, 100.0 * ev / n, worst);
    CHECK_MSG(ev <= n / 2, "the glow's airlight was evaluated at %ld of %ld pixels", ev, n);
    CHECK_MSG(worst <= 0.01, "the interpolated glow is off the closed form by %.3g", worst);
    atmos_image_destroy(img);

    spot_scene(&s, 192, 144);
    stepped r;
    if (render_stepped(&s, 4, &r)) {
        check_exact_diff(&r, s.width, s.height, "screen step 4, a spot's beam and shadow", 100, 0.03, 1e-3);
    }
    stepped_threads_free(&r, 4);
}

/* A spot's beam many cells wide (spot_scene's, screen_step 8 and 16, the default): its span is no
 * hint where it is at least SCREEN_WIDE cells' widths wide in a cell's rows (beams_screen.c), so its
 * edges are not strips of pixels all evaluated: the airlight is evaluated at fewer than 27 % of the
 * pixels (19.9 % at 8, 18.2 % at 16), the edges within 3 % and the mean within 0.1 % of the exact
 * image, 1 and 2 threads the same bytes. */
static void test_wide_span(int step)
{
    atmos_scene s;
    spot_scene(&s, 192, 144);
    stepped r;
    if (render_stepped(&s, step, &r)) {
        char what[64];
        snprintf(what, sizeof what, "a wide beam, screen step %d", step);
        check_exact_diff(&r, s.width, s.height, what, 0, 0.03, 1e-3);
        CHECK_MSG(r.ev < 0.27 * r.n, "the airlight was evaluated at %ld of %ld pixels", r.ev, r.n);
    }
    stepped_threads_free(&r, step);
}

/* The lit cones' hint (beams_screen.h): a spot's beam about a pixel wide, upright on column 82 of
 * 160 (between the nodes of a lattice of 8, 80 and 88, and the quarters' corners, 84; of 16, 80
 * and 96), is caught by its span though no node lies on it: with screen_step 8 and 16, every pixel
 * above 5 % of the brightest in the exact image (step 1) within 5 % of it, and 1 and 2 threads the
 * same bytes. */
static void test_thin_beam_hint(int step)
{
    atmos_scene s;
    base_scene(&s, 160, 120);
    memset(s.camera.position, 0, sizeof s.camera.position), memset(s.camera.look_at, 0, sizeof s.camera.look_at);
    s.camera.look_at[2] = -10, s.camera.fov_deg = 50;
    atmos_scene_light *l = &s.lights[0];
    l->type = ATMOS_LIGHT_SPOT, l->cone_deg = 0.5, l->edge_deg = 0.2, l->range_m = 60;
    l->direction[1] = 1;
    const double u = 82.5 - 80; /* the beam's column's centre, right of the image's centre */
    l->position_m[0] = u / 60 * 30 * tan(25 * ATMOS_PI / 180), l->position_m[1] = -20, l->position_m[2] = -30;
    stepped r;
    if (render_stepped(&s, step, &r)) {
        const atmos_image *exact = r.exact, *sub = r.sub;
        const int W = s.width, C = exact->channels;
        double top = 0, worst = 0;
        long lit = 0, lo = W, hi = 0;
        for (size_t i = 0; i < (size_t)W * s.height; i++) top = fmax(top, exact->pixels[i * C + 1]);
        for (int y = 0; y < s.height; y++)
            for (int x = 0; x < W; x++) {
                const size_t i = ((size_t)y * W + x) * C;
                if (!(exact->pixels[i + 1] > 0.05 * top)) continue;
                lit++, lo = x < lo ? x : lo, hi = x > hi ? x : hi;
                worst = fmax(worst, fabs(sub->pixels[i + 1] / exact->pixels[i + 1] - 1));
            }
        printf("screen step %d: a beam a pixel wide between the nodes, columns %ld-%ld, %ld pixels above 5 %% of "
               "the brightest, worst relative difference %.2e; airlight evaluated at %ld of %ld pixels\n",
               step, lo, hi, lit, worst, r.ev, r.n);
        CHECK_MSG(lit > 100 && lo > 80 && hi < 84, "the beam is not where the test puts it (columns %ld-%ld)", lo, hi);
        CHECK_MSG(worst <= 0.05, "the thin beam is lost between the nodes (%.3g off, step %d)", worst, step);
    }
    stepped_threads_free(&r, step);
}

/* A point light's glow with spots (beams_render.c, air_layers: the spots on a lattice of their
 * own): spot_scene's wide beam and its sphere's shadow, a spot's beam about a pixel wide and a
 * point light's glow round the sphere, with screen_step 8 and 16. The thin beam's span cuts only the
 * spots' lattice, so the glow is interpolated along it where smooth; the pixels at the edges
 * within 3 % of the exact image (step 1), those above 5 % of the brightest (the thin beam's among
 * them) within 5 %, the mean within 0.1 %, the airlight evaluated (the layers' evaluations summed:
 * 49.2 % at 8, 46.0 % at 16) fewer times than LAYERS_MAX of the pixels, 1 and 2 threads the same
 * bytes. */
#define LAYERS_MAX 0.55
static void test_layers(int step)
{
    atmos_scene s;
    spot_scene(&s, 192, 144);
    s.light_count = 3;
    atmos_scene_light *thin = &s.lights[1], *glow = &s.lights[2];
    *thin = s.lights[0], *glow = s.lights[0];
    thin->cone_deg = 0.5, thin->edge_deg = 0.2, thin->range_m = 60, thin->intensity_w_sr = 4e4;
    thin->position_m[0] = -6, thin->position_m[1] = 0.5, thin->position_m[2] = 0;
    thin->direction[0] = 0, thin->direction[1] = 1, thin->direction[2] = 0;
    glow->type = ATMOS_LIGHT_POINT, glow->intensity_w_sr = 100;
    glow->position_m[0] = 3, glow->position_m[1] = 3, glow->position_m[2] = 3;
    stepped r;
    if (render_stepped(&s, step, &r)) {
        char what[64];
        snprintf(what, sizeof what, "a glow with spots, screen step %d", step);
        check_exact_diff(&r, s.width, s.height, what, 100, 0.03, 1e-3);
        const int C = r.exact->channels;
        double top = 0, worst = 0;
        for (size_t i = 0; i < (size_t)r.n; i++) top = fmax(top, r.exact->pixels[i * C + 1]);
        for (size_t i = 0; i < (size_t)r.n; i++)
            if (r.exact->pixels[i * C + 1] > 0.05 * top)
                worst = fmax(worst, fabs(r.sub->pixels[i * C + 1] / r.exact->pixels[i * C + 1] - 1));
        printf("  the pixels above 5 %% of the brightest within %.2e of the exact ones\n", worst);
        CHECK_MSG(worst <= 0.05, "a bright pixel (the thin beam?) is off the exact one by %.3g", worst);
        CHECK_MSG(r.ev < LAYERS_MAX * r.n, "the airlight was evaluated %ld times over %ld pixels", r.ev, r.n);
    }
    stepped_threads_free(&r, step);
}

/* The rays of a cut cell share what its corners saw of a point light (beams_render.c,
 * agreed_intervals, shared_interval; beams_screen.h's known): a point light behind a fence of six
 * posts, whose shadows reach toward the eye through the fog as dark streaks, with screen_step 8
 * and 16. A pixel evaluated in a cut cell takes a stretch of its ray between two planes as lit or
 * dark only where all four of the cell's corners saw it so all along (and not cut by the light's
 * reach or a surface); so the streaks' edges are sampled: most evaluations were handed their
 * corners' agreement, and the image is as close to the exact one (step 1) as the lattice alone
 * makes it (its pixels at the edges within 3.23 % at 8 and 16, the mean 0.304 % and 0.334 %; the
 * bounds 4 % and 0.4 %; a stretch taken where any one corner saw it so: 7.6 % and 12.9 %, 0.91 %
 * and 2.4 %); a run of stretches they agree on is taken in one step, so more stretches than shared
 * evaluations are taken without their W looked up (16 194 at 8 over 4 421, 14 814 at 16 over
 * 4 054; none without the runs); a point light's merged sample of a single interval tells its
 * stretch to the cells around (668 at 8, 584 at 16; none before merged() told them); 1 and 2
 * threads the same bytes. */
static void test_shared_corners(int step)
{
    atmos_scene s;
    base_scene(&s, 192, 144);
    s.camera.position[0] = 1, s.camera.position[1] = 3, s.camera.position[2] = 14;
    s.camera.look_at[1] = 3, s.camera.look_at[2] = -4, s.camera.fov_deg = 60;
    s.lights[0].position_m[1] = 3, s.lights[0].position_m[2] = -4, s.lights[0].range_m = 40;
    s.beams.shadow_size = 512;
    s.object_count = 7;
    for (int i = 0; i < s.object_count; i++) { /* six posts of a fence between the light and the eye, a floor */
        atmos_scene_object *o = &s.objects[i];
        memset(o, 0, sizeof *o);
        o->scale[0] = o->scale[2] = i < 6 ? 0.3 : 30, o->scale[1] = i < 6 ? 6 : 30;
        o->albedo[0] = o->albedo[1] = o->albedo[2] = 0.5;
        snprintf(o->mesh, sizeof o->mesh, i < 6 ? "builtin:box" : "builtin:plane");
        if (i < 6) o->position_m[0] = -5 + 2 * i, o->position_m[1] = 3;
    }
    stepped r;
    if (render_stepped(&s, step, &r)) {
        char what[64];
        snprintf(what, sizeof what, "a point light's streaks, screen step %d", step);
        check_exact_diff(&r, s.width, s.height, what, 500, 0.04, 4e-3);
        printf("  %ld evaluations handed their corners' agreement; %ld stretches taken within runs, no W looked up; "
               "%ld told by merged samples\n", r.shared, r.unread, r.told);
        CHECK_MSG(r.shared > r.ev / 2, "only %ld of %ld evaluations shared their corners'", r.shared, r.ev);
        CHECK_MSG(r.unread > 2 * r.shared, "only %ld stretches of %ld shared evaluations were taken in runs", r.unread,
                  r.shared);
        CHECK_MSG(r.told > 0, "no merged sample told its stretch to the cells around");
    }
    stepped_threads_free(&r, step);
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_spectrum();
    test_airlight();
    test_shadow();
    test_light_sum();
    test_runs_across_faces();
    test_tiles_range();
    test_ray_faces();
    test_screen_spans();
    test_surface_spans();
    test_surface_closed_form();
    test_sky_on_lattice();
    test_threads();
    test_interleave();
    test_screen_step();
    for (int step = 8; step <= 16; step *= 2) { /* 16: the default since issue 17's twenty-sixth round */
        test_thin_beam_hint(step);
        test_wide_span(step);
        test_layers(step);
        test_shared_corners(step);
    }
    test_kept_frames();
    test_scene_files();
    test_cancel();
    test_plan_progress();
    test_extremes();
    atmos_context_destroy(ctx);
    return test_summary("test_beams");
}
