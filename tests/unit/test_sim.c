/* The cloud simulation (src/sim/, docs/clouds.md): saturation adjustment leaves neither
 * supersaturation nor cloud in unsaturated air; total water is conserved (rain on the
 * ground and the surface flux counted); cloud base at the lifting condensation level of
 * Espy's rule (Lawrence 2005); a dry spherical thermal accelerates at 2B/3 (Jeevanjee &
 * Lecoanet 2018); the projection leaves no divergence; results are the same bytes for 1 and
 * 2 threads and for a seed; bad presets and arguments are errors; an empty result warns.
 * Small grids, seconds. */
#include "atmos/atmos.h"
#include "sim/sim_internal.h"
#include "test.h"
#include "test_sim_state.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* After the adjustment: q_c = 0 and q_v <= q_s, or q_c > 0 and q_v = q_s (the condensate's
 * saturation: over ice below -23 C, mixed between); water and the moist static energy
 * c_p T + L q_v (at fixed pressure; L that of the starting temperature) unchanged. */
static void test_adjust(void)
{
    int bad = 0, cases = 0;
    for (double t = 220; t <= 310; t += 5)
        for (double p = 40000; p <= 100000; p += 20000)
            for (double rh = 0.3; rh <= 1.5; rh += 0.15)
                for (double qc0 = 0; qc0 <= 3e-3; qc0 += 1e-3) {
                    const double pi = pow(p / SIM_P00, SIM_RD / SIM_CP);
                    double th = t / pi, qv = rh * atmos__sim_qsat(t, p), qc = qc0;
                    const double lat = atmos__sim_latent(t), w0 = qv + qc, h0 = SIM_CP * t + lat * qv;
                    atmos__sim_adjust(&th, &qv, &qc, p, pi);
                    const double qs = atmos__sim_qsat_cond(th * pi, p), h1 = SIM_CP * th * pi + lat * qv;
                    cases++;
                    if (qc < 0 || qv > qs * (1 + 1e-6) || (qc > 0 && fabs(qv - qs) > 1e-6 * qs) ||
                        fabs(qv + qc - w0) > 1e-12 || fabs(h1 - h0) > 1e-6 * h0) {
                        if (bad++ < 3) printf("  adjust: T %g p %g rh %g qc %g -> qv %g qs %g qc %g\n", t, p, rh, qc0, qv, qs, qc);
                    }
                }
    printf("  adjust: %d states\n", cases);
    CHECK_MSG(bad == 0, "%d of %d adjusted states saturated wrongly", bad, cases);
    /* saturation over ice against the WMO's (Goff-Gratch) values: 1.0326 hPa at -20 C,
     * 0.1283 hPa at -40 C; the condensate's is over water at 0 C and above, over ice at -23 C
     * and below */
    CHECK_REL(atmos__sim_esat_ice(253.15), 103.26, 0.005);
    CHECK_REL(atmos__sim_esat_ice(233.15), 12.83, 0.005);
    CHECK_NEAR(atmos__sim_qsat_cond(280, 8e4), atmos__sim_qsat(280, 8e4), 0);
    const double ei = atmos__sim_esat_ice(240);
    CHECK_REL(atmos__sim_qsat_cond(240, 3e4), 0.622 * ei / (3e4 - ei), 1e-12);
}

/* Total water over many steps of a raining cloud: vapour + cloud + rain in the domain + rain
 * on the ground - water from the surface, to 1 %. */
static void test_budget(void)
{
    atmos_context *c = test_sim_ctx(1);
    sim_env e = *atmos__sim_preset("towering_cumulus");
    e.bubble_dth = 3.0, e.bubble_dqv = 3e-3, e.lhf = 5e-5, e.shf = 0.05, e.flux_noise = 0.5;
    atmos_sim *s = NULL;
    CHECK_OK(atmos__sim_create_env(c, &e, 20, 20, 24, 400, 7, &s));
    if (!s) return;
    atmos_sim_stats a, b;
    atmos_sim_get_stats(s, &a);
    double worst = 0, max_qr = 0;
    for (int n = 0; n < 1000; n++) {
        atmos_sim_step(c, s);
        if (n % 50 == 49) {
            atmos_sim_get_stats(s, &b);
            const double err = fabs(b.water + b.rain_out - b.surface_in - a.water) / a.water;
            worst = fmax(worst, err);
            max_qr = fmax(max_qr, b.max_qr);
        }
    }
    atmos_sim_get_stats(s, &b);
    printf("  budget: %ld steps, %.0f s: water %.4f -> %.4f kg/m2, rain out %.4f, surface in %.4f, worst error %.3f %%, "
           "max q_r %.2g\n",
           b.steps, b.time_s, a.water, b.water, b.rain_out, b.surface_in, 100 * worst, max_qr);
    CHECK_MSG(worst < 0.01, "total water drifted by %.3f %%", 100 * worst);
    CHECK_MSG(b.rain_out > 0, "no rain reached the ground, the budget test did not test the rain's fall");
    atmos_sim_destroy(s);
    atmos_context_destroy(c);
}

/* A warm moist bubble of mixed-layer air rises through a neutral layer with drier air aloft:
 * its cloud base is at the LCL of Espy's rule, z = 125 m/K (T - T_d) (Lawrence 2005, BAMS 86,
 * 225, Eq. 24), of the bubble's air at the ground, within one cell. */
static void test_lcl(void)
{
    atmos_context *c = test_sim_ctx(1);
    sim_env e;
    memset(&e, 0, sizeof e);
    e.kind = SIM_SOUNDING_LAYERED, e.dt_max = 5, e.micro = 1;
    e.theta_s = 300, e.zi = 400, e.inv_depth = 100, e.gamma_ft = 0, e.z_tp = 1e5, e.qv_bl = 14e-3, e.qv_ft = 9e-3,
    e.hq = 1500;
    e.bubbles = 1, e.bubble_rh = 500, e.bubble_rv = 400, e.bubble_z = 400, e.bubble_dth = 0.5, e.bubble_dqv = 0;
    atmos_sim *s = NULL;
    const double dx = 100;
    CHECK_OK(atmos__sim_create_env(c, &e, 32, 32, 30, dx, 1, &s));
    if (!s) return;
    /* the bubble's air: theta 300.5 K with 14 g/kg at 1000 hPa */
    const double t = (e.theta_s + e.bubble_dth) * 1.0, td = atmos__sim_dewpoint(e.qv_bl, SIM_P00);
    const double lcl = 125.0 * (t - td);
    atmos_sim_stats st;
    atmos_sim_get_stats(s, &st);
    CHECK_MSG(st.cloud_base_m < 0, "cloud before the bubble rose (base %g m)", st.cloud_base_m);
    double base = -1;
    for (int n = 0; n < 400 && base < 0; n++) {
        atmos_sim_step(c, s);
        atmos_sim_get_stats(s, &st);
        base = st.cloud_base_m;
    }
    /* the cell holding the LCL, or a neighbour: the thermal mixes with the surrounding air (its
     * own LCL 62 m lower, the drier air aloft's higher) */
    const int kb = (int)floor(base / dx), kl = (int)floor(lcl / dx);
    printf("  lcl: T %.2f K, Td %.2f K, Espy LCL %.0f m (cell %d); cloud base (lowest cell with q_c > 1e-5) %.0f m "
           "(cell %d) at t %.0f s, cells %g m\n",
           t, td, lcl, kl, base, kb, st.time_s, dx);
    CHECK_MSG(base > 0 && abs(kb - kl) <= 1, "cloud base %g m, LCL %g m", base, lcl);
    atmos_sim_destroy(s);
    atmos_context_destroy(c);
}

/* A uniform spherical thermal (theta' = 1 K, radius 10 cells) in a neutral, still, dry
 * layer: its fluid's mean updraught grows at 2B/3, B = g theta'/theta (the induced-mass
 * result of Jeevanjee & Lecoanet 2018, J. Atmos. Sci. 75, 4059, derived for a uniform sphere and
 * found in their DNS over a rise of about one thermal length), to 10 %. */
static void test_thermal(void)
{
    atmos_context *c = test_sim_ctx(1);
    sim_env e;
    memset(&e, 0, sizeof e);
    e.kind = SIM_SOUNDING_LAYERED, e.dt_max = 4, e.micro = 0;
    e.theta_s = 300, e.zi = 1e5, e.z_tp = 1e5, e.qv_bl = 0, e.hq = 1;
    atmos_sim *s = NULL;
    const int N = 64;
    const double dx = 50, R = 500;
    CHECK_OK(atmos__sim_create_env(c, &e, N, N, N, dx, 1, &s));
    if (!s) return;
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                const double x = (i + 0.5 - N / 2) * dx, y = (j + 0.5 - N / 2) * dx, z = (k + 0.5 - N / 2) * dx;
                if (x * x + y * y + z * z < R * R) s->th[sim_idx(s, i, j, k)] += 1.0f;
            }
    const double B = SIM_G * 1.0 / 300.0;
    for (int n = 0; n < 5; n++) atmos_sim_step(c, s);
    double sw = 0, sb = 0;
    for (int k = 0; k < N; k++)
        for (size_t m = (size_t)k * N * N; m < (size_t)(k + 1) * N * N; m++) {
            const double b = s->th[m] - 300.0;
            if (b <= 0) continue;
            sw += b * 0.5 * (s->w[m] + s->w[m + (size_t)N * N]);
            sb += b;
        }
    const double wm = sw / sb, expect = 2.0 / 3.0 * B * s->t;
    printf("  thermal: after %.0f s the anomaly's mean w %.4f m/s, 2Bt/3 = %.4f m/s (ratio %.3f)\n", s->t, wm, expect,
           wm / expect);
    CHECK_REL(wm, expect, 0.10);
    /* and it has risen */
    CHECK(wm > 0);
    CHECK_MSG(atmos__sim_max_divergence(s) < 1e-4, "divergence %g m/s left", atmos__sim_max_divergence(s));
    atmos_sim_destroy(s);
    atmos_context_destroy(c);
}

static atmos_sim *run_preset(int threads, const char *preset, uint64_t seed, int steps)
{
    atmos_context *c = test_sim_ctx(threads);
    atmos_sim_desc d = {.preset = preset, .minutes = 0, .grid = 24, .seed = seed};
    atmos_sim *s = NULL;
    if (atmos_sim_create(c, &d, &s) == ATMOS_OK)
        for (int n = 0; n < steps; n++) atmos_sim_step(c, s);
    atmos_context_destroy(c);
    return s;
}

static void test_threads(void)
{
    atmos_sim *a = run_preset(1, "towering_cumulus", 3, 40), *b = run_preset(2, "towering_cumulus", 3, 40),
              *d = run_preset(1, "towering_cumulus", 4, 40);
    CHECK(a && b && d);
    if (a && b && d) {
        atmos_sim_stats st;
        atmos_sim_get_stats(a, &st);
        printf("  threads: towering_cumulus 24^2 x %d, %ld steps to %.0f s, max w %.2f m/s, max q_c %.2g\n", st.dims[2],
               st.steps, st.time_s, st.max_w, st.max_qc);
        CHECK_MSG(test_sim_same_state(a, b), "1 and 2 threads differ");
        CHECK_MSG(!test_sim_same_state(a, d), "seeds 3 and 4 give the same state");
        CHECK(st.max_qc > 0); /* clouds formed */
    }
    atmos_sim_destroy(a);
    atmos_sim_destroy(b);
    atmos_sim_destroy(d);
}

static void test_bad(void)
{
    atmos_context *c = test_sim_ctx(1);
    atmos_sim *s = NULL;
    atmos_sim_desc d = {.preset = "cumulonimbuss", .minutes = 0, .grid = 32, .seed = 1};
    CHECK(atmos_sim_create(c, &d, &s) == ATMOS_E_INVALID_ARG && !s);
    CHECK(strstr(atmos_context_error(c), "cumulus_field") != NULL);
    d.preset = NULL;
    CHECK(atmos_sim_create(c, &d, &s) == ATMOS_E_INVALID_ARG);
    d.preset = "cumulonimbus";
    const int grids[] = {8, 15, 513, -4};
    for (int i = 0; i < 4; i++) {
        d.grid = grids[i];
        CHECK(atmos_sim_create(c, &d, &s) == ATMOS_E_INVALID_ARG && !s);
    }
    d.grid = 16;
    const double mins[] = {-1, NAN, 1e9};
    for (int i = 0; i < 3; i++) {
        d.minutes = mins[i];
        CHECK(atmos_sim_create(c, &d, &s) == ATMOS_E_INVALID_ARG && !s);
    }
    CHECK(atmos_sim_create(c, NULL, &s) == ATMOS_E_INVALID_ARG);
    atmos_volume *v = NULL;
    CHECK(atmos_simulate(c, NULL, &v) == ATMOS_E_INVALID_ARG && !v);
    CHECK(atmos_sim_preset_minutes("nope") == 0);
    int n = 0;
    for (const char *const *p = atmos_sim_preset_names(); *p; p++) n++;
    CHECK(n == 4);
    atmos_context_destroy(c);
}

/* The volume: cloud and rain number densities q rho / m, y up. */
static void test_volume(void)
{
    atmos_context *c = test_sim_ctx(1);
    atmos_sim_desc d = {.preset = "stratocumulus", .minutes = 0, .grid = 16, .seed = 1};
    atmos_sim *s = NULL;
    CHECK_OK(atmos_sim_create(c, &d, &s));
    if (!s) return;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_sim_to_volume(c, s, &v));
    if (v) {
        const atmos_volume_desc *vd = atmos_volume_get_desc(v);
        CHECK(vd->dims[0] == s->nx && vd->dims[1] == s->nz && vd->dims[2] == s->ny);
        CHECK(!strcmp(atmos_volume_field_name(v, 0), "cloud") && !strcmp(atmos_volume_field_name(v, 1), "rain"));
        /* a cell of the deck: the density at its centre */
        int kk = -1;
        for (int k = 0; k < s->nz && kk < 0; k++)
            if (s->qc[sim_idx(s, 3, 5, k)] > 1e-4f) kk = k;
        CHECK(kk >= 0);
        if (kk >= 0) {
            double p[3] = {vd->origin_m[0] + 3.5 * s->dx, (kk + 0.5) * s->dx, vd->origin_m[2] + 5.5 * s->dx};
            const double expect = s->qc[sim_idx(s, 3, 5, kk)] * s->rho0[kk] / atmos_particle_mean_mass("cloud");
            CHECK_REL(atmos_volume_sample(v, 0, p), expect, 1e-5);
        }
    }
    atmos_volume_destroy(v);
    atmos_sim_destroy(s);
    atmos_context_destroy(c);
}

/* Whether two volumes hold the same values at every voxel centre of every field. */
static int same_volume(const atmos_volume *a, const atmos_volume *b)
{
    const atmos_volume_desc *da = atmos_volume_get_desc(a), *db = atmos_volume_get_desc(b);
    if (memcmp(da->dims, db->dims, sizeof da->dims) || atmos_volume_field_count(a) != atmos_volume_field_count(b)) return 0;
    for (int f = 0; f < atmos_volume_field_count(a); f++)
        for (int k = 0; k < da->dims[2]; k++)
            for (int j = 0; j < da->dims[1]; j++)
                for (int i = 0; i < da->dims[0]; i++) {
                    const double p[3] = {da->origin_m[0] + (i + 0.5) * da->voxel_size_m,
                                         da->origin_m[1] + (j + 0.5) * da->voxel_size_m,
                                         da->origin_m[2] + (k + 0.5) * da->voxel_size_m};
                    if (atmos_volume_sample(a, f, p) != atmos_volume_sample(b, f, p)) return 0;
                }
    return 1;
}

/* A time-lapse (atmos_sim_volume_at): each time's volume the same as a run of its own to that
 * time, whatever was asked before; going back is refused. */
static void test_timelapse(void)
{
    atmos_context *c = test_sim_ctx(2);
    atmos_sim_desc d = {.preset = "towering_cumulus", .minutes = 0, .grid = 16, .seed = 5};
    atmos_sim *s = NULL;
    CHECK_OK(atmos_sim_create(c, &d, &s));
    if (!s) return;
    const double times[] = {9.0, 10.37, 10.37, 12.1}; /* cloud from about 8 minutes at grid 16 */
    int same = 0, differ = 0;
    atmos_volume *prev = NULL;
    for (int q = 0; q < 4; q++) {
        atmos_volume *lapse = NULL, *alone = NULL;
        d.minutes = times[q];
        CHECK_OK(atmos_sim_volume_at(c, s, times[q], &lapse));
        CHECK_OK(atmos_simulate(c, &d, &alone));
        if (lapse && alone) same += same_volume(lapse, alone);
        if (lapse && prev && times[q] != times[q - 1]) differ += !same_volume(lapse, prev);
        atmos_sim_stats st;
        atmos_sim_get_stats(s, &st);
        CHECK(st.time_s <= times[q] * 60 + 1e-9 && st.time_s > times[q] * 60 - 60); /* never past it */
        atmos_volume_destroy(alone), atmos_volume_destroy(prev);
        prev = lapse;
    }
    printf("  time-lapse: %d of 4 times the same as a run of its own, %d of 2 changes seen\n", same, differ);
    CHECK(same == 4 && differ == 2);
    atmos_volume *v = NULL;
    CHECK(atmos_sim_volume_at(c, s, 11.0, &v) == ATMOS_E_INVALID_ARG && !v);
    atmos_volume_destroy(prev);
    atmos_sim_destroy(s);
    atmos_context_destroy(c);
}

/* A scene names a simulation: its settings parsed, bad ones refused with the key's path. */
static void test_scene(void)
{
    atmos_context *c = test_sim_ctx(1);
    atmos_scene sc;
    const char *good = "{\"volume\": {\"simulate\": {\"preset\": \"stratocumulus\", \"minutes\": 2, \"grid\": 16, "
                       "\"seed\": 5}, \"position_m\": [0, 0, -3000]}}";
    CHECK_OK(atmos_scene_parse(c, good, strlen(good), "test", &sc));
    CHECK(!strcmp(sc.volume.source, "simulate:stratocumulus") && sc.volume.sim_minutes == 2 && sc.volume.sim_grid == 16 &&
          sc.volume.seed == 5);
    atmos_volume *v = NULL;
    double off[3];
    CHECK_OK(atmos_scene_load_volume(c, &sc, &v, off));
    CHECK(v && atmos_volume_field_count(v) == 2);
    atmos_volume_destroy(v);
    const char *bad[] = {
        "{\"volume\": {\"simulate\": {\"preset\": \"cirrus\"}}}",
        "{\"volume\": {\"simulate\": {\"minutes\": 3}}}",
        "{\"volume\": {\"simulate\": {\"preset\": \"cumulonimbus\", \"grid\": 8}}}",
        "{\"volume\": {\"simulate\": {\"preset\": \"cumulonimbus\", \"minutes\": 0}}}",
        "{\"volume\": {\"simulate\": {\"preset\": \"cumulonimbus\", \"wind\": 3}}}",
        "{\"volume\": {\"simulate\": {\"preset\": \"cumulonimbus\"}, \"generate\": \"storm\"}}",
        "{\"volume\": {\"simulate\": {\"preset\": \"cumulonimbus\"}, \"seed\": 3}}",
        "{\"volume\": {\"simulate\": \"cumulonimbus\"}}",
    };
    for (int i = 0; i < (int)(sizeof bad / sizeof bad[0]); i++) {
        const atmos_status st = atmos_scene_parse(c, bad[i], strlen(bad[i]), "test", &sc);
        CHECK_MSG(st == ATMOS_E_INVALID_ARG, "accepted: %s", bad[i]);
        if (i == 0) CHECK(strstr(atmos_context_error(c), "towering_cumulus") != NULL);
    }
    atmos_context_destroy(c);
}

static void keep_warning(void *user, atmos_log_level level, const char *msg)
{
    if (level == ATMOS_LOG_WARN) snprintf(user, 256, "%s", msg);
}

/* A run too short for any cloud (a scene's "simulate" source too) warns that the volume is
 * empty; one with cloud does not. */
static void test_empty_warning(void)
{
    for (int cloudy = 0; cloudy < 2; cloudy++) {
        char warned[256] = "";
        atmos_context_desc cd;
        atmos_context_defaults(&cd);
        cd.threads = 1;
        cd.log = keep_warning;
        cd.log_user = warned;
        cd.log_level = ATMOS_LOG_WARN;
        atmos_context *c = NULL;
        CHECK_OK(atmos_context_create(&cd, &c));
        atmos_sim_desc d = {.preset = cloudy ? "stratocumulus" : "towering_cumulus", .minutes = 0.5, .grid = 16, .seed = 1};
        atmos_volume *v = NULL;
        CHECK_OK(atmos_simulate(c, &d, &v));
        if (cloudy) CHECK_MSG(!warned[0], "stratocumulus warned: %s", warned);
        else CHECK_MSG(strstr(warned, "empty") && strstr(warned, "minutes"), "no empty-volume warning: '%s'", warned);
        atmos_volume_destroy(v);
        atmos_context_destroy(c);
    }
}

int main(void)
{
    test_scene();
    test_empty_warning();
    test_adjust();
    test_bad();
    test_volume();
    test_thermal();
    test_lcl();
    test_budget();
    test_threads();
    test_timelapse();
    return test_summary("test_sim");
}
