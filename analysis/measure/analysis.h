/* analysis: the analysis context of cdem-strain. It reads increments from a source (a cdem
 * HDF5 file, or states held in memory), keeps a small LRU cache of loaded increments and the
 * running cumulative-strain sums, and answers per-element quantities, colour limits,
 * displacement vectors and grid axes for any increment (rules in docs/analysis.md):
 *   incremental: increment k against k - 5 (against the first while fewer than 5 precede);
 *   total: k against the end of equilibration (the last increment whose phase is
 *     equilibration; the first increment when none is), growth elements (born after it)
 *     against the first increment numbered >= their birth; NaN before the end of
 *     equilibration; cumulative: sum over successive pairs from the end of equilibration.
 *   The end of equilibration is known once an increment of a later phase follows it (or the
 *     run completed): a run stopped, killed or still running in equilibration has not written
 *     it, and total and cumulative quantities then fail (CDEM_ERR_NOTFOUND, "not defined
 *     yet") rather than measure from its last increment.
 * Ownership: the context owns its cache; states returned through `const cdem_state **` are
 * borrowed and stay valid until the next call on the same context; value arrays are
 * malloc'd and owned by the caller. Thread safety: one context per thread (the cache
 * mutates); computations inside use OpenMP with results independent of the thread count. */
#ifndef CDEM_ANALYSIS_H
#define CDEM_ANALYSIS_H

#include "axes.h"
#include "cdem_error.h"
#include "h5format.h"
#include "colorlimits.h"
#include "params.h"
#include "quantity.h"
#include "state.h"

#include <stddef.h>

#define CDEM_ANALYSIS_INCR_LAG 5 /* incremental quantities compare k with k - 5 */

typedef struct cdem_analysis cdem_analysis;

/* Where increments come from. */
typedef struct {
    size_t (*count)(void *ctx); /* increments available */
    cdem_status (*info)(void *ctx, size_t index, cdem_increment_info *info, cdem_error *err);
    /* s is empty on entry (zeroed); load fills it */
    cdem_status (*load)(void *ctx, size_t index, cdem_state *s, cdem_error *err);
    void (*close)(void *ctx);             /* releases ctx at cdem_analysis_close; may be NULL */
    cdem_h5_reader *(*reader)(void *ctx); /* the file reader, or NULL (may be NULL) */
} cdem_analysis_source;

/* Builds a context over any source; params (copied) gives total_strain_max. */
cdem_status cdem_analysis_open_source(const cdem_analysis_source *src, void *ctx,
                                      const cdem_params *params, cdem_analysis **out,
                                      cdem_error *err);

/* Builds a context over n in-memory states and their infos (borrowed: they must outlive
 * the context). */
cdem_status cdem_analysis_open_states(const cdem_state *states, const cdem_increment_info *infos,
                                      size_t n, const cdem_params *params, cdem_analysis **out,
                                      cdem_error *err);

void cdem_analysis_close(cdem_analysis *a);

/* Names the run in messages that concern the whole run ("RUN.h5: increment 3 does not
 * exist"); cdem_analysis_open (input/run_file.h) sets the file's path. name is copied; NULL clears
 * it. */
void cdem_analysis_set_name(cdem_analysis *a, const char *name);

size_t cdem_analysis_count(const cdem_analysis *a);
const cdem_increment_info *cdem_analysis_info(const cdem_analysis *a, size_t index);
/* Index of the end-of-equilibration increment (meaningful when cdem_analysis_equil_known). */
size_t cdem_analysis_equil_index(const cdem_analysis *a);
/* 1 when the end of equilibration is known, 0 while the run has not left equilibration (its
 * increments all are of that phase and it did not complete: stopped, killed or running). */
int cdem_analysis_equil_known(const cdem_analysis *a);
/* Why it is not known ("the run stopped during equilibration", "the run is still in
 * equilibration"), "" when it is. */
const char *cdem_analysis_equil_why(const cdem_analysis *a);
/* 1 for a quantity measured from the end of equilibration (total and cumulative ones). */
int cdem_analysis_from_equil(const cdem_quantity *q);
const cdem_params *cdem_analysis_params(const cdem_analysis *a);
/* The reader of a file-backed context (NULL otherwise). */
cdem_h5_reader *cdem_analysis_reader(const cdem_analysis *a);

/* Resolves "K" (increment number), "last", "first" or "equil" to an index ("equil" fails
 * while the end of equilibration is not known). */
cdem_status cdem_analysis_find(const cdem_analysis *a, const char *spec, size_t *index,
                               cdem_error *err);

/* The state of increment `index` (borrowed: valid until the next call on a that reads
 * another increment, which may evict it from the cache; values, limits, vectors and axes
 * may read several). */
cdem_status cdem_analysis_state(cdem_analysis *a, size_t index, const cdem_state **s,
                                cdem_error *err);

/* Per-element values of quantity q at increment index, aligned with *s (borrowed); *values is
 * malloc'd (caller frees), NaN where undefined. Stress quantities on an increment without
 * stress fail with CDEM_ERR_NOTFOUND. */
cdem_status cdem_analysis_values(cdem_analysis *a, size_t index, const cdem_quantity *q,
                                 const cdem_state **s, double **values, cdem_error *err);

/* Colour limits of q for increment index (see colorlimits.h and docs/analysis.md). */
cdem_status cdem_analysis_limits(cdem_analysis *a, size_t index, const cdem_quantity *q,
                                 cdem_limits *lim, cdem_error *err);

/* Displacement vectors (incremental when total == 0, else total), aligned with *s. */
cdem_status cdem_analysis_vectors(cdem_analysis *a, size_t index, int total, const cdem_state **s,
                                  double **ux, double **uy, cdem_error *err);

typedef enum {
    CDEM_AXES_INCR_STRAIN = 0, /* principal/max-shear axes of incremental strain */
    CDEM_AXES_TOTAL_STRAIN,    /* of total strain (pre-growth elements only) */
    CDEM_AXES_STRESS,          /* principal stress axes */
} cdem_axes_kind;

/* Axes on the grid for increment index (out owned by the caller: cdem_axes_free). */
cdem_status cdem_analysis_axes(cdem_analysis *a, size_t index, cdem_axes_kind kind, cdem_axes *out,
                               cdem_error *err);

#endif
