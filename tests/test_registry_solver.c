/* The registration tables of cdem-run are complete (issue 20): every boundary mode and every
 * granular contact law that the parameter table offers (the words of boundary.mode and
 * material.granular_law, common/params.c) is
 *   - implemented: the mode's row of common/modes.def has its ops (cdem_bc_find succeeds, the
 *     required hooks are there, what it excludes are parameters (or the processes); every
 *     registered mode, the
 *     tests' fixtures too); the law is accepted by the contact kernel
 *     (cdem_contact_law_init) and gives a tangential force of its own in a sliding contact
 *     (every registered law: also the tests' fixtures, which no parameter file names); a law
 *     with coefficients or history slots of its own has no vector kernel (common/laws/law.h:
 *     the vector paths pass neither, so they evaluate it by its scalar kernel);
 *   - documented: docs/solver.md names it as `NAME` and docs/parameters.md lists it;
 *   - tested: a test source under tests/ (other than this file) names its enum constant
 *     (CDEM_MODE_<NAME> / CDEM_LAW_<NAME>, '-' as '_').
 * Adding a mode or a law without its registration, documentation or test fails here, naming
 * it. The checker itself is tested on a text with a name left out. Runs from the repository
 * root. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "contact.h"
#include "force.h"
#include "h5format.h"
#include "params.h"
#include "process.h"

#include <ctype.h>
#include <glob.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "law_fixtures.h"
#include "scratch.h"

/* The choice words of an enum parameter, and their count. */
static const char *const *choices_of(const char *section, const char *key, size_t *n) {
    const cdem_param_def *d = cdem_params_find(section, key);
    assert_non_null(d);
    assert_int_equal(d->type, CDEM_PTYPE_ENUM);
    *n = 0;
    while (d->choices[*n])
        ++*n;
    assert_true(*n > 0);
    return d->choices;
}

/* "planar-fault" with prefix "CDEM_MODE_" -> "CDEM_MODE_PLANAR_FAULT". */
static void constant_name(char *out, size_t cap, const char *prefix, const char *word) {
    size_t k = (size_t)snprintf(out, cap, "%s", prefix);
    for (const char *c = word; *c && k + 1 < cap; c++)
        out[k++] = *c == '-' ? '_' : (char)toupper((unsigned char)*c);
    out[k] = '\0';
}

/* Every test source except this one, concatenated. */
static char *test_sources(void) {
    glob_t g;
    assert_int_equal(glob("tests/test_*.c", 0, NULL, &g), 0);
    char *all = calloc(1, 1);
    size_t len = 0;
    for (size_t i = 0; i < g.gl_pathc; i++) {
        if (strstr(g.gl_pathv[i], "test_registry_solver.c"))
            continue;
        char *text = scratch_read_file(g.gl_pathv[i]);
        assert_non_null(text);
        size_t n = strlen(text);
        char *grown = realloc(all, len + n + 1);
        assert_non_null(grown);
        memcpy(grown + len, text, n + 1);
        all = grown;
        len += n;
        free(text);
    }
    globfree(&g);
    return all;
}

/* The first word of words[0..n) that `docs` does not quote as `WORD` or `tests` does not
 * name as PREFIX<WORD>; NULL when every word is there. */
static const char *first_missing(const char *const *words, size_t n, const char *prefix,
                                 const char *docs, const char *params_doc, const char *tests) {
    for (size_t i = 0; i < n; i++) {
        char quoted[96], constant[96];
        snprintf(quoted, sizeof quoted, "`%s`", words[i]);
        constant_name(constant, sizeof constant, prefix, words[i]);
        if (!strstr(docs, quoted) || !strstr(params_doc, words[i]) || !strstr(tests, constant))
            return words[i];
    }
    return NULL;
}

/* Fails naming the first of the parameter's words that the repository's docs or tests miss. */
static void assert_documented_and_tested(const char *param, const char *const *words, size_t n,
                                         const char *prefix) {
    char *docs = scratch_read_file("docs/solver.md");
    char *params = scratch_read_file("docs/parameters.md");
    char *tests = test_sources();
    assert_non_null(docs);
    assert_non_null(params);
    const char *miss = first_missing(words, n, prefix, docs, params, tests);
    if (miss)
        fail_msg("%s = %s: not quoted in docs/solver.md, not in docs/parameters.md or no test "
                 "names %s of it",
                 param, miss, prefix);
    free(docs);
    free(params);
    free(tests);
}

static void test_registry_boundary_modes(void **state) {
    (void)state;
    size_t n;
    const char *const *modes = choices_of("boundary", "mode", &n);
    assert_int_equal(n, CDEM_MODE_WORDS);
    /* every registered mode, the tests' fixtures too, has its ops with the required hooks;
     * what it excludes are parameters of the table; a mode that moves no boundary says what
     * happens instead (the summary's words) */
    for (int i = 0; i < CDEM_MODE_COUNT; i++) {
        const cdem_mode mode = (cdem_mode)i;
        const char *word = cdem_mode_name(mode);
        const cdem_bc_ops *ops = NULL;
        cdem_error err;
        if (cdem_bc_find(mode, &ops, &err) != CDEM_OK)
            fail_msg("boundary.mode = %s has no implementation: %s", word, err.msg);
        assert_non_null(ops);
        if ((size_t)i < n)
            assert_string_equal(word, modes[i]);
        if (!ops->init || !ops->net_displacement || !ops->view || ops->state_size == 0 ||
            !(ops->apply || (ops->step_begin && ops->step_move)))
            fail_msg("boundary.mode = %s: a required hook of cdem_bc_ops is missing (bc.h)", word);
        for (size_t k = 0; ops->excludes && ops->excludes[k]; k++) {
            if (strcmp(ops->excludes[k], CDEM_EXCLUDES_PROCESSES) == 0)
                continue; /* the processes: their own rules refuse them */
            char section[32];
            const char *dot = strchr(ops->excludes[k], '.');
            assert_non_null(dot);
            snprintf(section, sizeof section, "%.*s", (int)(dot - ops->excludes[k]),
                     ops->excludes[k]);
            if (!cdem_params_find(section, dot + 1))
                fail_msg("boundary.mode = %s excludes %s, which is no parameter", word,
                         ops->excludes[k]);
        }
        cdem_params p;
        cdem_params_defaults(&p);
        p.mode = mode;
        cdem_model_mode mm = cdem_model_mode_default();
        if (ops->derive)
            ops->derive(&p, &mm);
        if (mm.moving_boundaries == 0 && !mm.still)
            fail_msg("boundary.mode = %s moves no boundary but does not say what happens", word);
        if (mm.input && !mm.input_what)
            fail_msg("boundary.mode = %s names an input file without saying what it is", word);
        /* its row's clock (what the analysis labels an increment with) is time exactly when it
         * moves no boundary, its display interval then being in seconds */
        if ((cdem_mode_clock_of(mode) == CDEM_CLOCK_TIME) != (mm.moving_boundaries == 0))
            fail_msg("boundary.mode = %s: its row's clock is %s but it moves %d boundaries", word,
                     cdem_mode_clock_of(mode) == CDEM_CLOCK_TIME ? "time" : "not time",
                     mm.moving_boundaries);
        assert_true(strcmp(cdem_mode_description(mode), "?") != 0);
    }
    assert_documented_and_tested("boundary.mode", modes, n, "CDEM_MODE_");
}

static void test_registry_contact_laws(void **state) {
    (void)state;
    size_t n;
    const char *const *laws = choices_of("material", "granular_law", &n);
    assert_int_equal(n, CDEM_LAW_WORDS);
    /* every registered law, the tests' fixtures too, is accepted by the contact kernel, has
     * its word and its description, and is a law of its own: a cohesive contact pushed past
     * its strength transmits a different tangential force under each law */
    double force[CDEM_LAW_COUNT];
    for (int i = 0; i < CDEM_LAW_COUNT; i++) {
        const cdem_granular_law law = (cdem_granular_law)i;
        if ((size_t)i < n)
            assert_string_equal(cdem_law_name(law), laws[i]);
        assert_true(strcmp(cdem_law_description(law), "?") != 0);
        force[i] = law_fx_sliding_force(law);
        /* a force of the law's sign: every law has a shear strength */
        assert_true(isfinite(force[i]) && force[i] > 0.0);
        for (int j = 0; j < i; j++)
            if (force[j] == force[i])
                fail_msg("laws %s and %s give the same sliding force %g", cdem_law_name(j),
                         cdem_law_name(law), force[i]);
        cdem_params pl;
        cdem_params_defaults(&pl);
        pl.granular_law = law;
        cdem_contact_law cl;
        cdem_error err;
        assert_int_equal(cdem_contact_law_init(&cl, &pl, 1e9, 1e9, &err), CDEM_OK);
        if ((cl.coefficient_count > 0 || cl.slot_count > 0) && cdem_force_law_vectorised(law))
            fail_msg("law %s has %d coefficients and %d history slots of its own and an AVX2 "
                     "kernel, which would get neither (law.h)",
                     cdem_law_name(law), cl.coefficient_count, cl.slot_count);
    }
    /* a value that is no law is refused, naming the laws */
    cdem_params p;
    cdem_params_defaults(&p);
    p.granular_law = CDEM_LAW_COUNT;
    cdem_contact_law cl;
    cdem_error err;
    assert_int_equal(cdem_contact_law_init(&cl, &p, 1e9, 1e9, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "must be normal-cohesion, coulomb or spring-cohesion"));
    assert_documented_and_tested("material.granular_law", laws, n, "CDEM_LAW_");
}

/* Every registered process (common/processes.def) has its required hook and a context; the
 * flag its elements carry is one of CDEM_FLAGS_PROCESS (state.h), so that the pair list
 * leaves their pairs to it; each of the processes' series columns (CDEM_PROCESS_SERIES) is a
 * member of the sample the writer takes, with bounds, and docs/format.md quotes it. */
static void test_registry_processes(void **state) {
    (void)state;
    const cdem_process_ops *const all[] = {
#define CDEM_PROCESS(ID, id, word) cdem_process_##id,
#define CDEM_TEST_PROCESS          CDEM_PROCESS
#include "processes.def"
#undef CDEM_PROCESS
#undef CDEM_TEST_PROCESS
    };
    for (size_t k = 0; k < sizeof all / sizeof all[0]; k++) {
        assert_non_null(all[k]->word);
        if (!all[k]->active || all[k]->state_size == 0)
            fail_msg("process %s: active and state_size are required (process.h)", all[k]->word);
        if (all[k]->flag & ~(uint32_t)CDEM_FLAGS_PROCESS)
            fail_msg("process %s: its flag 0x%x is not in CDEM_FLAGS_PROCESS (state.h)",
                     all[k]->word, (unsigned)all[k]->flag);
    }
    char *format = scratch_read_file("docs/format.md");
    assert_non_null(format);
    cdem_series_sample q;
    memset(&q, 0, sizeof q);
    cdem_series_processes_absent(&q);
    size_t n = 0;
#define CDEM_PROCESS_SERIES(name, unit, lo, hi, label)                                             \
    do {                                                                                           \
        n++;                                                                                       \
        assert_true(isnan(q.name) && (double)(lo) < (double)(hi) && *(unit) && *(label));          \
        if (!strstr(format, "| `" #name "` | float64 |"))                                          \
            fail_msg("series column %s: not in docs/format.md's table", #name);                    \
    } while (0);
#include "processes.def"
#undef CDEM_PROCESS_SERIES
    assert_int_equal(n, CDEM_PROCESS_SERIES_COUNT);
    free(format);
}

/* The checker finds a word left out of the docs, of the parameter page or of the tests. */
static void test_registry_checker_finds_omissions(void **state) {
    (void)state;
    static const char *const words[] = {"planar-fault", "new-mode", NULL};
    const char *docs = "`planar-fault` and `new-mode`", *params = "planar-fault, new-mode";
    const char *tests = "CDEM_MODE_PLANAR_FAULT CDEM_MODE_NEW_MODE";
    assert_null(first_missing(words, 2, "CDEM_MODE_", docs, params, tests));
    assert_string_equal(first_missing(words, 2, "CDEM_MODE_", "`planar-fault`", params, tests),
                        "new-mode");
    assert_string_equal(first_missing(words, 2, "CDEM_MODE_", docs, "planar-fault", tests),
                        "new-mode");
    assert_string_equal(first_missing(words, 2, "CDEM_MODE_", docs, params, "CDEM_MODE_NEW_MODE"),
                        "planar-fault");
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_registry_boundary_modes),
        cmocka_unit_test(test_registry_contact_laws),
        cmocka_unit_test(test_registry_processes),
        cmocka_unit_test(test_registry_checker_finds_omissions),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
