/* Slicing stripes: a wide, flat volume seen obliquely from above (as a WRF domain is) was
 * sampled by 256 planes spread over its whole extent along the half-angle axis, a few
 * planes per column of the thin layer, and showed diagonal bands that vanish at 2048
 * slices. With the slice count left to the renderer (docs/slice.md, "Slice count") the
 * image must match a 2048-slice reference within a bound; 256 explicit slices are still
 * honoured (and still band, which the test also checks so that it can fail). */
#include "atmos/atmos.h"
#include "test.h"
#include "test_optics.h"

#define NX 256
#define NY 3
#define VOX 500.0

/* A slab 128 km x 1.5 km x 128 km of uniform density, halved in its outer voxels, base at 1 km. */
static atmos_volume *slab(atmos_context *ctx, double density, int nx, int ny)
{
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = nx, vd.dims[1] = ny, vd.dims[2] = nx;
    vd.voxel_size_m = VOX;
    vd.origin_m[0] = -nx * VOX / 2, vd.origin_m[1] = 1000, vd.origin_m[2] = -nx * VOX / 2 - 30000;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    int f = -1;
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "hg07", &f));
    static float buf[NX * NY * NX];
    for (int k = 0; k < nx; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                int edge = i < 2 || k < 2 || i >= nx - 2 || k >= nx - 2;
                buf[((size_t)k * ny + j) * nx + i] = (float)(edge ? 0.5 * density : density);
            }
    int off[3] = {0, 0, 0}, size[3] = {nx, ny, nx};
    CHECK_OK(atmos_volume_set_dense(ctx, v, f, off, size, buf, 1.0f));
    CHECK_OK(atmos_volume_finalize(ctx, v));
    return v;
}

typedef test_optics optics;

/* Henyey-Greenstein g = 0.7, sigma_ext 1e-9 m^2, albedo 0.95: quick to build. */
static void make_optics(atmos_context *ctx, optics *op)
{
    test_hg_optics(ctx, "hg07", 0.7, 0.95, 1, op);
}

/* slices 0: the renderer's choice. The camera looks down at about 37 degrees from 25 km;
 * low: from 6 km at about 7.6 degrees, the sun 3 degrees up (the half-angle axis almost
 * level, so the slab's thinnest extent along it is its width). */
static atmos_image *render_view(atmos_context *ctx, const atmos_volume *v, const optics *op, int slices, int low)
{
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.width = 96, s.height = 64;
    s.samples_per_pixel = 1;
    const double pos[3] = {0, low ? 6000 : 25000, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s.camera);
    s.camera.look_at[0] = 0, s.camera.look_at[1] = low ? 2000 : 2500, s.camera.look_at[2] = -30000;
    s.camera.fov_deg = 50;
    s.sun.from_time = 0;
    s.sun.elevation_deg = low ? 3 : 30;
    s.sun.azimuth_deg = 120;
    s.wavelengths = ATMOS_WAVELENGTHS_RGB;
    s.slice.slices = slices;
    s.slice.light_size = 128;
    atmos_slice_settings ss;
    atmos_slice_defaults(&ss);
    ss.optics = &op->o;
    atmos_image *img = NULL;
    atmos_status st = atmos_render_slice(ctx, &s, v, &ss, &img, NULL);
    CHECK_MSG(st == ATMOS_OK, "render with %d slices: %s", slices, atmos_context_error(ctx));
    return img;
}

static atmos_image *render(atmos_context *ctx, const atmos_volume *v, const optics *op, int slices)
{
    return render_view(ctx, v, op, slices, 0);
}

/* Root-mean-square difference to the reference over the pixels the volume covers
 * (alpha > 0.5), relative to the reference's mean there. */
static double rel_rms(const atmos_image *a, const atmos_image *ref)
{
    double d2 = 0, m = 0;
    long n = 0;
    for (int p = 0; p < a->width * a->height; p++) {
        if (ref->pixels[p * 4 + 3] < 0.5f) continue;
        for (int c = 0; c < 3; c++) {
            double d = (double)a->pixels[p * 4 + c] - ref->pixels[p * 4 + c];
            d2 += d * d, m += ref->pixels[p * 4 + c], n++;
        }
    }
    return n ? sqrt(d2 / n) / (m / n) : INFINITY;
}

/* Seen low with a low sun, the planes stand almost upright: the slab's thinnest extent along
 * h is its width and asks for few planes, but a ray through the thin layer must still not
 * step over a voxel (docs/slice.md, "Slice count"). */
static void test_low_view(atmos_context *ctx, const atmos_volume *v, const optics *op)
{
    atmos_image *ref = render_view(ctx, v, op, 2048, 1), *fixed = render_view(ctx, v, op, 256, 1);
    atmos_image *chosen = render_view(ctx, v, op, 0, 1);
    if (ref && fixed && chosen) {
        const double e256 = rel_rms(fixed, ref), eauto = rel_rms(chosen, ref);
        const char *used = atmos_image_get_meta(chosen, "atmos:slice");
        printf("low view, relative rms difference to 2048 slices: 256 slices %.5f, renderer's choice %.5f (%s)\n", e256,
               eauto, used ? used : "?");
        /* two samples a voxel along the rays: 406 slices, 0.0058 against 256 slices' 0.0095 */
        CHECK_MSG(eauto < 0.7 * e256, "the renderer's choice %g not below 0.7 of 256 slices' %g", eauto, e256);
    }
    atmos_image_destroy(ref);
    atmos_image_destroy(fixed);
    atmos_image_destroy(chosen);
}

int main(void)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 2;
    d.log = NULL;
    atmos_context *ctx = NULL;
    if (atmos_context_create(&d, &ctx) != ATMOS_OK) return 1;
    optics op;
    make_optics(ctx, &op);
    atmos_volume *v = slab(ctx, 4e5, NX, NY); /* vertical optical depth 0.6 */
    atmos_image *ref = render(ctx, v, &op, 2048), *fixed = render(ctx, v, &op, 256), *chosen = render(ctx, v, &op, 0);
    if (ref && fixed && chosen) {
        double e256 = rel_rms(fixed, ref), eauto = rel_rms(chosen, ref);
        const char *used = atmos_image_get_meta(chosen, "atmos:slice");
        printf("wide flat slab, relative rms difference to 2048 slices: 256 slices %.5f, renderer's choice %.5f (%s)\n",
               e256, eauto, used ? used : "?");
        /* the banding, so that the test can fail: measured 0.0090, 0.0033 since the beam's own
           attenuation across a slab is integrated (atmos__slice_beam_len) */
        CHECK(e256 > 0.002);
        /* the renderer's choice (1847 slices here) within a tenth of 256's banding: measured 7e-5;
           fails for a count below about 1250 */
        CHECK(eauto < 0.1 * e256);
    }
    test_low_view(ctx, v, &op);
    /* A compact volume (32 x 24 x 32 voxels) keeps the former fixed count, 256. */
    atmos_volume *cube = slab(ctx, 4e6, 32, 24);
    atmos_image *c = render(ctx, cube, &op, 0);
    const char *used = c ? atmos_image_get_meta(c, "atmos:slice") : NULL;
    printf("compact volume: %s\n", used ? used : "?");
    CHECK(used && strncmp(used, "256 slices (chosen)", 19) == 0);
    atmos_image_destroy(c);
    atmos_volume_destroy(cube);
    atmos_image_destroy(ref);
    atmos_image_destroy(fixed);
    atmos_image_destroy(chosen);
    atmos_volume_destroy(v);
    atmos_msphase_destroy(op.m);
    atmos_phase_table_destroy(op.t);
    atmos_context_destroy(ctx);
    return test_summary("test_slice_banding");
}
