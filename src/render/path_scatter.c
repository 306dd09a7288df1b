/* The scattering at an event of the path tracer (path_trace.h): the fields' and the
 * wavelengths' shares, the mixture's phase function, the hero wavelengths' direction
 * strategies, directions around an axis. */
#include "core/vec.h"
#include "render/path_trace.h"

/* Orthonormal basis around unit n (Duff et al. 2017). */
static inline void onb(const double n[3], double t[3], double b[3])
{
    double s = n[2] >= 0 ? 1.0 : -1.0;
    double a = -1.0 / (s + n[2]);
    double c = n[0] * n[1] * a;
    t[0] = 1.0 + s * n[0] * n[0] * a, t[1] = s * c, t[2] = -s * n[0];
    b[0] = c, b[1] = s + n[1] * n[1] * a, b[2] = -n[1];
}

/* Russian roulette on the largest weight; returns 0 to stop. */
int atmos__path_roulette(double *w, int m, atmos__stream *r)
{
    double q = 0;
    for (int i = 0; i < m; i++)
        if (w[i] > q) q = w[i];
    if (!(q > 0)) return 0;
    if (q >= 1) return 1;
    if (atmos__stream_u(r) >= q) return 0;
    for (int i = 0; i < m; i++) w[i] /= q;
    return 1;
}

/* Direction at cos(theta) = mu, azimuth phi around unit axis n. */
void atmos__path_around(const double n[3], double mu, double phi, double out[3])
{
    double t[3], b[3];
    onb(n, t, b);
    double st = sqrt(fmax(0.0, 1.0 - mu * mu)), c = cos(phi) * st, s = sin(phi) * st;
    for (int a = 0; a < 3; a++) out[a] = mu * n[a] + c * t[a] + s * b[a];
    double l = 1.0 / sqrt(atmos__dot3(out, out));
    for (int a = 0; a < 3; a++) out[a] *= l;
}

/* A direction cosine-distributed about unit n (u1, u2 uniform in [0, 1)), in a frame that is
 * the world's axes for n = +y. */
void atmos__path_cosine(const double n[3], double u1, double u2, double out[3])
{
    double t[3], b[3];
    const double z[3] = {0, 0, 1};
    atmos__cross3(n, z, t);
    if (atmos__dot3(t, t) < 1e-12) t[0] = 1, t[1] = t[2] = 0;
    atmos__normalize3(t);
    atmos__cross3(t, n, b);
    const double phi = 2.0 * ATMOS_PI * u2, st = sqrt(u1);
    const double x = st * cos(phi), y = sqrt(fmax(0.0, 1.0 - u1)), zz = st * sin(phi);
    for (int a = 0; a < 3; a++) out[a] = x * t[a] + y * n[a] + zz * b[a];
}

/* Phase function of the mixture of fields at a scattering event for every carried
 * wavelength: pk[i] = sum_f ssf[f][i] p_f,k(mu) / ss[i], 0 where nothing scatters. */
void atmos__path_phase_mix(const path_phase *P, const path_bundle *b, int nf, const path_scatter *e, double mu,
                           double *pk)
{
    path_angle ang;
    atmos__path_angle(P, mu, &ang);
    for (int i = 0; i < b->m; i++) {
        double s = 0;
        if (e->ss[i] > 0) {
            for (int f = 0; f < nf; f++)
                if (e->ssf[f][i] > 0) s += e->ssf[f][i] * atmos__path_phase_eval(P, f, b->k[i], &ang);
            s /= e->ss[i];
        }
        pk[i] = s;
    }
}

/* Hero wavelengths, multiple importance sampling over whole paths. A path draws every
 * direction from the phase function of one carried wavelength, its hero h, chosen
 * uniformly once (Wilkie et al. 2014, "Hero wavelength spectral sampling"); where h does
 * not scatter, from the first wavelength that does (a fixed rule, so a function of the
 * path). Wavelength k is then weighted by prod_e p_k(e) / ((1/m) sum_j prod_e pdf_j(e)), the
 * balance heuristic over the m strategies "hero = j": at most m whatever the path's length.
 * (Weighting every event separately, p_k / mean_j p_j, compounds over a path: after twenty
 * events in a droplet cloud, whose phase functions differ between wavelengths by factors of
 * two in the forward peak and more around the glory and the rainbow, single weights of
 * hundreds made the fireflies of the first version.) S[j] holds prod_e pdf_j(e),
 * normalised to mean 1 after every event; the weights w carry the ratio. */
double atmos__path_strategies(int m, const double *S, const int *g, const double *pd, double *pj)
{
    double D = 0;
    for (int j = 0; j < m; j++) {
        if (pj) pj[j] = pd[g[j]];
        D += S[j] * pd[g[j]];
    }
    return D / m;
}

/* The scattering at a point of the volume (densities dens) for the carried wavelengths:
 * per field ssf and in all ss (m^-1), and for each hero its direction strategy g: itself,
 * or the first carried wavelength that scatters. Returns how many scatter. */
int atmos__path_scatter_at(const path_job *J, const path_bundle *b, const float *dens, path_scatter *e, int *g)
{
    const path_medium *M = J->med;
    int elig[PATH_B], ne = 0;
    for (int i = 0; i < b->m; i++) {
        e->ss[i] = 0;
        for (int f = 0; f < M->nf; f++) {
            e->ssf[f][i] = (double)dens[f] * M->sca[f][b->k[i]];
            e->ss[i] += e->ssf[f][i];
        }
        if (e->ss[i] > 0) elig[ne++] = i;
    }
    for (int i = 0; i < b->m; i++) g[i] = e->ss[i] > 0 ? i : (ne ? elig[0] : i);
    return ne;
}

/* A field for a new direction of wavelength j: in proportion to its share of the scattering
 * there (no random number with one field). */
int atmos__path_pick_field(const path_scatter *e, int j, int nf, atmos__stream *r)
{
    int f = 0;
    if (nf > 1) {
        double u = atmos__stream_u(r) * e->ss[j], acc = 0;
        for (f = 0; f < nf - 1; f++) {
            acc += e->ssf[f][j];
            if (u < acc) break;
        }
        while (f > 0 && e->ssf[f][j] <= 0) f--;
    }
    return f;
}

/* The aureole estimate's density of a (path_light.c). */
double atmos__path_aureole_pdf(const path_job *J, const path_bundle *b, const path_scatter *e, const double a[3])
{
    double pk[PATH_B], s = 0;
    int ne = 0;
    atmos__path_phase_mix(J->ph, b, J->med->nf, e, atmos__dot3(a, J->sun), pk);
    for (int i = 0; i < b->m; i++)
        if (e->ss[i] > 0) s += pk[i], ne++;
    return ne ? s / ne : 0.0;
}
