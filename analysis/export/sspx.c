/* sspx: see sspx.h. */
#include "sspx.h"

#include "params.h"

#include "outfile.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

cdem_status cdem_sspx_write(const char *path, const cdem_state *s, cdem_error *err) {
    cdem_outfile of; /* written to path.tmp, renamed on success */
    FILE *f;
    CDEM_TRY(cdem_outfile_open_text(&of, path, &f, err));
    for (size_t i = 0; i < s->n; i++)
        fprintf(f, "%d %.6f %.6f %.6f %d\n", (int)s->id[i], s->x[i], s->y[i], s->radius[i],
                (int)s->layer[i]);
    return cdem_outfile_close_text(&of, f, CDEM_OK, err);
}

cdem_status cdem_sspx_read(const char *path, cdem_state *s, cdem_error *err) {
    FILE *f = fopen(path, "r");
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot open %s: %s", path, strerror(errno));
    cdem_status st = cdem_state_init(s, 1024, 0, err);
    char line[512];
    long ln = 0;
    while (st == CDEM_OK && fgets(line, sizeof line, f)) {
        ln++;
        char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\n' || *p == '\r' || *p == '\0' || *p == '#')
            continue;
        long id, layer;
        double x, y, r;
        char tail[8];
        int got = sscanf(p, "%ld %lf %lf %lf %ld %7s", &id, &x, &y, &r, &layer, tail);
        if (got != 5 || id < 0 || id > INT32_MAX || layer < 0 || layer > INT32_MAX ||
            !isfinite(x) || !isfinite(y) || !(r > 0.0)) {
            p[strcspn(p, "\r\n")] = '\0';
            st = CDEM_FAIL(err, CDEM_ERR_PARSE,
                           "%s:%ld: expected 'id x y radius layer' (id, layer whole numbers "
                           ">= 0, radius > 0), found '%.60s'",
                           path, ln, p);
            break;
        }
        st = cdem_state_append(s, (int32_t)id, x, y, r, 0.0, (int32_t)layer,
                               layer == 0 ? CDEM_FLAG_WALL : 0, 0, NULL, err);
    }
    fclose(f);
    return st;
}

cdem_status cdem_sspx_export(cdem_analysis *a, size_t first, size_t last, const char *dir,
                             const char *prefix, size_t *written, cdem_error *err) {
    if (written)
        *written = 0;
    if (first > last || last >= cdem_analysis_count(a))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "export: increment range %zu..%zu is not within "
                         "0..%zu",
                         first, last, cdem_analysis_count(a) - 1);
    if (!cdem_params_prefix_ok(prefix))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "export: prefix '%s' %s",
                         prefix ? prefix : "(null)", CDEM_PREFIX_RULE);
    int dirlen = (int)strlen(dir); /* "out/" and "out" name the same directory */
    while (dirlen > 1 && dir[dirlen - 1] == '/')
        dirlen--;
    cdem_status st = CDEM_OK;
    size_t k = first;
    char path[CDEM_PATH_MAX + 128];
    for (; k <= last; k++) { /* on failure k is the increment that failed */
        const cdem_state *s;
        st = cdem_analysis_state(a, k, &s, err);
        if (st != CDEM_OK)
            break;
        int n = snprintf(path, sizeof path, "%.*s/%s%d.txt", dirlen, dir, prefix,
                         (int)cdem_analysis_info(a, k)->number);
        if (n < 0 || (size_t)n >= sizeof path) {
            st = CDEM_FAIL(err, CDEM_ERR_INVALID, "export: output path in '%s' is too long", dir);
            break;
        }
        st = cdem_sspx_write(path, s, err);
        if (st != CDEM_OK)
            break;
        if (written)
            (*written)++;
    }
    if (st != CDEM_OK) {
        /* no partial set that looks like a complete one: remove this call's files */
        for (size_t j = first; j < k; j++) {
            snprintf(path, sizeof path, "%.*s/%s%d.txt", dirlen, dir, prefix,
                     (int)cdem_analysis_info(a, j)->number);
            remove(path);
        }
        if (written)
            *written = 0;
    }
    return st;
}

cdem_status cdem_sspx_parse_range(const cdem_analysis *a, const char *spec, size_t *first,
                                  size_t *last, cdem_error *err) {
    char buf[64];
    if (!spec || strlen(spec) >= sizeof buf)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "increment range '%.40s' must look like 56-282 (or equil-last)",
                         spec ? spec : "");
    strcpy(buf, spec);
    char *dash = strchr(buf, '-');
    if (dash)
        *dash = '\0';
    CDEM_TRY(cdem_analysis_find(a, buf, first, err));
    if (!dash) {
        *last = *first;
        return CDEM_OK;
    }
    CDEM_TRY(cdem_analysis_find(a, dash + 1, last, err));
    if (*first > *last)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "increment range '%s' runs backwards", spec);
    return CDEM_OK;
}
