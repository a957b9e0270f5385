/* test_analysis_h5: the analysis context over a real cdem file written with the h5format
 * writer (values identical to the in-memory context), the cdem2D import written to a cdem
 * file (then read back as a native run) and errors on unreadable files. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "assert_near.h"

#include "analysis.h"
#include "analysis_fixtures.h"
#include "cdem2d.h"
#include "run_file.h"
#include "cmd_render.h"
#include "scratch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define NINC 9

static void remove_run(const char *h5) {
    char xmf[1200];
    snprintf(xmf, sizeof xmf, "%.*s.xmf", (int)(strlen(h5) - 3), h5);
    remove(h5);
    remove(xmf);
}

/* States: 0..3 still (equilibration), then simple shear 0.01 per increment; stress on. */
static void make_run(cdem_state *st, cdem_increment_info *info) {
    cdem_error err;
    make_packing(&st[0], 200, 3000.0, 1500.0, 77);
    for (int k = 0; k < NINC; k++) {
        if (k > 0)
            cdem_state_copy(&st[k], &st[k - 1], &err);
        if (k > 3) {
            const double F[4] = {1, 0.01, 0, 1};
            deform_affine(&st[k], F, 0, 0);
        }
        cdem_state_enable_stress(&st[k], &err);
        for (size_t i = 0; i < st[k].n; i++) {
            st[k].sxx[i] = 1e6 * (double)(i % 50);
            st[k].syy[i] = 3e6;
            st[k].sxy[i] = 1e5 * k;
        }
        memset(&info[k], 0, sizeof info[k]);
        info[k].number = k;
        info[k].step = 1000 * k;
        info[k].time = 10.0 * k;
        info[k].phase = k <= 3 ? CDEM_PHASE_EQUILIBRATION : CDEM_PHASE_DEFORMATION;
        info[k].sea_level = NAN;
        info[k].has_stress = 1;
        info[k].n_elements = (int64_t)st[k].n;
    }
}

static void write_run(const char *path, cdem_state *st, cdem_increment_info *info,
                      const cdem_params *p) {
    cdem_run_meta meta = {p, "", "test run", "0", "test", 0};
    cdem_h5_writer *w;
    cdem_error err;
    assert_int_equal(cdem_h5_writer_create(path, &meta, &w, &err), CDEM_OK);
    for (int k = 0; k < NINC; k++)
        assert_int_equal(cdem_h5_writer_write_increment(w, &info[k], &st[k], &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_set_stop_reason(w, "completed", "", &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
}

static void test_analysis_h5_matches_memory(void **state) {
    (void)state;
    cdem_state st[NINC] = {{0}};
    cdem_increment_info info[NINC];
    cdem_params p;
    cdem_params_defaults(&p);
    p.total_strain_max = 3.0;
    make_run(st, info);
    char path[1100];
    scratch_path(path, sizeof path, "run.h5");
    write_run(path, st, info, &p);
    cdem_analysis *af, *am;
    cdem_error err;
    assert_int_equal(cdem_analysis_open(path, &af, &err), CDEM_OK);
    assert_int_equal(cdem_analysis_open_states(st, info, NINC, &p, &am, &err), CDEM_OK);
    assert_int_equal(cdem_analysis_count(af), NINC);
    assert_int_equal(cdem_analysis_equil_index(af), 3);
    assert_near(cdem_analysis_params(af)->total_strain_max, 3.0, 0);
    assert_non_null(cdem_analysis_reader(af));
    const char *names[] = {"total-max-shear", "cum-e1", "incr-rotation", "uplift", "sigma1"};
    for (size_t q = 0; q < sizeof names / sizeof names[0]; q++) {
        const cdem_quantity *qq;
        cdem_quantity_find(names[q], &qq, &err);
        const cdem_state *sf, *sm;
        double *vf, *vm;
        assert_int_equal(cdem_analysis_values(af, 8, qq, &sf, &vf, &err), CDEM_OK);
        assert_int_equal(cdem_analysis_values(am, 8, qq, &sm, &vm, &err), CDEM_OK);
        assert_int_equal(sf->n, sm->n);
        for (size_t i = 0; i < sf->n; i++) {
            assert_int_equal(sf->id[i], sm->id[i]);
            assert_true((isnan(vf[i]) && isnan(vm[i])) || vf[i] == vm[i]);
        }
        free(vf);
        free(vm);
        cdem_limits lf, lm;
        assert_int_equal(cdem_analysis_limits(af, 8, qq, &lf, &err), CDEM_OK);
        assert_int_equal(cdem_analysis_limits(am, 8, qq, &lm, &err), CDEM_OK);
        assert_true(lf.vmin == lm.vmin && lf.vmax == lm.vmax);
    }
    cdem_analysis_close(af);
    cdem_analysis_close(am);
    for (int k = 0; k < NINC; k++)
        cdem_state_free(&st[k]);
    remove_run(path);
}

static void test_analysis_h5_open_errors(void **state) {
    (void)state;
    cdem_analysis *a;
    cdem_error err;
    assert_int_not_equal(cdem_analysis_open("/nonexistent/run.h5", &a, &err), CDEM_OK);
    assert_non_null(strstr(err.msg, "/nonexistent/run.h5"));
    assert_null(a);
    char path[1100];
    scratch_path(path, sizeof path, "notcdem.h5");
    FILE *f = fopen(path, "w");
    fputs("not an hdf5 file\n", f);
    fclose(f);
    assert_int_not_equal(cdem_analysis_open(path, &a, &err), CDEM_OK);
    assert_non_null(strstr(err.msg, path));
    remove(path);
}

static cdem_status collect(void *user, const cdem_increment_info *info, const cdem_state *s,
                           cdem_error *err) {
    cdem_state *st = user;
    return cdem_state_copy(&st[info->number], s, err);
}

static void test_analysis_h5_cdem2d_import(void **state) {
    (void)state;
    char dir[1024], path[1100];
    const char *d = getenv("CDEM_TEST_DATA");
    snprintf(dir, sizeof dir, "%s/cdem2d_crlf", d ? d : "tests/data");
    scratch_path(path, sizeof path, "imported.h5");
    cdem_error err;
    assert_int_equal(cdem_cdem2d_import_h5(dir, path, &err), CDEM_OK);
    cdem_state mem[4] = {{0}};
    cdem_cdem2d_meta meta;
    assert_int_equal(cdem_cdem2d_import(dir, collect, mem, &meta, &err), CDEM_OK);
    cdem_analysis *a;
    assert_int_equal(cdem_analysis_open(path, &a, &err), CDEM_OK);
    assert_int_equal(cdem_analysis_count(a), 4);
    assert_int_equal(cdem_analysis_equil_index(a), 1);
    assert_int_equal(cdem_analysis_params(a)->calculate_stress, 1);
    assert_non_null(strstr(cdem_h5_reader_summary(cdem_analysis_reader(a)), "Pre-growth layers"));
    for (size_t k = 0; k < 4; k++) {
        const cdem_state *s;
        assert_int_equal(cdem_analysis_state(a, k, &s, &err), CDEM_OK);
        assert_int_equal(s->n, mem[k].n);
        /* the file holds the rows by ascending id (docs/format.md), the folder in file order:
         * every element of the folder is in the file with the same values */
        for (size_t j = 0; j < mem[k].n; j++) {
            size_t i = 0;
            while (i < s->n && s->id[i] != mem[k].id[j])
                i++;
            assert_true(i < s->n);
            assert_true(i == 0 || s->id[i - 1] < s->id[i]);
            assert_true(s->x[i] == mem[k].x[j] && s->sxx[i] == mem[k].sxx[j]);
            assert_int_equal(s->flags[i], mem[k].flags[j]);
        }
    }
    /* behaves as a native run: total displacement of element 0 after 2 deformation steps */
    const cdem_quantity *q;
    cdem_quantity_find("total-disp-x", &q, &err);
    const cdem_state *s;
    double *v;
    assert_int_equal(cdem_analysis_values(a, 3, q, &s, &v, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] == 0)
            assert_near(v[i], 2 * (5.0 + 0.02 * 100.0), 1e-5);
    free(v);
    /* the picture label gives what the folder gives: the increment number, no displacement
     * (issue 18: "Net displacement 0.0 m" on every increment) */
    char label[256];
    cdem_render_increment_label(a, 3, label, sizeof label);
    assert_string_equal(label, "Increment 3");
    cdem_analysis_close(a);
    cdem_cdem2d_meta_free(&meta);
    for (int k = 0; k < 4; k++)
        cdem_state_free(&mem[k]);
    remove_run(path);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_analysis_h5_matches_memory),
        cmocka_unit_test(test_analysis_h5_open_errors),
        cmocka_unit_test(test_analysis_h5_cdem2d_import),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
