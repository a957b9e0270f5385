/* Tests of solver/run: a short end-to-end run of a small model (10 x 2.5 units) written to
 * CDEM_TEST_TMP and read back (increments, phases, layers, net displacement, time series,
 * stop reason), early stop by max_steps, interruption by the stop flag, and refused
 * parameters. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "force.h"
#include "h5format.h"
#include "bc.h"
#include "xdmf.h"
#include "model.h"
#include "run.h"
#include "scratch.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cdem_params small_params(void) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.width = 10.0;
    p.height = 2.5;
    p.equilibration = 100.0;
    p.runtime = 150.0;
    p.series_interval = 50;
    return p;
}

static cdem_run_options quiet_options(const char *path) {
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    return o;
}

static void test_run_small_model_end_to_end(void **st) {
    (void)st;
    char path[1024];
    scratch_path(path, sizeof path, "test_run_small.h5");
    cdem_params p = small_params();
    p.calculate_stress = 1;
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    char *logbuf = NULL;
    size_t loglen = 0;
    FILE *log = open_memstream(&logbuf, &loglen);
    cdem_run_options o = quiet_options(path);
    o.quiet = 0;
    o.log = log;
    o.progress_is_tty = 0;
    cdem_status stt = cdem_run(&p, &o, &err);
    fclose(log);
    if (stt != CDEM_OK)
        fail_msg("cdem_run: %s", err.msg);
    /* plain progress lines (not a tty) */
    assert_non_null(strstr(logbuf, "cdem-run: deformation, step"));
    assert_non_null(strstr(logbuf, "end of equilibration at step"));
    free(logbuf);

    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_increment_count(r), (size_t)m.n_increments_total + 1);
    assert_string_equal(cdem_h5_reader_stop_reason(r), "completed");
    size_t ie = 0;
    assert_int_equal(cdem_h5_reader_find_increment(r, "equil", &ie, &err), CDEM_OK);
    cdem_increment_info info;
    cdem_state s;
    memset(&s, 0, sizeof s);
    assert_int_equal(cdem_h5_reader_load_increment(r, ie, &s, &info, &err), CDEM_OK);
    assert_int_equal(info.number, m.n_increments_equil);
    assert_int_equal(info.step, m.equil_steps);
    assert_int_equal(info.phase, CDEM_PHASE_EQUILIBRATION);
    assert_float_equal(info.net_displacement, 0.0, 0.0);
    /* 24 layers of equal thickness by height: layer k holds the centres between
     * lo + (k-1) h/24 and lo + k h/24, lo/hi the lowest/highest free-element centre */
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < s.n; i++)
        if (!(s.flags[i] & CDEM_FLAGS_BOUNDARY)) {
            lo = fmin(lo, s.y[i]);
            hi = fmax(hi, s.y[i]);
        }
    int seen[25] = {0};
    for (size_t i = 0; i < s.n; i++) {
        if (s.flags[i] & CDEM_FLAGS_BOUNDARY) {
            assert_int_equal(s.layer[i], 0);
            continue;
        }
        assert_true(s.layer[i] >= 1 && s.layer[i] <= 24);
        const double th = (hi - lo) / 24.0;
        assert_true(s.y[i] >= lo + (s.layer[i] - 1) * th - 1e-6);
        assert_true(s.y[i] <= lo + s.layer[i] * th + 1e-6);
        seen[s.layer[i]] = 1;
    }
    assert_true(seen[1] && seen[24]);
    /* stress present and compressive on average at depth */
    assert_true(info.has_stress);
    double mean_syy = 0.0;
    long cnt = 0;
    for (size_t i = 0; i < s.n; i++)
        if (!(s.flags[i] & CDEM_FLAGS_BOUNDARY) && s.layer[i] <= 6) {
            mean_syy += s.syy[i];
            cnt++;
        }
    assert_true(cnt > 10 && mean_syy / (double)cnt > 0.0);
    /* the last increment: end of the run, deformation, net displacement of the block */
    assert_int_equal(
        cdem_h5_reader_load_increment(r, cdem_h5_reader_increment_count(r) - 1, &s, &info, &err),
        CDEM_OK);
    assert_int_equal(info.step, m.total_steps);
    assert_int_equal(info.phase, CDEM_PHASE_DEFORMATION);
    const double net = (double)(m.total_steps - m.equil_steps) * m.displacement_per_step;
    assert_float_equal(info.net_displacement, net, 1e-6 * net);
    /* the time series: one sample at step 0 and every 50 steps */
    cdem_series_sample *ser = NULL;
    size_t ns = 0;
    assert_int_equal(cdem_h5_reader_read_series(r, &ser, &ns, &err), CDEM_OK);
    assert_int_equal(ns, (size_t)(m.total_steps / 50) + 1);
    assert_int_equal(ser[ns - 1].step, (m.total_steps / 50) * 50);
    assert_true(ser[ns - 1].contacts > 1000);
    assert_true(ser[ns - 1].bonds > 0);          /* cohesive contacts created at the end of equil */
    assert_int_equal(ser[1].bonds, 0);           /* and not before */
    assert_true(ser[ns - 1].base_force_y < 0.0); /* the assembly's weight pushes the base down */
    free(ser);
    cdem_state_free(&s);
    cdem_h5_reader_close(r);
}

static void test_run_stops_early_and_on_signal(void **st) {
    (void)st;
    char path[1024];
    scratch_path(path, sizeof path, "test_run_stop.h5");
    cdem_params p = small_params();
    cdem_error err;
    cdem_run_options o = quiet_options(path);
    cdem_model m;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    o.max_steps = m.equil_steps + 40; /* just past the end of equilibration */
    /* on a tty: one line redrawn in place (carriage return, erase line) */
    char *logbuf = NULL;
    size_t loglen = 0;
    FILE *log = open_memstream(&logbuf, &loglen);
    o.quiet = 0;
    o.progress_is_tty = 1;
    o.log = log;
    assert_int_equal(cdem_run(&p, &o, &err), CDEM_OK);
    fclose(log);
    assert_non_null(strstr(logbuf, "\r\033[Kequilibration, increment "));
    assert_non_null(strstr(logbuf, "steps/s"));
    assert_null(strstr(logbuf, "cdem-run: equilibration, step")); /* no plain log lines */
    assert_int_equal(logbuf[loglen - 1], '\n');                   /* line closed at the end */
    /* the end-of-equilibration line is not overdrawn by the progress line (issue 18) */
    assert_non_null(strstr(logbuf, "\ncdem-run: end of equilibration at step "));
    /* the last progress line says how the run ended, not a time left */
    const char *last = strrchr(logbuf, '\r');
    assert_non_null(last);
    assert_non_null(strstr(last, "stopped early after "));
    assert_null(strstr(last, " s left"));
    /* and the final line names the file, its size and how to continue */
    char want[1200];
    snprintf(want, sizeof want, "cdem-run: wrote %s (", path);
    assert_non_null(strstr(last, want));
    assert_non_null(strstr(last, " MB; "));
    /* with the steps this process took, its wall time and speed */
    snprintf(want, sizeof want, "; %ld steps in ", m.equil_steps + 40);
    assert_non_null(strstr(last, want));
    assert_non_null(strstr(last, " s wall time, "));
    /* and the threads it ran on (omp_get_max_threads of this process) */
    snprintf(want, sizeof want, " element-steps/s on %d thread%s", omp_get_max_threads(),
             omp_get_max_threads() == 1 ? "" : "s");
    assert_non_null(strstr(last, want));
    /* and the pair kernel that ran (CDEM_SIMD=scalar chooses the scalar one; without a
     * request, on a CPU with AVX2 and AVX-512, the faster of the two measured) */
    {
        const char *req = getenv("CDEM_SIMD");
        const int measured = (!req || !*req || strcmp(req, "auto") == 0) &&
                             cdem_force_path_usable(CDEM_FORCE_PATH_AVX512);
        const cdem_force_path named[3] = {cdem_force_path_choose(req), CDEM_FORCE_PATH_AVX2,
                                          CDEM_FORCE_PATH_AVX512};
        int found = 0;
        for (int k = 0; k < (measured ? 3 : 1); k++) {
            snprintf(want, sizeof want,
                     "; pair kernel %s; stop reason: ", cdem_force_path_name(named[k]));
            found |= strstr(last, want) != NULL;
        }
        assert_true(found);
    }
    snprintf(
        want, sizeof want,
        "stop reason: stopped-early; continue it with: cdem-run --resume %s); ParaView: ", path);
    assert_non_null(strstr(last, want));
    /* the sidecar as ParaView opens it (issue 35, item 12: a bare name made it abort; this
     * path is absolute, so it needs no "./") */
    char *xmf = cdem_xdmf_path_for(path);
    assert_non_null(xmf);
    snprintf(want, sizeof want, "); ParaView: %s\n", xmf);
    assert_non_null(strstr(last, want));
    free(xmf);
    free(logbuf);
    o.quiet = 1;
    o.log = NULL;
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    assert_string_equal(cdem_h5_reader_stop_reason(r), "stopped-early");
    cdem_increment_info info;
    assert_int_equal(
        cdem_h5_reader_increment_info(r, cdem_h5_reader_increment_count(r) - 1, &info, &err),
        CDEM_OK);
    assert_int_equal(info.step, o.max_steps);
    cdem_h5_reader_close(r);

    volatile sig_atomic_t flag = 1; /* as if SIGINT arrived before the first step */
    o.max_steps = 0;
    o.stop_requested = &flag;
    assert_int_equal(cdem_run(&p, &o, &err), CDEM_ERR_INTERRUPTED);
    assert_non_null(strstr(err.msg, "stopped by a signal after step 1"));
    char resume[1200]; /* the message says how to continue */
    snprintf(resume, sizeof resume, "continue it with: cdem-run --resume %s", path);
    assert_non_null(strstr(err.msg, resume));
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    assert_string_equal(cdem_h5_reader_stop_reason(r), "interrupted");
    assert_int_equal(cdem_h5_reader_increment_count(r), 2); /* start + final */
    assert_int_equal(cdem_h5_reader_increment_info(r, 1, &info, &err), CDEM_OK);
    assert_int_equal(info.step, 1);
    cdem_h5_reader_close(r);
}

static void test_run_refuses_bad_requests(void **st) {
    (void)st;
    char path[1024];
    scratch_path(path, sizeof path, "test_run_refused.h5");
    cdem_params p = small_params();
    cdem_error err;
    cdem_run_options o = quiet_options(path);
    p.mode = (cdem_mode)42; /* not a mode: refused before anything is written */
    assert_int_not_equal(cdem_run(&p, &o, &err), CDEM_OK);
    assert_non_null(strstr(err.msg, "mode"));
    p = small_params();
    /* a missing folder is named as such, not taken for a full disk (issue 19, item 7) */
    o.output_path = "/nonexistent-dir/x.h5";
    assert_int_equal(cdem_run(&p, &o, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "folder /nonexistent-dir does not exist"));
    assert_null(strstr(err.msg, "free some space"));
    assert_int_equal(cdem_run(&p, NULL, &err), CDEM_ERR_INVALID);
    long ni = 0, nw = 0;
    assert_int_equal(cdem_run_count_elements(&p, &ni, &nw, &err), CDEM_OK);
    assert_true(ni > 500 && nw > 100);
}

/* The last log line of a short run of p written to NAME (the log's last line). */
static void last_log_line(cdem_params *p, const char *name, char *line, size_t cap) {
    char path[1024];
    scratch_path(path, sizeof path, name);
    cdem_error err;
    cdem_run_options o = quiet_options(path);
    cdem_model m;
    assert_int_equal(cdem_bc_derive_model(p, &m, &err), CDEM_OK);
    o.max_steps = 200;
    o.quiet = 0;
    char *logbuf = NULL;
    size_t loglen = 0;
    FILE *log = open_memstream(&logbuf, &loglen);
    o.log = log;
    assert_int_equal(cdem_run(p, &o, &err), CDEM_OK);
    fclose(log);
    const char *last = strstr(logbuf, "cdem-run: wrote ");
    assert_non_null(last);
    snprintf(line, cap, "%s", last);
    free(logbuf);
}

/* A law without a vector kernel on a vector machine is named in the log's pair-kernel line
 * (issue 45, item 5): the vector path evaluates it by its scalar kernel, and is not reported
 * as the vector one; a request for the AVX-512 path runs it and says so too. */
static void test_run_names_a_law_without_a_vector_kernel(void **st) {
    (void)st;
    cdem_params p = small_params();
    p.granular_law = CDEM_LAW_TEST_SCALAR_ONLY; /* the tests' law without an AVX2 kernel */
    assert_int_equal(cdem_force_law_vectorised(CDEM_LAW_TEST_SCALAR_ONLY), 0);
    assert_int_equal(cdem_force_law_vectorised(CDEM_LAW_NORMAL_COHESION),
                     cdem_force_path_usable(CDEM_FORCE_PATH_AVX2));
    const char *saved = getenv("CDEM_SIMD");
    char keep[64] = "";
    if (saved)
        snprintf(keep, sizeof keep, "%s", saved);
    char line[2048], want[160];
    unsetenv("CDEM_SIMD");
    last_log_line(&p, "test_run_scalar_law.h5", line, sizeof line);
    /* no request: AVX2 where the CPU has it (not measured against AVX-512: the same loop) */
    snprintf(want, sizeof want, "; pair kernel %s; stop reason",
             cdem_force_path_usable(CDEM_FORCE_PATH_AVX2) ? "avx2, scalar for law test-scalar-only"
                                                          : "scalar");
    if (!strstr(line, want))
        fail_msg("expected \"%s\" in: %s", want, line);
    if (cdem_force_path_usable(CDEM_FORCE_PATH_AVX512)) {
        setenv("CDEM_SIMD", "avx512", 1);
        last_log_line(&p, "test_run_scalar_law512.h5", line, sizeof line);
        if (!strstr(line, "; pair kernel avx512, scalar for law test-scalar-only; stop reason"))
            fail_msg("with CDEM_SIMD=avx512: %s", line);
    }
    /* the default law on the same machine: the path's name alone */
    p.granular_law = CDEM_LAW_NORMAL_COHESION;
    setenv("CDEM_SIMD", "scalar", 1);
    last_log_line(&p, "test_run_vector_law.h5", line, sizeof line);
    assert_non_null(strstr(line, "; pair kernel scalar; stop reason"));
    if (saved)
        setenv("CDEM_SIMD", keep, 1);
    else
        unsetenv("CDEM_SIMD");
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_run_small_model_end_to_end),
        cmocka_unit_test(test_run_stops_early_and_on_signal),
        cmocka_unit_test(test_run_refuses_bad_requests),
        cmocka_unit_test(test_run_names_a_law_without_a_vector_kernel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
