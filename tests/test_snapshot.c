/* Tests of common/snapshot.c: put/get round trip of every type, replacement, checked
 * access with its messages, equality and bad names. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "snapshot.h"

#include <string.h>

static cdem_snapshot *make(void) {
    cdem_snapshot *s = NULL;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_snapshot_alloc(&s, &err), CDEM_OK);
    return s;
}

static void test_snapshot_round_trip_every_type(void **state) {
    (void)state;
    cdem_snapshot *s = make();
    cdem_error err;
    const double x[3] = {1.5, -2.25, 1e300};
    const int64_t step[1] = {INT64_C(9007199254740993)};
    const int32_t id[2] = {-7, 42};
    const uint32_t flags[2] = {0xffffffffu, 5u};
    const uint8_t bytes[4] = {0, 255, 17, 3};
    assert_int_equal(cdem_snapshot_put(s, "state.x", CDEM_SNAP_F64, 3, x, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_put(s, "run.step", CDEM_SNAP_I64, 1, step, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_put(s, "state.id", CDEM_SNAP_I32, 2, id, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_put(s, "state.flags", CDEM_SNAP_U32, 2, flags, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_put(s, "rng.state", CDEM_SNAP_U8, 4, bytes, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_put(s, "contact.empty", CDEM_SNAP_F64, 0, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_count(s), 6);

    const cdem_snapshot_array *a = cdem_snapshot_get(s, "state.x");
    assert_non_null(a);
    assert_int_equal(a->count, 3);
    assert_memory_equal(a->data, x, sizeof x);
    a = cdem_snapshot_get(s, "run.step");
    assert_true(((const int64_t *)a->data)[0] == step[0]);
    assert_memory_equal(cdem_snapshot_get(s, "state.flags")->data, flags, sizeof flags);
    assert_memory_equal(cdem_snapshot_get(s, "rng.state")->data, bytes, sizeof bytes);
    assert_int_equal(cdem_snapshot_get(s, "contact.empty")->count, 0);
    assert_null(cdem_snapshot_get(s, "state.y"));
    /* insertion order */
    assert_string_equal(cdem_snapshot_at(s, 0)->name, "state.x");
    assert_string_equal(cdem_snapshot_at(s, 4)->name, "rng.state");
    assert_null(cdem_snapshot_at(s, 6));
    cdem_snapshot_free(s);
}

static void test_snapshot_put_copies_and_replaces(void **state) {
    (void)state;
    cdem_snapshot *s = make();
    cdem_error err;
    double v[2] = {1.0, 2.0};
    assert_int_equal(cdem_snapshot_put(s, "a", CDEM_SNAP_F64, 2, v, &err), CDEM_OK);
    v[0] = 99.0; /* the snapshot keeps its own copy */
    assert_true(((const double *)cdem_snapshot_get(s, "a")->data)[0] == 1.0);
    const int32_t w[3] = {4, 5, 6};
    assert_int_equal(cdem_snapshot_put(s, "a", CDEM_SNAP_I32, 3, w, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_count(s), 1);
    assert_int_equal(cdem_snapshot_get(s, "a")->type, CDEM_SNAP_I32);
    assert_int_equal(cdem_snapshot_get(s, "a")->count, 3);
    cdem_snapshot_clear(s);
    assert_int_equal(cdem_snapshot_count(s), 0);
    assert_int_equal(cdem_snapshot_put(s, "b", CDEM_SNAP_I32, 3, w, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_count(s), 1);
    cdem_snapshot_free(s);
    cdem_snapshot_free(NULL);
}

static void test_snapshot_require_names_the_problem(void **state) {
    (void)state;
    cdem_snapshot *s = make();
    cdem_error err;
    const double v[2] = {1.0, 2.0};
    assert_int_equal(cdem_snapshot_put(s, "state.vx", CDEM_SNAP_F64, 2, v, &err), CDEM_OK);
    const cdem_snapshot_array *a = NULL;
    assert_int_equal(cdem_snapshot_require(s, "state.vx", CDEM_SNAP_F64, 2, &a, &err), CDEM_OK);
    assert_ptr_equal(a, cdem_snapshot_get(s, "state.vx"));
    assert_int_equal(cdem_snapshot_require(s, "state.vx", CDEM_SNAP_F64, SIZE_MAX, &a, &err),
                     CDEM_OK);

    assert_int_equal(cdem_snapshot_require(s, "state.vy", CDEM_SNAP_F64, 2, &a, &err),
                     CDEM_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "no array \"state.vy\""));
    assert_int_equal(cdem_snapshot_require(s, "state.vx", CDEM_SNAP_I64, 2, &a, &err),
                     CDEM_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "type f64, expected i64"));
    assert_int_equal(cdem_snapshot_require(s, "state.vx", CDEM_SNAP_F64, 3, &a, &err),
                     CDEM_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "has 2 values, expected 3"));
    cdem_snapshot_free(s);
}

static void test_snapshot_rejects_bad_names(void **state) {
    (void)state;
    cdem_snapshot *s = make();
    cdem_error err;
    const double v = 1.0;
    assert_int_equal(cdem_snapshot_put(s, "", CDEM_SNAP_F64, 1, &v, &err), CDEM_ERR_INVALID);
    assert_int_equal(cdem_snapshot_put(s, "a/b", CDEM_SNAP_F64, 1, &v, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "\"a/b\""));
    char longname[CDEM_SNAPSHOT_NAME_MAX + 1];
    memset(longname, 'n', sizeof longname - 1);
    longname[sizeof longname - 1] = '\0';
    assert_int_equal(cdem_snapshot_put(s, longname, CDEM_SNAP_F64, 1, &v, &err), CDEM_ERR_INVALID);
    assert_int_equal(cdem_snapshot_put(s, "x", (cdem_snapshot_type)17, 1, &v, &err),
                     CDEM_ERR_INVALID);
    assert_int_equal(cdem_snapshot_put(s, "x", CDEM_SNAP_F64, 1, NULL, &err), CDEM_ERR_INVALID);
    assert_int_equal(cdem_snapshot_count(s), 0);
    cdem_snapshot_free(s);
}

static void test_snapshot_equal_finds_first_difference(void **state) {
    (void)state;
    cdem_snapshot *a = make(), *b = make();
    cdem_error err;
    const double x[2] = {1.0, 2.0}, y[2] = {3.0, 4.0};
    const double y2[2] = {3.0, 4.0000000000000009};
    assert_int_equal(cdem_snapshot_put(a, "x", CDEM_SNAP_F64, 2, x, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_put(a, "y", CDEM_SNAP_F64, 2, y, &err), CDEM_OK);
    /* other order, same content */
    assert_int_equal(cdem_snapshot_put(b, "y", CDEM_SNAP_F64, 2, y, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_put(b, "x", CDEM_SNAP_F64, 2, x, &err), CDEM_OK);
    const char *diff = NULL;
    assert_true(cdem_snapshot_equal(a, b, &diff));
    /* one bit in the last place */
    assert_int_equal(cdem_snapshot_put(b, "y", CDEM_SNAP_F64, 2, y2, &err), CDEM_OK);
    assert_false(cdem_snapshot_equal(a, b, &diff));
    assert_string_equal(diff, "y");
    assert_int_equal(cdem_snapshot_put(b, "y", CDEM_SNAP_F64, 2, y, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_put(b, "z", CDEM_SNAP_U8, 0, NULL, &err), CDEM_OK);
    assert_false(cdem_snapshot_equal(a, b, &diff));
    assert_string_equal(diff, "z");
    cdem_snapshot_free(a);
    cdem_snapshot_free(b);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_snapshot_round_trip_every_type),
        cmocka_unit_test(test_snapshot_put_copies_and_replaces),
        cmocka_unit_test(test_snapshot_require_names_the_problem),
        cmocka_unit_test(test_snapshot_rejects_bad_names),
        cmocka_unit_test(test_snapshot_equal_finds_first_difference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
