/* qexport: writes computed per-element quantities to CSV or HDF5 (cdem-strain compute).
 *
 * CSV: a header line "id,x,y,value" (or "increment,id,x,y,value" when several increments
 * go to one file), then one element per line; undefined values are written "nan".
 * HDF5: root attributes quantity, label, unit; one group /increments/NNNNNN (6-digit
 * increment number, attribute number) per increment holding 1-D datasets id (int32), x, y
 * (m) and value (double, NaN = undefined), aligned. See docs/analysis.md.
 * Ownership: the writer handle owns its file (cdem_qexport_close accepts NULL).
 * Thread safety: one handle per thread. */
#ifndef CDEM_QEXPORT_H
#define CDEM_QEXPORT_H

#include "cdem_error.h"
#include "quantity.h"
#include "state.h"

#include <stdio.h>

/* CSV rows of one increment to f; with_increment adds the leading increment column. */
cdem_status cdem_qexport_csv_header(FILE *f, int with_increment, cdem_error *err);
cdem_status cdem_qexport_csv_rows(FILE *f, int with_increment, int32_t number, const cdem_state *s,
                                  const double *values, cdem_error *err);

typedef struct cdem_qexport_h5 cdem_qexport_h5;

cdem_status cdem_qexport_h5_create(const char *path, const cdem_quantity *q, cdem_qexport_h5 **out,
                                   cdem_error *err);
cdem_status cdem_qexport_h5_write(cdem_qexport_h5 *h, int32_t number, const cdem_state *s,
                                  const double *values, cdem_error *err);
cdem_status cdem_qexport_h5_close(cdem_qexport_h5 *h, cdem_error *err);

#endif
