/* Boundaries compose (issue 45, item 3): a run holds a list of boundary actors, [boundary]
 * and [boundary.2] ..., each a mode instance with its own keys and its own window of the run's
 * boundary displacement (solver/modes/bc.h, docs/solver.md "Boundaries on a timeline").
 *   actors-1: the sections parse, write and read back; -s boundary.N.key sets them; a key of
 *             [boundary.N] is checked as the actor's own; the record of a run that sets no
 *             window or actor holds exactly the keys it held before actors existed.
 *   actors-2: bad sections and windows are refused with messages naming the section and key.
 *   actors-3: two planar faults one after the other: the blocks move as the two faults'
 *             kinematics say (the block right of both by both slips, the block between them by
 *             the second only, the left block not at all), to rounding.
 *   actors-4: that run stopped in either stage (and SIGKILLed at the end of equilibration)
 *             and resumed ends bit-identical to the straight run. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "h5format.h"
#include "params.h"
#include "run.h"
#include "scratch.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* The two-stage model: the default fault at the middle for 15 m, then a second planar fault
 * at a quarter of the base for the rest of the run (about 20 m). Small: 10 x 2.5 units. */
static const char two_stages[] = "[assembly]\n"
                                 "width = 10\n"
                                 "height = 2.5\n"
                                 "[time]\n"
                                 "equilibration = 100\n"
                                 "runtime = 150\n"
                                 "[output]\n"
                                 "series_interval = 50\n"
                                 "checkpoint_interval = 2\n"
                                 "[boundary]\n"
                                 "mode = planar-fault\n"
                                 "stop = 15\n"
                                 "[boundary.2]\n"
                                 "mode = planar-fault\n"
                                 "fault_location = 0.25\n"
                                 "fault_dip = 45\n"
                                 "start = 15\n";

static cdem_params parsed(const char *text) {
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_error err;
    if (cdem_params_parse_text(&p, text, "two.ini", &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    return p;
}

static char *written(const cdem_params *p, int record) {
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    if (record)
        cdem_params_write_record(p, f);
    else
        cdem_params_write(p, f);
    fclose(f);
    return buf;
}

/* actors-1 */
static void test_actors_parse_write_read(void **state) {
    (void)state;
    cdem_params p = parsed(two_stages);
    cdem_error err;
    assert_int_equal(cdem_params_actor_count(&p), 2);
    cdem_params a0, a1;
    assert_int_equal(cdem_params_actor(&p, 0, &a0, &err), CDEM_OK);
    assert_int_equal(cdem_params_actor(&p, 1, &a1, &err), CDEM_OK);
    assert_true(a0.window_stop == 15.0 && a0.window_start == 0.0 && a0.fault_location == 0.5);
    /* the second actor: its own keys over [boundary]'s, its own window */
    assert_true(a1.fault_location == 0.25 && a1.fault_dip == 45.0 && a1.window_start == 15.0);
    assert_true(a1.window_stop == 0.0);
    assert_int_equal(cdem_params_actor_count(&a1), 1);
    assert_int_equal(cdem_params_actor(&p, 2, &a1, &err), CDEM_ERR_RANGE);
    /* written and read back: the same actors */
    char *text = written(&p, 0);
    assert_non_null(strstr(text, "\n[boundary.2]\n"));
    cdem_params q = parsed(text);
    assert_string_equal(q.actor_keys[0], p.actor_keys[0]);
    assert_true(q.window_stop == 15.0);
    free(text);
    /* -s boundary.N.key: a key of an actor, replacing its line */
    assert_int_equal(cdem_params_override(&q, "boundary.2.fault_dip=60", &err), CDEM_OK);
    assert_int_equal(cdem_params_actor(&q, 1, &a1, &err), CDEM_OK);
    assert_true(a1.fault_dip == 60.0 && a1.fault_location == 0.25);
    assert_int_equal(cdem_params_override(&q, "boundary.3.mode=planar-fault", &err), CDEM_OK);
    assert_int_equal(cdem_params_actor_count(&q), 3);
    /* a run that sets no window and no actor: its record holds the keys of before */
    cdem_params d;
    cdem_params_defaults(&d);
    char *rec = written(&d, 1), *all = written(&d, 0);
    assert_null(strstr(rec, "\nstart = "));
    assert_null(strstr(rec, "\nstop = "));
    assert_non_null(strstr(all, "\nstart = 0\n")); /* --print-defaults lists them */
    free(rec);
    free(all);
    size_t n = 0;
    const cdem_param_def *t = cdem_params_table(&n);
    int left_out = 0;
    for (size_t i = 0; i < n; i++)
        left_out += !t[i].fixture && !cdem_params_recorded(&d, &t[i]);
    /* [boundary] start and stop, and [tilt]'s three (a tests' fixture's keys aside) */
    assert_int_equal(left_out, 5);
    rec = written(&p, 1);
    assert_non_null(strstr(rec, "\nstop = 15\n")); /* set: recorded */
    free(rec);
}

static void expect_parse_error(const char *text, const char *needle) {
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_error err;
    assert_int_not_equal(cdem_params_parse_text(&p, text, "bad.ini", &err), CDEM_OK);
    if (!strstr(err.msg, needle))
        fail_msg("expected \"%s\" in: %s", needle, err.msg);
}

static void expect_rule(const char *text, const char *needle) {
    cdem_params p = parsed(text);
    cdem_error err;
    assert_int_not_equal(cdem_run_validate(&p, &err), CDEM_OK);
    if (!strstr(err.msg, needle))
        fail_msg("expected \"%s\" in: %s", needle, err.msg);
}

/* actors-2 */
static void test_actors_refused(void **state) {
    (void)state;
    expect_parse_error("[boundary.3]\nmode = planar-fault\n",
                       "bad.ini:2: [boundary.3] mode: set a key of [boundary.2] (at least its "
                       "mode) first");
    expect_parse_error("[boundary.9]\n", "bad.ini:1: section [boundary.9]: a boundary actor's "
                                         "section is [boundary.2] to [boundary.8]");
    expect_parse_error("[boundary.x]\n", "bad.ini:1: section [boundary.x]: a boundary actor's "
                                         "section is [boundary.2] to [boundary.8]");
    expect_parse_error("[boundary.2]\nfault_dip = 30\nfault_dip = 40\n",
                       "bad.ini:3: [boundary.2] fault_dip: duplicate key; keep one");
    expect_parse_error("[boundary.2]\nfault_dip = 95\n", "bad.ini:2: fault_dip = 95");
    expect_parse_error("[boundary.2]\ngravity = 5\n",
                       "bad.ini:2: [boundary.2] gravity: unknown key; it belongs in [physics]");
    expect_rule("[boundary]\nstop = 5\nstart = 10\n",
                "[boundary] stop = 5 m must be after start = 10 m");
    expect_rule("[time]\nruntime = 450\n[boundary.2]\nstart = 5000\n",
                "[boundary.2] start = 5000 m is past the run's boundary displacement");
    expect_rule("[boundary.2]\nmode = detachment\n",
                "[boundary.2] mode = detachment cannot be one of several boundary actors");
    expect_rule("[boundary]\nmode = detachment\n[boundary.2]\nmode = planar-fault\n",
                "[boundary] mode = detachment cannot be one of several boundary actors");
    expect_rule("[boundary]\nmode = repose\nstop = 10\n", "mode = repose moves no boundary");
    expect_parse_error("[boundary.2]\nfault_dip = 60\ninversion_percent = 0\n",
                       "bad.ini:3: inversion_percent = 0: must be > 0 and < 100 %");
    /* two faults at the same time whose blocks share elements (the right block rides on both):
     * well defined since issue 47, the block takes both motions (tests/test_bc_faults.c) */
    cdem_params p = parsed("[assembly]\nheight = 2.5\n[time]\nequilibration = 100\nruntime = "
                           "150\n[boundary.2]\nfault_location = 0.25\n");
    cdem_error err;
    assert_int_equal(cdem_run_validate(&p, &err), CDEM_OK);
}

/* One base element's displacement from increment 0 to the last: the base row, nearest x. */
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

typedef struct {
    char bin[1024];
    scratch_dir scratch;
} act_ctx;

static int setup(void **state) {
    act_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    char rel[1024];
    snprintf(rel, sizeof rel, "%s/cdem-run", b && b[0] ? b : "build");
    if (!realpath(rel, c->bin))
        snprintf(c->bin, sizeof c->bin, "%s", rel);
    if (scratch_dir_make(&c->scratch, "test_bc_actors") != 0) {
        free(c);
        return -1;
    }
    char ini[1100];
    scratch_dir_path(&c->scratch, ini, sizeof ini, "two.ini");
    FILE *f = fopen(ini, "w");
    if (!f)
        return -1;
    fputs(two_stages, f);
    fclose(f);
    *state = c;
    return 0;
}

static int teardown(void **state) {
    act_ctx *c = *state;
    const int rc = scratch_dir_remove(&c->scratch);
    free(c);
    return rc;
}

/* "cdem-run ARGS" in the scratch folder (keeping a completed run's checkpoints); its status. */
static int run(const act_ctx *c, const char *args) {
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && env OMP_WAIT_POLICY=passive CDEM_KEEP_CHECKPOINTS=1 '%s' %s "
             "2>'%s/err.txt'",
             c->scratch.dir, c->bin, args, c->scratch.dir);
    const int st = system(cmd);
    assert_true(WIFEXITED(st));
    return WEXITSTATUS(st);
}

static cdem_h5_reader *open_run_file(const act_ctx *c, const char *name) {
    char path[1200];
    scratch_dir_path(&c->scratch, path, sizeof path, name);
    cdem_h5_reader *r = NULL;
    cdem_error err;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    return r;
}

/* actors-3 */
static void test_actors_two_faults_in_turn(void **state) {
    const act_ctx *c = *state;
    assert_int_equal(run(c, "two.ini -q -o straight.h5"), 0);
    cdem_h5_reader *r = open_run_file(c, "straight.h5");
    cdem_error err;
    const size_t n = cdem_h5_reader_increment_count(r);
    cdem_state a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    cdem_increment_info ia, ib;
    assert_int_equal(cdem_h5_reader_load_increment(r, 0, &a, &ia, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_load_increment(r, n - 1, &b, &ib, &err), CDEM_OK);
    /* the run's boundary displacement: both actors' */
    const double total = ib.net_displacement, first = 15.0, second = total - first;
    assert_true(second > 10.0);
    const double d1 = 30.0 * M_PI / 180.0, d2 = 45.0 * M_PI / 180.0;
    double dx, dy;
    base_move(&a, &b, 1000.0, &dx, &dy); /* left of both faults: still */
    assert_true(dx == 0.0 && dy == 0.0);
    base_move(&a, &b, 4000.0, &dx, &dy); /* between them: the second fault's slip */
    if (fabs(dx - second * cos(d2)) > 0.05 || fabs(dy + second * sin(d2)) > 0.05)
        fail_msg("the middle block moved (%.4f, %.4f) m; the second fault's %.4f m at 45 deg is "
                 "(%.4f, %.4f)",
                 dx, dy, second, second * cos(d2), -second * sin(d2));
    base_move(&a, &b, 8000.0, &dx, &dy); /* right of both: both slips */
    const double ex = first * cos(d1) + second * cos(d2), ey = -first * sin(d1) - second * sin(d2);
    if (fabs(dx - ex) > 0.05 || fabs(dy - ey) > 0.05)
        fail_msg("the right block moved (%.4f, %.4f) m; expected (%.4f, %.4f)", dx, dy, ex, ey);
    /* the first actor's block carries its flag, the second's its own */
    size_t moving = 0, second_actor = 0;
    for (size_t i = 0; i < a.n; i++) {
        moving += (a.flags[i] & CDEM_FLAG_MOVING) != 0;
        second_actor += (a.flags[i] & CDEM_FLAG_ACTOR_MOVING(2)) != 0;
    }
    assert_true(moving > 0 && second_actor > moving);
    cdem_state_free(&a);
    cdem_state_free(&b);
    /* the summary states both actors and their windows */
    const char *summary = cdem_h5_reader_summary(r);
    assert_non_null(strstr(summary, "window:                      from 0 m to 15 m"));
    assert_non_null(strstr(summary, "actor 2 ([boundary.2]):      mode planar-fault"));
    cdem_h5_reader_close(r);
}

/* The increments and series of two files, value for value. */
static void same_runs(const act_ctx *c, const char *na, const char *nb) {
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
        if (memcmp(&qa[k].kinetic_energy, &qb[k].kinetic_energy, sizeof(double)) ||
            memcmp(&qa[k].net_displacement, &qb[k].net_displacement, sizeof(double)))
            fail_msg("%s and %s differ at series sample %zu", na, nb, k);
    free(qa);
    free(qb);
    cdem_h5_reader_close(a);
    cdem_h5_reader_close(b);
}

/* cdem-run two.ini -o NAME started and SIGKILLed once its log says the equilibration ended. */
static void kill_at_end_of_equilibration(const act_ctx *c, const char *name) {
    char log[1200], out[1200], ini[1200];
    scratch_dir_path(&c->scratch, log, sizeof log, "killed.log");
    scratch_dir_path(&c->scratch, out, sizeof out, name);
    scratch_dir_path(&c->scratch, ini, sizeof ini, "two.ini");
    const pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        if (!freopen(log, "wb", stderr) || !freopen("/dev/null", "wb", stdout))
            _exit(99);
        execl(c->bin, c->bin, ini, "-o", out, (char *)NULL);
        _exit(98);
    }
    for (int i = 0; i < 60000; i++) {
        int st = 0;
        if (waitpid(pid, &st, WNOHANG) == pid)
            fail_msg("cdem-run ended (status %d) before it could be killed", st);
        char *text = scratch_read_file(log);
        const int due = text && strstr(text, "end of equilibration");
        free(text);
        if (due)
            break;
        const struct timespec ts = {0, 5000000};
        nanosleep(&ts, NULL);
    }
    assert_int_equal(kill(pid, SIGKILL), 0);
    int st = 0;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    assert_true(WIFSIGNALED(st));
}

/* actors-4 */
static void test_actors_resumed_bit_identical(void **state) {
    const act_ctx *c = *state;
    assert_int_equal(run(c, "two.ini -q -o straight.h5 --force"), 0);
    /* stopped in the first stage (at 6 m) and in the second (at 24 m), then resumed */
    assert_int_equal(run(c, "two.ini -q -o first.h5 --max-steps 3850"), 0);
    assert_int_equal(run(c, "-q --resume first.h5"), 0);
    same_runs(c, "straight.h5", "first.h5");
    assert_int_equal(run(c, "two.ini -q -o second.h5 --max-steps 4750"), 0);
    assert_int_equal(run(c, "-q --resume second.h5"), 0);
    same_runs(c, "straight.h5", "second.h5");
    /* killed, then resumed (from the checkpoint of the equilibration) */
    kill_at_end_of_equilibration(c, "killed.h5");
    assert_int_equal(run(c, "-q --resume killed.h5"), 0);
    same_runs(c, "straight.h5", "killed.h5");
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_actors_parse_write_read),
        cmocka_unit_test(test_actors_refused),
        cmocka_unit_test(test_actors_two_faults_in_turn),
        cmocka_unit_test(test_actors_resumed_bit_identical),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
