/* sspx: per-increment text export for SSPX ("Load Stations from cdem") and other tools, and
 * the matching reader used to check round trips.
 *
 * One file per increment, named <dir>/<prefix><number>.txt (e.g. cdem282.txt). No header
 * line; one element per line, in the increment's element order, five whitespace-separated
 * columns: id x y radius layer (id and layer integers; x, y, radius in m with 6 decimals;
 * layer 0 = wall element). LF line endings. See docs/formats-text.md.
 * Ownership: plain functions; the caller owns every buffer. Thread safety: no shared state. */
#ifndef CDEM_SSPX_H
#define CDEM_SSPX_H

#include "analysis.h"
#include "cdem_error.h"
#include "state.h"

#include <stddef.h>

/* Writes one state to path. */
cdem_status cdem_sspx_write(const char *path, const cdem_state *s, cdem_error *err);

/* Reads a file written by cdem_sspx_write into s (re-initialised; masses, velocities zero;
 * flags WALL for layer 0). Malformed lines fail naming file and line. */
cdem_status cdem_sspx_read(const char *path, cdem_state *s, cdem_error *err);

/* Exports the increments with index first..last (inclusive) of a into dir; *written (may be
 * NULL) receives the number of files. dir must exist. */
cdem_status cdem_sspx_export(cdem_analysis *a, size_t first, size_t last, const char *dir,
                             const char *prefix, size_t *written, cdem_error *err);

/* Parses "A-B" or "A" (increment numbers; "equil", "last", "first" allowed on either side)
 * into an index range of a. */
cdem_status cdem_sspx_parse_range(const cdem_analysis *a, const char *spec, size_t *first,
                                  size_t *last, cdem_error *err);

#endif
