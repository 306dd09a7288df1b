/* `atmos mie`: Lorenz-Mie efficiencies and amplitudes of one homogeneous sphere.
 * Turns the options into one atmos_mie call and prints the result; the physics lives
 * in src/optics/mie.c. */
#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const MIE_CMD = "mie";

#define MIE_MAX_ANGLES 100000

static void mie_usage(FILE *f)
{
    fputs("Usage: atmos mie --m RE,IM --x X [--angles A,B,...] [--json]\n"
          "\n"
          "Lorenz-Mie scattering by a homogeneous sphere (Bohren & Huffman 1983;\n"
          "Wiscombe 1980): efficiencies Q_ext, Q_sca, Q_back, asymmetry g, and the\n"
          "amplitudes S1, S2 at the given scattering angles.\n"
          "\n"
          "  --m RE,IM       relative refractive index, MIEV0 convention: IM <= 0 absorbs\n"
          "                  (water at 550 nm: 1.334,-1.9e-9); 0,0 = perfectly conducting sphere\n"
          "  --x X           size parameter 2 pi r / lambda, in [1e-6, 1e5]\n"
          "  --angles LIST   scattering angles in degrees, in [0, 180], comma-separated\n"
          "                  (default 0,30,60,90,120,150,180)\n"
          "  --json          print one JSON object: qext, qsca, qback, g, angles_deg,\n"
          "                  s1, s2 (each a list of [re, im] pairs)\n"
          "  -h, --help      show this help\n"
          "\n"
          "S1, S2 follow MIEV0's convention (complex conjugates of Bohren & Huffman's);\n"
          "Q_ext = 4 Re S(0) / x^2, Q_back = 4 |S(180)|^2 / x^2.\n",
          f);
    fputs(CLI_HELP_EXIT, f);
}

/* Splits "a,b,c" into doubles; returns the count, or -1 after printing a usage error. */
static int parse_list(const char *opt, const char *text, double *out, int cap)
{
    int n = 0;
    const char *p = text;
    for (;;) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        char item[64];
        if (len == 0 || len >= sizeof item) {
            cli_usage_error(MIE_CMD, "%s: expected comma-separated numbers, got '%s'", opt, text);
            return -1;
        }
        if (n >= cap) {
            cli_usage_error(MIE_CMD, "%s: at most %d values", opt, cap);
            return -1;
        }
        memcpy(item, p, len);
        item[len] = '\0';
        if (!cli_parse_double(MIE_CMD, opt, item, &out[n])) return -1;
        n++;
        if (!comma) break;
        p = comma + 1;
    }
    return n;
}

static void print_pairs(const atmos_complex *s, int n)
{
    putchar('[');
    for (int i = 0; i < n; i++) printf("%s[%.10g, %.10g]", i ? ", " : "", s[i].re, s[i].im);
    putchar(']');
}

int cli_cmd_mie(int argc, char **argv)
{
    const char *m_text = NULL, *x_text = NULL, *angles_text = NULL;
    int json = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = NULL;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            mie_usage(stdout);
            return CLI_EXIT_OK;
        } else if (strcmp(a, "--json") == 0) {
            json = 1;
        } else if (cli_take_value(argc, argv, &i, "--m", &v)) {
            if (!v) return cli_usage_error(MIE_CMD, "--m: missing value");
            m_text = v;
        } else if (cli_take_value(argc, argv, &i, "--x", &v)) {
            if (!v) return cli_usage_error(MIE_CMD, "--x: missing value");
            x_text = v;
        } else if (cli_take_value(argc, argv, &i, "--angles", &v)) {
            if (!v) return cli_usage_error(MIE_CMD, "--angles: missing value");
            angles_text = v;
        } else if (a[0] == '-') {
            return cli_usage_error(MIE_CMD, "unknown option '%s'", a);
        } else {
            return cli_usage_error(MIE_CMD, "unexpected argument '%s'", a);
        }
    }
    if (!m_text) return cli_usage_error(MIE_CMD, "--m is required");
    if (!x_text) return cli_usage_error(MIE_CMD, "--x is required");

    double mv[2], x;
    int nm = parse_list("--m", m_text, mv, 2);
    if (nm < 0) return CLI_EXIT_USAGE;
    if (nm != 2) return cli_usage_error(MIE_CMD, "--m: expected RE,IM, got '%s'", m_text);
    if (!cli_parse_double(MIE_CMD, "--x", x_text, &x)) return CLI_EXIT_USAGE;

    double *deg = malloc(MIE_MAX_ANGLES * sizeof *deg);
    double *mu = malloc(MIE_MAX_ANGLES * sizeof *mu);
    atmos_complex *s1 = malloc(MIE_MAX_ANGLES * sizeof *s1), *s2 = malloc(MIE_MAX_ANGLES * sizeof *s2);
    int rc = CLI_EXIT_OK, n = 0;
    atmos_context *ctx = NULL;
    if (!deg || !mu || !s1 || !s2) {
        rc = cli_runtime_error(MIE_CMD, NULL, ATMOS_E_NOMEM);
        goto done;
    }
    if (angles_text) {
        n = parse_list("--angles", angles_text, deg, MIE_MAX_ANGLES);
        if (n < 0) {
            rc = CLI_EXIT_USAGE;
            goto done;
        }
    } else {
        for (n = 0; n <= 6; n++) deg[n] = 30.0 * n;
    }
    for (int i = 0; i < n; i++) {
        if (!(deg[i] >= 0.0 && deg[i] <= 180.0)) {
            rc = cli_usage_error(MIE_CMD, "--angles: each angle must be in [0, 180] degrees, got %g", deg[i]);
            goto done;
        }
        /* exact cosines at the ends so that S(0) and S(180) are the forward/backward amplitudes */
        mu[i] = deg[i] == 0.0 ? 1.0 : deg[i] == 180.0 ? -1.0 : deg[i] == 90.0 ? 0.0 : cos(deg[i] * (3.14159265358979323846 / 180.0));
    }

    ctx = cli_context(1, 1);
    if (!ctx) {
        rc = cli_runtime_error(MIE_CMD, NULL, ATMOS_E_NOMEM);
        goto done;
    }
    atmos_mie_result r;
    atmos_status st = atmos_mie(ctx, (atmos_complex){mv[0], mv[1]}, x, n, mu, s1, s2, &r);
    if (st == ATMOS_E_INVALID_ARG) {
        rc = cli_usage_error(MIE_CMD, "%s", atmos_context_error(ctx));
    } else if (st != ATMOS_OK) {
        rc = cli_runtime_error(MIE_CMD, ctx, st);
    } else if (json) {
        printf("{\"qext\": %.10g, \"qsca\": %.10g, \"qback\": %.10g, \"g\": %.10g, \"angles_deg\": [", r.qext, r.qsca,
               r.qback, r.g);
        for (int i = 0; i < n; i++) printf("%s%.10g", i ? ", " : "", deg[i]);
        printf("], \"s1\": ");
        print_pairs(s1, n);
        printf(", \"s2\": ");
        print_pairs(s2, n);
        printf("}\n");
    } else {
        printf("m = %.10g%+.10gi, x = %.10g (%d terms)\n", mv[0], mv[1], x, r.terms);
        printf("Q_ext  = %.10g\nQ_sca  = %.10g\nQ_abs  = %.10g\nQ_back = %.10g\ng      = %.10g\n", r.qext, r.qsca,
               r.qext - r.qsca, r.qback, r.g);
        if (n > 0) printf("\n%10s %17s %17s %17s %17s\n", "angle", "Re S1", "Im S1", "Re S2", "Im S2");
        for (int i = 0; i < n; i++)
            printf("%10.4f %17.10g %17.10g %17.10g %17.10g\n", deg[i], s1[i].re, s1[i].im, s2[i].re, s2[i].im);
    }
    if (fflush(stdout) != 0 && rc == CLI_EXIT_OK) {
        fprintf(stderr, "atmos %s: cannot write to standard output\n", MIE_CMD);
        rc = CLI_EXIT_RUNTIME;
    }
done:
    atmos_context_destroy(ctx);
    free(deg), free(mu), free(s1), free(s2);
    return rc;
}
