/* snapshot: a named set of typed arrays — the complete state a stopped run needs to go on.
 *
 * The solver fills one at a checkpoint (every module puts its own arrays under its own name
 * prefix, e.g. "state.x", "contact.shear", "rng.state") and reads them back on --resume; the
 * file format stores and loads a snapshot without knowing what the arrays mean. A scalar is
 * an array of count 1. Names are unique: putting an existing name replaces its array.
 * Ownership: the snapshot copies the data it is given and owns every array; arrays returned
 * by _get stay valid until the next _put of the same name, _clear or _free.
 * Thread safety: none; one owner at a time. */
#ifndef CDEM_SNAPSHOT_H
#define CDEM_SNAPSHOT_H

#include "cdem_error.h"

#include <stddef.h>
#include <stdint.h>

#define CDEM_SNAPSHOT_NAME_MAX 64 /* longest name, including the terminating NUL */

typedef enum {
    CDEM_SNAP_F64 = 0, /* double */
    CDEM_SNAP_I64 = 1, /* int64_t */
    CDEM_SNAP_I32 = 2, /* int32_t */
    CDEM_SNAP_U32 = 3, /* uint32_t */
    CDEM_SNAP_U8 = 4,  /* uint8_t (also opaque bytes) */
} cdem_snapshot_type;

typedef struct {
    char name[CDEM_SNAPSHOT_NAME_MAX]; /* unique name, printable ASCII without '/' */
    cdem_snapshot_type type;           /* element type of data */
    size_t count;                      /* number of values (0 allowed; data may then be NULL) */
    void *data;                        /* count values of type, owned by the snapshot */
} cdem_snapshot_array;

typedef struct cdem_snapshot cdem_snapshot;

/* Size in bytes of one value of type (0 for an unknown type). */
size_t cdem_snapshot_type_size(cdem_snapshot_type type);

cdem_status cdem_snapshot_alloc(cdem_snapshot **out, cdem_error *err);
void cdem_snapshot_free(cdem_snapshot *s);

/* Removes every array (keeps the snapshot usable). */
void cdem_snapshot_clear(cdem_snapshot *s);

/* Copies count values of type from data under name (replacing an array of the same name).
 * Fails with CDEM_ERR_INVALID for an empty, too long or '/'-containing name or a bad type. */
cdem_status cdem_snapshot_put(cdem_snapshot *s, const char *name, cdem_snapshot_type type,
                              size_t count, const void *data, cdem_error *err);

/* The array called name, or NULL. */
const cdem_snapshot_array *cdem_snapshot_get(const cdem_snapshot *s, const char *name);

/* The array called name, checked: fails with CDEM_ERR_FORMAT naming the array when it is
 * missing, of another type, or (expected_count != SIZE_MAX) of another length. */
cdem_status cdem_snapshot_require(const cdem_snapshot *s, const char *name, cdem_snapshot_type type,
                                  size_t expected_count, const cdem_snapshot_array **out,
                                  cdem_error *err);

/* Number of arrays and the i-th one (in insertion order, i < count). */
size_t cdem_snapshot_count(const cdem_snapshot *s);
const cdem_snapshot_array *cdem_snapshot_at(const cdem_snapshot *s, size_t i);

/* 1 when a and b hold the same names, types, counts and bytes (order ignored); else 0. When
 * they differ and first_difference is not NULL, it receives the name of the first array
 * (in a's order, then b's) that differs. */
int cdem_snapshot_equal(const cdem_snapshot *a, const cdem_snapshot *b,
                        const char **first_difference);

#endif
