/* The slice renderer's plan (Riley et al. 2004 §4.2-§5; include/atmos/slice.h): what every
 * frame shares (the volume box-filtered onto the render grid, the optics tables, the light
 * ring, the per-pixel planes and spans grown to the largest frame so far, the light frame of
 * the last sun), and a frame: the sky, the job, the slices, the §5 composite. */
#include "atmosphere/atmosphere_ops.h"
#include "render/slice_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void atmos__slice_plan_destroy(atmos__slice_plan *sp)
{
    if (!sp) return;
    atmos__sgrid_free(&sp->g);
    atmos__stables_free(&sp->tab);
    free(sp->pixblock), free(sp->spans), free(sp->lk), free(sp->ring), free(sp->I), free(sp->nsc);
    free(sp->light.ta), free(sp->light.tb), free(sp->light.hit), free(sp->light.sl);
    free(sp->edge);
    atmos__aerial_free(&sp->aerial);
    atmos__dfield_free(&sp->df);
    atmos__slice_do_free(sp);
    atmos__slice_shadow_free(sp);
    free(sp);
}

/* The light ring: B + 1 slots of L^2 texels of n + 1 floats (I per wavelength, then n: one
 * cache line serves all of a texel), B up to 16 within 32 MB. Slots are padded by three
 * cache lines so that they do not alias in the caches. Also the texels' slice ranges and the
 * light frame's per-texel arrays. */
static int light_buffers(atmos_context *ctx, atmos__slice_plan *sp)
{
    const size_t LL = (size_t)sp->L * sp->L, slotf = LL * (size_t)(sp->n + 1) + 48, slot = sizeof(float) * slotf;
    const size_t fit = ((size_t)32 << 20) / slot;
    sp->batch = fit > 17 ? 16 : (fit > 2 ? (int)fit - 1 : 1);
    /* the per-texel arrays' sizes, each allocated and counted from the same figure */
    const size_t ring_b = slot * (size_t)(sp->batch + 1), lk_b = sizeof(int) * LL * 2, t_b = sizeof(double) * LL,
                 sl_b = sizeof(float) * LL * (size_t)sp->n;
    const double bytes = (double)ring_b + lk_b + 2.0 * t_b + LL + sl_b;
    if (bytes > (double)(1u << 30)) /* a large light_size's cost, before it is paid */
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "render slice: light_size %d takes about %.1f GB for the light buffers (%.0f bytes a texel) and time "
                   "in proportion; 256 (the default) to 2048 are the usual sizes", sp->L, bytes / 1e9, bytes / (double)LL);
    sp->ring = atmos__big_alloc(ring_b);
    sp->I = malloc(sizeof(float *) * (size_t)(sp->batch + 1));
    sp->nsc = malloc(sizeof(float *) * (size_t)(sp->batch + 1));
    sp->lk = malloc(lk_b);
    sp->light.ta = malloc(t_b);
    sp->light.tb = malloc(t_b);
    sp->light.hit = malloc(LL);
    sp->light.sl = malloc(sl_b);
    if (!sp->ring || !sp->I || !sp->nsc || !sp->lk || !sp->light.ta || !sp->light.tb || !sp->light.hit || !sp->light.sl)
        return 0;
    for (int q = 0; q <= sp->batch; q++) {
        sp->I[q] = sp->ring + (size_t)q * slotf;
        sp->nsc[q] = sp->I[q] + sp->n;
    }
    return 1;
}

atmos_status atmos__slice_plan_create(atmos_plan *p, atmos__slice_plan **out)
{
    atmos_context *ctx = p->ctx;
    const atmos_scene_slice *ss = &p->scene.slice;
    const double t0 = atmos__now();
    atmos__slice_plan *sp = calloc(1, sizeof *sp);
    if (!sp) return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory");
    sp->n = p->wl.count;
    sp->nf = atmos_volume_field_count(p->volume);
    sp->L = ss->light_size;
    sp->low_albedo = ss->low_albedo;
    sp->eq24 = ss->eq24;
    sp->xi = (float)ss->xi;
    sp->edge_aa = ss->edge_aa;
    const atmos_slice_field field = atmos_scene_slice_field(ss); /* "field" (scene_slice_field.c) */
    sp->do_field = field == ATMOS_SLICE_FIELD_DO && !ss->low_albedo;
    sp->diffuse = field == ATMOS_SLICE_FIELD_P1 && !ss->low_albedo;
    sp->reference = p->reference;
    sp->air_shadows = ss->air_shadows;
    atmos__vol_xform_init(p->volume, p->offset, &sp->x);
    atmos_status st = atmos__sgrid_build(ctx, p->volume, p->scene.volume.density_scale, ss->grid_max_dim, &sp->g);
    if (st == ATMOS_OK && sp->g.v) st = atmos__stables_build(ctx, p->optics, sp->n, ss->max_order, &sp->tab);
    if (st == ATMOS_OK && sp->g.v && !light_buffers(ctx, sp))
        st = atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the light buffer");
    if (st == ATMOS_OK && sp->g.v && sp->diffuse)
        st = atmos__dfield_prepare(ctx, &sp->df, &sp->g, &sp->tab, &sp->x, p->optics, "render slice");
    if (st == ATMOS_OK && sp->g.v && sp->do_field) st = atmos__slice_do_prepare(p, sp);
    if (st != ATMOS_OK) {
        atmos__slice_plan_destroy(sp);
        return st;
    }
    sp->prepare_s = atmos__now() - t0;
    *out = sp;
    return ATMOS_OK;
}

/* The eye buffer's size for a view (as job_geometry sets it). */
static void eye_size(const atmos__view *v, int *w, int *h)
{
    *w = v->cam.width, *h = v->cam.height;
    if (v->eye_scale != 1.0) {
        int we = (int)lround(v->eye_scale * v->cam.width), he = (int)lround(v->eye_scale * v->cam.height);
        *w = we < 1 ? 1 : we, *h = he < 1 ? 1 : he;
    }
}

void atmos__slice_describe(const atmos_plan *p, const atmos__view *v, char *buf, size_t cap)
{
    const atmos_scene_slice *ss = &p->scene.slice;
    int w, h;
    eye_size(v, &w, &h);
    const int slices = v->slices > 0 ? v->slices : p->slice->slices_used;
    const int dof = p->slice->do_field; /* "do": no xi, the delta-M direct beam (slice_do.c) */
    const int edges = atmos__slice_edge_mode(p->slice, v);
    snprintf(buf, cap, "%d slices%s, light buffer %d, eye buffer %dx%d%s, xi %g, %s%s", slices,
             v->slices > 0 ? "" : " (chosen)", ss->light_size, edges ? 2 * w : w, edges ? 2 * h : h,
             edges ? " (four rays at the volume's edges, one elsewhere)" : "", dof ? 0.0 : ss->xi,
             dof ? "delta-M beam" : (ss->eq24 ? "eq24" : "eq25"),
             ss->low_albedo ? ", low albedo" : (dof ? "" : (p->slice->diffuse ? ", diffuse field" : "")));
    atmos__slice_do_describe(p->slice, buf, cap);
}

atmos_status atmos__slice_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out,
                                 atmos_slice_timing *tm)
{
    atmos_context *ctx = p->ctx;
    atmos__slice_plan *sp = p->slice;
    const double t_start = atmos__now();
    memset(tm, 0, sizeof *tm);
    memcpy(tm->grid_dims, sp->g.c, sizeof sp->g.c);
    /* The sky behind everything, sun's disk included. */
    atmos_status st = atmos__sky_render(ctx, p->atm, v, r, out, p->sky_keep);
    if (st != ATMOS_OK) return st;
    tm->sky = atmos__now() - t_start;
    if (sp->g.v) { /* an empty volume leaves the sky alone */
        sjob j;
        const double t_setup = atmos__now();
        if ((st = atmos__slice_frame_setup(ctx, sp, p->atm, v, r, &j)) != ATMOS_OK) return st;
        if (sp->diffuse) {
            int built = 0;
            /* held (the viewer's preview while the sun moves): the last solved sun's field, not
             * solved again; the next frame without hold_field solves it for its sun */
            if ((!v->hold_field || !sp->df.field.valid) &&
                (st = atmos__dfield_update(ctx, &sp->df, p->atm, v->sun, v->warm_field, 0, &built)) != ATMOS_OK)
                return st;
            j.field = &sp->df.field, j.fsca = sp->df.tab->sca[0], j.fg = sp->df.fg[0];
            double eu[3]; /* the eye in render-voxel coordinates */
            for (int a = 0; a < 3; a++) eu[a] = j.eye[a] * sp->g.sc + sp->g.off[a];
            atmos__dfield_view(&sp->df, eu, atmos__threads(ctx));
            j.fview = sp->df.view, j.fvq = sp->df.vq;
            if (built) tm->field = sp->df.field.build_s, tm->field_sweeps = sp->df.field.sweeps;
        }
        if (sp->do_field && (st = atmos__slice_do_update(p, sp, v, &j, tm)) != ATMOS_OK) return st;
        tm->setup = atmos__now() - t_setup;
        tm->prepare = sp->prepare_s;
        tm->eye_dims[0] = j.W, tm->eye_dims[1] = j.H;
        if ((st = atmos__slice_passes(ctx, sp, &j, tm)) != ATMOS_OK) return st;
        /* the volume's shadow on the air, taken from the sky image (and, in front of the
         * volume, from the air the composite puts there) */
        if (sp->air_shadows && !v->no_air_shadows &&
            (st = atmos__slice_air_shadow(ctx, sp, p->atm, v, r, &j, out, &tm->air_shadow)) != ATMOS_OK)
            return st;
        const double t_c0 = atmos__now();
        /* the reference passes ask the atmosphere per pixel: the check of the aerial volume */
        atmos__slice_composite(&j, p->atm, &v->cam, v->sun, &sp->x, r, sp->reference ? NULL : &sp->aerial, out,
                               atmos__threads(ctx));
        tm->aerial = atmos__now() - t_c0;
        tm->sky += tm->aerial + tm->air_shadow;
        tm->sunlight = sp->sunlight_s;
    }
    tm->total = atmos__now() - t_start;
    return ATMOS_OK;
}
