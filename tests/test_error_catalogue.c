/* docs/errors.md against the sources, read independently of the script that generates it
 * (scripts/error_catalogue.py, `make errors`): the page claims every message cdem-run and
 * cdem-strain can print, so every message call of common/, solver/ and analysis/ must be on
 * it. test_man checks that the committed page equals the script's output; this test checks
 * that the script misses no message, with its own reading of the C sources (a tokenizer
 * that skips comments and character literals: the script's first reader was thrown off
 * by a '"' and missed every message after it, and it knew neither H5FAIL nor the usage
 * messages).
 *
 * The test walks common/, solver/ and analysis/ itself, at any depth, and a file with
 * messages must have rows of its own on the page ("| path:LINE |"), so a folder the script
 * does not walk fails here even when some of its texts are on the page under another file
 * (issue 46, item 9: the script still listed the solver's old flat paths and missed every
 * message of solver/'s subfolders).
 *
 * A message call is a call of one of MESSAGE_CALLS with a string literal (or a buffer
 * filled by snprintf with one) as its format; its text, with each printf conversion shown
 * as <…>, must appear in docs/errors.md. A new kind of message source fails the test until
 * it is added to the table here and to the script: a function declared
 * __attribute__((format(printf, ...))), a macro that calls a message function, or a
 * function that passes its own parameter on as a message format. Functions that print no
 * message (the run summary's line()) are named in NOT_MESSAGES with the reason.
 * Runs from the repository root (tests/run_tests.sh). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <ctype.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct {
    const char *name; /* function or macro */
    int fmt_arg;      /* 1-based position of the format (or message) argument */
} message_call;

/* Keep in step with MESSAGE_CALLS in scripts/error_catalogue.py. */
static const message_call MESSAGE_CALLS[] = {
    {"CDEM_FAIL", 3},         /* common/cdem_error.h: the error record of every library call */
    {"cdem_error_set", 5},    /* what CDEM_FAIL calls */
    {"H5FAIL", 3},            /* common/h5/h5_internal.h: the run file's errors */
    {"h5i_fail_at", 5},       /* what H5FAIL calls */
    {"cdem_error_prefix", 2}, /* context put before a message on its way up */
    {"cdem_rule_add",
     2},                /* common/params.c and the solver: rules between keys, reported together */
    {"usage_error", 1}, /* solver/main.c: cdem-run's usage errors */
    {"cdem_cmd_usage", 2}, /* analysis/cli/cmd_support.c: cdem-strain's usage errors */
    {"usage", 1},          /* analysis/cli/cmd_render.c: cdem_cmd_usage with render's help */
    {"fprintf", 2},        /* only fprintf(stderr, ...) */
    {"say_why", 3},        /* common/h5/h5_layout.c: why a value of a run file is refused */
};
#define N_CALLS (sizeof MESSAGE_CALLS / sizeof MESSAGE_CALLS[0])

/* printf-like functions that print no message of the programs. */
static const char *NOT_MESSAGES[] = {
    "line", /* common/summary.c: one line of the run summary (cdem-run --summary, stdout) */
    "cdem_summary_line", /* solver/base/summary_line.h: the same, the modes' lines too */
    "say", /* analysis/cli/cmd_calibrate.c: calibrate's report (stdout and calibration.txt) */
    NULL,
};

/* ------------------------------------------------------------------ tokens */

typedef enum { T_IDENT, T_STRING, T_PUNCT, T_OTHER } tok_type;

typedef struct {
    tok_type type;
    const char *s; /* into the file's text; a string token without its quotes */
    size_t len;
    int line;
    int depth; /* brace depth before the token */
} token;

typedef struct {
    char path[256];
    char *text;
    token *toks;
    size_t n;
    char **defines; /* preprocessor directives, continuation lines joined */
    size_t n_defines;
} source;

static char *slurp(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    if (buf)
        buf[n] = '\0';
    fclose(f);
    return buf;
}

static void push(source *src, size_t *cap, token t) {
    if (src->n == *cap) {
        *cap = *cap ? 2 * *cap : 1024;
        src->toks = realloc(src->toks, *cap * sizeof *src->toks);
        assert_non_null(src->toks);
    }
    src->toks[src->n++] = t;
}

/* Splits a C file into tokens; comments are skipped, character literals are one T_OTHER
 * token; preprocessor directives are also kept whole (for #define). */
static void tokenize(source *src) {
    const char *p = src->text;
    size_t cap = 0;
    int line = 1, depth = 0, at_line_start = 1;
    while (*p) {
        if (*p == '\n') {
            line++;
            p++;
            at_line_start = 1;
            continue;
        }
        if (isspace((unsigned char)*p)) {
            p++;
            continue;
        }
        if (p[0] == '/' && p[1] == '/') {
            while (*p && *p != '\n')
                p++;
            continue;
        }
        if (p[0] == '/' && p[1] == '*') {
            p += 2;
            while (*p && !(p[0] == '*' && p[1] == '/'))
                line += *p++ == '\n';
            p += *p ? 2 : 0;
            continue;
        }
        if (*p == '#' && at_line_start) {
            /* kept aside whole for the macro check, and tokenized like code: a message
             * call inside a macro's body is a message too */
            const char *end = p;
            while (*end && !(*end == '\n' && end[-1] != '\\'))
                end++;
            char *d = strndup(p, (size_t)(end - p));
            assert_non_null(d);
            src->defines = realloc(src->defines, (src->n_defines + 1) * sizeof *src->defines);
            assert_non_null(src->defines);
            src->defines[src->n_defines++] = d;
        }
        at_line_start = 0;
        token t = {.s = p, .line = line, .depth = depth};
        if (*p == '"' || *p == '\'') {
            const char q = *p++;
            t.s = p;
            while (*p && *p != q) {
                if (*p == '\\' && p[1])
                    p++;
                line += *p++ == '\n';
            }
            t.type = q == '"' ? T_STRING : T_OTHER;
            t.len = (size_t)(p - t.s);
            p += *p ? 1 : 0;
        } else if (isalpha((unsigned char)*p) || *p == '_') {
            while (isalnum((unsigned char)*p) || *p == '_')
                p++;
            t.type = T_IDENT;
            t.len = (size_t)(p - t.s);
        } else if (isdigit((unsigned char)*p)) {
            while (isalnum((unsigned char)*p) || *p == '.' || *p == '_')
                p++;
            t.type = T_OTHER;
            t.len = (size_t)(p - t.s);
        } else {
            t.type = T_PUNCT;
            t.len = 1;
            depth += *p == '{';
            depth -= *p == '}';
            p++;
        }
        push(src, &cap, t);
    }
}

static int is(const token *t, const char *s) {
    return t->len == strlen(s) && !strncmp(t->s, s, t->len);
}

static int punct(const token *t, char c) {
    return t->type == T_PUNCT && t->s[0] == c;
}

static int message_named(const char *name) {
    for (size_t k = 0; k < N_CALLS; k++)
        if (!strcmp(name, MESSAGE_CALLS[k].name))
            return 1;
    return 0;
}

static const message_call *message_fn(const token *t) {
    if (t->type != T_IDENT)
        return NULL;
    for (size_t k = 0; k < N_CALLS; k++)
        if (is(t, MESSAGE_CALLS[k].name))
            return &MESSAGE_CALLS[k];
    return NULL;
}

/* Splits the arguments of the call whose '(' is toks[open]: starts[a]..ends[a] (exclusive)
 * for each argument; returns their number (at most max), *close = index of the ')'. */
static int split_args(const source *src, size_t open, size_t *starts, size_t *ends, int max,
                      size_t *close) {
    int n = 0, depth = 0;
    size_t i = open + 1;
    if (n < max)
        starts[n] = i;
    for (; i < src->n; i++) {
        const token *t = &src->toks[i];
        if (t->type == T_PUNCT && strchr("([{", t->s[0])) {
            depth++;
        } else if (t->type == T_PUNCT && strchr(")]}", t->s[0])) {
            if (depth-- == 0)
                break;
        } else if (punct(t, ',') && depth == 0) {
            if (n < max)
                ends[n] = i;
            n++;
            if (n < max)
                starts[n] = i + 1;
        }
    }
    if (n < max)
        ends[n] = i;
    *close = i;
    return i == open + 1 ? 0 : n + 1;
}

/* ------------------------------------------------------------------ messages */

/* The page's form of a format: escapes undone, conversions as <…>, '|' escaped, trailing
 * spaces (a final \n) dropped. The same as show() in scripts/error_catalogue.py. */
static void page_form(const char *fmt, char *out, size_t cap) {
    size_t o = 0;
#define PUT(c)                                                                                     \
    do {                                                                                           \
        if (o + 1 < cap)                                                                           \
            out[o++] = (c);                                                                        \
    } while (0)
    for (const char *p = fmt; *p;) {
        if (p[0] == '\\' && p[1]) {
            const char c = p[1];
            PUT(c == 'n' || c == 't' ? ' ' : c);
            p += 2;
        } else if (p[0] == '%' && p[1] == '%') {
            PUT('%');
            p += 2;
        } else if (p[0] == '%') {
            p++;
            while (*p && strchr("-+ #0", *p))
                p++;
            while (*p && (isdigit((unsigned char)*p) || *p == '*'))
                p++;
            if (*p == '.') {
                p++;
                while (*p && (isdigit((unsigned char)*p) || *p == '*'))
                    p++;
            }
            while (*p && strchr("hlzjt", *p))
                p++;
            if (*p)
                p++;
            for (const char *r = "<…>"; *r; r++)
                PUT(*r);
        } else if (*p == '|') {
            PUT('\\');
            PUT('|');
            p++;
        } else {
            PUT(*p++);
        }
    }
#undef PUT
    while (o > 0 && out[o - 1] == ' ')
        o--;
    out[o] = '\0';
}

/* Appends the adjacent string literals starting at toks[*i] (i advanced past them). */
static void literal_at(const source *src, size_t *i, size_t end, char *out, size_t cap) {
    out[0] = '\0';
    for (; *i < end && src->toks[*i].type == T_STRING; ++*i) {
        const size_t have = strlen(out), add = src->toks[*i].len;
        if (have + add + 1 < cap) {
            memcpy(out + have, src->toks[*i].s, add);
            out[have + add] = '\0';
        }
    }
}

typedef struct {
    int missing;
    int checked;
    int files; /* source files with at least one message */
    char report[65536];
} result;

static void check_text(result *r, const char *page, const source *src, int line, const char *fmt) {
    char form[4096];
    page_form(fmt, form, sizeof form);
    if (!form[0])
        return;
    r->checked++;
    if (!strstr(page, form)) {
        r->missing++;
        const size_t o = strlen(r->report);
        snprintf(r->report + o, sizeof r->report - o, "\n  %s:%d: %.120s", src->path, line, form);
    }
}

/* Checks the literal alternatives of the argument toks[a..b) (a ternary has two); a lone
 * buffer is followed back to the snprintf that filled it in the same function. Returns
 * the number of literals found. */
static int check_argument(result *r, const char *page, const source *src, size_t a, size_t b,
                          size_t call) {
    char fmt[4096];
    int found = 0;
    for (size_t i = a; i < b;) {
        if (src->toks[i].type != T_STRING) {
            i++;
            continue;
        }
        const int line = src->toks[i].line;
        literal_at(src, &i, b, fmt, sizeof fmt);
        check_text(r, page, src, line, fmt);
        found++;
    }
    if (found || b != a + 1 || src->toks[a].type != T_IDENT)
        return found;
    /* a buffer: the snprintf(buf, ...) before the call, back to the function's start */
    for (size_t i = call; i-- > 0 && src->toks[i].depth > 0;) {
        if (!is(&src->toks[i], "snprintf") || i + 3 >= src->n || !punct(&src->toks[i + 1], '(') ||
            src->toks[i + 2].type != T_IDENT || src->toks[i + 2].len != src->toks[a].len ||
            strncmp(src->toks[i + 2].s, src->toks[a].s, src->toks[a].len) != 0)
            continue;
        size_t st[8], en[8], close;
        if (split_args(src, i + 1, st, en, 8, &close) >= 3)
            return check_argument(r, page, src, st[2], en[2], i);
    }
    return 0;
}

/* The name of the function whose body holds toks[i] (into fn) and whether IDENT t (when
 * not NULL) names one of its parameters. */
static int is_parameter(const source *src, size_t i, const token *t, char *fn, size_t cap) {
    size_t k = i;
    while (k > 0 && src->toks[k].depth > 0)
        k--;
    /* toks[k] is the body's '{'; the parameter list's ')' is before it */
    size_t close = k;
    while (close > 0 && !punct(&src->toks[close], ')'))
        close--;
    int d = 0;
    size_t open = close;
    for (; open > 0; open--) {
        d += punct(&src->toks[open], ')');
        d -= punct(&src->toks[open], '(');
        if (d == 0)
            break;
    }
    snprintf(fn, cap, "%.*s", open ? (int)src->toks[open - 1].len : 1,
             open ? src->toks[open - 1].s : "?");
    for (size_t j = open + 1; t && j < close; j++)
        if (src->toks[j].type == T_IDENT && src->toks[j].len == t->len &&
            !strncmp(src->toks[j].s, t->s, t->len) &&
            (punct(&src->toks[j + 1], ',') || punct(&src->toks[j + 1], ')')))
            return 1;
    return 0;
}

static int listed(const char *name) {
    for (size_t k = 0; k < N_CALLS; k++)
        if (!strcmp(name, MESSAGE_CALLS[k].name))
            return 1;
    for (size_t k = 0; NOT_MESSAGES[k]; k++)
        if (!strcmp(name, NOT_MESSAGES[k]))
            return 1;
    return 0;
}

static void unlisted(result *r, const source *src, int line, const char *what, const char *name) {
    r->missing++;
    const size_t o = strlen(r->report);
    snprintf(r->report + o, sizeof r->report - o,
             "\n  %s:%d: %s %s is not a message source of the catalogue (add it to "
             "MESSAGE_CALLS here and in scripts/error_catalogue.py, or to NOT_MESSAGES)",
             src->path, line, what, name);
}

/* Every message call of one file, and every message source the tables do not know. */
static void check_source(result *r, const char *page, const source *src) {
    for (size_t i = 0; i + 1 < src->n; i++) {
        const token *t = &src->toks[i];
        /* printf-like declarations: __attribute__((format(printf, F, A))) */
        if (is(t, "format") && i + 2 < src->n && punct(&src->toks[i + 1], '(') &&
            is(&src->toks[i + 2], "printf")) {
            size_t k = i;
            while (k > 0 && !is(&src->toks[k], "__attribute__"))
                k--;
            int d = 0;
            size_t open = k - 1; /* the parameter list's ')' before the attribute */
            for (; open > 0; open--) {
                d += punct(&src->toks[open], ')');
                d -= punct(&src->toks[open], '(');
                if (d == 0)
                    break;
            }
            char name[128];
            snprintf(name, sizeof name, "%.*s", (int)src->toks[open - 1].len,
                     src->toks[open - 1].s);
            if (!listed(name))
                unlisted(r, src, t->line, "printf-like function", name);
            continue;
        }
        const message_call *m = message_fn(t);
        if (!m || !punct(&src->toks[i + 1], '('))
            continue;
        /* a declaration or definition (a type or '*' before the name) is not a call */
        if (i > 0 && ((src->toks[i - 1].type == T_IDENT && !is(&src->toks[i - 1], "return")) ||
                      punct(&src->toks[i - 1], '*')))
            continue;
        char fn[128] = "";
        if (t->depth > 0)
            is_parameter(src, i, NULL, fn, sizeof fn);
        if (fn[0] && message_named(fn))
            continue; /* the message function's own implementation */
        size_t st[16], en[16], close;
        const int n = split_args(src, i + 1, st, en, 16, &close);
        if (n < m->fmt_arg)
            continue;
        if (!strcmp(m->name, "fprintf") && !(en[0] == st[0] + 1 && is(&src->toks[st[0]], "stderr")))
            continue;
        const size_t a = st[m->fmt_arg - 1], b = en[m->fmt_arg - 1];
        if (check_argument(r, page, src, a, b, i))
            continue;
        /* a parameter passed on as the format: the enclosing function is a message source */
        if (b == a + 1 && src->toks[a].type == T_IDENT && t->depth > 0 &&
            is_parameter(src, i, &src->toks[a], fn, sizeof fn) && !listed(fn))
            unlisted(r, src, t->line, "function (passes its parameter on as a message)", fn);
    }
    /* macros that pass their arguments on to a message function (a message call with a
     * literal inside a macro's body was checked above, as code) */
    for (size_t d = 0; d < src->n_defines; d++) {
        const char *s = src->defines[d] + 1;
        while (*s == ' ')
            s++;
        if (strncmp(s, "define", 6) != 0)
            continue;
        s += 6;
        while (*s == ' ')
            s++;
        size_t len = 0;
        while (isalnum((unsigned char)s[len]) || s[len] == '_')
            len++;
        char name[128];
        snprintf(name, sizeof name, "%.*s", (int)len, s);
        for (size_t k = 0; k < N_CALLS; k++) {
            const char *hit = strstr(s + len, MESSAGE_CALLS[k].name);
            const size_t nl = strlen(MESSAGE_CALLS[k].name);
            if (hit && !isalnum((unsigned char)hit[-1]) && hit[-1] != '_' && hit[nl] == '(' &&
                strstr(hit, "__VA_ARGS__") && !listed(name))
                unlisted(r, src, 0, "macro", name);
        }
    }
}

static void load(source *src, const char *path) {
    memset(src, 0, sizeof *src);
    snprintf(src->path, sizeof src->path, "%s", path);
    src->text = slurp(path);
    assert_non_null(src->text);
    tokenize(src);
}

static void unload(source *src) {
    for (size_t d = 0; d < src->n_defines; d++)
        free(src->defines[d]);
    free(src->defines);
    free(src->toks);
    free(src->text);
}

/* The folders whose C files (.c and .h, at any depth: the solver's and the analysis's
 * layers are subfolders) hold the programs' messages; scripts/error_catalogue.py walks the
 * same (TREES). */
static const char *const TREES[] = {"common", "solver", "analysis", NULL};

typedef struct {
    char **paths;
    size_t n, cap;
} path_list;

static int by_name(const void *a, const void *b) {
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Appends every .c and .h file under dir, at any depth, to l. */
static void walk(const char *dir, path_list *l) {
    DIR *d = opendir(dir);
    if (!d)
        fail_msg("cannot open the source folder %s (run from the repository root)", dir);
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        char path[1024];
        if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >= (int)sizeof(source){0}.path)
            fail_msg("%s/%s: path too long for this test", dir, e->d_name);
        struct stat sb;
        if (stat(path, &sb) != 0)
            continue;
        const size_t len = strlen(e->d_name);
        if (S_ISDIR(sb.st_mode)) {
            walk(path, l);
        } else if (S_ISREG(sb.st_mode) && len > 2 && e->d_name[len - 2] == '.' &&
                   (e->d_name[len - 1] == 'c' || e->d_name[len - 1] == 'h')) {
            if (l->n == l->cap) {
                l->cap = l->cap ? 2 * l->cap : 256;
                l->paths = realloc(l->paths, l->cap * sizeof *l->paths);
                assert_non_null(l->paths);
            }
            l->paths[l->n] = strdup(path);
            assert_non_null(l->paths[l->n]);
            l->n++;
        }
    }
    closedir(d);
}

/* Checks one source file: its messages are on the page, and a file with messages has its
 * rows ("| path:LINE |"): a folder the catalogue does not walk has none. */
static void check_file(result *r, const char *page, const char *path) {
    source src;
    load(&src, path);
    const int before = r->checked;
    check_source(r, page, &src);
    unload(&src);
    const int n = r->checked - before;
    if (n == 0)
        return;
    r->files++;
    char row[300];
    snprintf(row, sizeof row, "| %s:", path);
    if (!strstr(page, row)) {
        r->missing++;
        const size_t o = strlen(r->report);
        snprintf(r->report + o, sizeof r->report - o,
                 "\n  %s: %d messages and no row of its own (does scripts/error_catalogue.py "
                 "walk its folder?)",
                 path, n);
    }
}

static void check_tree(result *r, const char *page) {
    path_list l = {0};
    for (size_t t = 0; TREES[t]; t++)
        walk(TREES[t], &l);
    qsort(l.paths, l.n, sizeof *l.paths, by_name);
    for (size_t k = 0; k < l.n; k++) {
        check_file(r, page, l.paths[k]);
        free(l.paths[k]);
    }
    free(l.paths);
}

/* Every message of the sources is on docs/errors.md. */
static void test_error_catalogue_has_every_message(void **state) {
    (void)state;
    char *page = slurp("docs/errors.md");
    assert_non_null(page);
    static result r;
    memset(&r, 0, sizeof r);
    check_tree(&r, page);
    free(page);
    /* a sanity floor: the sources have several hundred messages (779 when this was written,
     * 945 once the walk reached the solver's subfolders) in about 90 files */
    if (r.checked < 900 || r.files < 80)
        fail_msg("only %d message calls in %d files found in the sources: the reader or the "
                 "walk is broken",
                 r.checked, r.files);
    if (r.missing) {
        fprintf(stderr, "not in docs/errors.md:%s\n", r.report); /* fail_msg cuts it short */
        fail_msg("%d of %d messages (or message sources) are not in docs/errors.md, listed "
                 "above (run `make errors`, after adding a new source to "
                 "scripts/error_catalogue.py)",
                 r.missing, r.checked);
    }
}

/* A file whose messages have no rows of its own fails, even when the same texts are on the
 * page under another file (issue 46, item 9: the catalogue listed the solver's old flat
 * paths and missed every file of solver/'s subfolders); and the messages the reviewer
 * found missing, of solver/step/neighbour.c, are there. */
static void test_error_catalogue_names_every_file(void **state) {
    (void)state;
    char *page = slurp("docs/errors.md");
    assert_non_null(page);
    assert_non_null(strstr(page, "| solver/step/neighbour.c:"));
    assert_non_null(strstr(page, "element id <…> has a non-finite position (x = <…>, y = <…>): "
                                 "the simulation blew up"));
    assert_non_null(strstr(page, "neighbour list: out of memory for the pairs of a threaded "
                                 "build (<…> elements)"));
    /* the rows of neighbour.c moved to another (made-up) file */
    static const char from[] = "| solver/step/neighbour.c:", to[] = "| solver/step/elsewhere.c:";
    for (char *p = strstr(page, from); p; p = strstr(p, from))
        memcpy(p, to, strlen(to));
    static result r;
    memset(&r, 0, sizeof r);
    check_file(&r, page, "solver/step/neighbour.c");
    free(page);
    assert_true(r.checked >= 8);
    assert_int_equal(r.missing, 1); /* every text found, the file's rows not */
    assert_non_null(strstr(r.report, "solver/step/neighbour.c: "));
    assert_non_null(strstr(r.report, "messages and no row of its own"));
    /* the walk reaches the third level */
    path_list l = {0};
    walk("solver", &l);
    int deep = 0;
    for (size_t k = 0; k < l.n; k++) {
        deep |= !strcmp(l.paths[k], "solver/step/neighbour.c");
        free(l.paths[k]);
    }
    free(l.paths);
    assert_true(deep);
}

/* The reader itself: a message after a '"' character literal and one in a comment. */
static void test_error_catalogue_reader(void **state) {
    (void)state;
    source src = {.path = "inline"};
    src.text =
        strdup("int f(char c, cdem_error *err) {\n"
               "    /* CDEM_FAIL(err, CDEM_ERR_IO, \"in a comment\") */\n"
               "    if (c == '\"' || c == '(')\n"
               "        return CDEM_FAIL(err, CDEM_ERR_IO, \"a %s \" \"quote %d%%\", \"x\", 1);\n"
               "    return H5FAIL(err, CDEM_ERR_FORMAT, c ? \"one|%.40s\" : \"two\", \"y\");\n"
               "}\n"
               "static void g(const char *fmt) { char m[9]; snprintf(m, 9, \"built %zu\", 1);\n"
               "    cdem_cmd_usage(h, m); fprintf(stderr, fmt, 1); }\n");
    assert_non_null(src.text);
    tokenize(&src);
    static result r;
    check_source(&r, "", &src);
    unload(&src);
    assert_int_equal(r.checked, 4);
    assert_non_null(strstr(r.report, "inline:4: a <…> quote <…>%"));
    assert_non_null(strstr(r.report, "inline:5: one\\|<…>"));
    assert_non_null(strstr(r.report, "inline:5: two"));
    assert_non_null(strstr(r.report, "inline:7: built <…>"));
    assert_non_null(strstr(r.report, "function (passes its parameter on as a message) g"));
    assert_null(strstr(r.report, "in a comment"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_error_catalogue_reader),
        cmocka_unit_test(test_error_catalogue_has_every_message),
        cmocka_unit_test(test_error_catalogue_names_every_file),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
