/* The slice eye pass's beam across a slab (atmos__slice_beam_len, render/slice_internal.h) against
 * its integral taken by quadrature. The eye passes hand it the exponentials they already hold:
 * T = e^-te (the slab's transmittance along the eye) and r = e^-tl (the light leaving the slab over
 * the light arriving, the ratio the light pass left in the light buffer), so that a sample takes
 * no exponential of its own. Analytic case: a homogeneous slab, the eye's optical depth te across
 * it along the eye ray of length del, the light's tl. Front to back the light and the eye enter by
 * the same face, the integrand e^-(te + tl) s / del; back to front the light enters by the far
 * one, e^-(te s / del) e^-(tl (1 - s / del)). Measured (2026-12-06): the largest relative error
 * 4.1e-5 (y = te -+ tl near the series' edge 1e-3: the float difference of two exponentials);
 * with e^-(te + tl) taken as T alone front to back 1 (78 cases failed), with e^-tl taken as 1 back
 * to front 2e17 (101 failed). */
#include "render/slice_internal.h"
#include "test.h"

#include <math.h>

/* the integral over s in [0, del] by Simpson's rule on 4096 intervals */
static double beam_quad(double del, double te, double tl, int btf)
{
    const int N = 4096;
    double sum = 0;
    for (int i = 0; i <= N; i++) {
        const double u = (double)i / N, f = btf ? exp(-te * u - tl * (1 - u)) : exp(-(te + tl) * u);
        sum += f * (i == 0 || i == N ? 1 : (i & 1) ? 4 : 2);
    }
    return del * sum / (3.0 * N);
}

int main(void)
{
    static const float taus[] = {0.0f, 1e-5f, 5e-4f, 1.2e-3f, 0.01f, 0.3f, 0.6f, 1.0f, 2.5f, 10.0f, 40.0f};
    const int nt = (int)(sizeof taus / sizeof taus[0]);
    double worst = 0;
    for (int btf = 0; btf < 2; btf++)
        for (int a = 0; a < nt; a++)
            for (int b = 0; b < nt; b++) {
                const float del = 3.0f, te = taus[a];
                /* the light's ratio as the light buffer holds it, and the passes' tl from it */
                const float r = atmos__slice_beam_ratio(1.0f, expf(-taus[b])), tl = -logf(r);
                const double got = atmos__slice_beam_len(del, te, expf(-te), tl, r, btf);
                const double want = beam_quad(del, te, tl, btf);
                const double err = fabs(got - want) / want;
                worst = err > worst ? err : worst;
                CHECK_MSG(err < 3e-4, "btf %d te %g tl %g: %.8g against %.8g (%.3g)", btf, te, tl, got, want, err);
            }
    printf("the beam across a slab against its quadrature: largest relative error %.3g\n", worst);
    /* no light lost (r 1, tl 0): the plain (1 - e^-te) / te length either way */
    CHECK_REL(atmos__slice_beam_len(2.0f, 0.5f, expf(-0.5f), 0.0f, 1.0f, 0), 2.0 * (1 - exp(-0.5)) / 0.5, 1e-6);
    CHECK_REL(atmos__slice_beam_len(2.0f, 0.5f, expf(-0.5f), 0.0f, 1.0f, 1), 2.0 * (1 - exp(-0.5)) / 0.5, 1e-6);
    /* a beam put out within the slab: the ratio held at e^-80, tl 80 */
    CHECK(atmos__slice_beam_ratio(1.0f, 0.0f) == ATMOS__SLICE_BEAM_MIN);
    CHECK(atmos__slice_beam_ratio(0.0f, 0.0f) == 1.0f && atmos__slice_beam_ratio(1.0f, 1.5f) == 1.0f);
    return test_summary("test_slice_beam");
}
