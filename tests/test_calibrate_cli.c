/* test_calibrate_cli: `cdem-strain calibrate` ($CDEM_BUILD/cdem-strain, with the cdem-run next
 * to it) on biaxial tests cut to a second each (100 s equilibration, 250 s runtime, 0 and
 * 20 MPa): the whole loop found in one series with its fresh-seed check, [material] block,
 * report and picture; a second invocation that runs nothing (finished runs are read); a
 * damaged run file run again; a work folder of another model refused; a target out of reach
 * refused with the range found; the unconfined strength as the target; runs that fail named with
 * their log; a Slurm job array through examples/slurm/sweep.sh under a stand-in sbatch; usage
 * errors. The search itself is test_calib.c; the loop at a larger size and its resumption after a
 * kill are in tests/validate/run_validate.sh. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "scratch.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static scratch_dir g_dir;
static char g_exe[2100], g_model[2100], g_root[1024];

/* The short biaxial tests of every command here. */
#define SHORT "-s time.equilibration=100 -s time.runtime=250 --pressures 0,20 --seeds 1 --jobs 2"

/* Runs cmd (2>&1) in the scratch folder; its exit status, its output (truncated) in out. */
static int run(const char *cmd, char *out, size_t n) {
    char full[8192];
    snprintf(full, sizeof full, "cd '%s' && %s 2>&1", g_dir.dir, cmd);
    FILE *p = popen(full, "r");
    assert_non_null(p);
    size_t got = fread(out, 1, n - 1, p);
    out[got] = '\0';
    while (fread(full, 1, sizeof full, p) > 0) {
    }
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int exists(const char *dir, const char *name) {
    char path[2200];
    snprintf(path, sizeof path, "%s/%s/%s", g_dir.dir, dir, name);
    struct stat st;
    return stat(path, &st) == 0;
}

static int setup(void **state) {
    (void)state;
    if (scratch_dir_make(&g_dir, "calibrate_cli") != 0)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    if (!getcwd(g_root, sizeof g_root))
        return -1;
    if (b && b[0] == '/')
        snprintf(g_exe, sizeof g_exe, "%s/cdem-strain", b);
    else
        snprintf(g_exe, sizeof g_exe, "%s/%s/cdem-strain", g_root, b ? b : "build");
    snprintf(g_model, sizeof g_model, "%s/examples/calibration/biaxial.ini", g_root);
    return 0;
}

static int teardown(void **state) {
    (void)state;
    return scratch_dir_remove(&g_dir);
}

static void test_calibrate_finds_checks_and_resumes(void **state) {
    (void)state;
    static char out[65536];
    char cmd[8192];
    /* a friction angle the model's own material meets within a wide tolerance */
    snprintf(cmd, sizeof cmd, "'%s' calibrate '%s' --phi 25 --phi-tol 25 " SHORT " --work w1",
             g_exe, g_model);
    int rc = run(cmd, out, sizeof out);
    if (rc != 0)
        print_error("%s\n", out);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(out, "series 1: mu = 0.25, C0 = 5e+09 N: phi = "));
    assert_non_null(strstr(out, "(2 runs, all run now)"));
    assert_non_null(strstr(out, "found in 1 series"));
    assert_non_null(strstr(out, "fresh-seed check: seeds 2..2"));
    assert_non_null(strstr(out, "fresh-seed check: within the tolerances"));
    assert_non_null(strstr(out, "[material]\n"));
    assert_non_null(strstr(out, "element_friction = 0.25\nelement_cohesion = 5e+09\n"));
    assert_non_null(strstr(out, "| series | mu | C0 (N) |"));
    /* every run an ordinary run file kept in the work folder, with its log */
    assert_true(exists("w1", "biaxial_mu0.25_C0-5e09_seed1_0MPa.h5"));
    assert_true(exists("w1", "biaxial_mu0.25_C0-5e09_seed1_20MPa.h5"));
    assert_true(exists("w1", "biaxial_mu0.25_C0-5e09_seed2_20MPa.h5"));
    assert_true(exists("w1", "biaxial_mu0.25_C0-5e09_seed1_0MPa.log"));
    assert_true(exists("w1", "model.ini"));
    assert_true(exists("w1", "material.ini"));
    assert_true(exists("w1", "calibration.txt"));
    assert_true(exists("w1", "calibration.png"));

    /* again: every run is found finished by its stop reason; nothing runs */
    rc = run(cmd, out, sizeof out);
    assert_int_equal(rc, 0);
    assert_null(strstr(out, "  running "));
    assert_non_null(strstr(out, "(2 runs, none run now)"));

    /* a run file left unreadable (killed before its first write) is run again, alone */
    char path[2200];
    snprintf(path, sizeof path, "%s/w1/biaxial_mu0.25_C0-5e09_seed1_20MPa.h5", g_dir.dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("not yet a run file", f);
    fclose(f);
    rc = run(cmd, out, sizeof out);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(out, "  running biaxial_mu0.25_C0-5e09_seed1_20MPa\n"));
    assert_null(strstr(out, "  running biaxial_mu0.25_C0-5e09_seed1_0MPa"));
    assert_non_null(strstr(out, "(2 runs, 1 of them run now)"));
    assert_non_null(strstr(out, "| 2 runs, 1 of them run now |"));

    /* a child that dies before writing (killed at its start) is run again: one run, counted
     * once (issue 46, item 13d: "2 runs, 3 run now" counted every round's starts) */
    snprintf(path, sizeof path, "%s/w1/biaxial_mu0.25_C0-5e09_seed1_20MPa.h5", g_dir.dir);
    assert_int_equal(unlink(path), 0);
    char wrapper[2200], real[2200];
    snprintf(wrapper, sizeof wrapper, "%s/die-once.sh", g_dir.dir);
    snprintf(real, sizeof real, "%.*s/cdem-run", (int)(strrchr(g_exe, '/') - g_exe), g_exe);
    f = fopen(wrapper, "w");
    assert_non_null(f);
    fprintf(f,
            "#!/bin/sh\n[ -e \"$0.once\" ] || { touch \"$0.once\"; exit 1; }\nexec '%s' \"$@\"\n",
            real);
    fclose(f);
    assert_int_equal(chmod(wrapper, 0755), 0);
    static char cmd2[8192 + 2300];
    snprintf(cmd2, sizeof cmd2, "%s --cdem-run '%s'", cmd, wrapper);
    rc = run(cmd2, out, sizeof out);
    if (rc != 0)
        print_error("%s\n", out);
    assert_int_equal(rc, 0);
    const char *first = strstr(out, "  running biaxial_mu0.25_C0-5e09_seed1_20MPa\n");
    assert_non_null(first);
    assert_non_null(strstr(first + 1, "  running biaxial_mu0.25_C0-5e09_seed1_20MPa\n"));
    assert_non_null(strstr(out, "(2 runs, 1 of them run now)"));
    assert_null(strstr(out, "2 of them"));

    /* the folder of another model (other overrides) is refused, never mixed */
    snprintf(cmd, sizeof cmd,
             "'%s' calibrate '%s' --phi 25 --phi-tol 25 " SHORT
             " -s physics.deformation_damping=0.5 --work w1",
             g_exe, g_model);
    rc = run(cmd, out, sizeof out);
    assert_int_equal(rc, 1);
    assert_non_null(strstr(out, "was made for another model"));
}

static void test_calibrate_refuses_a_target_out_of_reach(void **state) {
    (void)state;
    static char out[65536];
    char cmd[8192];
    /* phi 70 deg with mu at most 0.3: refused once mu = 0.3 is measured */
    snprintf(cmd, sizeof cmd,
             "'%s' calibrate '%s' --phi 70 --mu-range 0.2:0.3 " SHORT " --check-seeds 0 "
             "--work w2",
             g_exe, g_model);
    int rc = run(cmd, out, sizeof out);
    assert_int_equal(rc, 1);
    assert_non_null(strstr(out, "refused: the target friction angle 70 deg is out of reach"));
    assert_non_null(strstr(out, "With C0 fixed at 5e+09, mu at its upper bound (0.3, series "));
    assert_non_null(strstr(out, "friction angle can go no higher here"));
    assert_non_null(strstr(out, "Reachable friction angle found (series with C0 fixed at "
                                "5e+09): "));
    assert_non_null(strstr(out, "cdem-strain calibrate: refused: the target friction angle 70 "
                                "deg is out of reach (reachable with C0 fixed at 5e+09: "));
    assert_non_null(strstr(out, "mu = 0.3, C0 = 5e+09 N"));
    assert_null(strstr(out, "[material]"));
    assert_true(exists("w2", "calibration.png")); /* the nearest series' picture */
}

static void test_calibrate_names_a_failed_run(void **state) {
    (void)state;
    static char out[65536];
    char cmd[8192];
    /* each value is valid, the two together are not: every run fails in cdem-run */
    snprintf(cmd, sizeof cmd,
             "'%s' calibrate '%s' --phi 30 --pressures 0,20 --seeds 1 --jobs 1 "
             "-s time.equilibration=300 -s time.runtime=250 --work w3",
             g_exe, g_model);
    int rc = run(cmd, out, sizeof out);
    assert_int_equal(rc, 1);
    assert_non_null(strstr(out, "did not complete (stop reason: no file written)"));
    assert_non_null(strstr(out, ".log"));
    assert_non_null(strstr(out, "equilibration"));
}

static void test_calibrate_through_slurm(void **state) {
    (void)state;
    static char out[65536];
    char cmd[8192], path[2200];
    /* a stand-in sbatch: runs the array's tasks one after another, as Slurm would */
    snprintf(path, sizeof path, "%s/bin", g_dir.dir);
    mkdir(path, 0755);
    snprintf(path, sizeof path, "%s/bin/sbatch", g_dir.dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("#!/bin/sh\n"
          "for a in \"$@\"; do case $a in --array=*) array=${a#--array=};;\n"
          "  --output=*) output=${a#--output=};; --wait) ;; *) script=$a;; esac; done\n"
          "i=${array%-*}; rc=0\n"
          "while [ \"$i\" -le \"${array#*-}\" ]; do\n"
          "  o=$(echo \"$output\" | sed \"s/%A/7/;s/%a/$i/\")\n"
          "  SLURM_ARRAY_TASK_ID=$i bash \"$script\" > \"$o\" 2>&1 || rc=1\n"
          "  i=$((i + 1)); done\n"
          "exit $rc\n",
          f);
    fclose(f);
    chmod(path, 0755);
    snprintf(cmd, sizeof cmd,
             "PATH='%s/bin':$PATH '%s' calibrate '%s' --phi 25 --phi-tol 25 " SHORT
             " --slurm '%s/examples/slurm/sweep.sh' --work w4",
             g_dir.dir, g_exe, g_model, g_root);
    int rc = run(cmd, out, sizeof out);
    if (rc != 0)
        print_error("%s\n", out);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(out, "sbatch --wait --array=0-1 "));
    assert_non_null(strstr(out, "as a Slurm job array"));
    assert_non_null(strstr(out, "found in 1 series"));
    assert_true(exists("w4", "slurm-params-0.txt"));
    assert_true(exists("w4", "slurm-7_1.out"));
    assert_true(exists("w4", "biaxial_mu0.25_C0-5e09_seed1_20MPa.h5"));
    assert_true(exists("w4", "biaxial_mu0.25_C0-5e09_seed1_20MPa.log"));
    /* without sbatch the message says so */
    snprintf(cmd, sizeof cmd,
             "PATH=/nonexistent '%s' calibrate '%s' --phi 25 --phi-tol 25 " SHORT
             " --slurm '%s/examples/slurm/sweep.sh' --work w5",
             g_exe, g_model, g_root);
    rc = run(cmd, out, sizeof out);
    assert_int_equal(rc, 1);
    assert_non_null(strstr(out, "sbatch not found on PATH"));
}

static void test_calibrate_unconfined_strength(void **state) {
    (void)state;
    static char out[65536];
    char cmd[8192];
    /* the unconfined strength instead of C (the 0 MPa tests' peak), phi only reported */
    snprintf(cmd, sizeof cmd,
             "'%s' calibrate '%s' --ucs 5 --ucs-tol 50 " SHORT " --check-seeds 0 --work w6", g_exe,
             g_model);
    int rc = run(cmd, out, sizeof out);
    if (rc != 0)
        print_error("%s\n", out);
    assert_int_equal(rc, 0);
    assert_non_null(
        strstr(out, "targets: phi reported (mu = 0.25 fixed), unconfined = 5 +- 50 MPa"));
    assert_non_null(strstr(out, ", unconfined "));
    assert_non_null(strstr(out, "found in 1 series"));
    assert_null(strstr(out, "fresh-seed check"));
    assert_true(exists("w6", "material.ini"));
}

static void test_calibrate_usage_errors(void **state) {
    (void)state;
    static char out[16384];
    char cmd[8192];
    static const struct {
        const char *args, *says;
    } cases[] = {
        {"", "give the model"},
        {"MODEL", "give a target: --phi, --cohesion or --ucs"},
        {"MODEL --cohesion 4 --ucs 10", "give --cohesion or --ucs, not both"},
        {"MODEL --phi 34 --mu-range 1:0.5", "--mu-range 1:0.5: must be LO:HI"},
        {"MODEL --phi 34 --c0-range 0:1e9", "--c0-range 0:1e9: must be LO:HI (N) with 0 < LO"},
        {"MODEL --ucs 10 --pressures 5,10", "--ucs needs 0 among --pressures"},
        {"MODEL --phi 34 --pressures 5",
         "--pressures 5: one item only; give 2 to 12 different numbers >= 0 (MPa)"},
        {"MODEL --phi 95", "--phi 95: must be a number of degrees in 0..90"},
        {"MODEL --phi 34 --seeds 0", "--seeds 0: must be a whole number 1 to 8"},
        {"MODEL --phi 34 --margin 2", "--margin 2: must be a number in (0, 1]"},
        {"MODEL --phi 34 -s nonsense", "-s nonsense: must be section.key=value"},
        {"MODEL --phi 34 --bogus", "unknown option '--bogus'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char args[2300];
        const char *m = strstr(cases[i].args, "MODEL");
        if (m)
            snprintf(args, sizeof args, "'%s'%s", g_model, m + 5);
        else
            snprintf(args, sizeof args, "%s", cases[i].args);
        snprintf(cmd, sizeof cmd, "'%s' calibrate %s", g_exe, args);
        int rc = run(cmd, out, sizeof out);
        if (rc != 2 || !strstr(out, cases[i].says))
            print_error("%s\n-> %d: %s\n", cmd, rc, out);
        assert_int_equal(rc, 2);
        assert_non_null(strstr(out, cases[i].says));
    }
    /* not a biaxial model: refused, naming the key and what to give */
    snprintf(cmd, sizeof cmd, "'%s' calibrate '%s/examples/calibration/repose.ini' --phi 34", g_exe,
             g_root);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "boundary.mode = repose: calibrate runs biaxial tests"));
    /* a bad -s value: refused before anything runs, naming it */
    snprintf(cmd, sizeof cmd, "'%s' calibrate '%s' --phi 34 -s time.runtime=abc", g_exe, g_model);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "-s time.runtime=abc"));
    /* a --cdem-run that is not a program */
    snprintf(cmd, sizeof cmd, "'%s' calibrate '%s' --phi 34 --cdem-run /nonexistent", g_exe,
             g_model);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "--cdem-run /nonexistent: not an executable file"));
}

/* Every option is checked before the first run (issue 46, item 5): each value against the
 * range cdem-run's parameter table allows for the parameter it sets, empty list items, the
 * runs per series the envelope fit can take, the -s of a value calibrate sets itself and the
 * seeds the model's seed leads to. A stand-in cdem-run marks any run started: none is, and no
 * work folder is made. */
static void test_calibrate_checks_every_option_before_running(void **state) {
    (void)state;
    static char out[16384];
    char cmd[8192], standin[2200], marker[2200];
    snprintf(marker, sizeof marker, "%s/cdem-run-started", g_dir.dir);
    snprintf(standin, sizeof standin, "%s/standin-cdem-run", g_dir.dir);
    FILE *f = fopen(standin, "w");
    assert_non_null(f);
    fprintf(f, "#!/bin/sh\necho \"$@\" >> '%s'\nexit 1\n", marker);
    fclose(f);
    chmod(standin, 0755);
    static const struct {
        const char *args, *says;
    } cases[] = {
        {"--phi 34 --pressures 1e300,10",
         "--pressures 1e300,10: item 1, 1e+300 MPa, is outside the range cdem-run allows for "
         "boundary.confining_pressure: 0 to 1000 MPa"},
        {"--phi 34 --pressures 0,1001",
         "--pressures 0,1001: item 2, 1001 MPa, is outside the range cdem-run allows for "
         "boundary.confining_pressure: 0 to 1000 MPa"},
        {"--phi 34 --mu-range 0:1e300",
         "--mu-range 0:1e300: HI 1e+300 is outside the range cdem-run allows for "
         "material.element_friction: 0 to 10"},
        {"--cohesion 5 --c0-range 1e20:1e30",
         "--c0-range 1e20:1e30: LO 1e+20 is outside the range cdem-run allows for "
         "material.element_cohesion: 0 to 1e+15 N"},
        {"--phi 34 --pressures 0,,10", "--pressures 0,,10: item 2 is empty; give 2 to 12"},
        {"--phi 34 --pressures ,5,10", "--pressures ,5,10: item 1 is empty; give 2 to 12"},
        {"--phi 34 --pressures 0,5,", "--pressures 0,5,: item 3 is empty; give 2 to 12"},
        {"--phi 34 --pressures 0,5,x", "--pressures 0,5,x: item 3, 'x', is not a number"},
        {"--phi 34 --pressures 0,5,0", "--pressures 0,5,0: item 3, 0 MPa, repeats item 1"},
        {"--phi 34 --seeds 8 --pressures 0,1,2,3,4,5,6,7,8,9,10,11",
         "--seeds 8 with 12 --pressures: 96 runs per series, at most 64"},
        {"--phi 34 --check-seeds 6 --pressures 0,1,2,3,4,5,6,7,8,9,10,11",
         "--check-seeds 6 with 12 --pressures: 72 runs per series, at most 64"},
        {"--phi 34 -s material.element_friction=0.3",
         "-s material.element_friction=0.3: calibrate sets material.element_friction in every "
         "run itself (it searches it for --phi; bound it with --mu-range)"},
        {"--ucs 5 -s material.element_cohesion=1e9",
         "-s material.element_cohesion=1e9: calibrate sets material.element_cohesion in every "
         "run itself"},
        {"--phi 34 -s boundary.confining_pressure=5e6",
         "-s boundary.confining_pressure=5e6: calibrate sets boundary.confining_pressure"},
        {"--phi 34 -s assembly.seed=4", "-s assembly.seed=4: calibrate sets assembly.seed"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        snprintf(cmd, sizeof cmd, "'%s' calibrate '%s' %s --cdem-run '%s' --work w-opt", g_exe,
                 g_model, cases[i].args, standin);
        int rc = run(cmd, out, sizeof out);
        if (rc != 2 || !strstr(out, cases[i].says))
            print_error("%s\n-> %d: %s\n", cmd, rc, out);
        assert_int_equal(rc, 2);
        assert_non_null(strstr(out, cases[i].says));
        assert_int_equal(access(marker, F_OK), -1); /* no run started */
        assert_false(exists("w-opt", ""));          /* no work folder made */
    }
    /* the search's and the check's seeds S..S+N+M-1 from the model's seed S */
    char model[2200], line[512];
    snprintf(model, sizeof model, "%s/seed-max.ini", g_dir.dir);
    FILE *in = fopen(g_model, "r"), *mf = fopen(model, "w");
    assert_non_null(in);
    assert_non_null(mf);
    while (fgets(line, sizeof line, in)) {
        fputs(line, mf);
        if (!strncmp(line, "[assembly]", 10))
            fputs("seed = 2147483647\n", mf);
    }
    fclose(in);
    fclose(mf);
    snprintf(cmd, sizeof cmd, "'%s' calibrate '%s' --phi 34 --cdem-run '%s' --work w-opt", g_exe,
             model, standin);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "assembly.seed = 2147483647 with --seeds 2 and --check-seeds 1: "
                                "the runs would use seeds 2147483647..2147483649, beyond the "
                                "range cdem-run allows for assembly.seed (0 to 2147483647)"));
    assert_int_equal(access(marker, F_OK), -1);
    assert_false(exists("w-opt", ""));
    /* a value calibrate does not search may be set by -s: the model's, for every run */
    snprintf(cmd, sizeof cmd,
             "'%s' calibrate '%s' --cohesion 5 -s material.element_friction=0.3 --cdem-run "
             "/nonexistent --work w-opt",
             g_exe, g_model);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "--cdem-run /nonexistent: not an executable file"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_calibrate_finds_checks_and_resumes),
        cmocka_unit_test(test_calibrate_refuses_a_target_out_of_reach),
        cmocka_unit_test(test_calibrate_names_a_failed_run),
        cmocka_unit_test(test_calibrate_through_slurm),
        cmocka_unit_test(test_calibrate_unconfined_strength),
        cmocka_unit_test(test_calibrate_usage_errors),
        cmocka_unit_test(test_calibrate_checks_every_option_before_running),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
