/* biaxial: export of the uni/biaxial test series as a stress-strain text table (the
 * original program's "Save Uni/Biaxial data as text"), for plotting and for the failure
 * envelope from tests at several confining pressures.
 * Layout: a '#' header line naming the columns, then one sample per line, three
 * whitespace-separated columns: time step, axial strain (platen shortening / initial
 * height), differential stress sigma1 - sigma3 (N/m). See docs/formats-text.md.
 * Ownership: caller owns the samples. Thread safety: no shared state. */
#ifndef CDEM_BIAXIAL_H
#define CDEM_BIAXIAL_H

#include "cdem_error.h"
#include "h5format.h"

#include <stddef.h>

cdem_status cdem_biaxial_write(const char *path, const cdem_series_sample *samples, size_t n,
                               cdem_error *err);

#endif
