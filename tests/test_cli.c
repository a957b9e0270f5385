/* Tests of the cdem-run command line (solver/main.c), run as a program: --print-defaults
 * round trip, error messages and exit codes, -s overrides, --summary, usage errors.
 * The binary is $CDEM_BUILD/cdem-run (default build/); scratch files go to $CDEM_TEST_TMP. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "params.h"
#include "scratch.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct {
    char bin[1024];      /* path of cdem-run */
    scratch_dir scratch; /* private scratch directory */
} cli_ctx;

static int setup(void **state) {
    cli_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    snprintf(c->bin, sizeof c->bin, "%s/cdem-run", b && b[0] ? b : "build");
    if (scratch_dir_make(&c->scratch, "test_cli") != 0) {
        free(c);
        return -1;
    }
    *state = c;
    return 0;
}

static int teardown(void **state) {
    cli_ctx *c = *state;
    int rc = scratch_dir_remove(&c->scratch);
    free(c);
    return rc;
}

/* Runs cdem-run with args (shell syntax), stdout and stderr to files in tmp; returns the
 * exit status (124 when it ran for 10 minutes: a hang fails instead of stalling the tests). */
static int run(const cli_ctx *c, const char *args) {
    if (access(c->bin, X_OK) != 0) {
        print_error("%s is missing: build it first (make build/cdem-run)\n", c->bin);
        fail();
    }
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "timeout 600 '%s' %s >'%s/out.txt' 2>'%s/err.txt'", c->bin, args,
             c->scratch.dir, c->scratch.dir);
    int st = system(cmd);
    assert_true(WIFEXITED(st));
    return WEXITSTATUS(st);
}

static char *slurp(const cli_ctx *c, const char *name) {
    char path[1100];
    snprintf(path, sizeof path, "%s/%s", c->scratch.dir, name);
    char *buf = scratch_read_file(path);
    assert_non_null(buf);
    return buf;
}

static void write_file(const cli_ctx *c, const char *name, const char *text) {
    char path[1100];
    snprintf(path, sizeof path, "%s/%s", c->scratch.dir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void assert_has(const char *text, const char *needle) {
    if (!strstr(text, needle)) {
        print_error("output lacks \"%s\":\n%s\n", needle, text);
        fail();
    }
}

static void test_cli_print_defaults_round_trip(void **state) {
    cli_ctx *c = *state;
    assert_int_equal(run(c, "--print-defaults"), 0);
    char path[1100];
    snprintf(path, sizeof path, "%s/out.txt", c->scratch.dir);
    cdem_params p, d;
    cdem_error err;
    cdem_params_defaults(&d);
    memset(&p, 0, sizeof p);
    cdem_status st = cdem_params_load(&p, path, NULL, &err);
    if (st != CDEM_OK)
        print_error("%s\n", err.msg);
    assert_int_equal(st, CDEM_OK);
    size_t n;
    const cdem_param_def *t = cdem_params_table(&n);
    for (size_t i = 0; i < n; i++) {
        char a[1100], b[1100];
        if (t[i].fixture)
            continue; /* a tests' fixture's key: listed nowhere (params.h) */
        cdem_params_format_value(&p, &t[i], a, sizeof a);
        cdem_params_format_value(&d, &t[i], b, sizeof b);
        assert_string_equal(a, b);
    }
    assert_true(p.gravity == d.gravity && p.element.cohesion == d.element.cohesion);
}

static void test_cli_override_visible_in_print_defaults(void **state) {
    cli_ctx *c = *state;
    assert_int_equal(run(c, "-s time.runtime=3500 -s boundary.mode=detachment --print-defaults"),
                     0);
    char *out = slurp(c, "out.txt");
    assert_has(out, "\nruntime = 3500\n");
    assert_has(out, "\nmode = detachment\n");
    free(out);
    /* overrides apply after the file */
    write_file(c, "m.ini", "[time]\nruntime = 3000\n[physics]\ngravity = 5\n");
    char args[1200];
    snprintf(args, sizeof args, "'%s/m.ini' -s time.runtime=4000 --print-defaults", c->scratch.dir);
    assert_int_equal(run(c, args), 0);
    out = slurp(c, "out.txt");
    assert_has(out, "\nruntime = 4000\n");
    assert_has(out, "\ngravity = 5\n");
    free(out);
}

static void test_cli_bad_key_in_file(void **state) {
    cli_ctx *c = *state;
    write_file(c, "bad.ini", "[assembly]\nwidth = 12\nwidht = 13\n");
    char args[1200];
    snprintf(args, sizeof args, "'%s/bad.ini' --summary", c->scratch.dir);
    assert_int_equal(run(c, args), 1);
    char *err = slurp(c, "err.txt");
    assert_has(err, "cdem-run: ");
    assert_has(err, "bad.ini:3: [assembly] widht: unknown key; did you mean 'width'?\n");
    free(err);
}

static void test_cli_bad_override_and_rules(void **state) {
    cli_ctx *c = *state;
    assert_int_equal(run(c, "-s time.runtime=abc --summary"), 1);
    char *err = slurp(c, "err.txt");
    assert_has(err, "cdem-run: -s time.runtime=abc: runtime = abc: not a number");
    free(err);
    assert_int_equal(
        run(c, "-s boundary.mode=biaxial -s assembly.width=20 -s surface.erosion=on --summary"), 1);
    err = slurp(c, "err.txt");
    assert_has(err, "cdem-run: mode = biaxial requires width = 10");
    assert_has(err, "\ncdem-run: mode = biaxial excludes erosion");
    free(err);
}

/* --summary checks every input the run checks, and never waits on one (issue 35, item 6: a
 * fault file that is a FIFO hung --summary and the run; a missing, folder, device or invalid
 * one gave a summary and exit 0, then the run refused it). */
static void test_cli_summary_checks_the_fault_file(void **state) {
    const cli_ctx *c = *state;
    char fifo[1100], args[2400];
    snprintf(fifo, sizeof fifo, "%s/fault.fifo", c->scratch.dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    write_file(c, "bad.txt", "1400 0\n1000 800\n"); /* first point not at the fault location */
    const struct {
        const char *file; /* under the scratch folder unless absolute */
        const char *said;
    } cases[] = {
        {"fault.fifo", "is a pipe (FIFO), not a text file of x y points"},
        {"missing.txt", "cannot open: No such file or directory"},
        {".", "is a folder, not a text file of x y points"},
        {"/dev/zero", "is a device, not a text file of x y points"},
        {"bad.txt", "line 1: first point (1400, 0) m must be at the fault location"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        for (int summary = 0; summary < 2; summary++) {
            char path[1200];
            if (cases[k].file[0] == '/')
                snprintf(path, sizeof path, "%s", cases[k].file);
            else
                snprintf(path, sizeof path, "%s/%s", c->scratch.dir, cases[k].file);
            /* run()'s timeout: a hang fails the test (exit 124) instead of stalling it */
            snprintf(args, sizeof args,
                     "-s boundary.mode=irregular-fault -s 'boundary.fault_file=%s' %s", path,
                     summary ? "--summary" : "-q -o '/nonexistent-folder-of-the-test/x.h5'");
            const int rc = run(c, args);
            if (rc != 1)
                fail_msg("%s with fault file %s: exit %d, expected 1",
                         summary ? "--summary" : "run", cases[k].file, rc);
            char *e = slurp(c, "err.txt");
            assert_has(e, cases[k].said);
            free(e);
        }
    }
}

/* Any assembly and element size (issue 33): the paper's Fig. 14 set-up (a cdem2D model: 125 m
 * per unit, 6.25 x 2.8 km, average radius ~10 m) is accepted and builds 46,335 +- 3 % free
 * elements; a model too large for the machine is refused naming the memory it needs and the
 * memory there is; sizes are checked against the elements, not cdem's box. */
static void test_cli_any_size(void **state) {
    const cli_ctx *c = *state;
    assert_int_equal(run(c, "-s assembly.unit_scaling=125 -s assembly.width=50 -s "
                            "assembly.height=22.4 -s material.element_cohesion=6e7 --summary"),
                     0);
    char *o = slurp(c, "out.txt");
    const char *at = strstr(o, "free elements:");
    assert_non_null(at);
    const long free_elements = atol(at + strlen("free elements:"));
    if (free_elements < 44945 || free_elements > 47725) /* 46,335 +- 3 % */
        fail_msg("Fig. 14 set-up: %ld free elements, the paper 46,335", free_elements);
    free(o);
    /* cdem2D's finer elements: a tenth of the radii, 100 times the elements per area */
    assert_int_equal(run(c, "-s assembly.radius_scale=0.1 -s assembly.width=4 -s "
                            "assembly.height=2 --summary"),
                     0);
    o = slurp(c, "out.txt");
    assert_has(o, "radii:                       0.005-0.0125 units (0.1 x the full radii)");
    free(o);
    /* too large for any machine: refused by its memory, named (at 10 m a unit, within a run
     * file's bounds: 1e6 m across) */
    assert_int_equal(run(c, "-s assembly.width=100000 -s assembly.height=100000 -s "
                            "assembly.radius_scale=0.01 -s assembly.unit_scaling=10 --summary"),
                     1);
    char *e = slurp(c, "err.txt");
    assert_has(e, "elements and need about");
    assert_has(e, "GB of memory");
    assert_has(e, "but this machine has");
    free(e);
    /* smaller than 8 elements across; half radii with a scale */
    assert_int_equal(run(c, "-s assembly.height=1.5 --summary"), 1);
    e = slurp(c, "err.txt");
    assert_has(e, "height = 1.5 units: an assembly must be at least 8 of its largest elements");
    free(e);
    assert_int_equal(run(c, "-s assembly.half_radii=on -s assembly.radius_scale=0.25 --summary"),
                     1);
    e = slurp(c, "err.txt");
    assert_has(e, "half_radii = on and radius_scale = 0.25: choose one");
    free(e);
}

/* An assembly still sinking at the end of equilibration is named (the default model settles
 * in about 200 s: 100 s is too short, cdem's 400 s is enough). */
static void test_cli_warns_when_still_settling(void **state) {
    const cli_ctx *c = *state;
    char args[2048];
    snprintf(args, sizeof args,
             "-s time.equilibration=100 -s time.runtime=110 -s time.display_interval=100 -o "
             "'%s/short.h5'",
             c->scratch.dir);
    assert_int_equal(run(c, args), 0);
    char *e = slurp(c, "err.txt");
    assert_has(e, "warning: the assembly is still settling at the end of equilibration: its "
                  "free elements sink at");
    assert_has(e, "a longer time.equilibration lets it come to rest");
    free(e);
    snprintf(args, sizeof args,
             "-s time.runtime=410 -s time.display_interval=100 -o '%s/default.h5'", c->scratch.dir);
    assert_int_equal(run(c, args), 0);
    e = slurp(c, "err.txt");
    assert_has(e, "end of equilibration at step");
    if (strstr(e, "still settling"))
        fail_msg("the default model warned after cdem's 400 s: %s", e);
    free(e);
}

/* output.prefix names files inside an output folder, never a path (issue 35, item 8). */
static void test_cli_output_prefix_is_a_name(void **state) {
    const cli_ctx *c = *state;
    assert_int_equal(run(c, "-s output.prefix=../../etc/x --summary"), 1);
    char *e = slurp(c, "err.txt");
    assert_has(e, "[output] prefix = \"../../etc/x\": must be a file-name prefix");
    free(e);
    assert_int_equal(run(c, "-s output.prefix=run_a.v2 --summary"), 0);
}

static void test_cli_summary_and_dry_run(void **state) {
    cli_ctx *c = *state;
    assert_int_equal(run(c, "--summary"), 0);
    char *out = slurp(c, "out.txt");
    assert_has(out, "cdem-c model summary");
    assert_has(out, "283, numbered 0..282");
    assert_null(strstr(out, "dry run"));
    free(out);
    assert_int_equal(run(c, "--dry-run -q"), 0);
    out = slurp(c, "out.txt");
    assert_has(out, "end of equilibration:        increment 56");
    assert_has(out, "dry run: nothing simulated");
    free(out);
    char args[1200];
    snprintf(args, sizeof args, "'%s/crlf.ini' --summary",
             getenv("CDEM_TEST_DATA") ? getenv("CDEM_TEST_DATA") : "tests/data");
    assert_int_equal(run(c, args), 0);
    out = slurp(c, "out.txt");
    assert_has(out, "15 x 3 units = 15000 x 3000 m");
    assert_has(out, "detachment");
    free(out);
}

static void test_cli_usage_errors_and_info(void **state) {
    cli_ctx *c = *state;
    assert_int_equal(run(c, "--bogus"), 2);
    char *err = slurp(c, "err.txt");
    assert_has(err, "cdem-run: unknown option --bogus\n");
    free(err);
    assert_int_equal(run(c, "--thread 2"), 2);
    err = slurp(c, "err.txt");
    assert_has(err, "cdem-run: unknown option --thread; did you mean --threads?");
    free(err);
    assert_int_equal(run(c, "a.ini b.ini"), 2);
    assert_int_equal(run(c, "--max-steps zero"), 2);
    assert_int_equal(run(c, "-o"), 2);
    assert_int_equal(run(c, "--help"), 0);
    char *out = slurp(c, "out.txt");
    assert_has(out, "usage: cdem-run [MODEL.ini|-]");
    free(out);
    assert_int_equal(run(c, "--version"), 0);
    out = slurp(c, "out.txt");
    assert_has(out, "cdem-run ");
    free(out);
    assert_int_equal(run(c, "/nonexistent/x.ini"), 1);
    err = slurp(c, "err.txt");
    assert_has(err, "cdem-run: /nonexistent/x.ini: cannot open parameter file");
    free(err);
}

/* "cdem-run -": the parameter file on standard input (issue 18 item 8); errors name it. */
static void test_cli_parameters_from_stdin(void **state) {
    cli_ctx *c = *state;
    write_file(c, "piped.ini", "[boundary]\nfault_dip = 45\n");
    char args[2400];
    snprintf(args, sizeof args, "- --print-defaults < '%s/piped.ini'", c->scratch.dir);
    assert_int_equal(run(c, args), 0);
    char *out = slurp(c, "out.txt");
    assert_has(out, "fault_dip = 45");
    free(out);
    write_file(c, "bad.ini", "[physics]\ngravity = 40\n");
    snprintf(args, sizeof args, "- --summary < '%s/bad.ini'", c->scratch.dir);
    assert_int_equal(run(c, args), 1);
    char *err = slurp(c, "err.txt");
    assert_has(err, "cdem-run: standard input:2: gravity = 40");
    free(err);
}

static void test_cli_params_markdown(void **state) {
    cli_ctx *c = *state;
    assert_int_equal(run(c, "--params-markdown"), 0);
    char *out = slurp(c, "out.txt");
    assert_has(out, "| section | key | type | default | unit | range / values | meaning |\n");
    assert_has(out, "| physics | `gravity` | real | `9.81` | m/s^2 | 0.5 to 25 |");
    free(out);
}

/* One element count and one increment count everywhere (issue 18: the summary said 2091 +
 * 405 = 2496 elements and 282 increments, the progress line and cdem-strain info 2523 and
 * 283): the summary's "elements ... in increment 0" is the element count of increment 0 in
 * the file, its "increments: K, numbered 0..L" is what info and the final log line say, and
 * the progress line counts the same elements. A planar fault run: its mode adds fault-ramp
 * elements after the packing. */
static void test_cli_counts_agree(void **state) {
    cli_ctx *c = *state;
    char args[2400];
    snprintf(args, sizeof args,
             "-s assembly.height=2.5 -s time.equilibration=100 -s time.runtime=130 "
             "-s time.display_interval=10 -o '%s/counts.h5'",
             c->scratch.dir);
    assert_int_equal(run(c, args), 0);
    char *out = slurp(c, "out.txt"), *err = slurp(c, "err.txt");
    long elements = -1, free_el = -1, boundary = -1;
    int k = -1, last = -1, equil = -1;
    const char *at = strstr(out, "  elements:");
    assert_non_null(at);
    assert_int_equal(sscanf(at, "  elements: %ld in increment 0", &elements), 1);
    assert_int_equal(sscanf(strstr(out, "  free elements:"), "  free elements: %ld", &free_el), 1);
    assert_int_equal(sscanf(strstr(out, "  wall and fault elements:"),
                            "  wall and fault elements: %ld", &boundary),
                     1);
    assert_int_equal(elements, free_el + boundary);
    assert_int_equal(
        sscanf(strstr(out, "  increments:"), "  increments: %d, numbered 0..%d", &k, &last), 2);
    assert_int_equal(k, last + 1);
    assert_int_equal(sscanf(strstr(out, "  end of equilibration:"),
                            "  end of equilibration: increment %d", &equil),
                     1);
    /* the progress lines of equilibration (nothing has escaped yet) */
    char want[256];
    snprintf(want, sizeof want, " (0..%d), net displacement 0.0 m, %ld elements", last, elements);
    assert_has(err, want);
    snprintf(want, sizeof want, "; %d increments, numbered 0..%d;", k, last);
    assert_has(err, want);
    free(err);
    free(out);
    /* cdem-strain info on the file */
    char cmd[4400];
    snprintf(cmd, sizeof cmd, "'%.*scdem-strain' info '%s/counts.h5' > '%s/info.txt'",
             (int)(strrchr(c->bin, '/') - c->bin + 1), c->bin, c->scratch.dir, c->scratch.dir);
    assert_int_equal(system(cmd), 0);
    char *info = slurp(c, "info.txt");
    snprintf(want, sizeof want,
             "increments: %d, numbered 0..%d (end of equilibration: increment %d)", k, last, equil);
    assert_has(info, want);
    long n0 = -1;
    const char *row = strstr(info, "\n        0 ");
    assert_non_null(row);
    char phase[32];
    long long step;
    double time, net;
    assert_int_equal(sscanf(row, " %*d %lld %lf %31s %lf %ld", &step, &time, phase, &net, &n0), 5);
    assert_int_equal(n0, elements);
    free(info);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_cli_counts_agree, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_print_defaults_round_trip, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_override_visible_in_print_defaults, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(test_cli_bad_key_in_file, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_bad_override_and_rules, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_summary_and_dry_run, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_usage_errors_and_info, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_params_markdown, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_summary_checks_the_fault_file, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_output_prefix_is_a_name, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_any_size, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_warns_when_still_settling, setup, teardown),
        cmocka_unit_test_setup_teardown(test_cli_parameters_from_stdin, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
