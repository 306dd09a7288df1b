/* Particle clouds (src/particles/): conversion from a volume and back (a uniform box's
 * density and mass kept), Harris's light pass against Beer-Lambert through a uniform slab
 * (no forward share) and against the forward share's closed form, the eye pass of one thin
 * particle against the single-scattering integral, and the images' independence of the
 * thread count. */
#include "atmos/atmos.h"
#include "particles/pcloud.h"
#include "test.h"

#include <math.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* A box of nx x ny x nz voxels of 50 m at density rho (one "cloud" field). */
static atmos_volume *box(int nx, int ny, int nz, float rho)
{
    atmos_volume_desc d;
    memset(&d, 0, sizeof d);
    d.dims[0] = nx, d.dims[1] = ny, d.dims[2] = nz;
    d.voxel_size_m = 50;
    atmos_volume *v = NULL;
    int f;
    CHECK_OK(atmos_volume_create(NULL, &d, &v));
    CHECK_OK(atmos_volume_add_field(NULL, v, "cloud", "cloud", &f));
    float *vals = malloc(sizeof(float) * (size_t)nx * ny * nz);
    for (int i = 0; i < nx * ny * nz; i++) vals[i] = rho;
    const int off[3] = {0, 0, 0};
    CHECK_OK(atmos_volume_set_dense(NULL, v, f, off, d.dims, vals, 1.0f));
    CHECK_OK(atmos_volume_finalize(NULL, v));
    free(vals);
    return v;
}

static void convert(void)
{
    atmos_volume *v = box(24, 24, 24, 1e8f);
    const double off[3] = {0, 0, 0};
    atmos__pcloud pc;
    CHECK_OK(atmos__pcloud_from_volume(NULL, v, off, 100.0, 0, &pc));
    CHECK(pc.n == 12 * 12 * 12);
    CHECK(pc.nfields == 1 && !strcmp(pc.field_name[0], "cloud"));
    atmos_volume *g = NULL;
    CHECK_OK(atmos__pcloud_to_volume(NULL, &pc, 25.0, &g));
    /* the middle of the box: the lattice of Gaussians sums to the density */
    const double mid[3] = {600, 600, 600};
    const double inner = g ? atmos_volume_sample(g, 0, mid) : 0;
    printf("convert: %d particles, density at the centre %.5g (box 1e8)\n", pc.n, inner);
    CHECK_REL(inner, 1e8, 5e-3);
    const double corner[3] = {250, 250, 250}; /* the ripple of the cut lattice: 1 % */
    CHECK_REL(g ? atmos_volume_sample(g, 0, corner) : 0, 1e8, 1.5e-2);
    /* the mass: the sum over the grid (cut at 3 s, the particles keep their cells' mass) */
    double mass = 0;
    for (double z = 12.5; z < 1500; z += 25)
        for (double y = 12.5; y < 1500; y += 25)
            for (double x = 12.5; x < 1500; x += 25) {
                const double p[3] = {x - 150, y - 150, z - 150};
                mass += atmos_volume_sample(g, 0, p) * 25.0 * 25.0 * 25.0;
            }
    const double want = 1e8 * 1200.0 * 1200.0 * 1200.0;
    printf("convert: mass %.6g of %.6g\n", mass, want);
    CHECK_REL(mass, want, 3e-3);
    atmos_volume_destroy(g);
    atmos_volume_destroy(v);
    atmos__pcloud_free(&pc);
}

/* The light pass with no forward share against the optical depth toward the sun from each
 * particle's centre through the particles' own density grid (atmos__pcloud_to_volume, then
 * the volume's DDA: a second method): a uniform slab with the sun overhead and a
 * generated cumulus with the sun at 35 degrees. Returns |tau - tau_ref| / (tau_ref
 * + 0.1) over the particles: its rms (printed with the worst). */
static double light_vs_grid(atmos_volume *v, double h, const double sun[3], double sigma, const char *what)
{
    const double off[3] = {0, 0, 0};
    atmos__pcloud pc;
    CHECK_OK(atmos__pcloud_from_volume(NULL, v, off, h, 0, &pc));
    atmos_volume *g = NULL;
    CHECK_OK(atmos__pcloud_to_volume(NULL, &pc, 0.25 * h, &g));
    atmos__poptics o;
    memset(&o, 0, sizeof o);
    o.nw = 1;
    o.sigma_ext[0][0] = sigma, o.albedo[0][0] = 0.9;
    float *light = malloc(sizeof(float) * (size_t)pc.n), *order = malloc(sizeof(float) * (size_t)pc.n);
    CHECK_OK(atmos__pcloud_shade(NULL, &pc, NULL, 0, &o, sun, 0, 1.0, light, order));
    double worst = 0, worst_n = 0, mean = 0, rms = 0;
    for (int p = 0; p < pc.n && g; p++) {
        const double c[3] = {pc.x[p], pc.y[p], pc.z[p]};
        const double ref = atmos_volume_optical_depth(g, &sigma, c, sun, 0, 1e5);
        const double got = -log(light[p]);
        worst = fmax(worst, fabs(got - ref) / (ref + 0.1));
        worst_n = fmax(worst_n, fabs(order[p] - 0.9 * ref) / (0.9 * ref + 0.1));
        mean += got - ref;
        rms += (got - ref) * (got - ref) / ((ref + 0.1) * (ref + 0.1));
    }
    rms = sqrt(rms / pc.n);
    printf("light pass, %s: %d particles, |tau - tau_grid| / (tau_grid + 0.1): rms %.4f, worst %.4f; of the "
           "scattering count: worst %.4f; mean tau - tau_grid %.4f\n", what, pc.n, rms, worst, worst_n, mean / pc.n);
    CHECK(worst_n < 1.2 * worst + 1e-3);
    free(light), free(order);
    atmos_volume_destroy(g);
    atmos__pcloud_free(&pc);
    return rms;
}

static void light_pass(void)
{
    atmos_volume *v = box(40, 20, 40, 1e8f);
    const double up[3] = {0, 1, 0};
    CHECK(light_vs_grid(v, 100.0, up, 2e-11, "slab") < 0.02);
    atmos_volume_destroy(v);
    atmos_volume_generate_desc gd;
    memset(&gd, 0, sizeof gd);
    gd.seed = 3, gd.voxel_size_m = 100;
    CHECK_OK(atmos_volume_generate(NULL, "cumulus", &gd, &v));
    double sun[3];
    atmos_direction_from_angles(35, 120, sun);
    CHECK(light_vs_grid(v, 100.0, sun, 2e-11, "cumulus") < 0.05);
    atmos_volume_destroy(v);
}

/* The light pass of six wavelengths at once (in groups that share each texel's column) against
 * six passes of one wavelength each with the same optics: the same light at every particle
 * (within 1e-6) and the same scattering count (the mean of the six). */
static void light_groups(void)
{
    atmos_volume_generate_desc gd;
    memset(&gd, 0, sizeof gd);
    gd.seed = 5, gd.voxel_size_m = 100;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_generate(NULL, "cumulus", &gd, &v));
    const double off[3] = {0, 0, 0};
    atmos__pcloud pc;
    CHECK_OK(atmos__pcloud_from_volume(NULL, v, off, 100.0, 0, &pc));
    enum { NW = 6 };
    atmos__poptics o, o1;
    memset(&o, 0, sizeof o);
    o.nw = NW;
    for (int k = 0; k < NW; k++) o.sigma_ext[0][k] = (1.0 + 0.3 * k) * 1e-11, o.albedo[0][k] = 0.99 - 0.05 * k;
    double sun[3];
    atmos_direction_from_angles(35, 120, sun);
    const size_t n = (size_t)pc.n;
    float *light = malloc(sizeof(float) * n * NW), *order = malloc(sizeof(float) * n);
    float *l1 = malloc(sizeof(float) * n), *o1s = malloc(sizeof(float) * n), *mean = calloc(n, sizeof(float));
    CHECK_OK(atmos__pcloud_shade(NULL, &pc, NULL, 0, &o, sun, 0, 1.0, light, order));
    double worst = 0, worst_n = 0;
    for (int k = 0; k < NW; k++) {
        memset(&o1, 0, sizeof o1);
        o1.nw = 1, o1.sigma_ext[0][0] = o.sigma_ext[0][k], o1.albedo[0][0] = o.albedo[0][k];
        CHECK_OK(atmos__pcloud_shade(NULL, &pc, NULL, 0, &o1, sun, 0, 1.0, l1, o1s));
        for (size_t p = 0; p < n; p++) worst = fmax(worst, fabs(light[p * NW + k] - l1[p])), mean[p] += o1s[p] / NW;
    }
    for (size_t p = 0; p < n; p++) worst_n = fmax(worst_n, fabs(order[p] - mean[p]) / (mean[p] + 1.0));
    printf("light pass, %d wavelengths at once against one at a time: %d particles, light differs by %.3g, "
           "scattering count by %.3g\n", NW, pc.n, worst, worst_n);
    CHECK(worst <= 1e-6);
    CHECK(worst_n <= 1e-5);
    free(light), free(order), free(l1), free(o1s), free(mean);
    atmos__pcloud_free(&pc);
    atmos_volume_destroy(v);
}

/* One thin particle seen face on, isotropic scattering, against the single-scattering
 * integral a/(4 pi) E (1 - exp(-tau)) on the ray through its centre; and the same bytes
 * on 1 and 2 threads for a cloud of them. */
static void eye_pass(void)
{
    atmos__pcloud pc;
    memset(&pc, 0, sizeof pc);
    pc.nfields = 1;
    CHECK_OK(atmos__pcloud_add(&pc, 0, 0, -1000, 20, 1e9, 0));
    atmos__poptics o;
    memset(&o, 0, sizeof o);
    o.nw = 1;
    o.sigma_ext[0][0] = 1e-12, o.albedo[0][0] = 0.9;
    const float light[1] = {0.8f}, order[1] = {0.0f};
    const float *lp[1] = {light}, *op[1] = {order};
    const double sun[1][3] = {{0, 1, 0}}, sun_e[1][ATMOS_MAX_WAVELENGTHS] = {{1.5}};
    atmos_camera_desc cd;
    const double pos[3] = {0, 0, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &cd);
    cd.fov_deg = 10;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(NULL, &cd, 65, 65, &cam));
    atmos_image *img = NULL;
    CHECK_OK(atmos_image_create(NULL, 65, 65, 2, &img));
    const int rect[4] = {0, 0, 65, 65};
    int drawn = 0;
    const atmos__plights L1 = {1, lp, op, sun, sun_e, NULL, NULL, NULL};
    CHECK_OK(atmos__pcloud_splat(NULL, &pc, &o, &L1, NULL, 0, &cam, rect, img, &drawn));
    CHECK(drawn == 1);
    const double tau = 1e-12 * 1e9 * 20 * sqrt(2 * 3.141592653589793) * erf(3 / sqrt(2.0));
    const double want = 0.9 / (4 * 3.141592653589793) * 1.5 * 0.8 * (1 - exp(-tau));
    printf("eye pass: centre %.6g, single scattering %.6g (tau %.4f)\n", img->pixels[(32 * 65 + 32) * 2], want, tau);
    CHECK_REL(img->pixels[(32 * 65 + 32) * 2], want, 1e-3);
    CHECK_NEAR(img->pixels[(32 * 65 + 32) * 2 + 1], 1 - exp(-tau), 1e-4);
    CHECK(img->pixels[0] == 0.0f); /* the corner is beyond 3 s */
    /* many overlapping particles, 1 thread against 2 */
    for (int i = 0; i < 300; i++)
        CHECK_OK(atmos__pcloud_add(&pc, 30 * sin(i * 1.3), 30 * cos(i * 0.7), -900 - 0.5 * i, 5 + i % 7, 1e9, 0));
    float *lt = malloc(sizeof(float) * (size_t)pc.n), *od = calloc((size_t)pc.n, sizeof(float));
    for (int i = 0; i < pc.n; i++) lt[i] = 0.5f + 0.001f * i;
    const float *ltp[1] = {lt}, *odp[1] = {od};
    const atmos__plights L2 = {1, ltp, odp, sun, sun_e, NULL, NULL, NULL};
    atmos_image *img2 = NULL;
    CHECK_OK(atmos_image_create(NULL, 65, 65, 2, &img2));
#ifdef _OPENMP
    omp_set_num_threads(1);
#endif
    memset(img->pixels, 0, sizeof(float) * 65 * 65 * 2);
    CHECK_OK(atmos__pcloud_splat(NULL, &pc, &o, &L2, NULL, 0, &cam, rect, img, NULL));
#ifdef _OPENMP
    omp_set_num_threads(2);
#endif
    CHECK_OK(atmos__pcloud_splat(NULL, &pc, &o, &L2, NULL, 0, &cam, rect, img2, NULL));
    CHECK(memcmp(img->pixels, img2->pixels, sizeof(float) * 65 * 65 * 2) == 0);
    free(lt), free(od);
    atmos_image_destroy(img);
    atmos_image_destroy(img2);
    atmos__pcloud_free(&pc);
}

/* A small cloud of particles about c. */
static void blob(atmos__pcloud *pc, const double c[3], int n, double spread)
{
    for (int i = 0; i < n; i++)
        CHECK_OK(atmos__pcloud_add(pc, c[0] + spread * sin(i * 1.7), c[1] + spread * cos(i * 0.9),
                                   c[2] + spread * sin(i * 0.37 + 1), 40 + 10 * (i % 3), 4e8, 0));
}

static double rel_rms(const atmos_image *a, const atmos_image *b)
{
    double d2 = 0, r2 = 0;
    for (size_t i = 0; i < (size_t)a->width * a->height * a->channels; i++)
        d2 += (a->pixels[i] - b->pixels[i]) * (a->pixels[i] - b->pixels[i]), r2 += b->pixels[i] * b->pixels[i];
    return sqrt(d2 / r2);
}

/* An impostor's box of texels holding anything (atmos__pimpostor_make's) is tight, and drawing
 * only over the pixels that read it leaves every pixel's colour as drawing over the cloud's
 * whole sphere does (the same impostor without its box), bit for bit, the coverage within a
 * rounding (1 - (1 - a) for a); drawn over a frame that is not empty. */
static void texel_box_check(atmos__pimpostor *im, const double *c, const double *r, const atmos_camera *cam)
{
    const int R = im->res, C = im->img->channels, *b = im->box;
    int outside = 0, edge[4] = {0, 0, 0, 0};
    for (int y = 0; y < R; y++)
        for (int x = 0; x < R; x++)
            for (int k = 0; k < C; k++) {
                const float v = im->img->pixels[((size_t)y * R + x) * C + k];
                if (x < b[0] || x >= b[1] || y < b[2] || y >= b[3]) outside += v != 0.0f;
                else edge[0] |= x == b[0] && v != 0, edge[1] |= x == b[1] - 1 && v != 0, edge[2] |= y == b[2] && v != 0,
                    edge[3] |= y == b[3] - 1 && v != 0;
            }
    printf("impostor texel box [%d, %d) x [%d, %d) of %d\n", b[0], b[1], b[2], b[3], R);
    CHECK(im->has_box && outside == 0 && edge[0] && edge[1] && edge[2] && edge[3]);
    CHECK(b[1] - b[0] < R || b[3] - b[2] < R); /* the test means something: the box is smaller */
    const int W = cam->width, H = cam->height;
    atmos_image *boxed = NULL, *drawn = NULL;
    CHECK_OK(atmos_image_create(NULL, W, H, C, &boxed));
    CHECK_OK(atmos_image_create(NULL, W, H, C, &drawn));
    for (size_t i = 0; i < (size_t)W * H * C; i++) boxed->pixels[i] = drawn->pixels[i] = 0.1f + 0.3f * (float)(i % 7) / 7;
    atmos__pimpostor whole = *im;
    whole.has_box = 0;
    const atmos__pimpostor *one = im, *sphere = &whole;
    atmos__pimpostor_draw(NULL, 1, &one, &c, r, cam, (const int[4]){0, 0, W, H}, boxed);
    atmos__pimpostor_draw(NULL, 1, &sphere, &c, r, cam, (const int[4]){0, 0, W, H}, drawn);
    int colour = 0, cover = 0;
    for (size_t i = 0; i < (size_t)W * H * C; i++) {
        if ((int)(i % C) < C - 1) colour += memcmp(&boxed->pixels[i], &drawn->pixels[i], sizeof(float)) != 0;
        else cover += fabsf(boxed->pixels[i] - drawn->pixels[i]) > 1e-7f;
    }
    CHECK_MSG(colour == 0 && cover == 0, "texel box: %d colour values, %d coverages differ", colour, cover);
    atmos_image_destroy(boxed), atmos_image_destroy(drawn);
}

/* texel_box_check at the texture's edge: only the column before the last holds anything, which
 * a bilinear read clamped at the edge still takes (a thousandth of it) for rays beyond the last
 * column; seen magnified (a narrow camera at the impostor's eye looking at that edge), drawing
 * over the box's pixels gives the colours of drawing over the sphere's, bit for bit. */
static void texel_box_edge(atmos__pimpostor *im, const double *c, const double *r)
{
    const int R = im->res, C = im->img->channels;
    float *keep = malloc(sizeof(float) * (size_t)R * R * C);
    memcpy(keep, im->img->pixels, sizeof(float) * (size_t)R * R * C);
    memset(im->img->pixels, 0, sizeof(float) * (size_t)R * R * C);
    for (int y = 0; y < R; y++)
        for (int k = 0; k < C; k++) im->img->pixels[((size_t)y * R + R - 2) * C + k] = k < C - 1 ? 0.2f : 0.5f;
    const int box[4] = {im->box[0], im->box[1], im->box[2], im->box[3]};
    im->box[0] = R - 2, im->box[1] = R - 1, im->box[2] = 0, im->box[3] = R;
    atmos_camera_desc cd;
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, im->view, &cd);
    for (int i = 0; i < 3; i++) cd.look_at[i] = c[i] + 0.97 * r[0] * im->cam.right[i];
    cd.fov_deg = 1;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(NULL, &cd, 160, 160, &cam));
    atmos_image *boxed = NULL, *drawn = NULL;
    CHECK_OK(atmos_image_create(NULL, 160, 160, C, &boxed));
    CHECK_OK(atmos_image_create(NULL, 160, 160, C, &drawn));
    for (size_t i = 0; i < (size_t)160 * 160 * C; i++) boxed->pixels[i] = drawn->pixels[i] = 0.3f;
    atmos__pimpostor whole = *im;
    whole.has_box = 0;
    const atmos__pimpostor *one = im, *sphere = &whole;
    atmos__pimpostor_draw(NULL, 1, &one, &c, r, &cam, (const int[4]){0, 0, 160, 160}, boxed);
    atmos__pimpostor_draw(NULL, 1, &sphere, &c, r, &cam, (const int[4]){0, 0, 160, 160}, drawn);
    int colour = 0, touched = 0;
    for (size_t i = 0; i < (size_t)160 * 160 * C; i++)
        if ((int)(i % C) < C - 1) {
            colour += memcmp(&boxed->pixels[i], &drawn->pixels[i], sizeof(float)) != 0;
            touched += drawn->pixels[i] != 0.3f;
        }
    printf("texel box at the edge: %d colour values drawn, %d differ\n", touched, colour);
    CHECK(touched > 0);
    CHECK_MSG(colour == 0, "texel box at the edge: %d colour values differ", colour);
    memcpy(im->img->pixels, keep, sizeof(float) * (size_t)R * R * C);
    memcpy(im->box, box, sizeof box);
    free(keep);
    atmos_image_destroy(boxed), atmos_image_destroy(drawn);
}

/* The impostor tests' light: one sun (40 degrees up, azimuth 100) on pc's particles, grey
 * droplets of albedo 0.9, its light pass made; L points into the struct (sunlit_free after). */
typedef struct sunlit {
    atmos__poptics o;
    float *light, *order;
    const float *lp[1], *op[1];
    double sun[1][3], e1[1][ATMOS_MAX_WAVELENGTHS];
    atmos__plights L;
} sunlit;

static void sunlit_make(sunlit *s, const atmos__pcloud *pc)
{
    memset(s, 0, sizeof *s);
    s->o.nw = 1, s->o.sigma_ext[0][0] = 1e-11, s->o.albedo[0][0] = 0.9;
    s->light = malloc(sizeof(float) * (size_t)pc->n), s->order = malloc(sizeof(float) * (size_t)pc->n);
    atmos_direction_from_angles(40, 100, s->sun[0]);
    CHECK_OK(atmos__pcloud_shade(NULL, pc, NULL, 0, &s->o, s->sun[0], 0, 1.0, s->light, s->order));
    s->lp[0] = s->light, s->op[0] = s->order, s->e1[0][0] = 1.0;
    const atmos__plights L = {1, s->lp, s->op, s->sun, s->e1, NULL, NULL, NULL};
    s->L = L;
}

/* Clouds found as connected particles; an impostor drawn from where it was made matches the
 * particles splatted directly (within its resampling), drifts as the eye moves round the
 * cloud, and stops serving beyond the tolerance angle, inside the cloud or when too coarse. */
static void impostors(void)
{
    atmos__pcloud pc;
    memset(&pc, 0, sizeof pc);
    pc.nfields = 1;
    const double c1[3] = {0, 2000, -6000}, c2[3] = {3000, 2000, -6000};
    blob(&pc, c1, 200, 300), blob(&pc, c2, 150, 250);
    atmos__pclusters cl;
    CHECK_OK(atmos__pcloud_cluster(NULL, &pc, 0, &cl));
    CHECK(cl.n == 2);
    CHECK(cl.n == 2 && cl.start[1] == 200 && cl.idx[0] == 0 && cl.idx[200] == 200);
    sunlit sl;
    sunlit_make(&sl, &pc);
    const atmos__poptics o = sl.o;
    const atmos__plights L = sl.L;
    atmos_camera_desc cd;
    const double eye[3] = {0, 1800, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, eye, &cd);
    memcpy(cd.look_at, c1, sizeof cd.look_at);
    cd.fov_deg = 20;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(NULL, &cd, 160, 160, &cam));
    atmos_image *direct = NULL, *imp = NULL;
    CHECK_OK(atmos_image_create(NULL, 160, 160, 2, &direct));
    CHECK_OK(atmos_image_create(NULL, 160, 160, 2, &imp));
    const int rect[4] = {0, 0, 160, 160}, *idx = cl.idx + cl.start[0], nidx = cl.start[1] - cl.start[0];
    CHECK_OK(atmos__pcloud_splat(NULL, &pc, &o, &L, idx, nidx, &cam, rect, direct, NULL));
    const double f = 160 / (2 * tan(10 * 3.141592653589793 / 180));
    atmos__pimpostor im;
    memset(&im, 0, sizeof im);
    const atmos__pimpostor *one = &im;
    const double *cc = cl.centre[0];
    const int res = atmos__pimpostor_res(cl.radius[0], 6000, f, 512);
    CHECK_OK(atmos__pimpostor_make(NULL, &im, &pc, &o, &L, idx, nidx, cl.centre[0], cl.radius[0], eye, res));
    atmos__pimpostor_draw(NULL, 1, &one, &cc, cl.radius, &cam, rect, imp);
    const double e0 = rel_rms(imp, direct);
    /* the eye 0.5 degree round the cloud: the stale impostor against the direct splats */
    double eye2[3];
    const double ang = 0.5 * 3.141592653589793 / 180;
    eye2[0] = c1[0] + (eye[0] - c1[0]) * cos(ang) + (eye[2] - c1[2]) * sin(ang), eye2[1] = eye[1];
    eye2[2] = c1[2] - (eye[0] - c1[0]) * sin(ang) + (eye[2] - c1[2]) * cos(ang);
    memcpy(cd.position, eye2, sizeof cd.position);
    CHECK_OK(atmos_camera_init(NULL, &cd, 160, 160, &cam));
    memset(direct->pixels, 0, sizeof(float) * 160 * 160 * 2), memset(imp->pixels, 0, sizeof(float) * 160 * 160 * 2);
    CHECK_OK(atmos__pcloud_splat(NULL, &pc, &o, &L, idx, nidx, &cam, rect, direct, NULL));
    atmos__pimpostor_draw(NULL, 1, &one, &cc, cl.radius, &cam, rect, imp);
    const double e05 = rel_rms(imp, direct);
    printf("impostor: %d texels, rel rms against the splats %.4f where made, %.4f 0.5 degree round\n", res, e0, e05);
    texel_box_check(&im, cl.centre[0], cl.radius, &cam);
    texel_box_edge(&im, cl.centre[0], cl.radius);
    CHECK(e0 < 0.03);
    CHECK(e05 > e0);
    CHECK(atmos__pimpostor_serves(&im, cl.centre[0], cl.radius[0], eye, 0.15 * 3.141592653589793 / 180, f, 512));
    CHECK(!atmos__pimpostor_serves(&im, cl.centre[0], cl.radius[0], eye2, 0.15 * 3.141592653589793 / 180, f, 512));
    CHECK(atmos__pimpostor_serves(&im, cl.centre[0], cl.radius[0], eye2, 1.0 * 3.141592653589793 / 180, f, 512));
    const double near[3] = {c1[0], c1[1], c1[2] + 2 * cl.radius[0]}, inside[3] = {c1[0], c1[1], c1[2] + 10};
    CHECK(!atmos__pimpostor_serves(&im, cl.centre[0], cl.radius[0], near, 0.1, f, 512)); /* too coarse */
    CHECK(!atmos__pimpostor_serves(&im, cl.centre[0], cl.radius[0], inside, 3.0, f, 512));
    /* how far out of date: the angle round the centre over the tolerance, the texels wanted over
     * those made; never made or inside the sphere: infinite */
    const double deg = 3.141592653589793 / 180;
    CHECK(atmos__pimpostor_error(&im, cl.centre[0], cl.radius[0], eye, 0.15 * deg, f, 512) <= 1.0);
    const double e2 = atmos__pimpostor_error(&im, cl.centre[0], cl.radius[0], eye2, 0.15 * deg, f, 512);
    printf("impostor error 0.5 degree round, tolerance 0.15: %.4f (expect 3.333)\n", e2);
    CHECK(fabs(e2 - 0.5 / 0.15) < 0.01);
    CHECK(atmos__pimpostor_error(&im, cl.centre[0], cl.radius[0], near, 0.1, f, 512) > 1.0);
    CHECK(isinf(atmos__pimpostor_error(&im, cl.centre[0], cl.radius[0], inside, 3.0, f, 512)));
    atmos__pimpostor never;
    memset(&never, 0, sizeof never);
    CHECK(isinf(atmos__pimpostor_error(&never, cl.centre[0], cl.radius[0], eye, 0.15 * deg, f, 512)));
    atmos__pimpostor_free(&im);
    atmos_image_destroy(direct), atmos_image_destroy(imp);
    free(sl.light), free(sl.order);
    atmos__pclusters_free(&cl);
    atmos__pcloud_free(&pc);
}

/* An impostor's texels limited by its narrowest particle (atmos__pimpostor_max_res): the
 * fewest texels, in multiples of 8, in which that particle's width spans
 * ATMOS__PIMPOSTOR_TEXELS_PER_WIDTH texels. Seen so near that the view wants four times as
 * many, the impostor at the limit matches the particles splatted directly at the screen's
 * pixels (the independent reference) about as well as the one with every texel wanted. */
static void impostor_texels(void)
{
    atmos__pcloud pc;
    memset(&pc, 0, sizeof pc);
    pc.nfields = 1;
    const double c1[3] = {0, 2000, -6000};
    blob(&pc, c1, 200, 300);
    atmos__pclusters cl;
    CHECK_OK(atmos__pcloud_cluster(NULL, &pc, 0, &cl));
    double smin = INFINITY;
    for (int i = 0; i < pc.n; i++) smin = fmin(smin, pc.s[i]);
    const double r = cl.radius[0], K = ATMOS__PIMPOSTOR_TEXELS_PER_WIDTH;
    const int cap = atmos__pimpostor_max_res(r, smin, 512);
    printf("impostor texels: radius %.0f m, narrowest particle %.0f m: at most %d\n", r, smin, cap);
    CHECK(cap % 8 == 0 && smin * cap / (2 * r) >= K && smin * (cap - 8) / (2 * r) < K);
    CHECK(atmos__pimpostor_max_res(r, smin, 16) == 16);       /* never above the scene's limit */
    CHECK(atmos__pimpostor_max_res(r, 0.0, 512) == 512);      /* no width: the scene's limit */
    CHECK(atmos__pimpostor_max_res(1.0, 1000.0, 512) == 8);   /* at least 8 */
    sunlit sl;
    sunlit_make(&sl, &pc);
    const atmos__poptics o = sl.o;
    const atmos__plights L = sl.L;
    /* the eye so near that the cloud wants 4 cap texels across on a 320-pixel frame */
    enum { S = 320 };
    const double fov = 60, f = S / (2 * tan(0.5 * fov * 3.141592653589793 / 180)), d = 2 * r * f / (4 * cap);
    const double eye[3] = {c1[0], c1[1] - 0.3 * d, c1[2] + d * sqrt(1 - 0.09)};
    atmos_camera_desc cd;
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, eye, &cd);
    memcpy(cd.look_at, c1, sizeof cd.look_at);
    cd.fov_deg = fov;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(NULL, &cd, S, S, &cam));
    CHECK(atmos__pimpostor_res(r, d, f, 512) >= 4 * cap);
    atmos_image *direct = NULL, *img[2] = {NULL, NULL};
    CHECK_OK(atmos_image_create(NULL, S, S, 2, &direct));
    const int rect[4] = {0, 0, S, S}, *idx = cl.idx, nidx = cl.start[1];
    CHECK_OK(atmos__pcloud_splat(NULL, &pc, &o, &L, idx, nidx, &cam, rect, direct, NULL));
    double e[2];
    for (int i = 0; i < 2; i++) {
        atmos__pimpostor im;
        memset(&im, 0, sizeof im);
        const atmos__pimpostor *one = &im;
        const double *cc = cl.centre[0];
        CHECK_OK(atmos_image_create(NULL, S, S, 2, &img[i]));
        CHECK_OK(atmos__pimpostor_make(NULL, &im, &pc, &o, &L, idx, nidx, cl.centre[0], r, eye, i ? 4 * cap : cap));
        atmos__pimpostor_draw(NULL, 1, &one, &cc, cl.radius, &cam, rect, img[i]);
        e[i] = rel_rms(img[i], direct);
        atmos__pimpostor_free(&im);
    }
    printf("impostor texels: rel rms against the splats %.4f at %d texels, %.4f at %d\n", e[0], cap, e[1], 4 * cap);
    CHECK(e[0] < 0.03 && e[0] < e[1] + 0.01);
    atmos_image_destroy(direct), atmos_image_destroy(img[0]), atmos_image_destroy(img[1]);
    free(sl.light), free(sl.order);
    atmos__pclusters_free(&cl);
    atmos__pcloud_free(&pc);
}

/* The generated particle clouds: the same particles for a seed, a field of 120 separate
 * clouds (as the impostors need them), and their grid through the scene's generator (the
 * cloud every renderer sees) holding their mass. */
static void generated(void)
{
    atmos__pcloud a, b;
    double va, vb;
    CHECK_OK(atmos__pcloud_generate(NULL, "harris_field", 7, 1.0, 0.0, &a, &va));
    CHECK_OK(atmos__pcloud_generate(NULL, "harris_field", 7, 1.0, 0.0, &b, &vb));
    CHECK(a.n == b.n && a.n > 50000 && va == vb);
    CHECK(a.n == b.n && !memcmp(a.x, b.x, sizeof(float) * (size_t)a.n) && !memcmp(a.n0, b.n0, sizeof(float) * (size_t)a.n));
    atmos__pclusters cl;
    CHECK_OK(atmos__pcloud_cluster(NULL, &a, 0, &cl));
    printf("harris_field: %d particles, %d clouds, grid voxel %.1f m\n", a.n, cl.n, va);
    CHECK(cl.n == 120);
    atmos__pclusters_free(&cl);
    atmos__pcloud_free(&b);
    atmos_volume_generate_desc gd;
    memset(&gd, 0, sizeof gd);
    gd.seed = 2;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_scene_generate_volume(NULL, "harris_cumulus", &gd, &v));
    CHECK_OK(atmos__pcloud_generate(NULL, "harris_cumulus", 2, 1.0, 0.0, &b, &vb));
    double mass = 0, want = 0, lo[3], hi[3];
    for (int p = 0; p < b.n; p++) want += b.n0[p] * 0.9707091134651118 * 15.749609945722419 * pow(b.s[p], 3);
    atmos_volume_bounds(v, lo, hi);
    for (double z = lo[2] + 0.5 * vb; z < hi[2]; z += vb)
        for (double y = lo[1] + 0.5 * vb; y < hi[1]; y += vb)
            for (double x = lo[0] + 0.5 * vb; x < hi[0]; x += vb) {
                const double p[3] = {x, y, z};
                mass += atmos_volume_sample(v, 0, p) * vb * vb * vb;
            }
    printf("harris_cumulus: %d particles, grid mass %.5g of %.5g\n", b.n, mass, want);
    CHECK_REL(mass, want, 0.02);
    /* a given spacing (the scene's "harris": {"spacing_m"}) samples the same cloud finer: about
     * 8 times the particles at half the preset's spacing (1100 m / 24), the same droplets */
    atmos__pcloud fine;
    double vf, fine_mass = 0;
    CHECK_OK(atmos__pcloud_generate(NULL, "harris_cumulus", 2, 1.0, 0.5 * 1100.0 / 24.0, &fine, &vf));
    for (int p = 0; p < fine.n; p++) fine_mass += fine.n0[p] * 0.9707091134651118 * 15.749609945722419 * pow(fine.s[p], 3);
    printf("harris_cumulus at half the spacing: %d particles (%.2f times), mass %.5g of %.5g\n", fine.n,
           (double)fine.n / b.n, fine_mass, want);
    CHECK(fine.n > 7 * b.n && fine.n < 9 * b.n);
    CHECK_REL(fine_mass, want, 0.03);
    atmos__pcloud_free(&fine);
    int known = 0;
    for (const char *const *n = atmos_scene_generator_names(); *n; n++) known += !strcmp(*n, "harris_field") + !strcmp(*n, "cumulus");
    CHECK(known == 2);
    atmos_volume_destroy(v);
    atmos__pcloud_free(&a), atmos__pcloud_free(&b);
}

int main(void)
{
    convert();
    generated();
    impostors();
    impostor_texels();
    light_pass();
    light_groups();
    eye_pass();
    return test_summary("test_particles");
}
