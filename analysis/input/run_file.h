/* run_file: the analysis context (measure/analysis.h) over a cdem HDF5 run file, or over a
 * cdem file imported from cdem2D. It is the file-backed source of the context, kept apart
 * from measure/analysis.c so that the measures and the code that works on in-memory states
 * never link the HDF5 reader, and so that measure/ needs nothing of input/.
 * Ownership: the context owns the reader it opens (closed by cdem_analysis_close).
 * Thread safety: one context per thread. */
#ifndef CDEM_RUN_FILE_H
#define CDEM_RUN_FILE_H

#include "analysis.h"

/* Opens the cdem file at path; messages name it. */
cdem_status cdem_analysis_open(const char *path, cdem_analysis **out, cdem_error *err);
/* The same over a reader already open on path (the context owns it from now on: it is closed
 * on failure too), so that a command opens the file once (and warns of damage once). */
cdem_status cdem_analysis_open_reader(cdem_h5_reader *r, const char *path, cdem_analysis **out,
                                      cdem_error *err);

#endif
