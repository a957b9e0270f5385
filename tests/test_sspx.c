/* test_sspx: SSPX text export round trip (subtracting two exported increments by id gives
 * the total displacement the analysis computes), file naming, range parsing, malformed
 * input, and the biaxial stress-strain table. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "assert_near.h"

#include "analysis_fixtures.h"
#include "biaxial.h"
#include "sspx.h"
#include "scratch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define NINC 8

static void test_sspx_round_trip_total_displacement(void **st) {
    (void)st;
    cdem_state s[NINC] = {{0}};
    cdem_increment_info info[NINC];
    cdem_error err;
    make_packing(&s[0], 150, 2500.0, 1200.0, 31);
    memset(info, 0, sizeof info);
    for (int k = 0; k < NINC; k++) {
        if (k > 0)
            cdem_state_copy(&s[k], &s[k - 1], &err);
        for (size_t i = 0; i < s[k].n && k > 2; i++) {
            if (s[k].flags[i] & CDEM_FLAG_WALL)
                continue;
            s[k].x[i] += 3.0 + 0.01 * s[k].y[i];
            s[k].y[i] -= 1e-3 * s[k].x[i];
        }
        info[k].number = 50 + k;
        info[k].phase = k <= 2 ? 0 : 1;
    }
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_analysis *a;
    assert_int_equal(cdem_analysis_open_states(s, info, NINC, &p, &a, &err), CDEM_OK);
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/sspx_%d", scratch_root(), (int)getpid());
    char cmd[1100];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
    assert_int_equal(system(cmd), 0);
    size_t first, last, written;
    assert_int_equal(cdem_sspx_parse_range(a, "equil-last", &first, &last, &err), CDEM_OK);
    assert_int_equal(first, 2);
    assert_int_equal(last, NINC - 1);
    assert_int_equal(cdem_sspx_export(a, first, last, dir, "cdem", &written, &err), CDEM_OK);
    assert_int_equal(written, NINC - 2);
    /* read back the first and last files (named prefix + increment number) */
    char p0[1200], p1[1200];
    snprintf(p0, sizeof p0, "%s/cdem52.txt", dir);
    snprintf(p1, sizeof p1, "%s/cdem57.txt", dir);
    cdem_state r0 = {0}, r1 = {0};
    assert_int_equal(cdem_sspx_read(p0, &r0, &err), CDEM_OK);
    assert_int_equal(cdem_sspx_read(p1, &r1, &err), CDEM_OK);
    assert_int_equal(r1.n, s[NINC - 1].n);
    const cdem_quantity *qx, *qy;
    cdem_quantity_find("total-disp-x", &qx, &err);
    cdem_quantity_find("total-disp-y", &qy, &err);
    const cdem_state *cur;
    double *ux, *uy;
    assert_int_equal(cdem_analysis_values(a, NINC - 1, qx, &cur, &ux, &err), CDEM_OK);
    assert_int_equal(cdem_analysis_values(a, NINC - 1, qy, &cur, &uy, &err), CDEM_OK);
    cdem_id_map m0;
    cdem_id_map_build(&m0, &r0, &err);
    size_t moved = 0;
    for (size_t i = 0; i < r1.n; i++) {
        size_t j = cdem_id_map_find(&m0, r1.id[i]);
        assert_int_not_equal(j, SIZE_MAX);
        assert_int_equal(cur->id[i], r1.id[i]); /* same element order */
        assert_near(r1.x[i] - r0.x[j], ux[i], 2e-6);
        assert_near(r1.y[i] - r0.y[j], uy[i], 2e-6);
        assert_int_equal(r1.layer[i], cur->layer[i]);
        assert_near(r1.radius[i], cur->radius[i], 1e-6);
        moved += fabs(ux[i]) > 10.0;
    }
    assert_true(moved > 100);
    free(ux);
    free(uy);
    cdem_id_map_free(&m0);
    cdem_state_free(&r0);
    cdem_state_free(&r1);
    /* errors: bad prefix, missing directory, bad ranges */
    assert_int_equal(cdem_sspx_export(a, 0, 0, dir, "a/b", NULL, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "prefix 'a/b'"));
    assert_int_equal(cdem_sspx_export(a, 0, 0, "/nonexistent/dir", "cdem", NULL, &err),
                     CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, "/nonexistent/dir/cdem50.txt"));
    assert_int_equal(cdem_sspx_parse_range(a, "55-52", &first, &last, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "runs backwards"));
    assert_int_equal(cdem_sspx_parse_range(a, "40-52", &first, &last, &err), CDEM_ERR_NOTFOUND);
    assert_int_equal(cdem_sspx_parse_range(a, "53", &first, &last, &err), CDEM_OK);
    assert_true(first == 3 && last == 3);
    cdem_analysis_close(a);
    for (int k = 0; k < NINC; k++)
        cdem_state_free(&s[k]);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

static void test_sspx_read_malformed(void **st) {
    (void)st;
    char path[1100];
    snprintf(path, sizeof path, "%s/sspx_bad_%d.txt", scratch_root(), (int)getpid());
    FILE *f = fopen(path, "w");
    fprintf(f, "0 1.0 2.0 50.0 1\n1 1.0 2.0 -5 1\n");
    fclose(f);
    cdem_state s = {0};
    cdem_error err;
    assert_int_equal(cdem_sspx_read(path, &s, &err), CDEM_ERR_PARSE);
    assert_non_null(strstr(err.msg, ":2: expected 'id x y radius layer'"));
    assert_non_null(strstr(err.msg, "'1 1.0 2.0 -5 1'"));
    cdem_state_free(&s);
    remove(path);
}

static void test_sspx_biaxial_table(void **st) {
    (void)st;
    cdem_series_sample smp[3];
    memset(smp, 0, sizeof smp);
    for (int i = 0; i < 3; i++) {
        smp[i].step = 1000 * (i + 1);
        smp[i].axial_strain = 0.01 * i;
        smp[i].differential_stress = 1.5e7 * i;
    }
    char path[1100];
    snprintf(path, sizeof path, "%s/biaxial_%d.txt", scratch_root(), (int)getpid());
    cdem_error err;
    assert_int_equal(cdem_biaxial_write(path, smp, 3, &err), CDEM_OK);
    FILE *f = fopen(path, "r");
    char header[200];
    assert_non_null(fgets(header, sizeof header, f));
    assert_non_null(strstr(header, "# time_step axial_strain differential_stress"));
    for (int i = 0; i < 3; i++) {
        long long step;
        double e, s;
        assert_int_equal(fscanf(f, "%lld %lf %lf", &step, &e, &s), 3);
        assert_int_equal(step, 1000 * (i + 1));
        assert_near(e, 0.01 * i, 1e-12);
        assert_near(s, 1.5e7 * i, 1e-3);
    }
    fclose(f);
    remove(path);
    assert_int_equal(cdem_biaxial_write("/nonexistent/x.txt", smp, 3, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, "cannot create /nonexistent/x.txt"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sspx_round_trip_total_displacement),
        cmocka_unit_test(test_sspx_read_malformed),
        cmocka_unit_test(test_sspx_biaxial_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
