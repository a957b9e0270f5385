/* cdem2d: see cdem2d.h. Files are read whole into memory and parsed line by line with
 * strtod, so a malformed row is reported with its file and line. The previous increment is
 * kept (one state) for id matching. */
#include "cdem2d.h"

#include "grid.h"
#include "h5format.h"
#include "params.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cdem_status read_text(const char *path, char **out, int optional, cdem_error *err) {
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        if (optional && errno == ENOENT)
            return CDEM_OK;
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot open %s: %s", path, strerror(errno));
    }
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    for (;;) {
        if (!buf) {
            fclose(f);
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading %s", path);
        }
        n += fread(buf + n, 1, cap - n - 1, f);
        if (n < cap - 1)
            break;
        cap *= 2;
        char *nb = realloc(buf, cap);
        if (!nb)
            free(buf);
        buf = nb;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        return CDEM_FAIL(err, CDEM_ERR_IO, "error reading %s", path);
    }
    buf[n] = '\0';
    const char *nul = memchr(buf, '\0', n);
    if (nul) { /* the rows after it would be dropped silently */
        size_t at = (size_t)(nul - buf);
        free(buf);
        return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: byte %zu is a NUL byte: not a text file", path,
                         at + 1);
    }
    *out = buf;
    return CDEM_OK;
}

/* Normalises a key: lower case, runs of space, '_' and '-' become one space, trimmed. */
static void norm_key(const char *s, size_t len, char *out, size_t cap) {
    size_t j = 0;
    int space = 1;
    for (size_t i = 0; i < len && j + 1 < cap; i++) {
        unsigned char c = (unsigned char)s[i];
        if (isspace(c) || c == '_' || c == '-') {
            if (!space)
                out[j++] = ' ';
            space = 1;
        } else {
            out[j++] = (char)tolower(c);
            space = 0;
        }
    }
    while (j > 0 && out[j - 1] == ' ')
        j--;
    out[j] = '\0';
}

static void parse_params(cdem_cdem2d_meta *m) {
    const char *p = m->params_text;
    while (p && *p) {
        const char *eol = strchr(p, '\n');
        size_t len = eol ? (size_t)(eol - p) : strlen(p);
        const char *sep = NULL;
        for (size_t i = 0; i < len; i++)
            if (p[i] == '=' || p[i] == ':') {
                sep = p + i;
                break;
            }
        if (sep) {
            char key[96], val[96];
            norm_key(p, (size_t)(sep - p), key, sizeof key);
            norm_key(sep + 1, len - (size_t)(sep + 1 - p), val, sizeof val);
            if (!strcmp(key, "pre growth layers") || !strcmp(key, "pregrowth layers") ||
                !strcmp(key, "number of pre growth layers") ||
                !strcmp(key, "number of pregrowth layers")) {
                m->pregrowth_layers = atoi(val);
            } else if (!strcmp(key, "equilibration increment") ||
                       !strcmp(key, "end of equilibration increment") ||
                       !strcmp(key, "equilibration increments")) {
                m->equil_number = atoi(val);
            } else if (!strcmp(key, "faulting mode") || !strcmp(key, "mode")) {
                static const struct {
                    const char *word;
                    int mode;
                } modes[] = {{"planar", CDEM_MODE_PLANAR_FAULT},
                             {"listric", CDEM_MODE_LISTRIC_FAULT},
                             {"irregular", CDEM_MODE_IRREGULAR_FAULT},
                             {"caldera", CDEM_MODE_VERTICAL_FAULTS},
                             {"piston", CDEM_MODE_VERTICAL_FAULTS},
                             {"vertical", CDEM_MODE_VERTICAL_FAULTS},
                             {"detachment", CDEM_MODE_DETACHMENT},
                             {"repose", CDEM_MODE_REPOSE},
                             {"biaxial", CDEM_MODE_BIAXIAL},
                             {"uniaxial", CDEM_MODE_BIAXIAL}};
                for (size_t k = 0; k < sizeof modes / sizeof modes[0]; k++)
                    if (strstr(val, modes[k].word)) {
                        m->mode = modes[k].mode;
                        break;
                    }
            }
        }
        p = eol ? eol + 1 : NULL;
    }
}

/* Sorted list of increment numbers N with a modelresults_N.txt in dir. */
static cdem_status list_increments(const char *dir, long **nums, size_t *count, cdem_error *err) {
    *nums = NULL;
    *count = 0;
    DIR *d = opendir(dir);
    if (!d)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot open cdem2D folder %s: %s", dir,
                         strerror(errno));
    size_t cap = 0;
    struct dirent *e;
    cdem_status st = CDEM_OK;
    while ((e = readdir(d)) != NULL) {
        const char *pre = "modelresults_";
        if (strncmp(e->d_name, pre, strlen(pre)) != 0)
            continue;
        char *end;
        const char *num = e->d_name + strlen(pre);
        if (!isdigit((unsigned char)*num))
            continue;
        long v = strtol(num, &end, 10);
        if (strcmp(end, ".txt") != 0 || v < 0 || v > 100000000)
            continue;
        if (*count == cap) {
            cap = cap ? 2 * cap : 64;
            long *nn = realloc(*nums, cap * sizeof *nn);
            if (!nn) {
                st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory listing %s", dir);
                break;
            }
            *nums = nn;
        }
        (*nums)[(*count)++] = v;
    }
    closedir(d);
    if (st != CDEM_OK)
        return st;
    for (size_t i = 1; i < *count; i++) /* insertion sort: folders hold hundreds of files */
        for (size_t j = i; j > 0 && (*nums)[j - 1] > (*nums)[j]; j--) {
            long t = (*nums)[j];
            (*nums)[j] = (*nums)[j - 1];
            (*nums)[j - 1] = t;
        }
    /* modelresults_0.txt and modelresults_00.txt are both increment 0 (found by fuzzing:
     * the importer passed on two increments with one number) */
    for (size_t i = 1; st == CDEM_OK && i < *count; i++)
        if ((*nums)[i] == (*nums)[i - 1])
            st = CDEM_FAIL(err, CDEM_ERR_PARSE,
                           "%s holds two results files for increment %ld (a number written "
                           "with and without leading zeros, e.g. modelresults_%ld.txt and "
                           "modelresults_0%ld.txt): keep one",
                           dir, (*nums)[i], (*nums)[i], (*nums)[i]);
    if (st != CDEM_OK) {
        free(*nums);
        *nums = NULL;
        *count = 0;
        return st;
    }
    if (*count == 0)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "%s holds no modelresults_N.txt files: not a cdem2D simulation folder",
                         dir);
    return CDEM_OK;
}

/* Parses up to `want` numbers per non-blank, non-comment line; calls row(user, vals) for
 * each. Reports the file and line of a malformed row. */
typedef cdem_status (*row_fn)(void *user, const double *vals, const char *path, long line,
                              cdem_error *err);

static cdem_status parse_rows(const char *text, const char *path, int want, const char *what,
                              row_fn row, void *user, cdem_error *err) {
    long line = 0;
    const char *p = text;
    while (*p) {
        line++;
        const char *eol = strchr(p, '\n');
        const char *end = eol ? eol : p + strlen(p);
        const char *q = p;
        while (q < end && isspace((unsigned char)*q))
            q++;
        if (q < end && *q != '#') {
            double vals[8];
            int got = 0;
            while (got < want) {
                while (q < end && isspace((unsigned char)*q))
                    q++;
                if (q >= end)
                    break;
                char *e;
                double v = strtod(q, &e);
                if (e == q || e > end || (e < end && !isspace((unsigned char)*e)) || !isfinite(v)) {
                    int n = (int)(end - q);
                    while (n > 0 && (q[n - 1] == '\r'))
                        n--;
                    return CDEM_FAIL(err, CDEM_ERR_PARSE,
                                     "%s:%ld: expected %d numbers (%s), found '%.*s'", path, line,
                                     want, what, n > 40 ? 40 : n, q);
                }
                vals[got++] = v;
                q = e;
            }
            if (got < want)
                return CDEM_FAIL(err, CDEM_ERR_PARSE,
                                 "%s:%ld: expected %d numbers (%s), found only %d", path, line,
                                 want, what, got);
            CDEM_TRY(row(user, vals, path, line, err));
        }
        p = eol ? eol + 1 : end;
    }
    return CDEM_OK;
}

typedef struct {
    cdem_state *s;     /* state being filled */
    int pregrowth;     /* pre-growth layer count (0 = all pre-growth) */
    int32_t number;    /* increment number */
    size_t stress_row; /* next element to receive stress */
} fill_ctx;

/* Bounds of an imported row (m): far beyond any model, yet small enough that sums, squares
 * and the cell grid of the id matching stay finite (x = 1e308 or a radius of 1e300 were
 * imported once, and turned into infinities downstream). They are the run file's own
 * (h5format.h, docs/format.md "Physical bounds"): its writer refuses anything beyond. */
#define IMPORT_MAX_COORD  CDEM_FILE_MAX_LENGTH
#define IMPORT_MAX_RADIUS CDEM_FILE_MAX_RADIUS

static cdem_status result_row(void *user, const double *v, const char *path, long line,
                              cdem_error *err) {
    fill_ctx *c = user;
    if (!(v[2] > 0.0) || v[2] > IMPORT_MAX_RADIUS)
        return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s:%ld: radius %g must be > 0 and at most %g m",
                         path, line, v[2], IMPORT_MAX_RADIUS);
    for (int k = 0; k < 2; k++)
        if (!(fabs(v[k]) <= IMPORT_MAX_COORD))
            return CDEM_FAIL(err, CDEM_ERR_PARSE,
                             "%s:%ld: %s = %g m is outside the range -%g..%g m allowed for a "
                             "position",
                             path, line, k ? "y" : "x", v[k], IMPORT_MAX_COORD, IMPORT_MAX_COORD);
    if (v[3] < 0.0 || v[3] > 1e6 || v[3] != floor(v[3]))
        return CDEM_FAIL(err, CDEM_ERR_PARSE,
                         "%s:%ld: layer %g must be a whole number >= 0 (0 = wall)", path, line,
                         v[3]);
    const int32_t layer = (int32_t)v[3];
    uint32_t flags = 0;
    if (layer == 0)
        flags |= CDEM_FLAG_WALL;
    else if (c->pregrowth > 0 && layer > c->pregrowth)
        flags |= CDEM_FLAG_GROWTH;
    return cdem_state_append(c->s, 0, v[0], v[1], v[2], 0.0, layer, flags, c->number, NULL, err);
}

static cdem_status force_row(void *user, const double *v, const char *path, long line,
                             cdem_error *err) {
    fill_ctx *c = user;
    if (c->stress_row >= c->s->n)
        return CDEM_FAIL(err, CDEM_ERR_PARSE,
                         "%s:%ld: more stress rows than the %zu elements of the results file", path,
                         line, c->s->n);
    for (int k = 0; k < 3; k++)
        if (!(fabs(v[k]) <= CDEM_FILE_MAX_STRESS))
            return CDEM_FAIL(err, CDEM_ERR_PARSE,
                             "%s:%ld: %s = %g N/m is outside the range -%g..%g N/m allowed for a "
                             "stress",
                             path, line,
                             k == 0   ? "sxx"
                             : k == 1 ? "syy"
                                      : "sxy",
                             v[k], CDEM_FILE_MAX_STRESS, CDEM_FILE_MAX_STRESS);
    c->s->sxx[c->stress_row] = v[0];
    c->s->syy[c->stress_row] = v[1];
    c->s->sxy[c->stress_row] = v[2];
    c->stress_row++;
    return CDEM_OK;
}

/* Gives cur's elements ids: matched to prev (see cdem2d.h) or new from *next_id; born is
 * inherited from the matched element. */
static cdem_status assign_ids(const cdem_state *prev, cdem_state *cur, int32_t *next_id,
                              cdem_error *err) {
    if (!prev) {
        for (size_t i = 0; i < cur->n; i++)
            cur->id[i] = (*next_id)++;
        return CDEM_OK;
    }
    double rmax = 0.0;
    for (size_t i = 0; i < prev->n; i++)
        rmax = fmax(rmax, prev->radius[i]);
    const double tol = 2.0 * (rmax > 0.0 ? rmax : 1.0);
    cdem_grid_index g;
    CDEM_TRY(cdem_grid_index_build(&g, prev->x, prev->y, prev->n, NULL, tol, err));
    size_t *best = malloc((cur->n ? cur->n : 1) * sizeof *best);
    double *bestd = malloc((cur->n ? cur->n : 1) * sizeof *bestd);
    size_t *owner = malloc((prev->n ? prev->n : 1) * sizeof *owner);
    double *ownd = malloc((prev->n ? prev->n : 1) * sizeof *ownd);
    if (!best || !bestd || !owner || !ownd) {
        free(best);
        free(bestd);
        free(owner);
        free(ownd);
        cdem_grid_index_free(&g);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "cdem2D import: out of memory matching %zu elements",
                         cur->n);
    }
    for (size_t k = 0; k < prev->n; k++) {
        owner[k] = SIZE_MAX;
        ownd[k] = INFINITY;
    }
    for (size_t j = 0; j < cur->n; j++) {
        best[j] = SIZE_MAX;
        bestd[j] = INFINITY;
        cdem_grid_box box;
        if (!cdem_grid_index_range(&g, cur->x[j], cur->y[j], tol, &box))
            continue;
        for (size_t cy = box.y_lo; cy <= box.y_hi; cy++)
            for (size_t cx = box.x_lo; cx <= box.x_hi; cx++) {
                size_t c = cy * g.grid.nx + cx;
                for (int32_t q = g.start[c]; q < g.start[c + 1]; q++) {
                    size_t k = (size_t)g.items[q];
                    if (prev->layer[k] != cur->layer[j] ||
                        fabs(prev->radius[k] - cur->radius[j]) > 1e-9 * cur->radius[j])
                        continue;
                    double d = hypot(prev->x[k] - cur->x[j], prev->y[k] - cur->y[j]);
                    if (d <= tol && (d < bestd[j] || (d == bestd[j] && k < best[j]))) {
                        bestd[j] = d;
                        best[j] = k;
                    }
                }
            }
        if (best[j] != SIZE_MAX && bestd[j] < ownd[best[j]]) {
            ownd[best[j]] = bestd[j];
            owner[best[j]] = j;
        }
    }
    for (size_t j = 0; j < cur->n; j++) {
        size_t k = best[j];
        if (k != SIZE_MAX && owner[k] == j) {
            cur->id[j] = prev->id[k];
            cur->born[j] = prev->born[k];
        } else {
            cur->id[j] = (*next_id)++;
        }
    }
    cur->next_id = *next_id;
    free(best);
    free(bestd);
    free(owner);
    free(ownd);
    cdem_grid_index_free(&g);
    return CDEM_OK;
}

void cdem_cdem2d_meta_free(cdem_cdem2d_meta *meta) {
    if (!meta)
        return;
    free(meta->params_text);
    meta->params_text = NULL;
}

cdem_status cdem_cdem2d_import(const char *dir, cdem_cdem2d_sink sink, void *user,
                               cdem_cdem2d_meta *meta, cdem_error *err) {
    memset(meta, 0, sizeof *meta);
    meta->mode = -1;
    meta->equil_number = -1;
    char path[CDEM_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/modelparameters.txt", dir);
    CDEM_TRY(read_text(path, &meta->params_text, 1, err));
    if (!meta->params_text) {
        meta->params_text = calloc(1, 1);
        if (!meta->params_text)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    }
    parse_params(meta);
    long *nums;
    size_t count;
    CDEM_TRY(list_increments(dir, &nums, &count, err));
    meta->n_increments = count;
    if (meta->equil_number < 0)
        meta->equil_number = (int)nums[0];
    /* forces: used only when every increment has them */
    meta->has_forces = 1;
    for (size_t k = 0; k < count && meta->has_forces; k++) {
        snprintf(path, sizeof path, "%s/modelforces_%ld.txt", dir, nums[k]);
        FILE *f = fopen(path, "rb");
        if (f)
            fclose(f);
        else
            meta->has_forces = 0;
    }
    cdem_state prev = {0}, cur = {0};
    int have_prev = 0;
    int32_t next_id = 0;
    cdem_status st = CDEM_OK;
    for (size_t k = 0; k < count && st == CDEM_OK; k++) {
        char *text = NULL;
        snprintf(path, sizeof path, "%s/modelresults_%ld.txt", dir, nums[k]);
        st = read_text(path, &text, 0, err);
        if (st != CDEM_OK)
            break;
        cdem_state_free(&cur);
        st = cdem_state_init(&cur, 1024, meta->has_forces, err);
        fill_ctx fc = {&cur, meta->pregrowth_layers, (int32_t)nums[k], 0};
        if (st == CDEM_OK)
            st = parse_rows(text, path, 4, "x y radius layer", result_row, &fc, err);
        free(text);
        if (st == CDEM_OK && cur.n == 0) /* an increment without elements: truncated copy? */
            st = CDEM_FAIL(err, CDEM_ERR_PARSE,
                           "%s holds no element rows (x y radius layer): an empty or cut-off "
                           "results file",
                           path);
        if (st == CDEM_OK && meta->has_forces) {
            snprintf(path, sizeof path, "%s/modelforces_%ld.txt", dir, nums[k]);
            st = read_text(path, &text, 0, err);
            if (st == CDEM_OK)
                st = parse_rows(text, path, 3, "sxx syy sxy", force_row, &fc, err);
            free(text);
            if (st == CDEM_OK && fc.stress_row != cur.n)
                st = CDEM_FAIL(err, CDEM_ERR_PARSE,
                               "%s: %zu stress rows for %zu elements in modelresults_%ld.txt", path,
                               fc.stress_row, cur.n, nums[k]);
        }
        if (st == CDEM_OK) {
            st = assign_ids(have_prev ? &prev : NULL, &cur, &next_id, err);
            if (st != CDEM_OK) /* e.g. coordinates too far apart to match: name the file */
                cdem_error_prefix(err, "%s/modelresults_%ld.txt", dir, nums[k]);
        }
        if (st != CDEM_OK)
            break;
        cur.next_id = next_id;
        cdem_increment_info info;
        memset(&info, 0, sizeof info);
        info.number = (int32_t)nums[k];
        info.step = nums[k];
        info.time = 0.0;
        info.phase =
            nums[k] <= meta->equil_number ? CDEM_PHASE_EQUILIBRATION : CDEM_PHASE_DEFORMATION;
        info.sea_level = NAN;
        info.n_elements = (int64_t)cur.n;
        info.has_stress = meta->has_forces;
        st = sink(user, &info, &cur, err);
        if (st != CDEM_OK)
            break;
        st = cdem_state_assign(&prev, &cur, err); /* prev is reused */
        have_prev = 1;
    }
    free(nums);
    cdem_state_free(&prev);
    cdem_state_free(&cur);
    return st;
}
