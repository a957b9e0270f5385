/* checkpoint: see checkpoint.h. Names longer than CDEM_SNAPSHOT_NAME_MAX are refused by the
 * snapshot itself; every name used by the solver is short and fixed. */
#include "checkpoint.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cdem_status make_name(char *buf, const char *prefix, const char *name, cdem_error *err) {
    const int len = snprintf(buf, CDEM_SNAPSHOT_NAME_MAX, "%s.%s", prefix, name);
    if (len < 0 || len >= CDEM_SNAPSHOT_NAME_MAX)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "checkpoint: array name %s.%s is longer than %d characters", prefix, name,
                         CDEM_SNAPSHOT_NAME_MAX - 1);
    return CDEM_OK;
}

cdem_status cdem_ckpt_put_array(cdem_snapshot *s, const char *prefix, const char *name,
                                cdem_snapshot_type type, size_t count, const void *data,
                                cdem_error *err) {
    char full[CDEM_SNAPSHOT_NAME_MAX];
    CDEM_TRY(make_name(full, prefix, name, err));
    return cdem_snapshot_put(s, full, type, count, count ? data : NULL, err);
}

cdem_status cdem_ckpt_put_f64(cdem_snapshot *s, const char *prefix, const char *name, double v,
                              cdem_error *err) {
    return cdem_ckpt_put_array(s, prefix, name, CDEM_SNAP_F64, 1, &v, err);
}

cdem_status cdem_ckpt_put_i64(cdem_snapshot *s, const char *prefix, const char *name, int64_t v,
                              cdem_error *err) {
    return cdem_ckpt_put_array(s, prefix, name, CDEM_SNAP_I64, 1, &v, err);
}

cdem_status cdem_ckpt_put_text(cdem_snapshot *s, const char *prefix, const char *name,
                               const char *text, cdem_error *err) {
    const char *t = text ? text : "";
    return cdem_ckpt_put_array(s, prefix, name, CDEM_SNAP_U8, strlen(t), t, err);
}

cdem_status cdem_ckpt_get_array(const cdem_snapshot *s, const char *prefix, const char *name,
                                cdem_snapshot_type type, size_t count,
                                const cdem_snapshot_array **out, cdem_error *err) {
    char full[CDEM_SNAPSHOT_NAME_MAX];
    CDEM_TRY(make_name(full, prefix, name, err));
    return cdem_snapshot_require(s, full, type, count, out, err);
}

cdem_status cdem_ckpt_get_f64(const cdem_snapshot *s, const char *prefix, const char *name,
                              double *v, cdem_error *err) {
    const cdem_snapshot_array *a = NULL;
    CDEM_TRY(cdem_ckpt_get_array(s, prefix, name, CDEM_SNAP_F64, 1, &a, err));
    memcpy(v, a->data, sizeof *v);
    return CDEM_OK;
}

cdem_status cdem_ckpt_get_i64(const cdem_snapshot *s, const char *prefix, const char *name,
                              int64_t *v, cdem_error *err) {
    const cdem_snapshot_array *a = NULL;
    CDEM_TRY(cdem_ckpt_get_array(s, prefix, name, CDEM_SNAP_I64, 1, &a, err));
    memcpy(v, a->data, sizeof *v);
    return CDEM_OK;
}

cdem_status cdem_ckpt_get_range(const cdem_snapshot *s, const char *prefix, const char *name,
                                int64_t lo, int64_t hi, int64_t *v, cdem_error *err) {
    CDEM_TRY(cdem_ckpt_get_i64(s, prefix, name, v, err));
    if (*v < lo || *v > hi)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "checkpoint array %s.%s = %lld: outside the allowed %lld..%lld (corrupt "
                         "checkpoint)",
                         prefix, name, (long long)*v, (long long)lo, (long long)hi);
    return CDEM_OK;
}

cdem_status cdem_ckpt_check_text(const cdem_snapshot *s, const char *prefix, const char *name,
                                 const char *expected, const char *what, cdem_error *err) {
    const cdem_snapshot_array *a = NULL;
    CDEM_TRY(cdem_ckpt_get_array(s, prefix, name, CDEM_SNAP_U8, SIZE_MAX, &a, err));
    const char *e = expected ? expected : "";
    const size_t n = strlen(e);
    if (a->count == n && (n == 0 || memcmp(a->data, e, n) == 0))
        return CDEM_OK;
    /* first differing line, for the message */
    size_t k = 0;
    const char *d = a->data;
    while (k < n && k < a->count && d[k] == e[k])
        k++;
    size_t b = k;
    while (b > 0 && e[b - 1] != '\n')
        b--;
    size_t end = b;
    while (end < n && e[end] != '\n' && end - b < 80)
        end++;
    return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                     "checkpoint %s.%s: the %s of the checkpoint differs from this run's (first "
                     "difference in \"%.*s\")",
                     prefix, name, what, (int)(end - b), e + b);
}

cdem_status cdem_ckpt_check_f64(const cdem_snapshot *s, const char *prefix, const char *name,
                                double expected, cdem_error *err) {
    double v = 0.0;
    CDEM_TRY(cdem_ckpt_get_f64(s, prefix, name, &v, err));
    if (memcmp(&v, &expected, sizeof v) != 0)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "checkpoint %s.%s = %.17g but this run has %.17g: the checkpoint belongs "
                         "to another model",
                         prefix, name, v, expected);
    return CDEM_OK;
}

/* ---------------------------------------------------------------- element state */

/* The snapshot type of a state field's element type. */
static cdem_snapshot_type snap_type(cdem_field_type t) {
    return t == CDEM_FIELD_I32   ? CDEM_SNAP_I32
           : t == CDEM_FIELD_U32 ? CDEM_SNAP_U32
                                 : CDEM_SNAP_F64;
}

/* fx or fy with the boundary elements' values replaced by 0 (malloc'd; NULL: no memory). */
static double *free_forces_only(const cdem_state *st, const double *f) {
    double *c = malloc((st->n ? st->n : 1) * sizeof *c);
    if (!c)
        return NULL;
    for (size_t i = 0; i < st->n; i++)
        c[i] = (st->flags[i] & CDEM_FLAGS_BOUNDARY) ? 0.0 : f[i];
    return c;
}

cdem_status cdem_ckpt_state_put(const cdem_state *st, int boundary_forces, cdem_snapshot *s,
                                cdem_error *err) {
    CDEM_TRY(cdem_ckpt_put_i64(s, "state", "n", (int64_t)st->n, err));
    CDEM_TRY(cdem_ckpt_put_i64(s, "state", "next_id", st->next_id, err));
    CDEM_TRY(cdem_ckpt_put_i64(s, "state", "has_stress", st->has_stress, err));
    /* every field of the state (checkpoints resume the run exactly), in table order */
    for (size_t k = 0; k < cdem_state_field_count; k++) {
        const cdem_state_field *f = &cdem_state_fields[k];
        if (f->stress && !st->has_stress)
            continue;
        const void *data = cdem_state_field_array(st, f);
        double *copy = NULL;
        if (!boundary_forces && (data == st->fx || data == st->fy)) {
            copy = free_forces_only(st, data);
            if (!copy)
                return CDEM_FAIL(err, CDEM_ERR_NOMEM,
                                 "checkpoint: out of memory copying %zu forces", st->n);
            data = copy;
        }
        cdem_status rc =
            cdem_ckpt_put_array(s, "state", f->name, snap_type(f->type), st->n, data, err);
        free(copy);
        CDEM_TRY(rc);
    }
    return CDEM_OK;
}

/* 1 for a field added to the state after checkpoints first shipped, when the checkpoint
 * (written by an older cdem-run) lacks it: the field then takes its value of an element that
 * never changed it (area_ratio: 1, no process changed it then). */
static int added_later_and_absent(const cdem_state_field *f, const cdem_snapshot *s) {
    return strcmp(f->name, "area_ratio") == 0 && !cdem_snapshot_get(s, "state.area_ratio");
}

cdem_status cdem_ckpt_state_get(cdem_state *st, const cdem_snapshot *s, cdem_error *err) {
    int64_t n = 0, next_id = 0, has_stress = 0;
    CDEM_TRY(cdem_ckpt_get_range(s, "state", "n", 0, INT32_MAX, &n, err));
    CDEM_TRY(cdem_ckpt_get_range(s, "state", "next_id", 0, INT32_MAX, &next_id, err));
    CDEM_TRY(cdem_ckpt_get_range(s, "state", "has_stress", 0, 1, &has_stress, err));
    /* check every array before touching st */
    for (size_t k = 0; k < cdem_state_field_count; k++) {
        const cdem_state_field *f = &cdem_state_fields[k];
        if ((f->stress && !has_stress) || added_later_and_absent(f, s))
            continue;
        const cdem_snapshot_array *a = NULL;
        CDEM_TRY(cdem_ckpt_get_array(s, "state", f->name, snap_type(f->type), (size_t)n, &a, err));
    }
    CDEM_TRY(cdem_state_reserve(st, (size_t)n, err));
    if (has_stress)
        CDEM_TRY(cdem_state_enable_stress(st, err));
    for (size_t k = 0; k < cdem_state_field_count; k++) {
        const cdem_state_field *f = &cdem_state_fields[k];
        if (f->stress && !has_stress)
            continue;
        if (added_later_and_absent(f, s)) {
            for (int64_t i = 0; i < n; i++)
                st->area_ratio[i] = 1.0;
            continue;
        }
        const cdem_snapshot_array *a = NULL;
        CDEM_TRY(cdem_ckpt_get_array(s, "state", f->name, snap_type(f->type), (size_t)n, &a, err));
        if (n > 0)
            memcpy(cdem_state_field_array(st, f), a->data,
                   (size_t)n * cdem_field_type_size(f->type));
    }
    st->n = (size_t)n;
    st->next_id = (int32_t)next_id;
    return CDEM_OK;
}
