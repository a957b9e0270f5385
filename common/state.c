/* state: see state.h. Arrays grow together (one realloc per array, geometric), so every
 * index is valid in every array at all times. */
#include "state.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FIELD_ROW(name, ctype, ftype, in_increments, stress)                                       \
    {#name, ftype, offsetof(cdem_state, name), in_increments, stress},
const cdem_state_field cdem_state_fields[] = {CDEM_STATE_FIELDS(FIELD_ROW)};
#undef FIELD_ROW
const size_t cdem_state_field_count = sizeof cdem_state_fields / sizeof cdem_state_fields[0];

void *cdem_state_field_array(const cdem_state *s, const cdem_state_field *f) {
    void *p;
    memcpy(&p, (const char *)s + f->offset, sizeof p);
    return p;
}

size_t cdem_field_type_size(cdem_field_type t) {
    return t == CDEM_FIELD_F64 ? sizeof(double) : sizeof(int32_t);
}

static int grow_array(void **p, size_t elem_size, size_t old_cap, size_t new_cap) {
    void *q = realloc(*p, new_cap * elem_size);
    if (!q)
        return 0;
    memset((char *)q + old_cap * elem_size, 0, (new_cap - old_cap) * elem_size);
    *p = q;
    return 1;
}

cdem_status cdem_state_init(cdem_state *s, size_t capacity, int with_stress, cdem_error *err) {
    memset(s, 0, sizeof *s);
    s->next_id = 0;
    CDEM_TRY(cdem_state_reserve(s, capacity ? capacity : 16, err));
    if (with_stress)
        CDEM_TRY(cdem_state_enable_stress(s, err));
    return CDEM_OK;
}

void cdem_state_free(cdem_state *s) {
    if (!s)
        return;
#define FREE_ONE(name, ctype, ftype, in_increments, stress) free(s->name);
    CDEM_STATE_FIELDS(FREE_ONE)
#undef FREE_ONE
    memset(s, 0, sizeof *s);
}

cdem_status cdem_state_reserve(cdem_state *s, size_t capacity, cdem_error *err) {
    if (capacity <= s->capacity)
        return CDEM_OK;
    /* Refuse sizes whose byte count would overflow (8-byte arrays, 1.5x growth). */
    if (capacity > SIZE_MAX / 16)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "cannot hold %zu elements (too many for memory)",
                         capacity);
    size_t new_cap = s->capacity ? s->capacity : 16;
    while (new_cap < capacity)
        new_cap += new_cap / 2 + 1;
#define GROW_ONE(name, ctype, ftype, in_increments, stress)                                        \
    if ((!(stress) || s->has_stress) &&                                                            \
        !grow_array((void **)&s->name, sizeof(ctype), s->capacity, new_cap))                       \
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory growing element arrays to %zu",       \
                         new_cap);
    CDEM_STATE_FIELDS(GROW_ONE)
#undef GROW_ONE
    s->capacity = new_cap;
    return CDEM_OK;
}

cdem_status cdem_state_enable_stress(cdem_state *s, cdem_error *err) {
    if (s->has_stress)
        return CDEM_OK;
    int missing = 0;
#define ALLOC_ONE(name, ctype, ftype, in_increments, stress)                                       \
    if (stress)                                                                                    \
        missing |= !(s->name = calloc(s->capacity ? s->capacity : 1, sizeof(ctype)));
    /* All or none: a partial failure frees what it got (a retry must not leak). */
    CDEM_STATE_FIELDS(ALLOC_ONE)
#undef ALLOC_ONE
    if (missing) {
#define DROP_ONE(name, ctype, ftype, in_increments, stress)                                        \
    if (stress) {                                                                                  \
        free(s->name);                                                                             \
        s->name = NULL;                                                                            \
    }
        CDEM_STATE_FIELDS(DROP_ONE)
#undef DROP_ONE
        return CDEM_FAIL(err, CDEM_ERR_NOMEM,
                         "out of memory allocating stress arrays for %zu elements", s->capacity);
    }
    s->has_stress = 1;
    return CDEM_OK;
}

cdem_status cdem_state_append(cdem_state *s, int32_t id, double x, double y, double radius,
                              double mass, int32_t layer, uint32_t flags, int32_t born,
                              size_t *index, cdem_error *err) {
    if (id < 0)
        id = s->next_id;
    if (id == INT32_MAX)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "element id %d: ids must stay below %d (the id space is exhausted)",
                         (int)id, (int)INT32_MAX);
    CDEM_TRY(cdem_state_reserve(s, s->n + 1, err));
    size_t i = s->n++;
    if (id >= s->next_id)
        s->next_id = id + 1;
        /* every field zero (a slot freed by compaction keeps old values), then the given ones */
#define ZERO_ONE(name, ctype, ftype, in_increments, stress)                                        \
    if (!(stress) || s->has_stress)                                                                \
        s->name[i] = 0;
    CDEM_STATE_FIELDS(ZERO_ONE)
#undef ZERO_ONE
    s->id[i] = id;
    s->x[i] = x;
    s->y[i] = y;
    s->radius[i] = radius;
    s->mass[i] = mass;
    s->layer[i] = layer;
    s->flags[i] = flags;
    s->born[i] = born;
    s->area_ratio[i] = 1.0; /* a disc keeps its area; only a viscous process changes it */
    if (index)
        *index = i;
    return CDEM_OK;
}

void cdem_state_compact(cdem_state *s, const unsigned char *keep, size_t *new_index_out) {
    size_t j = 0;
    for (size_t i = 0; i < s->n; i++) {
        if (!keep[i]) {
            if (new_index_out)
                new_index_out[i] = SIZE_MAX;
            continue;
        }
        if (new_index_out)
            new_index_out[i] = j;
        if (j != i) {
#define MOVE_ONE(name, ctype, ftype, in_increments, stress)                                        \
    if (!(stress) || s->has_stress)                                                                \
        s->name[j] = s->name[i];
            CDEM_STATE_FIELDS(MOVE_ONE)
#undef MOVE_ONE
        }
        j++;
    }
    s->n = j;
}

cdem_status cdem_state_copy(cdem_state *dst, const cdem_state *src, cdem_error *err) {
    if (dst == src)
        return CDEM_OK;
    /* dst is not read: cdem_state_init overwrites it whole */
    cdem_status st = cdem_state_init(dst, src->n, src->has_stress, err);
    if (st != CDEM_OK) {
        cdem_state_free(dst); /* arrays the failed init did allocate */
        return st;
    }
#define COPY_ONE(name, ctype, ftype, in_increments, stress)                                        \
    if (!(stress) || src->has_stress)                                                              \
        memcpy(dst->name, src->name, src->n * sizeof(ctype));
    CDEM_STATE_FIELDS(COPY_ONE)
#undef COPY_ONE
    dst->n = src->n;
    dst->next_id = src->next_id;
    return CDEM_OK;
}

cdem_status cdem_state_assign(cdem_state *dst, const cdem_state *src, cdem_error *err) {
    if (dst == src)
        return CDEM_OK;
    cdem_state_free(dst);
    return cdem_state_copy(dst, src, err);
}

cdem_status cdem_id_map_build(cdem_id_map *map, const cdem_state *s, cdem_error *err) {
    memset(map, 0, sizeof *map);
    if (s->n == 0)
        return CDEM_OK;
    int32_t lo = s->id[0], hi = s->id[0];
    for (size_t i = 1; i < s->n; i++) {
        if (s->id[i] < lo)
            lo = s->id[i];
        if (s->id[i] > hi)
            hi = s->id[i];
    }
    size_t span = (size_t)((int64_t)hi - lo + 1);
    map->index = malloc(span * sizeof *map->index);
    if (!map->index)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory building an id map of %zu ids", span);
    for (size_t k = 0; k < span; k++)
        map->index[k] = SIZE_MAX;
    for (size_t i = 0; i < s->n; i++) {
        size_t *slot = &map->index[s->id[i] - lo];
        if (*slot != SIZE_MAX) {
            size_t first = *slot;
            free(map->index);
            memset(map, 0, sizeof *map);
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "duplicate element id %d at slots %zu and %zu (ids must be unique)",
                             (int)s->id[i], first, i);
        }
        *slot = i;
    }
    map->min_id = lo;
    map->max_id = hi;
    return CDEM_OK;
}

size_t cdem_id_map_find(const cdem_id_map *map, int32_t id) {
    if (!map->index || id < map->min_id || id > map->max_id)
        return SIZE_MAX;
    return map->index[id - map->min_id];
}

void cdem_id_map_free(cdem_id_map *map) {
    if (!map)
        return;
    free(map->index);
    memset(map, 0, sizeof *map);
}

void cdem_state_free_y_range(const cdem_state *s, double *lo, double *hi) {
    double l = INFINITY, h = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        l = fmin(l, s->y[i]);
        h = fmax(h, s->y[i]);
    }
    *lo = l;
    *hi = h;
}
