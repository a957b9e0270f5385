/* fuzz_params: the parameter-file parser (common/params.c) and everything cdem-run does with
 * a parsed file before it simulates (validate, derive the model constants, the summary).
 * Input: an INI text; after the first NUL byte, further NUL-separated strings are applied as
 * "-s section.key=value" overrides. Invariant checked: a file that parses and validates
 * writes back (cdem_params_write) to a text that parses to the same values. */
#include "bc.h"
#include "model.h"
#include "params.h"
#include "run.h"
#include "summary.h"

#include "fuzz_util.h"

/* Values of every parameter formatted as text, joined by '\n' (malloc'd). */
static char *fuzz_params_values(const cdem_params *p) {
    size_t count;
    const cdem_param_def *t = cdem_params_table(&count);
    size_t cap = count * (CDEM_PATH_MAX + 2) + 1, n = 0;
    char *out = malloc(cap);
    if (!out)
        return NULL;
    char buf[CDEM_PATH_MAX + 1];
    for (size_t i = 0; i < count; i++) {
        cdem_params_format_value(p, &t[i], buf, sizeof buf);
        n += (size_t)snprintf(out + n, cap - n, "%s\n", buf);
    }
    return out;
}

/* Writes p as a file, parses it back and checks every value is the same. */
static void fuzz_params_roundtrip(const cdem_params *p) {
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (!f)
        return;
    cdem_params_write(p, f);
    if (fclose(f) != 0) {
        free(text);
        return;
    }
    cdem_params q;
    cdem_params_defaults(&q);
    cdem_error err;
    cdem_error_clear(&err);
    cdem_status st = cdem_params_parse_text(&q, text, "roundtrip.ini", &err);
    if (st != CDEM_OK)
        fprintf(stderr, "roundtrip parse failed: %s\n---\n%s\n", err.msg, text);
    FUZZ_CHECK(st == CDEM_OK);
    char *a = fuzz_params_values(p), *b = fuzz_params_values(&q);
    if (a && b && strcmp(a, b) != 0)
        fprintf(stderr, "roundtrip changed values:\n%s\n---\n%s\n", a, b);
    FUZZ_CHECK(!a || !b || strcmp(a, b) == 0);
    free(a);
    free(b);
    free(text);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *text = fuzz_strndup(data, size);
    if (!text)
        return 0;
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_error err;
    cdem_error_clear(&err);
    cdem_status st = cdem_params_parse_text(&p, text, "fuzz.ini", &err);
    if (st != CDEM_OK)
        FUZZ_CHECK(err.code == st && err.msg[0] != '\0' && strlen(err.msg) < sizeof err.msg);
    /* overrides after the first NUL */
    size_t at = strlen(text) + 1;
    while (st == CDEM_OK && at < size) {
        const char *ov = text + at;
        at += strlen(ov) + 1;
        st = cdem_params_override(&p, ov, &err);
        if (st != CDEM_OK)
            FUZZ_CHECK(err.msg[0] != '\0');
    }
    if (st == CDEM_OK) {
        st = cdem_run_validate(&p, &err);
        if (st != CDEM_OK)
            FUZZ_CHECK(err.msg[0] != '\0');
    }
    if (st == CDEM_OK) {
        fuzz_params_roundtrip(&p);
        cdem_model m;
        if (cdem_bc_derive_model(&p, &m, &err) == CDEM_OK) {
            char *summary = NULL;
            if (cdem_summary_text(&p, &m, 1000, 100, 1, &summary, &err) == CDEM_OK)
                FUZZ_CHECK(summary && strlen(summary) > 0);
            free(summary);
        }
    }
    free(text);
    return 0;
}
