#include "snapshot.h"

#include <stdlib.h>
#include <string.h>

struct cdem_snapshot {
    cdem_snapshot_array *arrays; /* count used, capacity allocated */
    size_t count;                /* arrays in use */
    size_t capacity;             /* allocated entries of arrays */
};

size_t cdem_snapshot_type_size(cdem_snapshot_type type) {
    switch (type) {
    case CDEM_SNAP_F64:
    case CDEM_SNAP_I64:
        return 8;
    case CDEM_SNAP_I32:
    case CDEM_SNAP_U32:
        return 4;
    case CDEM_SNAP_U8:
        return 1;
    }
    return 0;
}

cdem_status cdem_snapshot_alloc(cdem_snapshot **out, cdem_error *err) {
    *out = calloc(1, sizeof **out);
    if (!*out)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory allocating a checkpoint snapshot");
    return CDEM_OK;
}

void cdem_snapshot_clear(cdem_snapshot *s) {
    if (!s)
        return;
    for (size_t i = 0; i < s->count; i++)
        free(s->arrays[i].data);
    s->count = 0;
}

void cdem_snapshot_free(cdem_snapshot *s) {
    if (!s)
        return;
    cdem_snapshot_clear(s);
    free(s->arrays);
    free(s);
}

static cdem_snapshot_array *find(const cdem_snapshot *s, const char *name) {
    for (size_t i = 0; i < s->count; i++)
        if (strcmp(s->arrays[i].name, name) == 0)
            return &s->arrays[i];
    return NULL;
}

cdem_status cdem_snapshot_put(cdem_snapshot *s, const char *name, cdem_snapshot_type type,
                              size_t count, const void *data, cdem_error *err) {
    const size_t len = name ? strlen(name) : 0;
    if (len == 0 || len >= CDEM_SNAPSHOT_NAME_MAX || strchr(name, '/'))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "snapshot array name \"%s\" is invalid: it must be 1 to %d characters "
                         "without '/'",
                         name ? name : "(null)", CDEM_SNAPSHOT_NAME_MAX - 1);
    const size_t size = cdem_snapshot_type_size(type);
    if (size == 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "snapshot array \"%s\": unknown type %d", name,
                         (int)type);
    if (count > 0 && !data)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "snapshot array \"%s\": %zu values but no data",
                         name, count);
    if (count > SIZE_MAX / size)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "snapshot array \"%s\": %zu values is too many", name,
                         count);

    void *copy = NULL;
    if (count > 0) {
        copy = malloc(count * size);
        if (!copy)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory copying snapshot array \"%s\"",
                             name);
        memcpy(copy, data, count * size);
    }

    cdem_snapshot_array *slot = find(s, name);
    if (!slot) {
        if (s->count == s->capacity) {
            const size_t cap = s->capacity ? 2 * s->capacity : 32;
            cdem_snapshot_array *grown = realloc(s->arrays, cap * sizeof *grown);
            if (!grown) {
                free(copy);
                return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory growing a snapshot");
            }
            s->arrays = grown;
            s->capacity = cap;
        }
        slot = &s->arrays[s->count++];
        memcpy(slot->name, name, len + 1);
    } else {
        free(slot->data);
    }
    slot->type = type;
    slot->count = count;
    slot->data = copy;
    return CDEM_OK;
}

const cdem_snapshot_array *cdem_snapshot_get(const cdem_snapshot *s, const char *name) {
    return (s && name) ? find(s, name) : NULL;
}

static const char *type_name(cdem_snapshot_type type) {
    static const char *const names[] = {"f64", "i64", "i32", "u32", "u8"};
    return (unsigned)type < sizeof names / sizeof names[0] ? names[type] : "unknown";
}

cdem_status cdem_snapshot_require(const cdem_snapshot *s, const char *name, cdem_snapshot_type type,
                                  size_t expected_count, const cdem_snapshot_array **out,
                                  cdem_error *err) {
    const cdem_snapshot_array *a = cdem_snapshot_get(s, name);
    if (!a)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "checkpoint has no array \"%s\"", name);
    if (a->type != type)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "checkpoint array \"%s\" has type %s, expected %s",
                         name, type_name(a->type), type_name(type));
    if (expected_count != SIZE_MAX && a->count != expected_count)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "checkpoint array \"%s\" has %zu values, expected %zu", name, a->count,
                         expected_count);
    *out = a;
    return CDEM_OK;
}

size_t cdem_snapshot_count(const cdem_snapshot *s) {
    return s ? s->count : 0;
}

const cdem_snapshot_array *cdem_snapshot_at(const cdem_snapshot *s, size_t i) {
    return (s && i < s->count) ? &s->arrays[i] : NULL;
}

static int same_array(const cdem_snapshot_array *a, const cdem_snapshot_array *b) {
    if (!b || a->type != b->type || a->count != b->count)
        return 0;
    return a->count == 0 ||
           memcmp(a->data, b->data, a->count * cdem_snapshot_type_size(a->type)) == 0;
}

int cdem_snapshot_equal(const cdem_snapshot *a, const cdem_snapshot *b,
                        const char **first_difference) {
    for (size_t i = 0; i < a->count; i++)
        if (!same_array(&a->arrays[i], find(b, a->arrays[i].name))) {
            if (first_difference)
                *first_difference = a->arrays[i].name;
            return 0;
        }
    for (size_t i = 0; i < b->count; i++)
        if (!find(a, b->arrays[i].name)) {
            if (first_difference)
                *first_difference = b->arrays[i].name;
            return 0;
        }
    return 1;
}
