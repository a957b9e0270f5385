/* mohr: see mohr.h. Error propagation of phi(b) and C(a, b):
 *   dphi/db = 1 / ((b + 1) sqrt(b)),
 *   dC/da = 1 / (2 sqrt(b)),  dC/db = -a / (4 b^(3/2)),
 *   var C = dC/da^2 var a + 2 dC/da dC/db cov(a, b) + dC/db^2 var b. */
#include "mohr.h"

#include "h5format.h"
#include "params.h"

#include <errno.h>
#include <gsl/gsl_fit.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

cdem_status cdem_mohr_fit_envelope(const double *sigma3, const double *q, size_t n,
                                   cdem_mohr_fit *fit, cdem_error *err) {
    if (n < 2)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "mohr: %zu test(s) given; the envelope needs at least 2 confining "
                         "pressures",
                         n);
    if (!sigma3 || !q || !fit)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "mohr: NULL argument");
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(sigma3[i]) || sigma3[i] < 0)
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "mohr: test %zu: confining pressure sigma3 = %g N/m; allowed: "
                             "finite, >= 0",
                             i + 1, sigma3[i]);
        if (!isfinite(q[i]) || q[i] <= 0)
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "mohr: test %zu: peak differential stress q = %g N/m; allowed: "
                             "finite, > 0",
                             i + 1, q[i]);
    }
    int distinct = 0;
    for (size_t i = 1; i < n; i++)
        distinct |= sigma3[i] != sigma3[0];
    if (!distinct)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "mohr: all %zu tests have the same confining pressure %g N/m; need at "
                         "least 2 different ones",
                         n, sigma3[0]);
    double *s1 = malloc(n * sizeof *s1);
    if (!s1)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "mohr: no memory for %zu tests", n);
    for (size_t i = 0; i < n; i++)
        s1[i] = sigma3[i] + q[i];
    memset(fit, 0, sizeof *fit);
    double a, b, caa, cab, cbb, ss;
    gsl_fit_linear(sigma3, 1, s1, 1, n, &a, &b, &caa, &cab, &cbb, &ss);
    free(s1);
    if (!(b >= 1.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "mohr: fitted slope d sigma1 / d sigma3 = %g < 1 would mean a negative "
                         "friction angle; check the tests' peak stresses",
                         b);
    if (n == 2) {
        caa = cab = cbb = NAN;
    }
    fit->a = a;
    fit->b = b;
    fit->cov_aa = caa;
    fit->cov_ab = cab;
    fit->cov_bb = cbb;
    fit->residual_ss = ss;
    fit->n = n;
    double sb = sqrt(b);
    fit->friction = asin((b - 1.0) / (b + 1.0));
    fit->cohesion = a / (2.0 * sb);
    double dphi = 1.0 / ((b + 1.0) * sb);
    double dca = 1.0 / (2.0 * sb), dcb = -a / (4.0 * b * sb);
    fit->friction_err = sqrt(dphi * dphi * cbb);
    double vc = dca * dca * caa + 2.0 * dca * dcb * cab + dcb * dcb * cbb;
    fit->cohesion_err = sqrt(vc > 0 ? vc : 0.0);
    if (n == 2)
        fit->cohesion_err = NAN;
    return CDEM_OK;
}

cdem_status cdem_mohr_read_table(const char *path, double **sigma3, double **q, size_t *n,
                                 cdem_error *err) {
    *sigma3 = *q = NULL;
    *n = 0;
    FILE *f = fopen(path, "r");
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_IO, "mohr: cannot open %s: %s", path, strerror(errno));
    char line[512];
    size_t cap = 0, lineno = 0;
    cdem_status st = CDEM_OK;
    while (st == CDEM_OK && fgets(line, sizeof line, f)) {
        lineno++;
        char *c = strchr(line, '#');
        if (c)
            *c = 0;
        line[strcspn(line, "\r\n")] = 0;
        char *p = line;
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
            p++;
        if (!*p)
            continue;
        char *e1, *e2;
        double v1 = strtod(p, &e1);
        double v2 = e1 != p ? strtod(e1, &e2) : 0.0;
        if (e1 == p || e2 == e1) {
            st = CDEM_FAIL(err, CDEM_ERR_PARSE,
                           "%s line %zu: '%.60s' is not two numbers 'sigma3 q' (N/m)", path, lineno,
                           p);
            break;
        }
        while (*e2 == ' ' || *e2 == '\t' || *e2 == '\r' || *e2 == '\n')
            e2++;
        if (*e2) {
            st = CDEM_FAIL(err, CDEM_ERR_PARSE,
                           "%s line %zu: extra text '%.40s' after 'sigma3 q'; expected two "
                           "columns",
                           path, lineno, e2);
            break;
        }
        if (*n == cap) {
            size_t nc = cap ? 2 * cap : 16;
            double *a = realloc(*sigma3, nc * sizeof *a);
            if (a)
                *sigma3 = a;
            double *b = a ? realloc(*q, nc * sizeof *b) : NULL;
            if (!b) {
                st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: no memory for %zu rows", path, nc);
                break;
            }
            *q = b;
            cap = nc;
        }
        (*sigma3)[*n] = v1;
        (*q)[*n] = v2;
        (*n)++;
    }
    fclose(f);
    if (st != CDEM_OK) {
        free(*sigma3);
        free(*q);
        *sigma3 = *q = NULL;
        *n = 0;
    }
    return st;
}

void cdem_mohr_runs_free(cdem_mohr_runs *r) {
    if (!r)
        return;
    for (size_t i = 0; i < r->n; i++) {
        if (r->strain)
            free(r->strain[i]);
        if (r->stress)
            free(r->stress[i]);
    }
    free(r->strain);
    free(r->stress);
    free(r->n_samples);
    free(r->sigma3);
    free(r->q);
    memset(r, 0, sizeof *r);
}

/* Run i of files into d: its confining pressure, its curve and the peak of the curve. */
static cdem_status read_run(const char *path, size_t i, cdem_mohr_runs *d, cdem_error *err) {
    cdem_h5_reader *r;
    CDEM_TRY(cdem_h5_reader_open(path, &r, err));
    cdem_params p;
    cdem_series_sample *smp = NULL;
    size_t n = 0;
    cdem_status st = cdem_h5_reader_params(r, &p, err);
    if (st == CDEM_OK)
        st = cdem_h5_reader_read_series(r, &smp, &n, err);
    cdem_h5_reader_close(r);
    if (st == CDEM_OK && p.mode != CDEM_MODE_BIAXIAL)
        st = CDEM_FAIL(err, CDEM_ERR_INVALID,
                       "%s is a '%s' run; mohr needs biaxial test runs (boundary.mode = "
                       "biaxial)",
                       path, cdem_mode_name(p.mode));
    if (st == CDEM_OK && n == 0)
        st = CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s has no time-series samples", path);
    if (st == CDEM_OK) {
        d->strain[i] = malloc(n * sizeof(double));
        d->stress[i] = malloc(n * sizeof(double));
        if (!d->strain[i] || !d->stress[i])
            st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "no memory for %zu samples", n);
    }
    if (st == CDEM_OK) {
        double peak = -INFINITY;
        for (size_t k = 0; k < n; k++) {
            d->strain[i][k] = smp[k].axial_strain;
            d->stress[i][k] = smp[k].differential_stress / 1e6;
            if (isfinite(smp[k].differential_stress))
                peak = fmax(peak, smp[k].differential_stress);
        }
        d->n_samples[i] = n;
        d->sigma3[i] = p.confining_pressure;
        d->q[i] = peak;
    }
    free(smp);
    return st;
}

cdem_status cdem_mohr_read_runs(const char *const *files, size_t n, cdem_mohr_runs *out,
                                cdem_error *err) {
    memset(out, 0, sizeof *out);
    out->sigma3 = malloc(n * sizeof(double));
    out->q = malloc(n * sizeof(double));
    out->strain = calloc(n ? n : 1, sizeof *out->strain);
    out->stress = calloc(n ? n : 1, sizeof *out->stress);
    out->n_samples = calloc(n ? n : 1, sizeof *out->n_samples);
    if (!out->sigma3 || !out->q || !out->strain || !out->stress || !out->n_samples)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "no memory for %zu runs", n);
    out->n = n;
    for (size_t i = 0; i < n; i++)
        CDEM_TRY(read_run(files[i], i, out, err));
    return CDEM_OK;
}
