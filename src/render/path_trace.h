/* The path tracer's integrator: what one camera path needs (path_job), the state it shares
 * with the estimates made along it (path_run), a scattering event as they see it
 * (path_event); the scattering at an event (path_scatter.c), the light estimates
 * (path_light.c) and the tracing of a path (path.c). Not part of the API. */
#ifndef ATMOS_RENDER_PATH_TRACE_H
#define ATMOS_RENDER_PATH_TRACE_H

#include "render/path_internal.h"
#include "render/path_lamps.h"

typedef struct {
    const path_medium *med; /* NULL: no volume */
    const path_phase *ph;
    const atmos_atmosphere *atm; /* the air, the ground, the sun and what lies beyond */
    const path_env *env;    /* NULL: no next-event estimation of the sky */
    int forced;             /* camera rays estimate their single scattering by forced_single() */
    int aureole;            /* the aureole estimate (a phase function with a forward peak) */
    atmos_camera cam;
    int n;                  /* wavelengths */
    double sun[3];
    double cos_sun, sun_omega;
    int disk_visible;       /* the sun's disk is drawn */
    double bg;              /* radiance from beyond the atmosphere (a vacuum's background) */
    double albedo;          /* the ground's */
    int max_depth;          /* scattering events per path (the scene's, else PATH_DEFAULT_DEPTH) */
    int depth_default;      /* max_depth is the default: a path stopped by it counts as cut */
    double deadline;        /* atmos__now() past which a path is abandoned (the time budget); INFINITY: none */
    int reference;          /* no volume, a planet's air: every path is the atmosphere's Monte Carlo reference */
    const path_lamps *lamps; /* the scene's lights, fog and objects: every path is traced by path_lamps.c */
    int roulette;           /* lamps: Russian roulette by the lights' nearness (path_lamps.c) */
    uint64_t seed;
} path_job;

/* The depth limit when the scene sets none: it bounds the walk in optically huge media (a
 * path there takes ~ tau^2 events to leave; docs/path.md, "Optically huge media"). */
#define PATH_DEFAULT_DEPTH 10000

typedef struct {
    long long events, tentative, shadow;
    long long cut;   /* paths stopped by the default depth limit */
    long long ended; /* walks ended at their roulette (path_medium.h, PATH_WALK_RR) */
} path_counts;

/* What every estimate along one camera path shares: the job, the carried wavelengths, the
 * random stream, the counters, and the sums: per carried wavelength the radiance L and the
 * radiance times the number of volume scattering events before it Lo. */
typedef struct {
    const path_job *J;
    const path_bundle *b;
    atmos__stream *r;
    path_counts *cnt;
    double *L, *Lo;
} path_run;

/* Adds contribution c of carried wavelength i at scattering order `order`. */
static inline void atmos__path_add(const path_run *R, int i, double c, int order)
{
    R->L[i] += c, R->Lo[i] += order * c;
}

/* The scattering at a point of the volume for the carried wavelengths: per field ssf and in
 * all ss (m^-1). */
typedef struct {
    double ssf[PATH_F][PATH_B], ss[PATH_B];
} path_scatter;

/* A scattering event of the volume as the estimates there see it: where (p), reached along
 * d with weights w (the path's throughput times the scattering coefficient over the density
 * of the point sampled), the scattering e, the direction strategies (S: the product of each
 * hero's densities so far, g: each hero's wavelength there), the continuation's survival
 * probability q (for multiple importance sampling), and the path's scattering order. */
typedef struct {
    double p[3], d[3];
    const double *w;
    const path_scatter *e;
    const double *S;
    const int *g;
    double q;
    int order;
} path_event;

/* ---- the scattering at an event (path_scatter.c) */

/* Per field ssf and in all ss at densities dens, and for each hero its direction strategy
 * g: itself, or the first carried wavelength that scatters. Returns how many scatter. */
int atmos__path_scatter_at(const path_job *J, const path_bundle *b, const float *dens, path_scatter *e, int *g);
/* A field for a new direction of wavelength j, in proportion to its share of the scattering. */
int atmos__path_pick_field(const path_scatter *e, int j, int nf, atmos__stream *r);
/* The mixture's phase function at cos theta mu for every carried wavelength (0 where
 * nothing scatters). */
void atmos__path_phase_mix(const path_phase *P, const path_bundle *b, int nf, const path_scatter *e, double mu,
                           double *pk);
/* The mean density of the m direction strategies (pj: each strategy's, may be NULL). */
double atmos__path_strategies(int m, const double *S, const int *g, const double *pd, double *pj);
/* The aureole estimate's density of direction a (the mean over the scattering wavelengths of
 * their phase functions centred on the sun). */
double atmos__path_aureole_pdf(const path_job *J, const path_bundle *b, const path_scatter *e, const double a[3]);
/* A direction at cos(theta) = mu, azimuth phi, around unit axis n. */
void atmos__path_around(const double n[3], double mu, double phi, double out[3]);
/* A direction cosine-distributed about unit n (u1, u2 uniform in [0, 1)). */
void atmos__path_cosine(const double n[3], double u1, double u2, double out[3]);
/* Russian roulette on the largest of the m weights w (divided by the survival probability
 * when it is below 1); 0 to stop. */
int atmos__path_roulette(double *w, int m, atmos__stream *r);

/* ---- the light (path_light.c) */

/* Sunlight at p for the carried wavelengths. */
void atmos__path_sunlight(const path_run *R, const double p[3], double *E);
/* The air's transmittance over p + t d, t in [0, K], multiplied into w. */
void atmos__path_air_transmit(const path_run *R, const double p[3], const double d[3], double K, double *w);
/* The volume's transmittance from p along d to the box's far side. */
void atmos__path_shadow(const path_run *R, const double p[3], const double d[3], double *T);
/* A direction in the sun's cone, uniformly (density 1 / sun_omega). */
void atmos__path_sample_sun(const path_run *R, double d[3]);
/* Does the sun (sunlight E) light anything the weights w carry? */
int atmos__path_sun_lit(const path_run *R, const double *w, const double *E);
/* The weight of next-event estimation of the sun against a continuation of density q_pdir. */
double atmos__path_mis_nee(const path_job *J, double q_pdir);

/* The part of a segment lying in the volume's box: the index-space ray and its start. */
typedef struct {
    const double *q, *qd;
    double t0;
} air_view;

/* The air's single scattering of sunlight along p + t d, t in [0, K], added times w wt
 * (path_light.c explains the shadowed part). */
void atmos__path_air_scatter(const path_run *R, const double p[3], const double d[3], double K, const double *w,
                             double wt, int order, const air_view *view);
/* The air's single scattering over [s0, s1] of the segment p + t d seen from p, by the
 * midpoint rule over AIR_SINGLE_N equal cells (path_air_single.c): per cell c and carried
 * wavelength i, g[c][i] = the single scattering's integrand (atmos__atm_single_cells_sub)
 * at the cell's centre times the air's transmittance from p to it times the cell's length;
 * sum[i] = the sum over the cells. */
#define AIR_SINGLE_N 8
typedef struct {
    double g[AIR_SINGLE_N][PATH_B], sum[PATH_B];
    double s0, dt;
} air_single;
void atmos__path_air_single(const path_run *R, const double p[3], const double d[3], double s0, double s1,
                            air_single *S);
/* A point *t of S's range: a cell drawn with probability proportional to the mean of
 * g[c][i] / sum[i] over the wavelengths with w[i] != 0, then uniformly in it; ratio[i] =
 * g[c][i] / that probability, so that sum over the cells of g[c][i] times the cell's mean
 * of a shadow is the expectation of ratio[i] times the shadow at *t. Returns 0 (no point)
 * when nothing scatters there. */
int atmos__path_air_single_point(const path_run *R, const air_single *S, const double *w, double *t, double *ratio);
/* Next-event estimation of the sun (E: its light at the event, NULL when it does not light
 * it; hs: the path's share against the aureole estimate) and of the sky at an event. */
void atmos__path_nee(const path_run *R, const path_event *ev, const double *E, double hs);
/* The aureole estimate from an event (see path_light.c). */
void atmos__path_aureole(const path_run *R, const path_event *ev);
/* Forced single scattering on a camera ray's crossing [t0, t1] of the box (index space
 * q + t qd, world p + t d); 1 if it made the estimate. */
int atmos__path_forced_single(const path_run *R, const double p[3], const double d[3], const double q[3],
                              const double qd[3], double t0, double t1, const double *w);

/* One camera path through world ray (o, d); adds the radiance of the carried wavelengths to
 * L[] and, for the scattering-order image, each contribution times the number of volume
 * scattering events before it to Lo[]. Returns 1 when the path met the volume (a scattering
 * event, or the camera ray's forced single-scattering estimate), else 0. */
/* atmos__path_trace's result for a path abandoned at the job's deadline (its sample is not
 * counted: the pass it belongs to is cut). */
#define PATH_ABANDONED (-1)
int atmos__path_trace(const path_job *J, const path_bundle *b, const double o[3], const double d[3], atmos__stream *r,
                       double *L, double *Lo, path_counts *cnt);
/* A camera path in a scene of lights, fog and objects (path_lamps.c), as atmos__path_trace. */
int atmos__path_trace_lamps(const path_job *J, const path_bundle *b, const double o[3], const double d[3],
                            atmos__stream *r, double *L, double *Lo, path_counts *cnt);

#endif
