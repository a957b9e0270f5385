/* Several faults on one timeline (issue 47, items 1 and 6; docs/solver.md "Boundaries on a
 * timeline", docs/analysis.md "Faults on a timeline"): planar, listric and irregular faults
 * compose, in sequence or together, and the analysis reads the timeline back.
 *   faults-1: a listric fault, then a planar fault right of it: the base left of the listric
 *             fault stays, the base between them moves by the listric slip along its basal
 *             dip, the base right of both by both slips, to 0.05 m.
 *   faults-2: the same two acting together: the right block carries both motions at once.
 *   faults-3: refusals naming both sections and keys: traces that cross inside the assembly
 *             while both act (allowed one after the other), a listric fault crossing a planar
 *             one (whatever the windows), two faults at the same base location.
 *   faults-4: the sequence stopped in its second stage and resumed ends bit-identical to the
 *             straight run, and so does the straight run on 2 threads.
 *   faults-5: three planar faults one after the other and all together: the activity measured
 *             from the incremental strain near each trace (cdem-strain faults --timeline)
 *             matches each prescribed window to one display interval; info lists the actors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "fault_timeline.h"
#include "h5format.h"
#include "params.h"
#include "run.h"
#include "run_file.h"
#include "scratch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

/* A listric fault (x = 3 km, 45 degrees) for 60 m, then a planar one (x = 7 km, 60 degrees). */
static const char listric_then_planar[] = "[assembly]\n"
                                          "width = 10\n"
                                          "height = 2.5\n"
                                          "[time]\n"
                                          "equilibration = 100\n"
                                          "runtime = 300\n"
                                          "display_interval = 20\n"
                                          "[output]\n"
                                          "series_interval = 200\n"
                                          "checkpoint_interval = 2\n"
                                          "[boundary]\n"
                                          "mode = listric-fault\n"
                                          "fault_location = 0.3\n"
                                          "fault_dip = 45\n"
                                          "stop = 60\n"
                                          "[boundary.2]\n"
                                          "mode = planar-fault\n"
                                          "fault_location = 0.7\n"
                                          "fault_dip = 60\n"
                                          "start = 60\n";

/* Three planar faults at 2.5, 5 and 7.5 km, 150 m each, one after the other. */
static const char three_in_turn[] = "[assembly]\n"
                                    "width = 10\n"
                                    "height = 2.5\n"
                                    "[time]\n"
                                    "equilibration = 400\n"
                                    "runtime = 1060\n"
                                    "display_interval = 50\n"
                                    "[output]\n"
                                    "series_interval = 500\n"
                                    "[boundary]\n"
                                    "mode = planar-fault\n"
                                    "fault_location = 0.25\n"
                                    "fault_dip = 60\n"
                                    "stop = 150\n"
                                    "[boundary.2]\n"
                                    "mode = planar-fault\n"
                                    "fault_location = 0.5\n"
                                    "fault_dip = 60\n"
                                    "start = 150\n"
                                    "stop = 300\n"
                                    "[boundary.3]\n"
                                    "mode = planar-fault\n"
                                    "fault_location = 0.75\n"
                                    "fault_dip = 60\n"
                                    "start = 300\n";

typedef struct {
    char bin[1024], strain[1024];
    scratch_dir scratch;
} faults_ctx;

/* text without its "start = " and "stop = " lines: every actor over the whole run */
static void write_file(const faults_ctx *c, const char *name, const char *text, int together) {
    char path[1200];
    scratch_dir_path(&c->scratch, path, sizeof path, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    for (const char *line = text; *line;) {
        const char *eol = strchr(line, '\n');
        const size_t len = eol ? (size_t)(eol - line + 1) : strlen(line);
        if (!(together && (!strncmp(line, "start = ", 8) || !strncmp(line, "stop = ", 7))))
            fwrite(line, 1, len, f);
        line += len;
    }
    fclose(f);
}

static int setup(void **state) {
    faults_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    char rel[1024];
    snprintf(rel, sizeof rel, "%s/cdem-run", b && b[0] ? b : "build");
    if (!realpath(rel, c->bin))
        snprintf(c->bin, sizeof c->bin, "%s", rel);
    snprintf(rel, sizeof rel, "%s/cdem-strain", b && b[0] ? b : "build");
    if (!realpath(rel, c->strain))
        snprintf(c->strain, sizeof c->strain, "%s", rel);
    if (scratch_dir_make(&c->scratch, "test_bc_faults") != 0) {
        free(c);
        return -1;
    }
    *state = c;
    write_file(c, "lp.ini", listric_then_planar, 0);
    write_file(c, "lp-together.ini", listric_then_planar, 1);
    write_file(c, "three.ini", three_in_turn, 0);
    write_file(c, "three-together.ini", three_in_turn, 1);
    return 0;
}

static int teardown(void **state) {
    faults_ctx *c = *state;
    const int rc = scratch_dir_remove(&c->scratch);
    free(c);
    return rc;
}

/* "PROGRAM ARGS" in the scratch folder on `threads` threads; its exit status. */
static int run_in(const faults_ctx *c, const char *program, int threads, const char *args) {
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && env OMP_NUM_THREADS=%d OMP_WAIT_POLICY=passive CDEM_KEEP_CHECKPOINTS=1 "
             "'%s' %s >'%s/out.txt' 2>'%s/err.txt'",
             c->scratch.dir, threads, program, args, c->scratch.dir, c->scratch.dir);
    const int st = system(cmd);
    assert_true(WIFEXITED(st));
    return WEXITSTATUS(st);
}

static int run(const faults_ctx *c, const char *args) {
    return run_in(c, c->bin, 1, args);
}

static cdem_h5_reader *open_run_file(const faults_ctx *c, const char *name) {
    char path[1200];
    scratch_dir_path(&c->scratch, path, sizeof path, name);
    cdem_h5_reader *r = NULL;
    cdem_error err;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    return r;
}

/* The displacement of the base element nearest x from increment 0 to the last. */
static void base_move(const cdem_state *a, const cdem_state *b, double x, double *dx, double *dy) {
    double ymin = INFINITY;
    for (size_t i = 0; i < a->n; i++)
        if (a->flags[i] & CDEM_FLAG_WALL)
            ymin = fmin(ymin, a->y[i]);
    size_t best = 0;
    double bd = INFINITY;
    for (size_t i = 0; i < a->n; i++)
        if ((a->flags[i] & CDEM_FLAG_WALL) && a->y[i] < ymin + 1.0 && fabs(a->x[i] - x) < bd) {
            bd = fabs(a->x[i] - x);
            best = i;
        }
    for (size_t k = 0; k < b->n; k++)
        if (b->id[k] == a->id[best]) {
            *dx = b->x[k] - a->x[best];
            *dy = b->y[k] - a->y[best];
            return;
        }
    fail_msg("base element id %d is gone", (int)a->id[best]);
}

static void expect_move(const cdem_state *a, const cdem_state *b, double x, double ex, double ey,
                        const char *what) {
    double dx = NAN, dy = NAN;
    base_move(a, b, x, &dx, &dy);
    if (fabs(dx - ex) > 0.05 || fabs(dy - ey) > 0.05)
        fail_msg("the base at x = %g m (%s) moved (%.4f, %.4f) m; expected (%.4f, %.4f)", x, what,
                 dx, dy, ex, ey);
}

/* The first and last increment of run file NAME, and the last one's net displacement. */
static double load_ends(const faults_ctx *c, const char *name, cdem_state *a, cdem_state *b) {
    cdem_h5_reader *r = open_run_file(c, name);
    cdem_error err;
    const size_t n = cdem_h5_reader_increment_count(r);
    memset(a, 0, sizeof *a);
    memset(b, 0, sizeof *b);
    cdem_increment_info ia, ib;
    assert_int_equal(cdem_h5_reader_load_increment(r, 0, a, &ia, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_load_increment(r, n - 1, b, &ib, &err), CDEM_OK);
    cdem_h5_reader_close(r);
    return ib.net_displacement;
}

static const double d45 = 45.0 * M_PI / 180.0, d60 = 60.0 * M_PI / 180.0;

/* faults-1 */
static void test_listric_then_planar(void **state) {
    const faults_ctx *c = *state;
    assert_int_equal(run(c, "lp.ini -q -o lp.h5"), 0);
    cdem_state a, b;
    const double total = load_ends(c, "lp.h5", &a, &b), first = 60.0, second = total - first;
    assert_true(second > 50.0);
    expect_move(&a, &b, 1000.0, 0.0, 0.0, "left of both: the listric fault's footwall");
    expect_move(&a, &b, 5000.0, first * cos(d45), -first * sin(d45), "the listric slip");
    expect_move(&a, &b, 9000.0, first * cos(d45) + second * cos(d60),
                -first * sin(d45) - second * sin(d60), "both slips");
    /* the listric fault's footwall is live material: no display-only element */
    for (size_t i = 0; i < a.n; i++)
        assert_false(a.flags[i] & CDEM_FLAG_FOOTWALL);
    cdem_state_free(&a);
    cdem_state_free(&b);
}

/* faults-2 */
static void test_listric_and_planar_together(void **state) {
    const faults_ctx *c = *state;
    assert_int_equal(run(c, "lp-together.ini -q -o together.h5"), 0);
    cdem_state a, b;
    const double each = 0.5 * load_ends(c, "together.h5", &a, &b); /* the net is both slips */
    assert_true(each > 100.0);
    expect_move(&a, &b, 1000.0, 0.0, 0.0, "left of both");
    expect_move(&a, &b, 5000.0, each * cos(d45), -each * sin(d45), "the listric slip");
    expect_move(&a, &b, 9000.0, each * (cos(d45) + cos(d60)), -each * (sin(d45) + sin(d60)),
                "both slips at once");
    cdem_state_free(&a);
    cdem_state_free(&b);
}

static cdem_params parsed(const char *text) {
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_error err;
    if (cdem_params_parse_text(&p, text, "faults.ini", &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    return p;
}

static void expect_rule(const char *text, const char *needle) {
    cdem_params p = parsed(text);
    cdem_error err;
    assert_int_not_equal(cdem_run_validate(&p, &err), CDEM_OK);
    if (!strstr(err.msg, needle))
        fail_msg("expected \"%s\" in: %s", needle, err.msg);
}

static void expect_valid(const char *text) {
    cdem_params p = parsed(text);
    cdem_error err;
    if (cdem_run_validate(&p, &err) != CDEM_OK)
        fail_msg("refused: %s", err.msg);
}

/* faults-3 */
static void test_faults_refused(void **state) {
    (void)state;
    static const char crossing[] = "[assembly]\nwidth = 10\nheight = 2.5\n[time]\nruntime = 600\n"
                                   "[boundary]\nfault_location = 0.3\nfault_dip = 80\n%s"
                                   "[boundary.2]\nfault_location = 0.6\nfault_dip = 30\n%s";
    char text[512];
    snprintf(text, sizeof text, crossing, "", "");
    expect_rule(text, "[boundary] (planar-fault; fault_location = 0.3, fault_dip = 80) and "
                      "[boundary.2] (planar-fault; fault_location = 0.6, fault_dip = 30) cross "
                      "inside the assembly");
    expect_rule(text, "the wedge above the crossing would move two ways at once while both act");
    /* one after the other: the later fault cuts the earlier's zone */
    snprintf(text, sizeof text, crossing, "stop = 10\n", "start = 10\n");
    expect_valid(text);
    /* a listric fault's elements would be cut, whatever the windows */
    expect_rule("[assembly]\nwidth = 10\nheight = 2.5\n[time]\nruntime = 600\n[boundary]\nmode = "
                "listric-fault\nfault_location = 0.5\nfault_dip = 80\nstop = 10\n[boundary.2]\n"
                "mode = planar-fault\nfault_location = 0.7\nfault_dip = 30\nstart = 10\n",
                "[boundary] (listric-fault; fault_location = 0.5, fault_dip = 80) and "
                "[boundary.2] (planar-fault; fault_location = 0.7, fault_dip = 30) cross inside "
                "the assembly");
    /* the same base location */
    expect_rule("[boundary.2]\nfault_location = 0.505\n",
                "[boundary] (planar-fault; fault_location = 0.5, fault_dip = 30) and "
                "[boundary.2] (planar-fault; fault_location = 0.505, fault_dip = 30) overlap");
    /* apart and parallel, together: well defined */
    expect_valid(
        "[assembly]\nwidth = 10\nheight = 2.5\n[time]\nruntime = 600\n[boundary]\nfault_location = "
        "0.3\n[boundary.2]\nmode = listric-fault\nfault_location = 0.6\n");
    /* a mode that does not compose is named with those that do */
    expect_rule("[boundary.2]\nmode = detachment\n",
                "modes that can: planar-fault, listric-fault or irregular-fault");
}

/* The increments and series of two files, value for value. */
static void same_runs(const faults_ctx *c, const char *na, const char *nb) {
    cdem_h5_reader *a = open_run_file(c, na), *b = open_run_file(c, nb);
    cdem_error err;
    const size_t n = cdem_h5_reader_increment_count(a);
    assert_int_equal(n, cdem_h5_reader_increment_count(b));
    for (size_t k = 0; k < n; k++) {
        cdem_state sa, sb;
        memset(&sa, 0, sizeof sa);
        memset(&sb, 0, sizeof sb);
        cdem_increment_info ia, ib;
        assert_int_equal(cdem_h5_reader_load_increment(a, k, &sa, &ia, &err), CDEM_OK);
        assert_int_equal(cdem_h5_reader_load_increment(b, k, &sb, &ib, &err), CDEM_OK);
        assert_int_equal(sa.n, sb.n);
        if (memcmp(sa.x, sb.x, sa.n * sizeof *sa.x) || memcmp(sa.y, sb.y, sa.n * sizeof *sa.y) ||
            memcmp(sa.vx, sb.vx, sa.n * sizeof *sa.vx) ||
            memcmp(sa.flags, sb.flags, sa.n * sizeof *sa.flags) ||
            memcmp(&ia.net_displacement, &ib.net_displacement, sizeof ia.net_displacement))
            fail_msg("%s and %s differ at increment %zu", na, nb, k);
        cdem_state_free(&sa);
        cdem_state_free(&sb);
    }
    cdem_series_sample *qa = NULL, *qb = NULL;
    size_t ma = 0, mb = 0;
    assert_int_equal(cdem_h5_reader_read_series(a, &qa, &ma, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_read_series(b, &qb, &mb, &err), CDEM_OK);
    assert_int_equal(ma, mb);
    for (size_t k = 0; k < ma; k++)
        if (memcmp(&qa[k].kinetic_energy, &qb[k].kinetic_energy, sizeof(double)))
            fail_msg("%s and %s differ at series sample %zu", na, nb, k);
    free(qa);
    free(qb);
    cdem_h5_reader_close(a);
    cdem_h5_reader_close(b);
}

/* faults-4 */
static void test_faults_resumed_and_threads(void **state) {
    const faults_ctx *c = *state;
    assert_int_equal(run(c, "lp.ini -q -o straight.h5 --force"), 0);
    /* stopped in the second stage (the planar fault, after 60 m = 3022 steps of 0.01986 m
     * past the 3548 of equilibration), then resumed */
    assert_int_equal(run(c, "lp.ini -q -o second.h5 --max-steps 7900"), 0);
    assert_int_equal(run(c, "-q --resume second.h5"), 0);
    same_runs(c, "straight.h5", "second.h5");
    assert_int_equal(run_in(c, c->bin, 2, "lp.ini -q -o two-threads.h5"), 0);
    same_runs(c, "straight.h5", "two-threads.h5");
}

/* The activity windows of run file NAME against the prescribed ones, to one increment. */
static void expect_timeline(const faults_ctx *c, const char *name) {
    char path[1200];
    scratch_dir_path(&c->scratch, path, sizeof path, name);
    cdem_analysis *a = NULL;
    cdem_error err;
    if (cdem_analysis_open(path, &a, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    cdem_timeline_options o;
    cdem_timeline_default_options(&o);
    cdem_timeline_result r;
    if (cdem_timeline_measure(a, &o, &r, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(r.n_actors, 3);
    for (int j = 0; j < 3; j++) {
        assert_true(r.first_window[j] >= 0 && r.first_active[j] >= 0);
        if (abs(r.first_active[j] - r.first_window[j]) > 1 ||
            abs(r.last_active[j] - r.last_window[j]) > 1)
            fail_msg("%s: %s active in increments %d-%d, prescribed %d-%d", name,
                     r.actor[j].section, r.first_active[j], r.last_active[j], r.first_window[j],
                     r.last_window[j]);
    }
    cdem_timeline_free(&r);
    cdem_analysis_close(a);
}

/* faults-5 */
static void test_activity_windows(void **state) {
    const faults_ctx *c = *state;
    assert_int_equal(run(c, "three.ini -q -o three.h5"), 0);
    assert_int_equal(run(c, "three-together.ini -q -o three-together.h5"), 0);
    expect_timeline(c, "three.h5");
    expect_timeline(c, "three-together.h5");
    /* in sequence each window is 3 increments of 50 m; together each spans the run */
    assert_int_equal(run_in(c, c->strain, 1, "info three.h5"), 0);
    char out[1200];
    scratch_dir_path(&c->scratch, out, sizeof out, "out.txt");
    char *text = scratch_read_file(out);
    assert_non_null(text);
    assert_non_null(strstr(text, "boundary actors: 3"));
    assert_non_null(strstr(text, "[boundary.2]   planar-fault         5000.0      60 150-300"));
    free(text);
    assert_int_equal(run_in(c, c->strain, 1, "faults three.h5 --timeline -o tl.csv"), 0);
    scratch_dir_path(&c->scratch, out, sizeof out, "err.txt");
    text = scratch_read_file(out);
    assert_non_null(text);
    assert_non_null(strstr(text, "[boundary.3] planar-fault at x = 7500 m: active in increments"));
    free(text);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_listric_then_planar),
        cmocka_unit_test(test_listric_and_planar_together),
        cmocka_unit_test(test_faults_refused),
        cmocka_unit_test(test_faults_resumed_and_threads),
        cmocka_unit_test(test_activity_windows),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
