/* test_cdem2d: import of the cdem2D fixture folders (tests/data/cdem2d_*, written by
 * tests/data/make_cdem2d_fixtures.py): ids carried by matching across a vanished element,
 * new growth elements and reversed row order, recognised modelparameters.txt keys, CRLF
 * endings with stress, and a malformed row reported with file and line. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "assert_near.h"

#include "cdem2d.h"
#include "scratch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAXINC 8

typedef struct {
    size_t n;
    cdem_state st[MAXINC];
    cdem_increment_info info[MAXINC];
} collected;

static cdem_status collect(void *user, const cdem_increment_info *info, const cdem_state *s,
                           cdem_error *err) {
    collected *c = user;
    if (c->n >= MAXINC)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "too many increments");
    c->info[c->n] = *info;
    memset(&c->st[c->n], 0, sizeof c->st[c->n]);
    return cdem_state_copy(&c->st[c->n++], s, err);
}

static void free_collected(collected *c) {
    for (size_t k = 0; k < c->n; k++)
        cdem_state_free(&c->st[k]);
}

static const char *data_dir(void) {
    const char *d = getenv("CDEM_TEST_DATA");
    return d ? d : "tests/data";
}

/* Original position of fixture element i (see make_cdem2d_fixtures.py) after k increments. */
static void fixture_pos(int i, int k, double *x, double *y) {
    int r = i / 6, c = i % 6;
    *x = 100.0 + 180.0 * c + 90.0 * (r % 2);
    *y = 100.0 + 156.0 * r;
    for (int s = 0; s < k; s++)
        *x += 5.0 + 0.02 * *y;
}

static void check_folder(const char *name, int with_forces) {
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/%s", data_dir(), name);
    collected c = {0};
    cdem_cdem2d_meta meta;
    cdem_error err;
    cdem_status st = cdem_cdem2d_import(dir, collect, &c, &meta, &err);
    if (st != CDEM_OK)
        print_error("%s\n", err.msg);
    assert_int_equal(st, CDEM_OK);
    assert_int_equal(meta.n_increments, 4);
    assert_int_equal(meta.pregrowth_layers, 3);
    assert_int_equal(meta.mode, 0 /* planar */);
    assert_int_equal(meta.equil_number, 1);
    assert_int_equal(meta.has_forces, with_forces);
    assert_non_null(strstr(meta.params_text, "Unit scaling = 1000"));
    assert_int_equal(c.n, 4);
    assert_int_equal(c.info[1].phase, 0);
    assert_int_equal(c.info[2].phase, 1);
    assert_int_equal(c.st[0].n, 36);
    assert_int_equal(c.st[2].n, 35);
    assert_int_equal(c.st[3].n, 37);
    /* ids of increment 0 follow file order; every later element keeps its id */
    for (int k = 0; k < 4; k++) {
        const cdem_state *s = &c.st[k];
        size_t growth = 0;
        for (size_t i = 0; i < s->n; i++) {
            if (s->layer[i] == 0) {
                assert_true(s->flags[i] & CDEM_FLAG_WALL);
                assert_true(s->id[i] >= 30 && s->id[i] < 36);
                continue;
            }
            if (s->layer[i] == 4) {
                assert_true(s->flags[i] & CDEM_FLAG_GROWTH);
                assert_true(s->id[i] >= 36);
                assert_int_equal(s->born[i], 3);
                growth++;
                continue;
            }
            assert_true(s->id[i] < 30);
            assert_int_not_equal(k >= 2 ? s->id[i] : -1, 7); /* vanished */
            double x, y;
            fixture_pos(s->id[i], k, &x, &y);
            assert_near(s->x[i], x, 1e-5);
            assert_near(s->y[i], y, 1e-5);
            assert_int_equal(s->born[i], 0);
            if (with_forces) {
                assert_near(s->sxx[i], 1e6 * (s->id[i] + 1), 0.5);
                assert_near(s->syy[i], 2e6, 0);
                assert_near(s->sxy[i], 0.5e6, 0);
            }
        }
        assert_int_equal(growth, k == 3 ? 2 : 0);
        assert_int_equal(s->has_stress, with_forces);
    }
    cdem_cdem2d_meta_free(&meta);
    free_collected(&c);
}

static void test_cdem2d_basic_folder(void **st) {
    (void)st;
    check_folder("cdem2d_basic", 0);
}

static void test_cdem2d_crlf_with_forces(void **st) {
    (void)st;
    check_folder("cdem2d_crlf", 1);
}

static void test_cdem2d_malformed_row(void **st) {
    (void)st;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/cdem2d_malformed", data_dir());
    collected c = {0};
    cdem_cdem2d_meta meta;
    cdem_error err;
    assert_int_equal(cdem_cdem2d_import(dir, collect, &c, &meta, &err), CDEM_ERR_PARSE);
    assert_non_null(strstr(err.msg, "modelresults_1.txt:3:"));
    assert_non_null(strstr(err.msg, "'abc 50 1'"));
    assert_int_equal(c.n, 1); /* increment 0 was fine */
    cdem_cdem2d_meta_free(&meta);
    free_collected(&c);
}

static void test_cdem2d_missing_folder(void **st) {
    (void)st;
    collected c = {0};
    cdem_cdem2d_meta meta;
    cdem_error err;
    assert_int_equal(cdem_cdem2d_import("/nonexistent/cdem2d", collect, &c, &meta, &err),
                     CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, "/nonexistent/cdem2d"));
    cdem_cdem2d_meta_free(&meta);
    /* a folder without modelresults files */
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", data_dir());
    assert_int_equal(cdem_cdem2d_import(dir, collect, &c, &meta, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "no modelresults_N.txt"));
    cdem_cdem2d_meta_free(&meta);
}

/* Writes a folder of three increments, the rows of increment 1 given, into dir. */
static void write_folder(const char *dir, const char *rows1) {
    char cmd[2200], path[1200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", dir, dir);
    assert_int_equal(system(cmd), 0);
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/modelresults_%d.txt", dir, k);
        FILE *f = fopen(path, "w");
        assert_non_null(f);
        fputs(k == 1 ? rows1 : "100 100 50 1\n280 100 75 1\n460 100 50 0\n", f);
        fclose(f);
    }
}

/* Rows that once imported and became infinities downstream (issue 19, item 8): positions of
 * +-1e308 m, a radius of 1e300 m; and an empty results file (an increment without
 * elements). Each is refused naming the file and line. */
static void test_cdem2d_absurd_rows(void **st) {
    (void)st;
    char dir[1024];
    scratch_path(dir, sizeof dir, "cdem2d_absurd");
    static const struct {
        const char *rows; /* increment 1 */
        const char *want; /* in the message */
    } bad[] = {
        {"1e308 100 50 1\n280 100 75 1\n", "modelresults_1.txt:1: x = 1e+308 m is outside"},
        {"100 100 50 1\n280 -1e308 75 1\n", "modelresults_1.txt:2: y = -1e+308 m is outside"},
        {"100 100 1e300 1\n", "modelresults_1.txt:1: radius 1e+300 must be > 0 and at most"},
        {"", "modelresults_1.txt holds no element rows"},
        {"# only a comment\n\n", "modelresults_1.txt holds no element rows"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        write_folder(dir, bad[k].rows);
        collected c = {0};
        cdem_cdem2d_meta meta;
        cdem_error err;
        assert_int_equal(cdem_cdem2d_import(dir, collect, &c, &meta, &err), CDEM_ERR_PARSE);
        if (!strstr(err.msg, bad[k].want))
            fail_msg("case %zu: %s", k, err.msg);
        assert_int_equal(c.n, 1); /* increment 0 was fine */
        cdem_cdem2d_meta_free(&meta);
        free_collected(&c);
    }
    char cmd[1100];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cdem2d_basic_folder),  cmocka_unit_test(test_cdem2d_crlf_with_forces),
        cmocka_unit_test(test_cdem2d_malformed_row), cmocka_unit_test(test_cdem2d_missing_folder),
        cmocka_unit_test(test_cdem2d_absurd_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
