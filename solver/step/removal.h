/* removal: which elements leave the model, and the record of those that did. Three causes
 * share one path (the stepper's list build with a keep mask, which compacts the state and
 * keeps the histories of the remaining pairs): escaping free elements (out of the box the
 * walls span, tested at every list rebuild once enabled), erosion (free elements above a
 * level) and the boundary mode's start-of-deformation hook (cdem_bc_begin_deformation).
 * This module marks the elements (keep[i] = 0) and records their ids; the stepper removes
 * them. Escape bounds: removed when x < xmin - r, x > xmax + r or y < ymin - max_radius, the
 * x bounds following the moving lateral walls. Thread safety: one per integrator. */
#ifndef CDEM_REMOVAL_H
#define CDEM_REMOVAL_H

#include "bc.h"
#include "cdem_error.h"
#include "state.h"

typedef struct {
    int bounds_set;                               /* 0/1: escapes enabled */
    double escape_xmin, escape_xmax, escape_ymin; /* m, the wall span at the last test */
    double max_radius;                            /* m, largest radius of the model */
    unsigned char *keep;                          /* per-element mask: 0 = remove (keepcap) */
    size_t keepcap;                               /* capacity of keep */
    long n_removed;        /* elements removed so far (escapes and erosion) */
    int32_t *removed_ids;  /* ids removed at the last removal (n_removed_last of them) */
    size_t n_removed_last; /* count at the last removal (0 after a step without one) */
    size_t removed_cap;    /* capacity of removed_ids */
} cdem_removal;

/* Escapes off, nothing removed. */
void cdem_removal_init(cdem_removal *r, double max_radius);
void cdem_removal_free(cdem_removal *r);

/* Grows keep to n elements. */
cdem_status cdem_removal_reserve(cdem_removal *r, size_t n, cdem_error *err);

/* Copies the ids of the elements with keep[i] == 0 (nrem of them) to removed_ids. */
cdem_status cdem_removal_collect(cdem_removal *r, const cdem_state *s, size_t nrem,
                                 cdem_error *err);

/* Marks the escaping free elements in keep (bounds from the current wall elements) and
 * collects their ids; *count = how many (0, keep untouched, when escapes are off or there are
 * no walls). */
cdem_status cdem_removal_find_escapes(cdem_removal *r, const cdem_state *s, size_t *count,
                                      cdem_error *err);

/* Erosion: marks every free element whose centre is above ymax in keep; *count = how many. */
cdem_status cdem_removal_mark_above(cdem_removal *r, const cdem_state *s, double ymax,
                                    size_t *count, cdem_error *err);

/* Start of deformation: marks in keep the elements the boundary mode's begin_deformation hook
 * removes (any kind, walls included); *count = how many. Fails with CDEM_ERR_INVALID when the
 * hook's count and its marks disagree. */
cdem_status cdem_removal_mark_by_mode(cdem_removal *r, cdem_state *s, cdem_bc *bc, size_t *count,
                                      cdem_error *err);

#endif
