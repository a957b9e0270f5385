/* csvtable: a numeric CSV table with a header line (the wedge tables, compute output, ...).
 *
 * The first line names the columns (comma-separated, surrounding spaces trimmed); every
 * further non-empty line holds as many numbers (strtod; "nan", "inf" accepted). Lines
 * starting with '#' are comments. Errors name the file, line, column and text.
 * Ownership: cdem_csvtable owns its names and values; cdem_csvtable_free releases them
 * (NULL accepted). Thread safety: none needed (no shared state). Units: the file's. */
#ifndef CDEM_CSVTABLE_H
#define CDEM_CSVTABLE_H

#include "cdem_error.h"

#include <stddef.h>

typedef struct {
    size_t n_cols;  /* columns, >= 1 */
    size_t n_rows;  /* data rows, >= 0 */
    char **names;   /* n_cols column names */
    double *values; /* n_rows x n_cols, row-major: values[r * n_cols + c] */
} cdem_csvtable;

/* Reads path into *t (which is overwritten). */
cdem_status cdem_csvtable_read(const char *path, cdem_csvtable *t, cdem_error *err);

/* Index of column `name`; fails naming the file and listing the columns. */
cdem_status cdem_csvtable_find(const cdem_csvtable *t, const char *name, const char *path,
                               size_t *col, cdem_error *err);

/* Copies column col into out (n_rows values). */
void cdem_csvtable_column(const cdem_csvtable *t, size_t col, double *out);

void cdem_csvtable_free(cdem_csvtable *t);

#endif
