/* csvtable: see csvtable.h. */
#include "csvtable.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LINE_MAX_LEN 65536
#define MAX_COLS     1024

void cdem_csvtable_free(cdem_csvtable *t) {
    if (!t)
        return;
    for (size_t c = 0; t->names && c < t->n_cols; c++)
        free(t->names[c]);
    free(t->names);
    free(t->values);
    memset(t, 0, sizeof *t);
}

static char *trim(char *s) {
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n > 0 && isspace((unsigned char)s[n - 1]))
        s[--n] = '\0';
    return s;
}

/* 1 when s is valid UTF-8 without control characters (a text header, not binary data). */
static int is_text(const char *s) {
    const unsigned char *p = (const unsigned char *)s;
    while (*p) {
        int more = *p < 0x80             ? 0
                   : (*p & 0xE0) == 0xC0 ? 1
                   : (*p & 0xF0) == 0xE0 ? 2
                   : (*p & 0xF8) == 0xF0 ? 3
                                         : -1;
        if (more < 0 || (*p < 0x20 && *p != '\t') || *p == 0x7f)
            return 0;
        p++;
        for (; more > 0; more--, p++)
            if ((*p & 0xC0) != 0x80)
                return 0;
    }
    return 1;
}

static cdem_status parse_header(char *line, const char *path, cdem_csvtable *t, cdem_error *err) {
    if (!is_text(line))
        return CDEM_FAIL(err, CDEM_ERR_PARSE,
                         "%s:1: the header line is not text (binary data?): a CSV file with a "
                         "header line of column names is needed",
                         path);
    size_t n = 1;
    for (const char *p = line; *p; p++)
        n += *p == ',';
    if (n > MAX_COLS)
        return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s:1: %zu columns: at most %d are allowed", path, n,
                         MAX_COLS);
    t->names = calloc(n, sizeof *t->names);
    if (!t->names)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: no memory for %zu column names", path, n);
    t->n_cols = n;
    char *tok = line;
    for (size_t c = 0; c < n; c++) {
        char *comma = strchr(tok, ',');
        if (comma)
            *comma = '\0';
        char *name = trim(tok);
        if (!name[0])
            return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s:1: column %zu has an empty name", path,
                             c + 1);
        if (!(t->names[c] = strdup(name)))
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: no memory for column names", path);
        tok = comma ? comma + 1 : tok + strlen(tok);
    }
    return CDEM_OK;
}

static cdem_status parse_row(char *line, size_t lineno, const char *path, cdem_csvtable *t,
                             size_t *cap, cdem_error *err) {
    if (t->n_rows == *cap) {
        size_t nc = *cap ? 2 * *cap : 64;
        double *v = realloc(t->values, nc * t->n_cols * sizeof *v);
        if (!v)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: no memory for %zu rows", path, nc);
        t->values = v;
        *cap = nc;
    }
    double *row = t->values + t->n_rows * t->n_cols;
    char *p = line;
    for (size_t c = 0; c < t->n_cols; c++) {
        char *end;
        errno = 0;
        double v = strtod(p, &end);
        while (isspace((unsigned char)*end))
            end++;
        const int last = c + 1 == t->n_cols;
        if (end == p || (last ? *end != '\0' : *end != ','))
            return CDEM_FAIL(
                err, CDEM_ERR_PARSE, "%s:%zu: column %zu (%s): '%.40s' is not a number%s", path,
                lineno, c + 1, t->names[c], p,
                last ? " (or the line has too many fields)" : " (or the line has too few fields)");
        row[c] = v;
        p = end + 1;
    }
    t->n_rows++;
    return CDEM_OK;
}

cdem_status cdem_csvtable_read(const char *path, cdem_csvtable *t, cdem_error *err) {
    if (!path || !t)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "csvtable: NULL argument");
    memset(t, 0, sizeof *t);
    FILE *f = fopen(path, "r");
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot open %s: %s", path, strerror(errno));
    char *line = malloc(LINE_MAX_LEN);
    if (!line) {
        fclose(f);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: no memory for a line", path);
    }
    cdem_status st = CDEM_OK;
    size_t lineno = 0, cap = 0;
    int have_header = 0;
    while (st == CDEM_OK && fgets(line, LINE_MAX_LEN, f)) {
        lineno++;
        size_t len = strlen(line);
        if (len == LINE_MAX_LEN - 1 && line[len - 1] != '\n') {
            st = CDEM_FAIL(err, CDEM_ERR_PARSE, "%s:%zu: line longer than %d characters", path,
                           lineno, LINE_MAX_LEN - 2);
            break;
        }
        char *s = trim(line);
        if (!s[0] || s[0] == '#')
            continue;
        if (!have_header) {
            st = parse_header(s, path, t, err);
            have_header = 1;
        } else {
            st = parse_row(s, lineno, path, t, &cap, err);
        }
    }
    if (st == CDEM_OK && ferror(f))
        st = CDEM_FAIL(err, CDEM_ERR_IO, "error reading %s", path);
    if (st == CDEM_OK && !have_header)
        st = CDEM_FAIL(err, CDEM_ERR_PARSE,
                       "%s: empty file: a header line of column names is "
                       "needed",
                       path);
    free(line);
    fclose(f);
    if (st != CDEM_OK)
        cdem_csvtable_free(t);
    return st;
}

cdem_status cdem_csvtable_find(const cdem_csvtable *t, const char *name, const char *path,
                               size_t *col, cdem_error *err) {
    for (size_t c = 0; c < t->n_cols; c++)
        if (name && !strcmp(t->names[c], name)) {
            *col = c;
            return CDEM_OK;
        }
    char list[600] = "";
    for (size_t c = 0; c < t->n_cols; c++) {
        strncat(list, t->names[c], sizeof list - strlen(list) - 1);
        if (c + 1 < t->n_cols)
            strncat(list, ", ", sizeof list - strlen(list) - 1);
    }
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s: no column '%s'; the columns are: %s",
                     path ? path : "table", name ? name : "(none)", list);
}

void cdem_csvtable_column(const cdem_csvtable *t, size_t col, double *out) {
    for (size_t r = 0; r < t->n_rows; r++)
        out[r] = t->values[r * t->n_cols + col];
}
