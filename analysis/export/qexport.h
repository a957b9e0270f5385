/* qexport: writes computed per-element quantities to CSV or HDF5 (cdem-strain compute).
 *
 * CSV: a header line "id,x,y,value" (or "increment,id,x,y,value" when several increments
 * go to one file), then one element per line; undefined values are written "nan".
 * HDF5: root attributes quantity, label, unit; one group /increments/NNNNNN (6-digit
 * increment number, attributes number and time) per increment holding 1-D datasets id
 * (int32), x, y (m) and value (double, NaN = undefined), aligned, and xy, an n x 2 virtual
 * view of x and y (no storage) for the XDMF 3 sidecar (xdmf.h) that cdem-strain writes
 * next to the file. See docs/analysis.md.
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
/* Increment `number` at model time `time` (s). */
cdem_status cdem_qexport_h5_write(cdem_qexport_h5 *h, int32_t number, double time,
                                  const cdem_state *s, const double *values, cdem_error *err);
cdem_status cdem_qexport_h5_close(cdem_qexport_h5 *h, cdem_error *err);

/* Writes the XDMF sidecar of a closed compute --format h5 file to xmf_path (NULL: q.h5 ->
 * q.xmf next to it): one grid per increment with the quantity (named after it) and id as
 * point attributes. flavour 3 or 2 as in xdmf.h; *written (may be NULL) gets the flavour
 * written (2 for files without the xy views). CDEM_ERR_FORMAT when the file is not such a
 * file. */
cdem_status cdem_qexport_write_xdmf(const char *h5_path, const char *xmf_path, int flavour,
                                    int *written, cdem_error *err);

#endif
