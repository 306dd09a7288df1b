/* The beam renderer's pre-integrated scattering table W(theta, x) (beams_internal.h): one
 * table for the fog, whatever the light, since the light's intensity and the visibility stay
 * outside it (Dobashi et al. 2002 Eq. 6: f_h times f_l). Its nodes are even in s = u / (|u| + v)
 * (so a look-up needs no arctangent); each row is a cumulative integral over theta by
 * Simpson's rule per cell (the cell's ends and its middle in angle); the phase function and
 * the tangent depend on theta alone and are evaluated once per angle. */
#include "render/beams_internal.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TABLE_S 2049 /* odd: s = 0 (theta = 0) is a node */
#define TABLE_X 512

void atmos__beams_table_free(atmos__beams_table *t)
{
    if (!t) return;
    free(t->w);
    memset(t, 0, sizeof *t);
}

/* The angle of the table's coordinate s = u / (|u| + v): tan(theta) = u / v = s / (1 - |s|). */
static double theta_of(double s) { return atan2(s, 1 - fabs(s)); }

atmos_status atmos__beams_table_build(atmos_context *ctx, double sigma_t, double sigma_s, const atmos__fog_optics *phase,
                                      double x_max, atmos__beams_table *t)
{
    memset(t, 0, sizeof *t);
    const int nt = TABLE_S, nx = TABLE_X, ns = 2 * nt - 1; /* the cells' ends and their angular midpoints */
    t->nt = nt, t->nx = nx, t->x_max = x_max > 0 ? x_max : 1e-9;
    t->w = malloc(sizeof(double) * (size_t)nt * nx);
    double *ph = malloc(sizeof(double) * ns), *tn = malloc(sizeof(double) * ns), *h = malloc(sizeof(double) * nt);
    double *rows = malloc(sizeof(double) * (size_t)nt * nx); /* row j at j nt, then stored by node */
    if (!t->w || !ph || !tn || !h || !rows) {
        free(ph), free(tn), free(h), free(rows), atmos__beams_table_free(t);
        return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for the scattering table");
    }
    for (int i = 0; i < ns; i++) {
        const double a = theta_of(-1 + 2.0 * (i / 2) / (nt - 1)), b = theta_of(-1 + 2.0 * ((i + 1) / 2) / (nt - 1));
        const double th = 0.5 * (a + b); /* a node, or the middle of a cell in angle */
        if (i % 2 == 0) h[i / 2] = i + 2 < ns ? theta_of(-1 + 2.0 * (i / 2 + 1) / (nt - 1)) - a : 0;
        ph[i] = sigma_s * atmos__fog_phase(phase, -sin(th));
        tn[i] = i == ns - 1 ? INFINITY : tan(0.25 * ATMOS_PI + 0.5 * th); /* (1 + sin th) / cos th */
    }
#pragma omp parallel for schedule(static) num_threads(atmos__threads(ctx))
    for (int j = 0; j < nx; j++) {
        const double w = (double)j / (nx - 1), x = t->x_max * w * w;
        double *row = rows + (size_t)j * nt, acc = 0;
        double f0 = ph[0]; /* tan = 0 at theta = -pi/2 */
        row[0] = 0;
        for (int i = 0; i + 1 < nt; i++) {
            const double fm = ph[2 * i + 1] * exp(-x * tn[2 * i + 1]);
            const double f1 = x > 0 ? (isinf(tn[2 * i + 2]) ? 0 : ph[2 * i + 2] * exp(-x * tn[2 * i + 2])) : ph[2 * i + 2];
            acc += h[i] / 6 * (f0 + 4 * fm + f1);
            row[i + 1] = acc;
            f0 = f1;
        }
    }
    /* by node: a look-up's four rows side by side (atmos__beams_table_at) */
#pragma omp parallel for schedule(static) num_threads(atmos__threads(ctx))
    for (int i = 0; i < nt; i++)
        for (int j = 0; j < nx; j++) t->w[(size_t)i * nx + j] = rows[(size_t)j * nt + i];
    free(ph), free(tn), free(h), free(rows);
    return ATMOS_OK;
}

void atmos__beams_table_column(const atmos__beams_table *t, double x, atmos__beams_column *c)
{
    /* cubic Lagrange over four rows around w = sqrt(x / x_max) */
    const double w = sqrt(atmos__clampd(x / t->x_max, 0, 1)) * (t->nx - 1);
    int j0 = (int)floor(w) - 1;
    if (j0 < 0) j0 = 0;
    if (j0 > t->nx - 4) j0 = t->nx - 4;
    const double s = w - j0; /* the rows sit at s = 0, 1, 2, 3 */
    c->wt[0] = -(s - 1) * (s - 2) * (s - 3) / 6;
    c->wt[1] = s * (s - 2) * (s - 3) / 2;
    c->wt[2] = -s * (s - 1) * (s - 3) / 2;
    c->wt[3] = s * (s - 1) * (s - 2) / 6;
    c->rows = t->w + j0;
}
