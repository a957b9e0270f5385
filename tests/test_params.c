/* Tests of common/params.c: the table, the INI parser, overrides, validation (with the
 * solver's rules, cdem_run_validate, as cdem-run checks a parameter set), the writers
 * and the docs/parameters.md table. Range tests are driven by the table itself, so a new
 * parameter is covered without editing this file. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "model.h"
#include "params.h"
#include "run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *data_dir(void) {
    const char *d = getenv("CDEM_TEST_DATA");
    return d && d[0] ? d : "tests/data";
}

/* Parses text over defaults; returns the status and leaves the message in err. */
static cdem_status parse(cdem_params *p, const char *text, cdem_error *err) {
    cdem_params_defaults(p);
    cdem_error_clear(err);
    return cdem_params_parse_text(p, text, "model.ini", err);
}

static double field_as_double(const cdem_params *p, const cdem_param_def *d) {
    const char *f = (const char *)p + d->offset;
    double v = 0;
    int i;
    long l;
    switch (d->type) {
    case CDEM_PTYPE_DOUBLE:
        memcpy(&v, f, sizeof v);
        return v;
    case CDEM_PTYPE_LONG:
        memcpy(&l, f, sizeof l);
        return (double)l;
    case CDEM_PTYPE_STRING:
        return 0;
    default:
        memcpy(&i, f, sizeof i);
        return i;
    }
}

/* 1 when every parameter of a and b is identical (doubles bit for bit). */
static int params_equal(const cdem_params *a, const cdem_params *b) {
    size_t n;
    const cdem_param_def *t = cdem_params_table(&n);
    for (size_t i = 0; i < n; i++) {
        const char *fa = (const char *)a + t[i].offset, *fb = (const char *)b + t[i].offset;
        if (t[i].type == CDEM_PTYPE_STRING) {
            if (strcmp(fa, fb) != 0)
                return 0;
        } else if (t[i].type == CDEM_PTYPE_DOUBLE) {
            if (memcmp(fa, fb, sizeof(double)) != 0)
                return 0;
        } else if (t[i].type == CDEM_PTYPE_LONG) {
            if (memcmp(fa, fb, sizeof(long)) != 0)
                return 0;
        } else if (memcmp(fa, fb, sizeof(int)) != 0) {
            return 0;
        }
    }
    return 1;
}

static void assert_msg_has(const cdem_error *err, const char *needle) {
    if (!strstr(err->msg, needle)) {
        print_error("message \"%s\" lacks \"%s\"\n", err->msg, needle);
        fail();
    }
}

static int is_numeric(const cdem_param_def *d) {
    return d->type == CDEM_PTYPE_DOUBLE || d->type == CDEM_PTYPE_INT || d->type == CDEM_PTYPE_LONG;
}

/* Sets one numeric value given as a double, through the parser. */
static cdem_status set_numeric(cdem_params *p, const cdem_param_def *d, double v, char *text,
                               size_t n, cdem_error *err) {
    if (d->type == CDEM_PTYPE_DOUBLE)
        snprintf(text, n, "[%s]\n%s = %.17g\n", d->section, d->key, v);
    else
        snprintf(text, n, "[%s]\n%s = %.0f\n", d->section, d->key, v);
    return parse(p, text, err);
}

/* ---------- table ---------- */

static void test_params_table_complete_and_defaults_parse(void **state) {
    (void)state;
    size_t n = 0;
    const cdem_param_def *t = cdem_params_table(&n);
    assert_true(n >= 50);
    for (size_t i = 0; i < n; i++) {
        assert_non_null(t[i].section);
        assert_non_null(t[i].key);
        assert_non_null(t[i].help);
        assert_true(strlen(t[i].help) > 5);
        assert_ptr_equal(cdem_params_find(t[i].section, t[i].key), &t[i]);
        for (size_t j = 0; j < i; j++) /* keys are unique over all sections */
            assert_string_not_equal(t[i].key, t[j].key);
        if (t[i].type == CDEM_PTYPE_ENUM)
            assert_non_null(t[i].choices);
    }
    assert_null(cdem_params_find("physics", "nope"));
    assert_null(cdem_params_find(NULL, "gravity"));
}

static void test_params_defaults_are_the_paper_model(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    assert_true(p.width == 10.0 && p.height == 5.0 && p.unit_scaling == 1000.0);
    assert_true(p.runtime == 2000.0 && p.equilibration == 400.0 && p.display_interval == 5.0);
    assert_true(p.gravity == 9.81 && p.density == 2500.0);
    assert_int_equal(p.material, CDEM_MATERIAL_GRANULAR);
    assert_true(p.element.friction == 0.25 && p.element.cohesion == 5e9);
    assert_int_equal(p.first_slip, 1);
    assert_int_equal(p.mode, CDEM_MODE_PLANAR_FAULT);
    assert_int_equal(p.fault_sense, CDEM_SENSE_NORMAL);
    assert_true(p.fault_location == 0.5 && p.fault_dip == 30.0);
    assert_int_equal(p.seed, 1);
    assert_int_equal(p.series_interval, 100);
    assert_string_equal(p.prefix, "cdem");
    assert_true(p.total_strain_max == 2.0);
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_params_validate(&p, NULL, &err), CDEM_OK);
}

/* ---------- every range boundary of every numeric parameter ---------- */

static void test_params_every_numeric_range_boundary(void **state) {
    (void)state;
    size_t n;
    const cdem_param_def *t = cdem_params_table(&n);
    cdem_params p;
    cdem_error err;
    char text[256], expect[128];
    int checked = 0;
    for (size_t i = 0; i < n; i++) {
        const cdem_param_def *d = &t[i];
        if (!is_numeric(d))
            continue;
        int integer = d->type != CDEM_PTYPE_DOUBLE;
        double step_lo = integer ? 1.0 : fmax(fabs(d->min) * 1e-6, 1e-9);
        double step_hi = integer ? 1.0 : fmax(fabs(d->max) * 1e-6, 1e-9);
        snprintf(expect, sizeof expect, "model.ini:2: %s = ", d->key);
        /* lower bound: the bound itself (accepted unless exclusive), then just outside */
        double inside_lo = d->min_exclusive ? d->min + step_lo : d->min;
        double outside_lo = d->min_exclusive ? d->min : d->min - step_lo;
        assert_int_equal(set_numeric(&p, d, inside_lo, text, sizeof text, &err), CDEM_OK);
        assert_true(field_as_double(&p, d) == inside_lo);
        assert_int_equal(set_numeric(&p, d, outside_lo, text, sizeof text, &err), CDEM_ERR_RANGE);
        assert_msg_has(&err, expect);
        assert_msg_has(&err, d->min_exclusive ? ": must be > " : ": must be ");
        if (d->unit[0])
            assert_msg_has(&err, d->unit);
        /* upper bound */
        double inside_hi = d->max_exclusive ? d->max - step_hi : d->max;
        double outside_hi = d->max_exclusive ? d->max : d->max + step_hi;
        assert_int_equal(set_numeric(&p, d, inside_hi, text, sizeof text, &err), CDEM_OK);
        assert_true(field_as_double(&p, d) == inside_hi);
        assert_int_equal(set_numeric(&p, d, outside_hi, text, sizeof text, &err), CDEM_ERR_RANGE);
        assert_msg_has(&err, expect);
        assert_msg_has(&err,
                       d->max_exclusive ? " and < " : (d->min_exclusive ? " and <= " : " and "));
        checked++;
    }
    assert_true(checked >= 34); /* 30 real, 3 int, 1 long parameters today */
}

static void test_params_range_message_shape(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    assert_int_equal(parse(&p, "# c\n\n[physics]\n\n\n\n\n\n\n\n\ngravity = 40\n", &err),
                     CDEM_ERR_RANGE);
    assert_string_equal(err.msg, "model.ini:12: gravity = 40: must be between 0.5 and 25 m/s^2");
    assert_int_equal(parse(&p, "[boundary]\nfault_dip = 0\n", &err), CDEM_ERR_RANGE);
    assert_string_equal(err.msg, "model.ini:2: fault_dip = 0: must be > 0 and <= 90 degrees");
    assert_int_equal(parse(&p, "[boundary]\nfault_location = 1\n", &err), CDEM_ERR_RANGE);
    assert_string_equal(err.msg, "model.ini:2: fault_location = 1: must be > 0 and < 1");
    assert_int_equal(parse(&p, "[boundary]\nfault_dip = 90\n", &err), CDEM_OK);
    assert_true(p.fault_dip == 90.0);
}

static void test_params_non_numeric_values(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    assert_int_equal(parse(&p, "[time]\nruntime = abc\n", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "model.ini:2: runtime = abc: not a number");
    assert_int_equal(parse(&p, "[time]\nruntime = 12x\n", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "runtime = 12x: not a number");
    assert_int_equal(parse(&p, "[time]\nruntime = nan\n", &err), CDEM_ERR_PARSE);
    assert_int_equal(parse(&p, "[time]\nruntime = inf\n", &err), CDEM_ERR_PARSE);
    assert_int_equal(parse(&p, "[time]\nruntime =\n", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "missing value");
    assert_int_equal(parse(&p, "[assembly]\nwall_height_multiplier = 2.5\n", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "wall_height_multiplier = 2.5: not a whole number");
    assert_int_equal(parse(&p, "[assembly]\nseed = 99999999999999999999999\n", &err),
                     CDEM_ERR_RANGE);
    assert_int_equal(parse(&p, "[time]\nruntime = 1e3\n", &err), CDEM_OK);
    assert_true(p.runtime == 1000.0);
    /* strtod reads hexadecimal: "0x10" was taken as 16 (issue 19, item 8) */
    assert_int_equal(parse(&p, "[physics]\ngravity = 0x10\n", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "model.ini:2: gravity = 0x10: not a number");
    assert_int_equal(parse(&p, "[time]\nruntime = 0x1p10\n", &err), CDEM_ERR_PARSE);
    assert_int_equal(parse(&p, "[time]\nruntime = infinity\n", &err), CDEM_ERR_PARSE);
    assert_int_equal(parse(&p, "[time]\nruntime = 1e\n", &err), CDEM_ERR_PARSE);
    assert_int_equal(parse(&p, "[time]\nruntime = .5e3\n", &err), CDEM_OK);
    assert_true(p.runtime == 500.0);
    assert_int_equal(parse(&p, "[time]\nruntime = +2000.\n", &err), CDEM_OK);
    assert_true(p.runtime == 2000.0);
    assert_int_not_equal(cdem_params_override(&p, "physics.gravity=0x10", &err), CDEM_OK);
    assert_msg_has(&err, "gravity = 0x10: not a number");
}

/* ---------- enums and booleans ---------- */

static void test_params_every_enum_word_and_a_wrong_one(void **state) {
    (void)state;
    size_t n;
    const cdem_param_def *t = cdem_params_table(&n);
    cdem_params p;
    cdem_error err;
    char text[256];
    int enums = 0;
    for (size_t i = 0; i < n; i++) {
        const cdem_param_def *d = &t[i];
        if (d->type != CDEM_PTYPE_ENUM)
            continue;
        enums++;
        for (int w = 0; d->choices[w]; w++) {
            snprintf(text, sizeof text, "[%s]\n%s = %s\n", d->section, d->key, d->choices[w]);
            assert_int_equal(parse(&p, text, &err), CDEM_OK);
            assert_int_equal((int)field_as_double(&p, d), w);
        }
        snprintf(text, sizeof text, "[%s]\n%s = bogus-word\n", d->section, d->key);
        assert_int_equal(parse(&p, text, &err), CDEM_ERR_RANGE);
        assert_msg_has(&err, "bogus-word: must be one of ");
        for (int w = 0; d->choices[w]; w++)
            assert_msg_has(&err, d->choices[w]);
    }
    assert_int_equal(enums, 18);
    assert_int_equal(parse(&p, "[surface]\nsea_level_rise = very-high\n", &err), CDEM_OK);
    assert_int_equal(p.sea_level_rise, CDEM_SEA_VERY_HIGH);
    assert_string_equal(cdem_mode_name(CDEM_MODE_VERTICAL_FAULTS), "vertical-faults");
    assert_string_equal(cdem_mode_name((cdem_mode)99), "unknown");
}

static void test_params_boolean_spellings(void **state) {
    (void)state;
    static const char *const yes[] = {"true", "yes", "on", "1", "TRUE", "On"};
    static const char *const no[] = {"false", "no", "off", "0", "False", "OFF"};
    cdem_params p;
    cdem_error err;
    char text[128];
    for (size_t i = 0; i < 6; i++) {
        snprintf(text, sizeof text, "[physics]\ncalculate_stress = %s\n", yes[i]);
        assert_int_equal(parse(&p, text, &err), CDEM_OK);
        assert_int_equal(p.calculate_stress, 1);
        snprintf(text, sizeof text, "[material]\nfirst_slip = %s\n", no[i]);
        assert_int_equal(parse(&p, text, &err), CDEM_OK);
        assert_int_equal(p.first_slip, 0);
    }
    assert_int_equal(parse(&p, "[material]\nfirst_slip = maybe\n", &err), CDEM_ERR_RANGE);
    assert_string_equal(err.msg, "model.ini:2: first_slip = maybe: must be one of true, false, "
                                 "yes, no, on, off, 1, 0");
}

/* ---------- syntax ---------- */

static void test_params_unknown_key_suggests(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    assert_int_equal(parse(&p, "[assembly]\n\nwidht = 12\n", &err), CDEM_ERR_PARSE);
    assert_string_equal(err.msg,
                        "model.ini:3: [assembly] widht: unknown key; did you mean 'width'?");
    assert_int_equal(parse(&p, "[time]\ngravity = 9\n", &err), CDEM_ERR_PARSE);
    assert_string_equal(err.msg,
                        "model.ini:2: [time] gravity: unknown key; it belongs in [physics]");
    assert_int_equal(parse(&p, "[time]\ngravty = 9\n", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "did you mean 'gravity' (it belongs in [physics])?");
    assert_int_equal(parse(&p, "[time]\nzzzzzzzzzzzz = 9\n", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "unknown key; `cdem-run --print-defaults` lists every key");
}

static void test_params_unknown_section(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    assert_int_equal(parse(&p, "\n\n\n\n\n\n[asembly]\n", &err), CDEM_ERR_PARSE);
    assert_string_equal(err.msg,
                        "model.ini:7: unknown section [asembly]; did you mean [assembly]?");
    assert_int_equal(parse(&p, "[qqqqqqqqqq]\n", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "unknown section [qqqqqqqqqq]; sections are assembly, time, physics");
}

static void test_params_malformed_lines(void **state) {
    (void)state;
    static const struct {
        const char *text;
        const char *msg;
    } cases[] = {
        {"[assembly]\nwidth 12\n",
         "model.ini:2: line is not 'key = value' or '[section]': width 12"},
        {"[assembly\n", "model.ini:1: line is not 'key = value' or '[section]': [assembly"},
        {"[assembly] x\n", "model.ini:1: line is not 'key = value' or '[section]': [assembly] x"},
        {"[assembly]\n = 12\n", "model.ini:2: line is not 'key = value' or '[section]': = 12"},
        {"[assembly]\nmy width = 12\n",
         "model.ini:2: line is not 'key = value' or '[section]': my width = 12"},
        {"width = 12\n", "model.ini:1: width: key before any [section]; put it under [assembly]"},
        {"[output]\nprefix = \"abc\n", "model.ini:2: prefix: unterminated quote"},
        {"[output]\nprefix = \"abc\" def\n", "text after the closing quote"},
    };
    cdem_params p;
    cdem_error err;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        assert_int_equal(parse(&p, cases[i].text, &err), CDEM_ERR_PARSE);
        assert_msg_has(&err, cases[i].msg);
    }
}

static void test_params_duplicate_keys_name_both_lines(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    assert_int_equal(
        parse(&p, "[physics]\ngravity = 9\n[time]\nruntime = 900\n[physics]\ngravity = 8\n", &err),
        CDEM_ERR_PARSE);
    assert_string_equal(err.msg, "model.ini:6: [physics] gravity: duplicate key (already set on "
                                 "line 2); keep one");
    /* a section may be reopened for other keys */
    assert_int_equal(parse(&p, "[physics]\ngravity = 9\n[time]\n[physics]\ndensity = 2000\n", &err),
                     CDEM_OK);
}

static void test_params_failed_parse_leaves_params_unchanged(void **state) {
    (void)state;
    cdem_params p, before;
    cdem_error err;
    cdem_params_defaults(&p);
    before = p;
    assert_int_equal(
        cdem_params_parse_text(&p, "[physics]\ngravity = 3\ndensity = 1\n", "m.ini", &err),
        CDEM_ERR_RANGE);
    assert_true(params_equal(&p, &before));
    assert_int_equal(cdem_params_parse_text(NULL, "", "m.ini", &err), CDEM_ERR_INVALID);
    assert_int_equal(cdem_params_parse_text(&p, NULL, "m.ini", &err), CDEM_ERR_INVALID);
}

static void test_params_comments_whitespace_bom_crlf(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    const char *text = "\xEF\xBB\xBF# full-line comment\r\n"
                       "; another\r\n"
                       "  [ physics ]  # section comment\r\n"
                       "\tgravity\t=\t5.5   # inline comment\r\n"
                       "density = 2000; not a comment without a space before it?\r\n";
    /* "2000;" has no blank before ';', so it is part of the value and not a number */
    assert_int_equal(parse(&p, text, &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "model.ini:5: density = 2000; not a comment");
    text = "\xEF\xBB\xBF[physics]\r\ngravity = 5.5 ; inline\r\ndensity=2000\r\n\r\n[output]\r\n"
           "prefix = run#1\r\n[boundary]\r\nfault_file = \"my faults/f #2.txt\" # quoted\r\n";
    assert_int_equal(parse(&p, text, &err), CDEM_OK);
    assert_true(p.gravity == 5.5 && p.density == 2000.0);
    assert_string_equal(p.prefix, "run#1");
    assert_string_equal(p.fault_file, "my faults/f #2.txt");
    /* an over-long line is refused, not silently cut */
    char *big = malloc(4000);
    assert_non_null(big);
    int w = snprintf(big, 4000, "[physics]\ngravity = 9.81");
    memset(big + w, ' ', 3000);
    snprintf(big + w + 3000, 4000 - (size_t)w - 3000, "x\n");
    assert_int_equal(parse(&p, big, &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "model.ini:2: line longer than ");
    free(big);
    /* last line without a newline */
    assert_int_equal(parse(&p, "[physics]\ngravity = 7", &err), CDEM_OK);
    assert_true(p.gravity == 7.0);
}

static void test_params_crlf_file(void **state) {
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/crlf.ini", data_dir());
    cdem_params p;
    cdem_error err;
    cdem_error_clear(&err);
    cdem_params_defaults(&p);
    char *text = NULL;
    cdem_status st = cdem_params_load(&p, path, &text, &err);
    if (st != CDEM_OK)
        print_error("%s\n", err.msg);
    assert_int_equal(st, CDEM_OK);
    assert_non_null(text);
    assert_non_null(strstr(text, "\r\n"));       /* the file really has Windows line endings */
    assert_true((unsigned char)text[0] == 0xEF); /* and a byte-order mark */
    free(text);
    assert_true(p.width == 15.0 && p.height == 3.0);
    assert_int_equal(p.half_radii, 1);
    assert_int_equal(p.mode, CDEM_MODE_DETACHMENT);
    assert_int_equal(p.detachment_walls, CDEM_WALLS_BOTH);
    assert_true(p.wall.friction == 0.0 && p.wall.cohesion == 0.0);
    assert_string_equal(p.prefix, "detach");
    assert_int_equal(cdem_params_validate(&p, NULL, &err), CDEM_OK);
}

static void test_params_load_errors(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    char *text = (char *)1;
    assert_int_equal(cdem_params_load(&p, "/nonexistent/dir/m.ini", &text, &err), CDEM_ERR_IO);
    assert_null(text);
    assert_msg_has(&err, "/nonexistent/dir/m.ini: cannot open parameter file");
    /* a folder: said so, not a bare "read error" (issue 19, item 7) */
    assert_int_equal(cdem_params_load(&p, data_dir(), &text, &err), CDEM_ERR_IO);
    assert_msg_has(&err, "is a folder, not a parameter file");
    char path[1024];
    snprintf(path, sizeof path, "%s/bad_key.ini", data_dir());
    assert_int_equal(cdem_params_load(&p, path, NULL, &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "bad_key.ini:4: [physics] gravit: unknown key; did you mean 'gravity'?");
}

/* ---------- overrides ---------- */

static void test_params_overrides(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    cdem_error_clear(&err);
    assert_int_equal(cdem_params_override(&p, "time.runtime=3000", &err), CDEM_OK);
    assert_true(p.runtime == 3000.0);
    assert_int_equal(cdem_params_override(&p, " boundary.mode = detachment ", &err), CDEM_OK);
    assert_int_equal(p.mode, CDEM_MODE_DETACHMENT);
    assert_int_equal(cdem_params_override(&p, "output.prefix=\"a b\"", &err), CDEM_OK);
    assert_string_equal(p.prefix, "a b");
    cdem_params before = p;
    assert_int_equal(cdem_params_override(&p, "time.runtime=abc", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "-s time.runtime=abc: runtime = abc: not a number");
    assert_int_equal(cdem_params_override(&p, "physics.gravity=40", &err), CDEM_ERR_RANGE);
    assert_string_equal(err.msg,
                        "-s physics.gravity=40: gravity = 40: must be between 0.5 and 25 m/s^2");
    assert_int_equal(cdem_params_override(&p, "gravity=5", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "-s gravity=5: expected section.key=value, e.g. physics.gravity=5");
    assert_int_equal(cdem_params_override(&p, "physics.gravity", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "expected section.key=value");
    assert_int_equal(cdem_params_override(&p, "physic.gravity=5", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "-s physic.gravity=5: unknown section [physic]; did you mean [physics]?");
    assert_int_equal(cdem_params_override(&p, "time.gravity=5", &err), CDEM_ERR_PARSE);
    assert_msg_has(&err, "-s time.gravity=5: [time] gravity: unknown key; it belongs in [physics]");
    assert_true(params_equal(&p, &before));
}

/* The base's material: a number, or the word "wall" (the default: the lateral walls' value),
 * which is stored as NaN and written back as "wall". */
static void test_params_base_material_word(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    assert_true(isnan(p.base.friction) && isnan(p.base.cohesion) && isnan(p.base.breaking_strain));
    assert_int_equal(cdem_params_override(&p, "material.base_friction=0", &err), CDEM_OK);
    assert_true(p.base.friction == 0.0);
    assert_int_equal(cdem_params_override(&p, "material.base_cohesion=WALL", &err), CDEM_OK);
    assert_true(isnan(p.base.cohesion));
    const cdem_param_def *d = cdem_params_find("material", "base_friction");
    assert_non_null(d);
    char buf[64];
    cdem_params_format_value(&p, d, buf, sizeof buf);
    assert_string_equal(buf, "0");
    cdem_params_format_value(&p, cdem_params_find("material", "base_cohesion"), buf, sizeof buf);
    assert_string_equal(buf, "wall");
    assert_int_equal(cdem_params_override(&p, "material.base_friction=-1", &err), CDEM_ERR_RANGE);
    assert_string_equal(err.msg, "-s material.base_friction=-1: base_friction = -1: must be "
                                 "between 0 and 10, or wall");
    assert_int_equal(cdem_params_override(&p, "material.base_friction=walls", &err),
                     CDEM_ERR_PARSE);
    assert_msg_has(&err, "base_friction = walls: not a number");
    assert_int_equal(cdem_params_validate(&p, NULL, &err), CDEM_OK);
    /* the material in force: the base's own friction, the wall's cohesion and strain */
    cdem_contact_material base;
    p.wall.cohesion = 7e8;
    assert_int_equal(cdem_params_base_material(&p, &base), 1);
    assert_true(base.friction == 0.0 && base.cohesion == 7e8 &&
                base.breaking_strain == p.wall.breaking_strain);
    cdem_params q;
    cdem_params_defaults(&q);
    assert_int_equal(cdem_params_base_material(&q, &base), 0);
    assert_true(base.friction == q.wall.friction && base.cohesion == q.wall.cohesion);
    /* a NaN in a row without the word is still refused */
    p.wall.friction = NAN;
    assert_int_equal(cdem_params_validate(&p, NULL, &err), CDEM_ERR_RANGE);
    assert_msg_has(&err, "wall_friction = nan");
}

/* ---------- validation ---------- */

typedef struct {
    const char *name;
    const char *overrides[6]; /* applied in order; NULL-terminated */
    const char *expect;       /* substring of the message */
} rule_case;

static const rule_case rule_cases[] = {
    {"equilibration",
     {"time.equilibration=2000", NULL},
     "equilibration = 2000 s must be shorter than runtime = 2000 s"},
    {"weak+layered",
     {"heterogeneity.weak_interval=lower", "heterogeneity.layered_friction=on", NULL},
     "weak_interval = lower excludes layered_friction = on"},
    {"layered+bonded",
     {"material.material=bonded", "heterogeneity.layered_friction=on", NULL},
     "layered_friction = on requires material = granular (got material = bonded)"},
    {"overburden+repose",
     {"surface.overburden_pressure=1e6", "boundary.mode=repose", NULL},
     "overburden_pressure = 1000000 N/m cannot be used with mode = repose"},
    {"overburden+biaxial",
     {"surface.overburden_pressure=1e6", "boundary.mode=biaxial", NULL},
     "overburden_pressure = 1000000 N/m cannot be used with mode = biaxial"},
    {"overburden+erosion",
     {"surface.overburden_pressure=1e6", "surface.erosion=on", NULL},
     "overburden_pressure = 1000000 N/m excludes erosion = on"},
    {"overburden+sedimentation",
     {"surface.overburden_pressure=1e6", "surface.sedimentation=on", NULL},
     "overburden_pressure = 1000000 N/m excludes sedimentation = on"},
    {"biaxial size",
     {"boundary.mode=biaxial", "assembly.width=20", NULL},
     "mode = biaxial requires width = 10 and height = 5 units (got width = 20, height = 5)"},
    {"biaxial height",
     {"boundary.mode=biaxial", "assembly.height=4", NULL},
     "(got width = 10, height = 4)"},
    {"biaxial flexural",
     {"boundary.mode=biaxial", "heterogeneity.flexural_slip=on", NULL},
     "mode = biaxial excludes flexural_slip"},
    {"biaxial weak",
     {"boundary.mode=biaxial", "heterogeneity.weak_interval=upper", NULL},
     "mode = biaxial excludes weak_interval = upper: set [heterogeneity] weak_interval = off"},
    {"biaxial layered",
     {"boundary.mode=biaxial", "heterogeneity.layered_friction=on", NULL},
     "mode = biaxial excludes layered_friction"},
    {"biaxial erosion",
     {"boundary.mode=biaxial", "surface.erosion=on", NULL},
     "mode = biaxial excludes erosion"},
    {"biaxial sedimentation",
     {"boundary.mode=biaxial", "surface.sedimentation=on", NULL},
     "mode = biaxial excludes sedimentation"},
    {"repose erosion",
     {"boundary.mode=repose", "surface.erosion=on", NULL},
     "mode = repose excludes erosion"},
    {"repose sedimentation",
     {"boundary.mode=repose", "surface.sedimentation=on", NULL},
     "mode = repose excludes sedimentation"},
    {"irregular file",
     {"boundary.mode=irregular-fault", NULL},
     "mode = irregular-fault requires fault_file"},
    {"vertical faults",
     {"boundary.mode=vertical-faults", "boundary.vertical_fault_location=0.6",
      "boundary.vertical_fault_spacing=0.4", NULL},
     "vertical_fault_location + vertical_fault_spacing = 0.6 + 0.4 must be < 1"},
    {"inversion mode",
     {"boundary.mode=detachment", "boundary.inversion=on", NULL},
     "inversion = on needs mode = planar-fault, listric-fault or irregular-fault (got mode = "
     "detachment)"},
    {"settling",
     {"surface.sedimentation=on", "time.equilibration=1500", NULL},
     "settling > displacement: the settling time 0.2 x equilibration = 0.2 x 1500 s = 300 s"},
    /* the salt's rules (solver/step/salt_rules.c) */
    {"salt bonded",
     {"salt.layer=basal", "physics.damping_mode=contact", "material.material=bonded", NULL},
     "salt.layer = basal: not supported with material.material = bonded"},
    {"salt biaxial",
     {"salt.layer=basal", "physics.damping_mode=contact", "boundary.mode=biaxial", NULL},
     "salt.layer = basal: not supported with boundary.mode = biaxial"},
    {"salt absolute damping",
     {"salt.layer=basal", NULL},
     "salt.layer = basal with physics.damping_mode = absolute"},
    {"salt interval order",
     {"salt.layer=interval", "physics.damping_mode=contact", "salt.interval_bottom_percent=50",
      "salt.interval_top_percent=30", NULL},
     "salt.interval_bottom_percent = 50 must be below salt.interval_top_percent = 30"},
    {"salt weak interval",
     {"salt.layer=basal", "physics.damping_mode=contact", "heterogeneity.weak_interval=lower",
      NULL},
     "salt.layer = basal conflicts with heterogeneity.weak_interval = lower"},
    {"salt too viscous",
     {"salt.layer=basal", "physics.damping_mode=contact", "salt.viscosity=1e21", "salt.rate=100",
      NULL},
     "too viscous for its grid"},
};

static void apply_overrides(cdem_params *p, const char *const *ov) {
    cdem_error err;
    for (size_t j = 0; ov[j]; j++) {
        cdem_status st = cdem_params_override(p, ov[j], &err);
        if (st != CDEM_OK)
            print_error("%s\n", err.msg);
        assert_int_equal(st, CDEM_OK);
    }
}

static void test_params_validate_each_rule(void **state) {
    (void)state;
    for (size_t i = 0; i < sizeof rule_cases / sizeof rule_cases[0]; i++) {
        cdem_params p;
        cdem_error err;
        cdem_params_defaults(&p);
        cdem_error_clear(&err);
        apply_overrides(&p, rule_cases[i].overrides);
        cdem_status st = cdem_run_validate(&p, &err);
        if (st != CDEM_ERR_CONFLICT)
            print_error("case %s: status %d\n", rule_cases[i].name, st);
        assert_int_equal(st, CDEM_ERR_CONFLICT);
        assert_msg_has(&err, rule_cases[i].expect);
    }
}

static void test_params_validate_allowed_combinations(void **state) {
    (void)state;
    static const char *const ok_sets[][6] = {
        {"boundary.mode=biaxial", "surface.overburden_pressure=0", NULL},
        {"boundary.mode=irregular-fault", "boundary.fault_file=tests/data/fault.txt",
         "boundary.inversion=on", NULL},
        {"boundary.mode=vertical-faults", "boundary.vertical_fault_location=0.6",
         "boundary.vertical_fault_spacing=0.39", NULL},
        {"surface.sedimentation=on", "surface.sea_level_rise=high", NULL},
        {"heterogeneity.layered_friction=on", NULL},
        {"surface.overburden_pressure=1e7", "boundary.mode=detachment", NULL},
        {"boundary.mode=repose", "time.display_interval=10", NULL},
        {"salt.layer=basal", "physics.damping_mode=contact", "boundary.mode=detachment", NULL},
        {"salt.layer=interval", "physics.damping_mode=contact", "salt.viscosity=1e19", NULL},
    };
    for (size_t i = 0; i < sizeof ok_sets / sizeof ok_sets[0]; i++) {
        cdem_params p;
        cdem_error err;
        cdem_params_defaults(&p);
        cdem_error_clear(&err);
        apply_overrides(&p, ok_sets[i]);
        cdem_status st = cdem_run_validate(&p, &err);
        if (st != CDEM_OK)
            print_error("set %zu: %s\n", i, err.msg);
        assert_int_equal(st, CDEM_OK);
    }
}

static void test_params_validate_reports_all_rules_at_once(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    static const char *const ov[] = {"time.equilibration=2500", "boundary.mode=biaxial",
                                     "assembly.width=20",       "surface.erosion=on",
                                     "boundary.inversion=on",   NULL};
    apply_overrides(&p, ov);
    assert_int_equal(cdem_run_validate(&p, &err), CDEM_ERR_CONFLICT);
    assert_msg_has(&err, "equilibration = 2500 s must be shorter than runtime = 2000 s");
    assert_msg_has(&err, "\nmode = biaxial requires width = 10");
    assert_msg_has(&err, "\nmode = biaxial excludes erosion");
    assert_msg_has(&err, "\ninversion = on needs mode");
    int lines = 1;
    for (const char *c = err.msg; *c; c++)
        lines += *c == '\n';
    assert_int_equal(lines, 4);
}

static void test_params_validate_settling_numbers(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    p.sedimentation = 1;
    /* Default model: v = 25 dt = 0.70461 m/s, so 30 x 5 m take 212.9 s; settling is
     * 0.2 x 400 = 80 s: accepted. With equilibration 1100 s the settling (220 s) is longer. */
    assert_int_equal(cdem_run_validate(&p, &err), CDEM_OK);
    p.equilibration = 1100;
    assert_int_equal(cdem_run_validate(&p, &err), CDEM_ERR_CONFLICT);
    assert_msg_has(&err, "settling > displacement:");
    assert_msg_has(&err, "= 30 x 5 m / 0.7046 m/s = 212.9 s");
    assert_msg_has(&err, "increase [time] display_interval to at least 5.168 m");
    assert_msg_has(&err, "reduce [time] equilibration to at most 1064 s");
    /* following the advice exactly fixes it (the numbers are rounded to the safe side) */
    p.display_interval = 5.168;
    assert_int_equal(cdem_run_validate(&p, &err), CDEM_OK);
    p.display_interval = 5.0;
    p.equilibration = 1064;
    assert_int_equal(cdem_run_validate(&p, &err), CDEM_OK);
}

static void test_params_validate_checks_ranges_of_coded_values(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    p.gravity = 40;
    p.mode = (cdem_mode)42;
    p.half_radii = 3;
    assert_int_equal(cdem_params_validate(&p, NULL, &err), CDEM_ERR_RANGE);
    assert_msg_has(&err, "[physics] gravity = 40: must be between 0.5 and 25 m/s^2");
    assert_msg_has(&err, "[boundary] mode = 42: not a valid choice");
    assert_msg_has(&err, "[assembly] half_radii = 3: must be 0 or 1");
    assert_int_equal(cdem_params_validate(NULL, NULL, &err), CDEM_ERR_INVALID);
}

/* ---------- writers ---------- */

static char *write_to_string(const cdem_params *p) {
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    cdem_params_write(p, f);
    fclose(f);
    return buf;
}

static void test_params_write_round_trip_defaults(void **state) {
    (void)state;
    cdem_params p, q;
    cdem_error err;
    cdem_params_defaults(&p);
    char *text = write_to_string(&p);
    assert_non_null(strstr(text, "[assembly]\n# assembly width in model units (cdem's box: 10 to "
                                 "100; beyond it, bounded by the memory the run needs, at least 8 "
                                 "largest diameters) (units; > 0 and <= 1000000; default 10)\n"
                                 "width = 10\n"));
    assert_non_null(strstr(text, "gravity = 9.81\n"));
    assert_int_equal(parse(&q, "", &err), CDEM_OK);
    memset(&q, 0, sizeof q); /* parse over zeros: every key must be present in the text */
    q.mode = CDEM_MODE_BIAXIAL;
    assert_int_equal(cdem_params_parse_text(&q, text, "written.ini", &err), CDEM_OK);
    /* but a fixture's (params.h): listed nowhere, so it keeps what the parse started from */
    size_t n;
    const cdem_param_def *t = cdem_params_table(&n);
    for (size_t i = 0; i < n; i++)
        if (t[i].fixture) {
            assert_null(strstr(text, t[i].key));
            memcpy((char *)&q + t[i].offset, (char *)&p + t[i].offset,
                   t[i].type == CDEM_PTYPE_STRING   ? t[i].size
                   : t[i].type == CDEM_PTYPE_DOUBLE ? sizeof(double)
                   : t[i].type == CDEM_PTYPE_LONG   ? sizeof(long)
                                                    : sizeof(int));
        }
    assert_true(params_equal(&p, &q));
    free(text);
}

static void test_params_write_round_trip_changed_values(void **state) {
    (void)state;
    size_t n;
    const cdem_param_def *t = cdem_params_table(&n);
    cdem_params p, q;
    cdem_error err;
    cdem_params_defaults(&p);
    /* move every numeric value to an awkward point inside its range */
    for (size_t i = 0; i < n; i++) {
        const cdem_param_def *d = &t[i];
        char *f = (char *)&p + d->offset;
        if (d->fixture)
            continue; /* a fixture's key is not written (params.h): it keeps its default */
        if (d->type == CDEM_PTYPE_DOUBLE) {
            double v = d->min + (d->max - d->min) / 3.0;
            memcpy(f, &v, sizeof v);
        } else if (d->type == CDEM_PTYPE_INT) {
            int v = (int)d->max;
            memcpy(f, &v, sizeof v);
        } else if (d->type == CDEM_PTYPE_BOOL || d->type == CDEM_PTYPE_ENUM) {
            int v = 1;
            memcpy(f, &v, sizeof v);
        }
    }
    p.seed = 2147483647L;
    snprintf(p.prefix, sizeof p.prefix, " run #2; x ");
    snprintf(p.fault_file, sizeof p.fault_file, "dir with space/f.txt");
    char *text = write_to_string(&p);
    cdem_params_defaults(&q);
    cdem_status st = cdem_params_parse_text(&q, text, "written.ini", &err);
    if (st != CDEM_OK)
        print_error("%s\n", err.msg);
    assert_int_equal(st, CDEM_OK);
    assert_true(params_equal(&p, &q));
    free(text);
}

static void test_params_format_value(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    char buf[64];
    cdem_params_format_value(&p, cdem_params_find("physics", "gravity"), buf, sizeof buf);
    assert_string_equal(buf, "9.81");
    cdem_params_format_value(&p, cdem_params_find("material", "element_cohesion"), buf, sizeof buf);
    assert_string_equal(buf, "5e+09");
    cdem_params_format_value(&p, cdem_params_find("boundary", "mode"), buf, sizeof buf);
    assert_string_equal(buf, "planar-fault");
    cdem_params_format_value(&p, cdem_params_find("material", "first_slip"), buf, sizeof buf);
    assert_string_equal(buf, "on");
    cdem_params_format_value(&p, cdem_params_find("boundary", "fault_file"), buf, sizeof buf);
    assert_string_equal(buf, "\"\"");
    cdem_params_format_value(&p, NULL, buf, sizeof buf);
    assert_string_equal(buf, "");
}

/* The text of docs/<name> (malloc'd), from the tests' data folder or the working directory. */
static char *read_doc(const char *name) {
    char path[1200];
    snprintf(path, sizeof path, "%s/../../docs/%s", data_dir(), name);
    FILE *doc = fopen(path, "rb");
    if (!doc) {
        snprintf(path, sizeof path, "docs/%s", name);
        doc = fopen(path, "rb");
    }
    assert_non_null(doc);
    const size_t cap = 1 << 21;
    char *text = malloc(cap);
    assert_non_null(text);
    size_t got = fread(text, 1, cap - 1, doc);
    fclose(doc);
    text[got] = '\0';
    return text;
}

static void test_params_markdown_and_docs_current(void **state) {
    (void)state;
    char *md = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&md, &len);
    assert_non_null(f);
    cdem_params_write_markdown(f);
    fclose(f);
    assert_non_null(strstr(md, "| physics | `gravity` | real | `9.81` | m/s^2 | 0.5 to 25 |"));
    assert_non_null(
        strstr(md, "| boundary | `fault_dip` | real | `30` | degrees | > 0 and <= 90 |"));
    size_t n, fixtures = 0;
    const cdem_param_def *t = cdem_params_table(&n);
    for (size_t i = 0; i < n; i++)
        fixtures += t[i].fixture != 0; /* not a user's key: not listed */
    size_t rows = 0;
    for (const char *c = md; *c; c++)
        rows += *c == '\n';
    assert_int_equal(rows, n - fixtures + 2);
    /* docs/parameters.md must contain the current table (regenerate it with
     * `build/cdem-run --params-markdown` when the table changes) */
    char *text = read_doc("parameters.md");
    if (!strstr(text, md))
        print_error("docs/parameters.md is stale: regenerate its table with "
                    "`build/cdem-run --params-markdown`\n");
    assert_non_null(strstr(text, md));
    free(text);
    free(md);
}

/* docs/solver.md holds the laws' and the modes' tables as the program prints them from the
 * registries' rows (regenerate with `build/cdem-run --laws-markdown` / `--modes-markdown`). */
static void test_params_registry_tables_in_docs(void **state) {
    (void)state;
    void (*writers[2])(FILE *) = {cdem_params_write_laws_markdown,
                                  cdem_params_write_modes_markdown};
    const char *flags[2] = {"--laws-markdown", "--modes-markdown"};
    char *text = read_doc("solver.md");
    for (int k = 0; k < 2; k++) {
        char *md = NULL;
        size_t len = 0;
        FILE *f = open_memstream(&md, &len);
        assert_non_null(f);
        writers[k](f);
        fclose(f);
        /* every word of the registry a file can name is a row; no fixture is */
        assert_non_null(strstr(md, k == 0 ? "| `coulomb` | " : "| `planar-fault` | "));
        assert_null(strstr(md, "test-"));
        if (!strstr(text, md))
            fail_msg("docs/solver.md is stale: regenerate its table with `build/cdem-run %s`",
                     flags[k]);
        free(md);
    }
    free(text);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_params_table_complete_and_defaults_parse),
        cmocka_unit_test(test_params_defaults_are_the_paper_model),
        cmocka_unit_test(test_params_every_numeric_range_boundary),
        cmocka_unit_test(test_params_range_message_shape),
        cmocka_unit_test(test_params_non_numeric_values),
        cmocka_unit_test(test_params_every_enum_word_and_a_wrong_one),
        cmocka_unit_test(test_params_boolean_spellings),
        cmocka_unit_test(test_params_unknown_key_suggests),
        cmocka_unit_test(test_params_unknown_section),
        cmocka_unit_test(test_params_malformed_lines),
        cmocka_unit_test(test_params_duplicate_keys_name_both_lines),
        cmocka_unit_test(test_params_failed_parse_leaves_params_unchanged),
        cmocka_unit_test(test_params_comments_whitespace_bom_crlf),
        cmocka_unit_test(test_params_crlf_file),
        cmocka_unit_test(test_params_load_errors),
        cmocka_unit_test(test_params_overrides),
        cmocka_unit_test(test_params_base_material_word),
        cmocka_unit_test(test_params_validate_each_rule),
        cmocka_unit_test(test_params_validate_allowed_combinations),
        cmocka_unit_test(test_params_validate_reports_all_rules_at_once),
        cmocka_unit_test(test_params_validate_settling_numbers),
        cmocka_unit_test(test_params_validate_checks_ranges_of_coded_values),
        cmocka_unit_test(test_params_write_round_trip_defaults),
        cmocka_unit_test(test_params_write_round_trip_changed_values),
        cmocka_unit_test(test_params_format_value),
        cmocka_unit_test(test_params_markdown_and_docs_current),
        cmocka_unit_test(test_params_registry_tables_in_docs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
