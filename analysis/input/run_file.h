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

#endif
