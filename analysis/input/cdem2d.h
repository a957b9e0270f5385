/* cdem2d: import of a cdem2D simulation folder (S. Hardy's DEM code) as a sequence of
 * element states, so an imported run behaves exactly as a native one.
 *
 * Folder: modelparameters.txt (kept verbatim as the summary text; a few keys are recognised,
 * see docs/formats-text.md), modelresults_N.txt per increment N (one element per line:
 * x y radius layer, whitespace-separated) and optionally modelforces_N.txt (same line order:
 * sxx syy sxy in N/m). CRLF line endings, blank lines and '#' comment lines are accepted.
 * cdem2D files carry no element ids: increment ids are assigned in file order in the first
 * increment and carried forward by matching each element to the nearest element of the
 * previous increment with the same radius and layer within 2 x the largest radius (cell
 * grid; a previous element claimed twice goes to the closer one); unmatched elements get
 * new ids. Layer 0 = wall element; layers above the pre-growth count = growth elements.
 * Ownership: the caller owns meta (cdem_cdem2d_meta_free). Thread safety: pure. */
#ifndef CDEM_CDEM2D_H
#define CDEM_CDEM2D_H

#include "cdem_error.h"
#include "h5format.h"
#include "state.h"

#include <stddef.h>

typedef struct {
    char *params_text;    /* modelparameters.txt content ("" when absent), malloc'd */
    int pregrowth_layers; /* from "pre-growth layers"; 0 = not given (no growth layers) */
    int mode;             /* cdem_mode from "faulting mode"; -1 = not given */
    int equil_number;     /* from "equilibration increment"; -1 = not given (first) */
    size_t n_increments;  /* increments found */
    int has_forces;       /* 1 when every increment has a modelforces_N.txt */
} cdem_cdem2d_meta;

/* Receives each increment in ascending number order; s is valid only during the call. */
typedef cdem_status (*cdem_cdem2d_sink)(void *user, const cdem_increment_info *info,
                                        const cdem_state *s, cdem_error *err);

/* Reads the folder, calling sink for every increment. meta is filled (free it even on
 * failure). Errors name the file and line. */
cdem_status cdem_cdem2d_import(const char *dir, cdem_cdem2d_sink sink, void *user,
                               cdem_cdem2d_meta *meta, cdem_error *err);

/* Imports the folder into a cdem file at out_path (written with the h5format writer). */
cdem_status cdem_cdem2d_import_h5(const char *dir, const char *out_path, cdem_error *err);

void cdem_cdem2d_meta_free(cdem_cdem2d_meta *meta);

#endif
