/* The Makefile's promises (issue 20, item 8), checked on `make -n -B` (the commands make
 * would run; nothing is compiled): a user's CFLAGS are appended to the project's flags,
 * never replace them; each layer compiles with the include paths of the layers it may use
 * (common: itself; solver and analysis: common and themselves; inside the solver, base/ <
 * contact/ < step/ < packing/ < run/ with modes/ on base/ alone; inside the analysis,
 * measure/ < input/, export/ < cli/ and draw/ < cli/); cdem-strain links no
 * solver code. Runs make from the repository root into a scratch BUILD. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The dry-run command line make prints for TARGET (with EXTRA make arguments) in OUT. */
static void dry_run(const char *target, const char *extra, char *out, size_t cap) {
    /* MAKEFLAGS of an enclosing make (its jobserver) must not leak into this one */
    char cmd[1024];
    snprintf(cmd, sizeof cmd,
             "env -u MAKEFLAGS -u MAKELEVEL make -n -B BUILD=dryrun-build %s "
             "dryrun-build/%s 2>&1",
             extra, target);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t n = fread(out, 1, cap - 1, p);
    out[n] = '\0';
    assert_int_equal(pclose(p), 0);
}

/* The line of OUT that compiles or links WHAT (a path in the command). */
static const char *line_with(const char *out, const char *what, char *line, size_t cap) {
    const char *hit = strstr(out, what);
    if (!hit)
        fail_msg("no command mentions %s in:\n%s", what, out);
    const char *start = hit;
    while (start > out && start[-1] != '\n')
        start--;
    const char *end = strchr(hit, '\n');
    size_t len = end ? (size_t)(end - start) : strlen(start);
    assert_true(len < cap);
    memcpy(line, start, len);
    line[len] = '\0';
    return line;
}

/* LINE = the command make would run for TARGET (with EXTRA make arguments) that mentions
 * WHAT. */
static void command_for(const char *target, const char *extra, const char *what, char *line,
                        size_t cap) {
    static char out[1 << 17];
    dry_run(target, extra, out, sizeof out);
    line_with(out, what, line, cap);
}

static int has_word(const char *line, const char *word) {
    size_t n = strlen(word);
    for (const char *p = strstr(line, word); p; p = strstr(p + 1, word))
        if ((p == line || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0'))
            return 1;
    return 0;
}

static void test_build_user_cflags_are_appended(void **state) {
    (void)state;
    char line[4096];
    command_for("common/state.o", "CFLAGS=-O1", "common/state.c", line, sizeof line);
    const char *kept[] = {"-std=c17", "-Werror", "-fopenmp", "-O1", "-Icommon"};
    for (size_t i = 0; i < sizeof kept / sizeof kept[0]; i++)
        if (!has_word(line, kept[i]))
            fail_msg("make CFLAGS=-O1 lost %s: %s", kept[i], line);
    /* the user's -O1 comes after the project's -O2, so it is the one that counts */
    assert_true(strstr(line, "-O1") > strstr(line, "-O2"));
}

static void test_build_layer_include_paths(void **state) {
    (void)state;
    static const struct {
        const char *object, *source;
        const char *allowed[3], *forbidden[5];
    } layers[] = {
        {"common/state.o", "common/state.c", {"-Icommon"}, {"-Isolver", "-Ianalysis"}},
        /* the solver's layers: base/ < contact/ < step/ < process/ < salt/ < packing/ < run/, and
         * modes/ sees base/ only (step/ and above see it) */
        {"solver/base/model.o",
         "solver/base/model.c",
         {"-Icommon", "-Isolver/base"},
         {"-Ianalysis", "-Isolver/contact", "-Isolver/modes", "-Isolver/run"}},
        {"solver/contact/contact.o",
         "solver/contact/contact.c",
         {"-Icommon", "-Isolver/base", "-Isolver/contact"},
         {"-Ianalysis", "-Isolver/modes", "-Isolver/step", "-Isolver/run"}},
        {"solver/modes/bc_registry.o",
         "solver/modes/bc_registry.c",
         {"-Icommon", "-Isolver/base", "-Isolver/modes"},
         {"-Ianalysis", "-Isolver/contact", "-Isolver/step", "-Isolver/run"}},
        {"solver/step/integrate.o",
         "solver/step/integrate.c",
         {"-Isolver/contact", "-Isolver/modes", "-Isolver/step"},
         {"-Ianalysis", "-Isolver/process", "-Isolver/salt", "-Isolver/packing", "-Isolver/run"}},
        /* the processes (process.h): their interface and registry see the stepper, a
         * process's folder sees them and the stepper, nothing above */
        {"solver/process/process_registry.o",
         "solver/process/process_registry.c",
         {"-Isolver/step", "-Isolver/process"},
         {"-Ianalysis", "-Isolver/salt", "-Isolver/packing", "-Isolver/run"}},
        {"solver/salt/salt_process.o",
         "solver/salt/salt_process.c",
         {"-Isolver/step", "-Isolver/process", "-Isolver/salt"},
         {"-Ianalysis", "-Isolver/packing", "-Isolver/run"}},
        {"solver/packing/sediment.o",
         "solver/packing/sediment.c",
         {"-Isolver/step", "-Isolver/packing"},
         {"-Ianalysis", "-Isolver/run"}},
        {"solver/run/run.o",
         "solver/run/run.c",
         {"-Icommon", "-Isolver/packing", "-Isolver/run"},
         {"-Ianalysis"}},
        /* the analysis's own layers (Makefile): measure/ sees none of the others, draw/
         * only itself, input/ and export/ the measures, cli/ everything of the analysis */
        {"analysis/measure/strain.o",
         "analysis/measure/strain.c",
         {"-Icommon", "-Ianalysis", "-Ianalysis/measure"},
         {"-Isolver", "-Ianalysis/input", "-Ianalysis/draw", "-Ianalysis/cli"}},
        {"analysis/draw/render.o",
         "analysis/draw/render.c",
         {"-Icommon", "-Ianalysis", "-Ianalysis/draw"},
         {"-Isolver", "-Ianalysis/measure", "-Ianalysis/input", "-Ianalysis/cli"}},
        {"analysis/export/sspx.o",
         "analysis/export/sspx.c",
         {"-Icommon", "-Ianalysis/measure", "-Ianalysis/export"},
         {"-Isolver", "-Ianalysis/input", "-Ianalysis/draw", "-Ianalysis/cli"}},
        {"analysis/input/cdem2d.o",
         "analysis/input/cdem2d.c",
         {"-Icommon", "-Ianalysis/measure", "-Ianalysis/input"},
         {"-Isolver", "-Ianalysis/export", "-Ianalysis/draw", "-Ianalysis/cli"}},
        {"analysis/cli/main.o",
         "analysis/cli/main.c",
         {"-Ianalysis/measure", "-Ianalysis/draw"},
         {"-Isolver"}},
    };
    char line[4096];
    for (size_t i = 0; i < sizeof layers / sizeof layers[0]; i++) {
        command_for(layers[i].object, "", layers[i].source, line, sizeof line);
        for (size_t k = 0; k < 3; k++)
            if (layers[i].allowed[k] && !has_word(line, layers[i].allowed[k]))
                fail_msg("%s compiles without %s: %s", layers[i].source, layers[i].allowed[k],
                         line);
        for (size_t k = 0; k < 4; k++)
            if (layers[i].forbidden[k] && has_word(line, layers[i].forbidden[k]))
                fail_msg("%s compiles with %s: %s", layers[i].source, layers[i].forbidden[k], line);
    }
}

static void test_build_strain_links_no_solver(void **state) {
    (void)state;
    char line[8192];
    command_for("cdem-strain", "", "-o dryrun-build/cdem-strain", line, sizeof line);
    assert_non_null(strstr(line, "libcdemanalysis.a"));
    assert_non_null(strstr(line, "libcdem.a"));
    if (strstr(line, "libcdemsolver.a"))
        fail_msg("cdem-strain links the solver library: %s", line);
}

/* Runs CMD (stdout and stderr) into OUT; returns its exit status. */
static int run_cmd(const char *cmd, char *out, size_t cap) {
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t n = fread(out, 1, cap - 1, p);
    out[n] = '\0';
    return pclose(p);
}

/* Every target builds in parallel by default, one job per core (issue 35: `make demo` built
 * serially and took 1.5 minutes on a fresh clone); a command-line -jN wins. */
static void test_build_parallel_by_default(void **unused) {
    (void)unused;
    static char out[4096];
    char want[64];
    const char *show = "printf 'show-makeflags:\\n\\t@echo $(MAKEFLAGS)\\n' | env -u MAKEFLAGS "
                       "-u MAKELEVEL make -s -f Makefile -f - show-makeflags %s 2>&1";
    char cmd[512];
    snprintf(cmd, sizeof cmd, show, "");
    assert_int_equal(run_cmd(cmd, out, sizeof out), 0);
    snprintf(want, sizeof want, " -j%ld", sysconf(_SC_NPROCESSORS_ONLN));
    if (!strstr(out, want))
        fail_msg("make's flags without -j are '%s': no %s", out, want);
    snprintf(cmd, sizeof cmd, show, "-j3");
    assert_int_equal(run_cmd(cmd, out, sizeof out), 0);
    assert_non_null(strstr(out, " -j3"));
}

/* `make -C examples help` lists the targets, a line each, and every folder (issue 35: there
 * was no help target). */
static void test_build_examples_help(void **unused) {
    (void)unused;
    static char out[8192];
    assert_int_equal(
        run_cmd("env -u MAKEFLAGS -u MAKELEVEL make -s -C examples help 2>&1", out, sizeof out), 0);
    const char *targets[] = {"  quick ", "  paper ",     "  clean ", "  tools ",
                             "  help ",  "quick-FOLDER", "QUICK=1"};
    for (size_t i = 0; i < sizeof targets / sizeof targets[0]; i++)
        if (!strstr(out, targets[i]))
            fail_msg("make -C examples help does not list '%s':\n%s", targets[i], out);
    FILE *ls = popen("ls examples/*/Makefile", "r");
    assert_non_null(ls);
    char line[512];
    while (fgets(line, sizeof line, ls)) {
        char folder[512];
        snprintf(folder, sizeof folder, "  %.*s ", (int)(strrchr(line, '/') - line - 9), line + 9);
        if (!strstr(out, folder))
            fail_msg("make -C examples help does not list the folder '%s':\n%s", folder, out);
    }
    pclose(ls);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_build_user_cflags_are_appended),
        cmocka_unit_test(test_build_layer_include_paths),
        cmocka_unit_test(test_build_strain_links_no_solver),
        cmocka_unit_test(test_build_parallel_by_default),
        cmocka_unit_test(test_build_examples_help),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
