/* checkpoint: small helpers every solver module uses to put its part of the run state into a
 * cdem_snapshot (common/snapshot.h) and to take it back on --resume, plus the element state.
 * Names are "<prefix>.<field>" (e.g. "it.step", "state.x"); a scalar is an array of count 1.
 * The _get helpers fail with CDEM_ERR_FORMAT naming the array when it is missing or of the
 * wrong type/length; cdem_ckpt_check_* fail with CDEM_ERR_CONFLICT when a configuration value
 * stored in the checkpoint differs from the one of the run being restored (e.g. another dt).
 * What each module stores, and why the rest is rebuilt: docs/reliability.md.
 * Ownership: the snapshot copies what is put; nothing here keeps pointers.
 * Thread safety: none (one run per snapshot). Units: those of the fields stored. */
#ifndef CDEM_CHECKPOINT_H
#define CDEM_CHECKPOINT_H

#include "cdem_error.h"
#include "snapshot.h"
#include "state.h"

#include <stddef.h>
#include <stdint.h>

cdem_status cdem_ckpt_put_f64(cdem_snapshot *s, const char *prefix, const char *name, double v,
                              cdem_error *err);
cdem_status cdem_ckpt_put_i64(cdem_snapshot *s, const char *prefix, const char *name, int64_t v,
                              cdem_error *err);
/* count values of type from data (count 0: data may be NULL). */
cdem_status cdem_ckpt_put_array(cdem_snapshot *s, const char *prefix, const char *name,
                                cdem_snapshot_type type, size_t count, const void *data,
                                cdem_error *err);
/* A NUL-terminated text stored as U8 bytes (without the NUL). */
cdem_status cdem_ckpt_put_text(cdem_snapshot *s, const char *prefix, const char *name,
                               const char *text, cdem_error *err);

cdem_status cdem_ckpt_get_f64(const cdem_snapshot *s, const char *prefix, const char *name,
                              double *v, cdem_error *err);
cdem_status cdem_ckpt_get_i64(const cdem_snapshot *s, const char *prefix, const char *name,
                              int64_t *v, cdem_error *err);
/* As cdem_ckpt_get_i64, also failing (CDEM_ERR_FORMAT) when the value is outside lo..hi. */
cdem_status cdem_ckpt_get_range(const cdem_snapshot *s, const char *prefix, const char *name,
                                int64_t lo, int64_t hi, int64_t *v, cdem_error *err);
/* The array; count SIZE_MAX accepts any length. */
cdem_status cdem_ckpt_get_array(const cdem_snapshot *s, const char *prefix, const char *name,
                                cdem_snapshot_type type, size_t count,
                                const cdem_snapshot_array **out, cdem_error *err);
/* Compares a stored text with `expected`: CDEM_ERR_CONFLICT naming `what` when they differ. */
cdem_status cdem_ckpt_check_text(const cdem_snapshot *s, const char *prefix, const char *name,
                                 const char *expected, const char *what, cdem_error *err);
/* Compares a stored double with `expected` bit for bit: CDEM_ERR_CONFLICT when they differ. */
cdem_status cdem_ckpt_check_f64(const cdem_snapshot *s, const char *prefix, const char *name,
                                double expected, cdem_error *err);

/* The element state: every array (id, x, y, vx, vy, fx, fy, radius, mass, layer, flags, born
 * and, when has_stress, sxx, syy, sxy) plus n, next_id and has_stress, under "state.".
 * boundary_forces = 0 (the last step was not a sample step): the fx, fy of boundary elements
 * are stored as 0. They are read only on sample steps, after the step's force pass has
 * summed them again, so results are the same. (The force pass once summed them on sample
 * steps only, when the stored ones were stale; it sums them on every step now, and the zeros
 * stay so that checkpoints keep their contents.) */
cdem_status cdem_ckpt_state_put(const cdem_state *st, int boundary_forces, cdem_snapshot *s,
                                cdem_error *err);
/* Replaces the contents of st (initialised) with the stored state (grown as needed; the
 * stress arrays enabled when they were stored). */
cdem_status cdem_ckpt_state_get(cdem_state *st, const cdem_snapshot *s, cdem_error *err);

#endif
