/* Sky light alone (the sun off) on a thin cloud: the slice renderer with the diffuse light
 * field against the path tracer. The sky is uniform (a vacuum atmosphere with a background
 * radiance from every direction) and the sun's irradiance is zero, so the forward model's
 * light buffer is dark and all the cloud's light is the sky's, which reaches it only through
 * the field's boundary sources and diffusion. Without the field the cloud is a dark
 * absorber in front of the sky; with it, it scatters the sky's light as the path tracer
 * does. Albedo 0.9, so that the cloud is not simply as bright as the sky (a conservative
 * cloud in a uniform sky is). Measured (256 paths per pixel): with the field bias +2.0 %,
 * relative RMS 0.047 (+1.9 %, 0.045 before the cold start's cascade); without it -35 % and
 * 0.49. The same for the discrete-ordinates field, whose sky's light enters its sweeps through
 * the grid's faces (slice "do" and the Nishita renderer's "do"; nishita_do.c): without that
 * inflow they are the dark absorber too (the Nishita renderer's with its sky off). Small sizes
 * (a 32^3 blob, 32 x 32 pixels) keep it fast. */
#include "atmos/atmos.h"
#include "test.h"
#include "test_blob.h"
#include "test_optics.h"

#define W 32
#define SKY 0.2 /* the sky's radiance, W m^-2 sr^-1 nm^-1 */

static char cache_dir[1024];


static void scene_for(atmos_scene *s)
{
    atmos_scene_defaults(s);
    s->width = s->height = W;
    double pos[3] = {0, 1500, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    s->camera.look_at[0] = 0, s->camera.look_at[1] = 1500, s->camera.look_at[2] = -1000;
    s->camera.fov_deg = 45;
    s->sun.from_time = 0;
    s->sun.elevation_deg = 40, s->sun.azimuth_deg = 150;
    s->sun.irradiance_count = 1, s->sun.irradiance[0] = 0.0; /* the sun off */
    s->atmosphere.kind = ATMOS_ATMOSPHERE_VACUUM;
    s->atmosphere.background_radiance = SKY;
    s->wavelengths = ATMOS_WAVELENGTHS_RGB;
}

/* The slice renderer: field 0 none, 1 the P1 diffuse field, 2 the discrete-ordinates field. */
static atmos_image *slice(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *v,
                          const atmos_volume_optics *o, int field)
{
    atmos_scene s = *scene;
    atmos_slice_settings ss;
    atmos_slice_defaults(&ss);
    ss.optics = o;
    s.slice.light_size = 96;
    s.slice.xi = 0; /* no ambient term: the sky's light is the field's alone */
    s.slice.field = field == 0 ? ATMOS_SLICE_FIELD_NONE : field == 1 ? ATMOS_SLICE_FIELD_P1 : ATMOS_SLICE_FIELD_DO;
    atmos_image *img = NULL;
    CHECK_MSG(atmos_render_slice(ctx, &s, v, &ss, &img, NULL) == ATMOS_OK, "slice: %s", atmos_context_error(ctx));
    return img;
}

/* The Nishita renderer with the discrete-ordinates field (its first order and the field; the
 * sky's light the field's inflow when sky). */
static atmos_image *nishita_do(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *v,
                               const atmos_volume_optics *o, int sky)
{
    atmos_scene s = *scene;
    s.renderer = ATMOS_RENDERER_NISHITA;
    s.nishita.orders = 1, s.nishita.sky = sky, s.nishita.mc_kphotons = 0, s.nishita.do_field = 1;
    s.nishita.mc_lmax = 3, s.nishita.mc_delta_m = 1;
    return test_plan_frame(ctx, &s, v, o);
}

/* Over the cloud's pixels (where the path tracer's image differs from the sky by more than
 * 1 %): the relative bias of img against ref and its relative RMS difference. */
static void cloud_error(const atmos_image *img, const atmos_image *ref, const atmos_image *dark, double *bias,
                        double *rms, int *pixels)
{
    double sd = 0, sr = 0, s2 = 0;
    int cnt = 0;
    for (int p = 0; p < W * W; p++) {
        const double r = ref->pixels[p * 4 + 1], m = img->pixels[p * 4 + 1], d = dark->pixels[p * 4 + 1];
        if (fabs(d - SKY) < 0.01 * SKY) continue; /* the cloud's pixels: where it dims the sky */
        sd += m - r, sr += r, s2 += (m - r) * (m - r) / (r * r), cnt++;
    }
    *bias = cnt ? sd / sr : 0, *rms = cnt ? sqrt(s2 / cnt) : 0, *pixels = cnt;
}

int main(void)
{
    test_tmp_path(cache_dir, sizeof cache_dir, "cache");
    atmos_context *ctx = test_context(2, cache_dir);
    test_optics op;
    test_hg_optics(ctx, "hg085", 0.85, 0.9, 1, &op);
    /* peak 1.5e7 m^-3: optical depth ~2.7 through the centre, ~0.5 near the rim */
    atmos_volume *v = test_blob(ctx, 1.5e7f);
    atmos_scene s;
    scene_for(&s);
    s.samples_per_pixel = 1;
    s.path.spp = 256;
    atmos_path_settings ps;
    atmos_path_defaults(&ps);
    ps.optics = &op.o;
    atmos_image *ref = NULL;
    CHECK_OK(atmos_render_path(ctx, &s, v, &ps, &ref, NULL));
    atmos_image *with = slice(ctx, &s, v, &op.o, 1), *without = slice(ctx, &s, v, &op.o, 0),
                *sdo = slice(ctx, &s, v, &op.o, 2), *ndo = nishita_do(ctx, &s, v, &op.o, 1),
                *ndo_dark = nishita_do(ctx, &s, v, &op.o, 0);
    CHECK(with && without && sdo && ndo && ndo_dark);
    if (!with || !without || !sdo || !ndo || !ndo_dark) return test_summary("test_slice_sky");
    double bw, rw, bo, ro;
    int nw, no;
    cloud_error(with, ref, without, &bw, &rw, &nw);
    cloud_error(without, ref, without, &bo, &ro, &no);
    printf("sky alone, %d cloud pixels: with the field bias %+.2f %% rms %.3f; without bias %+.2f %% rms %.3f\n", nw,
           100 * bw, rw, 100 * bo, ro);
    CHECK(nw > 100);
    CHECK(bo < -0.15); /* without the field the cloud is far too dark */
    CHECK(fabs(bw) < 0.05);
    CHECK(rw < 0.08);
    double bs, rs, bn, rn, bd, rd;
    int ns, nn, nd;
    cloud_error(sdo, ref, without, &bs, &rs, &ns);
    cloud_error(ndo, ref, without, &bn, &rn, &nn);
    cloud_error(ndo_dark, ref, without, &bd, &rd, &nd);
    printf("discrete ordinates: slice do bias %+.2f %% rms %.3f; Nishita do %+.2f %% rms %.3f; Nishita do without "
           "the sky %+.2f %% rms %.3f\n",
           100 * bs, rs, 100 * bn, rn, 100 * bd, rd);
    CHECK(bd < -0.15); /* without the sky's inflow as dark as without a field */
    CHECK(fabs(bs) < 0.05 && fabs(bn) < 0.05);
    CHECK(rs < 0.08 && rn < 0.08);
    /* with the sky every wavelength is solved (the first on both threads, the others one a thread,
       in parallel): the same bytes on one thread */
    atmos_context *ctx1 = test_context(1, cache_dir);
    atmos_image *sdo1 = slice(ctx1, &s, v, &op.o, 2);
    CHECK(sdo1 && sdo1->width == sdo->width && sdo1->height == sdo->height && sdo1->channels == sdo->channels);
    if (sdo1 && sdo1->width == sdo->width && sdo1->height == sdo->height && sdo1->channels == sdo->channels)
        CHECK(!memcmp(sdo1->pixels, sdo->pixels, sizeof(float) * sdo->width * sdo->height * sdo->channels));
    atmos_image_destroy(sdo1);
    atmos_context_destroy(ctx1);
    atmos_image_destroy(sdo), atmos_image_destroy(ndo), atmos_image_destroy(ndo_dark);
    atmos_image_destroy(ref), atmos_image_destroy(with), atmos_image_destroy(without);
    atmos_volume_destroy(v);
    test_optics_free(&op);
    atmos_context_destroy(ctx);
    return test_summary("test_slice_sky");
}
