/* fuzz_cdem2d: the cdem2D folder importer (analysis/input/cdem2d.c). The input is split into the
 * files of a temporary folder: each line "== NAME" starts a file NAME (characters outside
 * [A-Za-z0-9_.-] dropped, at most 80, "." and ".." ignored), whose content runs to the next
 * such line; an input with no "== " line is the single file modelresults_0.txt. So the
 * fuzzer reaches the parameter scan, the folder listing (numbers in names), the results and
 * forces row parsers and the id matching. Invariants checked: increments arrive in strictly
 * ascending number order with the promised element count, unique ids, finite positive
 * radii; a failure carries a message. */
#include "cdem2d.h"

#include "fuzz_util.h"

#include <math.h>

typedef struct {
    long last;    /* number of the previous increment, -1 before the first */
    size_t calls; /* increments received */
} fuzz_cdem2d_ctx;

static cdem_status fuzz_cdem2d_sink(void *user, const cdem_increment_info *info,
                                    const cdem_state *s, cdem_error *err) {
    (void)err;
    fuzz_cdem2d_ctx *c = user;
    FUZZ_CHECK(info->number > c->last);
    FUZZ_CHECK(info->n_elements == (int64_t)s->n);
    c->last = info->number;
    c->calls++;
    for (size_t i = 0; i < s->n; i++) {
        FUZZ_CHECK(isfinite(s->x[i]) && isfinite(s->y[i]));
        FUZZ_CHECK(s->radius[i] > 0.0 && isfinite(s->radius[i]));
        FUZZ_CHECK(s->id[i] >= 0 && s->id[i] < s->next_id);
        if (s->has_stress)
            FUZZ_CHECK(isfinite(s->sxx[i]) && isfinite(s->syy[i]) && isfinite(s->sxy[i]));
    }
    /* ids unique: mark them in a bitmap */
    if (s->n > 0 && s->next_id > 0) {
        unsigned char *seen = calloc((size_t)s->next_id, 1);
        if (seen) {
            for (size_t i = 0; i < s->n; i++) {
                FUZZ_CHECK(!seen[s->id[i]]);
                seen[s->id[i]] = 1;
            }
            free(seen);
        }
    }
    return CDEM_OK;
}

/* Writes one part of the input as dir/name (name sanitised). */
static void fuzz_cdem2d_put(const char *dir, const char *name, size_t name_len, const char *body,
                            size_t body_len) {
    char clean[96], path[700];
    size_t j = 0;
    for (size_t i = 0; i < name_len && j < 80; i++) {
        char ch = name[i];
        if ((ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') ||
            ch == '_' || ch == '.' || ch == '-')
            clean[j++] = ch;
    }
    clean[j] = '\0';
    if (j == 0 || !strcmp(clean, ".") || !strcmp(clean, ".."))
        return;
    snprintf(path, sizeof path, "%s/%s", dir, clean);
    fuzz_write_file(path, body, body_len);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char dir[512];
    if (fuzz_mkdtemp(dir, sizeof dir) != 0)
        return 0;
    const char *t = (const char *)data, *end = t + size;
    /* find "== " at the start of a line */
    const char *hdr = NULL;
    for (const char *p = t; p + 3 <= end; p++)
        if ((p == t || p[-1] == '\n') && !memcmp(p, "== ", 3)) {
            hdr = p;
            break;
        }
    if (!hdr) {
        fuzz_cdem2d_put(dir, "modelresults_0.txt", 18, t, size);
    } else {
        while (hdr) {
            const char *name = hdr + 3;
            const char *nl = memchr(name, '\n', (size_t)(end - name));
            const char *body = nl ? nl + 1 : end;
            const char *next = NULL;
            for (const char *p = body; p + 3 <= end; p++)
                if ((p == body || p[-1] == '\n') && !memcmp(p, "== ", 3)) {
                    next = p;
                    break;
                }
            size_t name_len = (size_t)((nl ? nl : end) - name);
            fuzz_cdem2d_put(dir, name, name_len, body, (size_t)((next ? next : end) - body));
            hdr = next;
        }
    }
    fuzz_cdem2d_ctx c = {-1, 0};
    cdem_cdem2d_meta meta;
    cdem_error err;
    cdem_error_clear(&err);
    cdem_status st = cdem_cdem2d_import(dir, fuzz_cdem2d_sink, &c, &meta, &err);
    if (st == CDEM_OK)
        FUZZ_CHECK(c.calls == meta.n_increments && c.calls > 0);
    else
        FUZZ_CHECK(err.msg[0] != '\0');
    FUZZ_CHECK(meta.params_text != NULL || st != CDEM_OK);
    cdem_cdem2d_meta_free(&meta);
    fuzz_rmdir(dir);
    return 0;
}
