/* Tests of the element state (common/state.c): appending and ids, growth, stress arrays,
 * compaction, copying and the id map. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "state.h"

#include <stdlib.h>
#include <string.h>

/* Appends n elements whose properties are functions of their index. */
static void fill(cdem_state *s, size_t n) {
    cdem_error err;
    for (size_t i = 0; i < n; i++) {
        size_t k = 99;
        assert_int_equal(cdem_state_append(s, -1, 1.5 * (double)i, -2.0 * (double)i,
                                           50.0 + (double)(i % 4) * 25.0, 10.0 + (double)i,
                                           (int32_t)(i % 25), (uint32_t)i * 3u, (int32_t)(i / 10),
                                           &k, &err),
                         CDEM_OK);
        assert_int_equal(k, s->n - 1);
    }
}

static void test_state_append_assigns_ids(void **state) {
    (void)state;
    cdem_state s;
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 0, 0, &err), CDEM_OK);
    assert_int_equal(s.n, 0);
    assert_true(s.capacity >= 1);
    assert_int_equal(s.has_stress, 0);
    assert_null(s.sxx);
    fill(&s, 3);
    assert_int_equal(s.id[0], 0);
    assert_int_equal(s.id[2], 2);
    assert_int_equal(s.next_id, 3);
    /* An explicit id above next_id moves next_id past it; one below leaves it. */
    assert_int_equal(cdem_state_append(&s, 40, 0, 0, 50, 1, 0, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(s.next_id, 41);
    assert_int_equal(cdem_state_append(&s, 7, 0, 0, 50, 1, 0, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(s.next_id, 41);
    assert_int_equal(cdem_state_append(&s, -1, 0, 0, 50, 1, 0, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(s.id[5], 41);
    /* Velocity and force start at zero, every property is stored. */
    assert_true(s.vx[1] == 0.0 && s.vy[1] == 0.0 && s.fx[1] == 0.0 && s.fy[1] == 0.0);
    assert_true(s.x[2] == 3.0 && s.y[2] == -4.0 && s.radius[2] == 100.0 && s.mass[2] == 12.0);
    assert_int_equal(s.layer[2], 2);
    assert_int_equal(s.flags[2], 6);
    assert_int_equal(s.born[2], 0);
    /* The id space ends below INT32_MAX. */
    assert_int_equal(cdem_state_append(&s, INT32_MAX, 0, 0, 50, 1, 0, 0, 0, NULL, &err),
                     CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "element id 2147483647"));
    assert_int_equal(s.n, 6);
    cdem_state_free(&s);
    assert_int_equal(s.n, 0);
    assert_null(s.x);
    cdem_state_free(&s); /* twice is harmless */
    cdem_state_free(NULL);
}

static void test_state_growth_preserves_data(void **state) {
    (void)state;
    cdem_state s;
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 4, 1, &err), CDEM_OK);
    fill(&s, 1000); /* many geometric growths */
    assert_true(s.capacity >= 1000);
    for (size_t i = 0; i < 1000; i++) {
        assert_int_equal(s.id[i], (int32_t)i);
        assert_true(s.x[i] == 1.5 * (double)i);
        assert_true(s.mass[i] == 10.0 + (double)i);
        assert_true(s.sxx[i] == 0.0 && s.syy[i] == 0.0 && s.sxy[i] == 0.0);
    }
    size_t cap = s.capacity;
    assert_int_equal(cdem_state_reserve(&s, 10, &err), CDEM_OK); /* never shrinks */
    assert_int_equal(s.capacity, cap);
    /* Memory beyond n is zeroed by growth. */
    assert_int_equal(cdem_state_reserve(&s, cap + 1, &err), CDEM_OK);
    assert_true(s.x[cap] == 0.0 && s.id[cap] == 0 && s.sxy[cap] == 0.0);
    /* An impossible size fails cleanly and leaves the state usable. */
    assert_int_equal(cdem_state_reserve(&s, SIZE_MAX / 2, &err), CDEM_ERR_NOMEM);
    assert_non_null(strstr(err.msg, "cannot hold"));
    assert_int_equal(s.n, 1000);
    assert_true(s.x[999] == 1.5 * 999.0);
    cdem_state_free(&s);
}

static void test_state_enable_stress_later(void **state) {
    (void)state;
    cdem_state s;
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 2, 0, &err), CDEM_OK);
    fill(&s, 5);
    assert_int_equal(cdem_state_enable_stress(&s, &err), CDEM_OK);
    assert_int_equal(s.has_stress, 1);
    for (size_t i = 0; i < 5; i++)
        assert_true(s.sxx[i] == 0.0 && s.syy[i] == 0.0 && s.sxy[i] == 0.0);
    s.sxx[4] = 7.0;
    assert_int_equal(cdem_state_enable_stress(&s, &err), CDEM_OK); /* idempotent */
    assert_true(s.sxx[4] == 7.0);
    fill(&s, 100); /* stress arrays grow with the others */
    assert_true(s.sxx[4] == 7.0 && s.sxy[104] == 0.0);
    cdem_state_free(&s);
}

static void test_state_compact_keeps_order(void **state) {
    (void)state;
    cdem_state s;
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 8, 1, &err), CDEM_OK);
    fill(&s, 10);
    for (size_t i = 0; i < 10; i++)
        s.sxy[i] = 100.0 + (double)i;
    unsigned char keep[10] = {1, 0, 1, 1, 0, 0, 1, 0, 0, 1};
    size_t map[10];
    cdem_state_compact(&s, keep, map);
    assert_int_equal(s.n, 5);
    const int32_t ids[5] = {0, 2, 3, 6, 9};
    for (size_t j = 0; j < 5; j++) {
        assert_int_equal(s.id[j], ids[j]);
        assert_true(s.x[j] == 1.5 * ids[j]);
        assert_true(s.sxy[j] == 100.0 + ids[j]);
        assert_int_equal(s.flags[j], (uint32_t)ids[j] * 3u);
    }
    const size_t expect[10] = {0, SIZE_MAX, 1, 2, SIZE_MAX, SIZE_MAX, 3, SIZE_MAX, SIZE_MAX, 4};
    for (size_t i = 0; i < 10; i++)
        assert_true(map[i] == expect[i]);
    /* Removing everything; then new ids continue after the old ones. */
    memset(keep, 0, sizeof keep);
    cdem_state_compact(&s, keep, NULL);
    assert_int_equal(s.n, 0);
    fill(&s, 1);
    assert_int_equal(s.id[0], 10);
    cdem_state_free(&s);
}

static void test_state_copy_is_deep(void **state) {
    (void)state;
    cdem_state a, b = {0};
    cdem_error err;
    assert_int_equal(cdem_state_init(&a, 4, 1, &err), CDEM_OK);
    fill(&a, 20);
    a.vx[3] = 5.0;
    a.syy[19] = -3.0;
    assert_int_equal(cdem_state_copy(&b, &a, &err), CDEM_OK);
    assert_int_equal(b.n, 20);
    assert_int_equal(b.next_id, 20);
    assert_int_equal(b.has_stress, 1);
    assert_true(b.vx[3] == 5.0 && b.syy[19] == -3.0 && b.born[19] == 1);
    assert_ptr_not_equal(a.x, b.x);
    b.x[0] = 99.0;
    assert_true(a.x[0] == 0.0);
    /* Copying over an already used state, and onto itself. */
    cdem_state c;
    assert_int_equal(cdem_state_init(&c, 2, 0, &err), CDEM_OK);
    fill(&c, 2);
    assert_int_equal(cdem_state_assign(&b, &c, &err), CDEM_OK);
    assert_int_equal(b.n, 2);
    assert_int_equal(b.has_stress, 0);
    assert_null(b.sxx);
    assert_int_equal(cdem_state_copy(&a, &a, &err), CDEM_OK);
    assert_int_equal(a.n, 20);
    assert_true(a.syy[19] == -3.0);
    cdem_state_free(&a);
    cdem_state_free(&b);
    cdem_state_free(&c);
}

/* The destination of a copy is an output: an uninitialised variable (here: garbage bytes,
 * as on the stack) must not be read or freed. Before the fix, cdem_state_copy freed the
 * destination's pointers, and a test that copied into an uninitialised `cdem_state before;`
 * crashed make asan depending on what the stack held. */
static void test_state_copy_into_uninitialised_destination(void **state) {
    (void)state;
    cdem_state a, garbage;
    cdem_error err;
    assert_int_equal(cdem_state_init(&a, 4, 1, &err), CDEM_OK);
    fill(&a, 5);
    memset(&garbage, 0xA5, sizeof garbage); /* pointers 0xA5A5...: freeing them aborts */
    assert_int_equal(cdem_state_copy(&garbage, &a, &err), CDEM_OK);
    assert_int_equal(garbage.n, 5);
    assert_int_equal(garbage.has_stress, 1);
    assert_true(garbage.x[4] == a.x[4] && garbage.id[4] == a.id[4]);
    /* assign reuses an initialised destination without leaking (LeakSanitizer checks) */
    for (int k = 0; k < 3; k++)
        assert_int_equal(cdem_state_assign(&garbage, &a, &err), CDEM_OK);
    assert_int_equal(cdem_state_assign(&garbage, &garbage, &err), CDEM_OK);
    assert_int_equal(garbage.n, 5);
    cdem_state_free(&garbage);
    cdem_state_free(&a);
}

static void test_state_id_map_finds_slots(void **state) {
    (void)state;
    cdem_state s;
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    cdem_id_map map;
    assert_int_equal(cdem_id_map_build(&map, &s, &err), CDEM_OK); /* empty */
    assert_true(cdem_id_map_find(&map, 0) == SIZE_MAX);
    cdem_id_map_free(&map);
    const int32_t ids[] = {105, 3, 77, 12, 4000};
    for (size_t i = 0; i < 5; i++)
        assert_int_equal(cdem_state_append(&s, ids[i], 0, 0, 50, 1, 0, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_id_map_build(&map, &s, &err), CDEM_OK);
    assert_int_equal(map.min_id, 3);
    assert_int_equal(map.max_id, 4000);
    for (size_t i = 0; i < 5; i++)
        assert_int_equal(cdem_id_map_find(&map, ids[i]), i);
    const int32_t absent[] = {-5, 0, 2, 4, 104, 3999, 4001, INT32_MAX, INT32_MIN};
    for (size_t i = 0; i < sizeof absent / sizeof absent[0]; i++)
        assert_true(cdem_id_map_find(&map, absent[i]) == SIZE_MAX);
    cdem_id_map_free(&map);
    cdem_id_map_free(&map);
    cdem_id_map_free(NULL);
    /* A duplicated id is refused with both slots named. */
    s.id[4] = 77;
    assert_int_equal(cdem_id_map_build(&map, &s, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "duplicate element id 77 at slots 2 and 4"));
    assert_null(map.index);
    cdem_state_free(&s);
}

/* The field table (CDEM_STATE_FIELDS as data) describes cdem_state exactly: every array
 * member once, at its offset, with its element size; the fields stored in each increment of
 * the run file are the ones docs/format.md lists, in that order; and copy and compaction
 * carry every field (each element of each field gets a distinct value through the table,
 * so a field the loops forgot would show). */
static void test_state_field_table_drives_every_field(void **state) {
    (void)state;
    assert_int_equal(cdem_state_field_count, 16);
    size_t members = 0;
    for (size_t k = 0; k < cdem_state_field_count; k++) {
        const cdem_state_field *f = &cdem_state_fields[k];
        assert_true(f->offset >= offsetof(cdem_state, id) &&
                    f->offset <= offsetof(cdem_state, area_ratio));
        assert_int_equal(f->offset, offsetof(cdem_state, id) + k * sizeof(void *));
        members++;
    }
    assert_int_equal(members * sizeof(void *), sizeof(cdem_state) - offsetof(cdem_state, id));
    static const char *const in_file[] = {"id",    "x",    "y",   "radius", "layer",
                                          "flags", "born", "sxx", "syy",    "sxy"};
    size_t j = 0;
    for (size_t k = 0; k < cdem_state_field_count; k++)
        if (cdem_state_fields[k].in_increments) {
            assert_true(j < sizeof in_file / sizeof in_file[0]);
            assert_string_equal(cdem_state_fields[k].name, in_file[j++]);
        }
    assert_int_equal(j, sizeof in_file / sizeof in_file[0]);

    cdem_error err;
    cdem_state s;
    assert_int_equal(cdem_state_init(&s, 4, 1, &err), CDEM_OK);
    for (int i = 0; i < 5; i++)
        assert_int_equal(cdem_state_append(&s, -1, 0, 0, 1, 1, 1, 0, 0, NULL, &err), CDEM_OK);
    /* value of element i in field k: 100 k + i, whatever the field's type */
    for (size_t k = 0; k < cdem_state_field_count; k++) {
        const cdem_state_field *f = &cdem_state_fields[k];
        void *a = cdem_state_field_array(&s, f);
        assert_non_null(a);
        assert_int_equal(cdem_field_type_size(f->type), f->type == CDEM_FIELD_F64 ? 8 : 4);
        for (size_t i = 0; i < s.n; i++) {
            const double v = 100.0 * (double)k + (double)i;
            if (f->type == CDEM_FIELD_F64)
                ((double *)a)[i] = v;
            else if (f->type == CDEM_FIELD_I32)
                ((int32_t *)a)[i] = (int32_t)v;
            else
                ((uint32_t *)a)[i] = (uint32_t)v;
        }
    }
    cdem_state c;
    assert_int_equal(cdem_state_copy(&c, &s, &err), CDEM_OK);
    const unsigned char keep[5] = {1, 0, 1, 0, 1}; /* elements 0, 2, 4 stay */
    cdem_state_compact(&c, keep, NULL);
    assert_int_equal(c.n, 3);
    for (size_t k = 0; k < cdem_state_field_count; k++) {
        const cdem_state_field *f = &cdem_state_fields[k];
        const void *a = cdem_state_field_array(&c, f);
        for (size_t i = 0; i < c.n; i++) {
            const double want = 100.0 * (double)k + (double)(2 * i);
            const double got = f->type == CDEM_FIELD_F64   ? ((const double *)a)[i]
                               : f->type == CDEM_FIELD_I32 ? (double)((const int32_t *)a)[i]
                                                           : (double)((const uint32_t *)a)[i];
            if (got != want)
                fail_msg("field %s, element %zu: %g, expected %g", f->name, i, got, want);
        }
    }
    cdem_state_free(&c);
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_state_append_assigns_ids),
        cmocka_unit_test(test_state_growth_preserves_data),
        cmocka_unit_test(test_state_enable_stress_later),
        cmocka_unit_test(test_state_compact_keeps_order),
        cmocka_unit_test(test_state_copy_is_deep),
        cmocka_unit_test(test_state_copy_into_uninitialised_destination),
        cmocka_unit_test(test_state_id_map_finds_slots),
        cmocka_unit_test(test_state_field_table_drives_every_field),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
