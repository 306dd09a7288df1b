/* Objects inside Harris's particle clouds (Harris 2002 §3.2, impostor splitting): the light
 * passes' probes (an object's vertices) read the light buffer as particles do, and below a cloud
 * the transmittance of its column; an opaque
 * aircraft in a cumulus is veiled by exactly the particles in front of it (the transmittance of
 * their columns along each pixel's ray, summed here from the particles themselves), the particles
 * behind it are hidden, the split impostors give the particles' own image within the impostors'
 * error, and no image depends on the thread count. */
#include "atmos/atmos.h"
#include "render/harris_internal.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 128, H = 96 };
#define FOV 16.0
#define SCALE 150.0

static atmos_context *context(int threads)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = threads;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&d, &ctx));
    return ctx;
}

/* The scene: the cumulus of scenes/harris_fly_through.json seen in the dark (no air) from eye
 * looking at c, and an aircraft of albedo alb at o (NULL: none). */
static atmos_plan *plan(atmos_context *ctx, const double c[3], const double *o, const double eye[3], double alb,
                        int impostors)
{
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d}, \"background\": \"black\", \"renderer\": \"harris\","
             "\"wavelengths\": {\"mode\": \"rgb\"},"
             "\"camera\": {\"type\": \"pinhole\", \"position_m\": [%.17g, %.17g, %.17g], \"look_at_m\": [%.17g, %.17g, %.17g],"
             " \"fov_deg\": %g}, \"sun\": {\"elevation_deg\": 40, \"azimuth_deg\": 150},"
             "\"volume\": {\"generate\": \"harris_cumulus\", \"seed\": 3, \"position_m\": [0, 1440, 0]},"
             "\"harris\": {\"sky_lights\": 0, \"impostors\": %s}%s",
             W, H, eye[0], eye[1], eye[2], c[0], c[1], c[2], FOV, impostors ? "true" : "false", o ? "," : "}");
    if (o)
        snprintf(json + strlen(json), sizeof json - strlen(json),
                 "\"objects\": [{\"mesh\": \"builtin:aircraft\", \"position_m\": [%.17g, %.17g, %.17g], \"scale\": %g,"
                 " \"rotation_deg\": [0, 60, 0], \"albedo\": %g}]}", o[0], o[1], o[2], SCALE, alb);
    atmos_scene s;
    CHECK_OK(atmos_scene_parse(ctx, json, strlen(json), "test", &s));
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, NULL, NULL, &p));
    return p;
}

static atmos_image *render(atmos_context *ctx, atmos_plan *p, const double c[3], const double eye[3])
{
    atmos_frame f;
    memset(&f, 0, sizeof f);
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, eye, &f.camera);
    memcpy(f.camera.look_at, c, sizeof f.camera.look_at);
    f.camera.fov_deg = FOV;
    f.width = W, f.height = H, f.samples_per_pixel = 1;
    atmos_direction_from_angles(40, 150, f.sun_dir);
    atmos_image *img = NULL;
    CHECK_OK(atmos_plan_image_create(p, &f, &img));
    CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
    (void)ctx;
    return img;
}

static double rel_rms(const atmos_image *a, const atmos_image *b)
{
    double d2 = 0, r2 = 0;
    for (size_t i = 0; i < (size_t)a->width * a->height * a->channels; i++)
        d2 += (a->pixels[i] - b->pixels[i]) * (a->pixels[i] - b->pixels[i]), r2 += b->pixels[i] * b->pixels[i];
    return sqrt(d2 / r2);
}

/* The column of particle p along the unit ray (eye, d), libm's erf: exp(-u/2) erf(sqrt((9-u)/2)). */
static double column(const atmos__pcloud *pc, int p, const double eye[3], const double d[3])
{
    const double r[3] = {pc->x[p] - eye[0], pc->y[p] - eye[1], pc->z[p] - eye[2]};
    const double x[3] = {r[1] * d[2] - r[2] * d[1], r[2] * d[0] - r[0] * d[2], r[0] * d[1] - r[1] * d[0]};
    const double u = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) / ((double)pc->s[p] * pc->s[p]);
    return u >= 9 ? 0 : exp(-0.5 * u) * erf(sqrt(0.5 * (9 - u))) * pc->n0[p] * pc->s[p] * 2.5066282746310002;
}

/* The light passes' probes: a probe at a particle's centre reads what the particle reads, one
 * beside the cloud or sunward of it the whole light, one in its shadow less; the particles' own
 * light is the same bytes with and without probes. */
static void probes(void)
{
    atmos__pcloud pc;
    memset(&pc, 0, sizeof pc);
    pc.nfields = 1;
    for (int i = 0; i < 300; i++)
        CHECK_OK(atmos__pcloud_add(&pc, 200 * sin(i * 1.7), 2000 + 200 * cos(i * 0.9), 200 * sin(i * 0.37 + 1),
                                   40 + 10 * (i % 3), 4e8, 0));
    atmos__poptics o;
    memset(&o, 0, sizeof o);
    o.nw = 1, o.sigma_ext[0][0] = 2e-12, o.albedo[0][0] = 0.9;
    const double sun[3] = {0, 1, 0};
    float *l0 = malloc(sizeof(float) * 300), *l1 = malloc(sizeof(float) * 300), *o0 = malloc(sizeof(float) * 300),
          *o1 = malloc(sizeof(float) * 300), plight[5];
    const float xyz[15] = {pc.x[7], pc.y[7], pc.z[7], pc.x[123], pc.y[123], pc.z[123], 2000, 2000, 0, 0, 2600, 0, 0, 1500, 0};
    const atmos__pprobes pr = {5, xyz, plight};
    CHECK_OK(atmos__pcloud_shade(NULL, &pc, NULL, 0, &o, sun, 0, 1.0, l0, o0));
    CHECK_OK(atmos__pcloud_shade_probes(NULL, &pc, NULL, 0, &o, sun, 0, 1.0, l1, o1, &pr));
    printf("probes: at particles %.4f (%.4f), %.4f (%.4f); beside %.3f, above %.3f, below %.4f\n", plight[0], l0[7],
           plight[1], l0[123], plight[2], plight[3], plight[4]);
    CHECK(!memcmp(l0, l1, sizeof(float) * 300) && !memcmp(o0, o1, sizeof(float) * 300));
    CHECK(plight[0] == l0[7] && plight[1] == l0[123]);
    CHECK(plight[2] == 1.0f && plight[3] == 1.0f);
    /* below the cloud (no forward scattering without tables): exp(-tau) of the whole column */
    double tau = 0;
    const double below[3] = {0, 1500, 0}, up[3] = {0, 1, 0};
    for (int i = 0; i < pc.n; i++) tau += column(&pc, i, below, up) * o.sigma_ext[0][0];
    printf("probe below the cloud %.4f, exp(-tau) of the particles' column %.4f\n", plight[4], exp(-tau));
    CHECK(exp(-tau) < 0.5);
    CHECK_REL(plight[4], exp(-tau), 0.02);
    free(l0), free(l1), free(o0), free(o1);
    atmos__pcloud_free(&pc);
}

int main(void)
{
    probes();
    atmos_context *c2 = context(2), *c1 = context(1);
    /* the cloud's centre, from a plan without the aircraft */
    double c[3], eye[3];
    const double e0[3] = {0, 1900, 2600}, look[3] = {0, 1800, 0};
    atmos_plan *p0 = plan(c2, look, NULL, e0, 0, 0);
    memcpy(c, p0->harris->clouds.centre[0], sizeof c);
    for (int a = 0; a < 3; a++) eye[a] = c[a] + (a == 1 ? 150 : a == 2 ? 2200 : 0);
    const double ac[3] = {c[0], c[1], c[2] + 300}; /* the aircraft: inside, on the eye's side */
    atmos_image *none = render(c2, p0, c, eye);
    /* A: the aircraft, B: the same aircraft black; the particles splatted one by one */
    atmos_plan *pa = plan(c2, c, ac, eye, 0.8, 0), *pb = plan(c2, c, ac, eye, 0.0, 0);
    atmos_image *A = render(c2, pa, c, eye), *B = render(c2, pb, c, eye);
    const atmos__harris_plan *h = pa->harris;
    const atmos__harris_objects *ob = h->obj;
    const int nw = h->o.nw, C = nw + 1;
    /* the split by the test's own reckoning: the aircraft's box centre */
    atmos_mesh *m = NULL;
    CHECK_OK(atmos_mesh_load(c2, "builtin:aircraft", 0, &m));
    atmos_mesh_transform t;
    atmos_mesh_transform_identity(&t);
    memcpy(t.position_m, ac, sizeof t.position_m);
    t.scale[0] = t.scale[1] = t.scale[2] = SCALE, t.rotation_deg[1] = 60;
    CHECK_OK(atmos_mesh_apply_transform(c2, m, &t));
    double split = 0;
    for (int a = 0; a < 3; a++) split += pow(0.5 * (m->lo[a] + m->hi[a]) - eye[a], 2);
    split = sqrt(split);
    CHECK_REL(h->split_m, split, 1e-7);
    int *near = malloc(sizeof(int) * (size_t)h->pc.n), nn = 0, *all = malloc(sizeof(int) * (size_t)h->pc.n);
    for (int i = 0; i < h->pc.n; i++) {
        all[i] = i;
        if (sqrt(pow(h->pc.x[i] - eye[0], 2) + pow(h->pc.y[i] - eye[1], 2) + pow(h->pc.z[i] - eye[2], 2)) <= split)
            near[nn++] = i;
    }
    printf("%d particles, cloud centre (%.0f, %.0f, %.0f) m, radius %.0f m, %d in front of the split at %.1f m\n", h->pc.n, c[0],
           c[1], c[2], h->clouds.radius[0], nn, split);
    CHECK(nn > 100 && nn < h->pc.n - 100);
    /* the near particles alone and all of them, splatted over black with the plan's light */
    const atmos__plights L = {h->nlights, (const float *const *)h->light, (const float *const *)h->order,
                              (const double(*)[3])h->dir, (const double(*)[ATMOS_MAX_WAVELENGTHS])h->e, h->air_t, h->air_l,
                              h->diffuse && h->field_ok ? h->dview : NULL}; /* the field: the default */
    atmos_image *nearimg = NULL, *allimg = NULL;
    CHECK_OK(atmos_image_create(c2, W, H, C, &nearimg));
    CHECK_OK(atmos_image_create(c2, W, H, C, &allimg));
    memset(nearimg->pixels, 0, sizeof(float) * W * H * C), memset(allimg->pixels, 0, sizeof(float) * W * H * C);
    const int rect[4] = {0, 0, W, H};
    atmos_camera_desc cd;
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, eye, &cd);
    memcpy(cd.look_at, c, sizeof cd.look_at);
    cd.fov_deg = FOV;
    atmos_camera camera;
    CHECK_OK(atmos_camera_init(c2, &cd, W, H, &camera));
    const atmos_camera *cam = &camera;
    CHECK_OK(atmos__pcloud_splat(c2, &h->pc, &h->o, &L, near, nn, cam, rect, nearimg, NULL));
    CHECK_OK(atmos__pcloud_splat(c2, &h->pc, &h->o, &L, all, h->pc.n, cam, rect, allimg, NULL));
    /* over the aircraft's pixels: A - B = T_front L_object, B = the near particles alone */
    int hits = 0, mismatch = 0, edge = 0;
    double worst_veil = 0, worst_hide = 0, far_light = 0, tmin = 1;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double d[3];
            atmos_mesh_hit hit;
            const double u = (2.0 * (x + 0.5) - W) / H * cam->tan_half_fov, v = (H - 2.0 * (y + 0.5)) / H * cam->tan_half_fov;
            double l = 0;
            for (int a = 0; a < 3; a++) d[a] = cam->forward[a] + u * cam->right[a] + v * cam->up[a], l += d[a] * d[a];
            for (int a = 0; a < 3; a++) d[a] /= sqrt(l);
            const int on = atmos_mesh_intersect(m, eye, d, 0, INFINITY, &hit);
            const size_t at = (size_t)y * W + x;
            /* the renderer's layer (within its box, 2 x 2 rays a pixel): a pixel the centre ray
             * meets is covered, a wholly covered one is met by it; the checks below on the wholly
             * covered pixels */
            const int box = x >= ob->box[0] && x < ob->box[1] && y >= ob->box[2] && y < ob->box[3];
            const float cover = box ? ob->cover[at] : 0.0f;
            mismatch += (on && !(cover > 0)) || (cover == 1.0f && !on);
            edge += on && cover < 1.0f;
            if (!on || cover < 1.0f) continue;
            hits++;
            double tau = 0;
            for (int q = 0; q < nn; q++) tau += column(&h->pc, near[q], eye, d);
            for (int k = 0; k < nw; k++) {
                const double T = exp(-tau * h->o.sigma_ext[0][k]), Lo = ob->col[at * nw + k];
                const double veil = A->pixels[at * C + k] - B->pixels[at * C + k];
                worst_veil = fmax(worst_veil, fabs(veil - T * Lo) / (T * Lo + 1e-3 * Lo));
                const double n = nearimg->pixels[at * C + k];
                worst_hide = fmax(worst_hide, fabs(B->pixels[at * C + k] - n) / (n + 1e-6));
                far_light = fmax(far_light, (allimg->pixels[at * C + k] - n) / (n + 1e-6));
                tmin = fmin(tmin, T);
            }
        }
    printf("aircraft: %d pixels; least transmittance in front %.3f; veil: worst |(A - B) - T L| / T L %.2e; "
           "hidden: worst |B - near| / near %.2e (the far particles would add %.2f)\n",
           hits, tmin, worst_veil, worst_hide, far_light);
    printf("aircraft: %d pixels wholly covered, %d at its edges, %d mismatches\n", hits, edge, mismatch);
    CHECK(hits > 40 && edge > 10 && mismatch == 0);
    CHECK(tmin < 0.5);          /* the aircraft is well inside: veiled */
    CHECK(worst_veil < 1e-4);   /* by exactly the particles in front */
    CHECK(worst_hide < 1e-4);   /* and nothing from behind */
    CHECK(far_light > 0.05);    /* (which would show) */
    /* impostor splitting: the far and near impostors against the particles themselves */
    atmos_plan *pi = plan(c2, c, ac, eye, 0.8, 1);
    atmos_image *I = render(c2, pi, c, eye);
    const double e = rel_rms(I, A);
    printf("split impostors: %d clouds split, %d impostor updates, rel rms against the particles %.2e\n",
           pi->harris->splits, pi->harris->updates, e);
    CHECK(pi->harris->splits == 1 && pi->harris->updates == 2);
    CHECK(e < 0.01);
    /* the eye 4 m aside (0.1 degree round the cloud): the split impostors serve on */
    const double eye2[3] = {eye[0] + 4, eye[1], eye[2]};
    atmos_image *I2 = render(c2, pi, c, eye2);
    const int reused = pi->harris->updates == 0 && pi->harris->splits == 1;
    atmos_plan *pd = plan(c2, c, ac, eye2, 0.8, 0);
    atmos_image *D2 = render(c2, pd, c, eye2);
    const double e2 = rel_rms(I2, D2);
    printf("4 m aside: %d impostor updates, rel rms against the particles %.2e\n", pi->harris->updates, e2);
    CHECK(reused);
    CHECK(e2 < 0.01);
    atmos_image_destroy(I2), atmos_image_destroy(D2);
    atmos_plan_destroy(pd);
    /* the same bytes on one thread */
    atmos_plan *pa1 = plan(c1, c, ac, eye, 0.8, 0), *pi1 = plan(c1, c, ac, eye, 0.8, 1);
    atmos_image *A1 = render(c1, pa1, c, eye), *I1 = render(c1, pi1, c, eye);
    CHECK(!memcmp(A1->pixels, A->pixels, sizeof(float) * W * H * C));
    CHECK(!memcmp(I1->pixels, I->pixels, sizeof(float) * W * H * C));
    /* an aircraft out of view changes nothing */
    const double behind[3] = {eye[0], eye[1], eye[2] + 3000};
    atmos_plan *pz = plan(c2, c, behind, eye, 0.8, 0);
    atmos_image *Z = render(c2, pz, c, eye);
    CHECK(!memcmp(Z->pixels, none->pixels, sizeof(float) * W * H * C));
    atmos_image_destroy(none), atmos_image_destroy(A), atmos_image_destroy(B), atmos_image_destroy(I);
    atmos_image_destroy(A1), atmos_image_destroy(I1), atmos_image_destroy(Z);
    atmos_image_destroy(nearimg), atmos_image_destroy(allimg);
    atmos_plan_destroy(p0), atmos_plan_destroy(pa), atmos_plan_destroy(pb), atmos_plan_destroy(pi);
    atmos_plan_destroy(pa1), atmos_plan_destroy(pi1), atmos_plan_destroy(pz);
    atmos_mesh_destroy(m);
    free(near), free(all);
    atmos_context_destroy(c1), atmos_context_destroy(c2);
    return test_summary("test_harris_objects");
}
