/* cli_help: see cli_help.h. Wrapping is greedy at spaces; in usage forms a space inside
 * [...] is not a break point, so an optional group is never split across lines. */
#include "cli_help.h"

#include "suggest.h"

#include <string.h>

static const cdem_cli_option help_option = {"-h, --help", NULL, "print this help and exit"};

/* Length of the word starting at s: up to the next space at bracket depth 0 (brackets
 * counted only when keep_brackets), or the end. */
static size_t word_len(const char *s, int keep_brackets) {
    size_t n = 0;
    int depth = 0;
    while (s[n] && s[n] != '\n' && (s[n] != ' ' || depth > 0)) {
        if (keep_brackets && s[n] == '[')
            depth++;
        else if (keep_brackets && s[n] == ']' && depth > 0)
            depth--;
        n++;
    }
    return n;
}

/* Writes text from column col (the cursor's current column), wrapping at
 * CDEM_CLI_HELP_WIDTH with continuation lines indented to indent; ends with a newline.
 * A '\n' in text forces a line break. */
static void wrap(FILE *f, const char *text, int col, int indent, int keep_brackets) {
    const char *s = text;
    int at_line_start = 1;
    while (*s) {
        if (*s == '\n') {
            fprintf(f, "\n%*s", indent, "");
            col = indent;
            at_line_start = 1;
            s++;
            continue;
        }
        if (*s == ' ') {
            s++;
            continue;
        }
        size_t n = word_len(s, keep_brackets);
        if (!at_line_start && col + 1 + (int)n > CDEM_CLI_HELP_WIDTH) {
            fprintf(f, "\n%*s", indent, "");
            col = indent;
            at_line_start = 1;
        }
        if (!at_line_start) {
            fputc(' ', f);
            col++;
        }
        fwrite(s, 1, n, f);
        col += (int)n;
        at_line_start = 0;
        s += n;
    }
    fputc('\n', f);
}

/* Paragraphs separated by blank lines; a paragraph starting with a space is printed as it
 * is (examples, tables), the others are wrapped. */
static void paragraphs(FILE *f, const char *text) {
    const char *s = text;
    while (*s) {
        const char *end = strstr(s, "\n\n");
        size_t n = end ? (size_t)(end - s) : strlen(s);
        char buf[4096];
        if (n >= sizeof buf)
            n = sizeof buf - 1;
        memcpy(buf, s, n);
        buf[n] = '\0';
        if (buf[0] == ' ')
            fprintf(f, "%s\n", buf);
        else
            wrap(f, buf, 0, 0, 0);
        s += n;
        while (*s == '\n')
            s++;
        if (*s)
            fputc('\n', f);
    }
}

static void option_row(FILE *f, const cdem_cli_option *o) {
    int col = fprintf(f, "  %s%s%s", o->names, o->arg ? " " : "", o->arg ? o->arg : "");
    if (col > CDEM_CLI_HELP_COLUMN - 2) {
        fprintf(f, "\n%*s", CDEM_CLI_HELP_COLUMN, "");
    } else {
        fprintf(f, "%*s", CDEM_CLI_HELP_COLUMN - col, "");
    }
    wrap(f, o->help, CDEM_CLI_HELP_COLUMN, CDEM_CLI_HELP_COLUMN, 0);
}

void cdem_cli_help_print(FILE *f, const cdem_cli_help *h) {
    const int indent = 7 + (int)strlen(h->program) + 1; /* under the first argument */
    for (size_t k = 0; h->forms[k]; k++) {
        int col = fprintf(f, "%s%s", k == 0 ? "usage: " : "       ", h->program);
        if (h->forms[k][0]) {
            fputc(' ', f);
            col++;
        }
        wrap(f, h->forms[k], col, indent, 1);
    }
    if (h->about && h->about[0]) {
        fputc('\n', f);
        paragraphs(f, h->about);
    }
    if (h->rows_heading && h->rows) {
        fprintf(f, "\n%s:\n", h->rows_heading);
        for (size_t k = 0; h->rows[k].name; k++) {
            cdem_cli_option o = {h->rows[k].name, NULL, h->rows[k].help};
            option_row(f, &o);
        }
    }
    fprintf(f, "\nOptions:\n");
    for (size_t k = 0; h->options && h->options[k].names; k++)
        option_row(f, &h->options[k]);
    option_row(f, &help_option);
    if (h->notes && h->notes[0]) {
        fputc('\n', f);
        paragraphs(f, h->notes);
    }
    char status[512];
    snprintf(status, sizeof status, "Exit status: %s",
             h->exit_status ? h->exit_status : "0 success, 1 error, 2 usage error.");
    fputc('\n', f);
    wrap(f, status, 0, 0, 0);
}

void cdem_cli_usage_print(FILE *f, const cdem_cli_help *h, const char *what) {
    fprintf(f, "%s: %s\n", h->program, what);
    int col = fprintf(f, "usage: %s", h->program);
    if (h->forms[0][0]) {
        fputc(' ', f);
        col++;
    }
    wrap(f, h->forms[0], col, 7 + (int)strlen(h->program) + 1, 1);
    fprintf(f, "Try '%s --help' for more information.\n", h->program);
}

int cdem_cli_option_is(const cdem_cli_option *o, const char *name) {
    const size_t len = strlen(name);
    const char *s = o->names;
    while (*s) {
        while (*s == ' ' || *s == ',')
            s++;
        size_t n = strcspn(s, ", ");
        if (n == len && strncmp(s, name, len) == 0)
            return 1;
        s += n;
    }
    return 0;
}

const char *cdem_cli_suggest_option(const cdem_cli_help *h, const char *arg, char *buf,
                                    size_t cap) {
    char name[128];
    const size_t len = strcspn(arg, "=");
    if (strncmp(arg, "--", 2) != 0 || len >= sizeof name || cap == 0)
        return NULL; /* a one-letter option has no spelling near enough to offer */
    memcpy(name, arg, len);
    name[len] = '\0';
    size_t best_d = cdem_edit_distance(name, "--help");
    snprintf(buf, cap, "--help");
    for (size_t k = 0; h->options && h->options[k].names; k++)
        for (const char *s = h->options[k].names; *s;) {
            while (*s == ' ' || *s == ',')
                s++;
            const size_t n = strcspn(s, ", ");
            char spelling[128];
            if (n > 2 && n < sizeof spelling && strncmp(s, "--", 2) == 0) {
                memcpy(spelling, s, n);
                spelling[n] = '\0';
                const size_t d = cdem_edit_distance(name, spelling);
                if (d < best_d) {
                    best_d = d;
                    snprintf(buf, cap, "%s", spelling);
                }
            }
            s += n;
        }
    return cdem_suggest_close(best_d, name) ? buf : NULL;
}

const cdem_cli_option *cdem_cli_find_option(const cdem_cli_help *h, const char *arg,
                                            const char **inline_value) {
    *inline_value = NULL;
    const char *eq = strchr(arg, '=');
    char name[128];
    size_t n = eq ? (size_t)(eq - arg) : strlen(arg);
    if (n >= sizeof name)
        return NULL;
    memcpy(name, arg, n);
    name[n] = '\0';
    for (size_t k = 0; h->options && h->options[k].names; k++) {
        const cdem_cli_option *o = &h->options[k];
        if (!cdem_cli_option_is(o, name))
            continue;
        if (eq && !o->arg)
            return NULL; /* a switch takes no value */
        *inline_value = eq ? eq + 1 : NULL;
        return o;
    }
    return NULL;
}

int cdem_cli_wants_help(int argc, char *const *argv, int first, const cdem_cli_help *h) {
    for (int i = first; i < argc; i++) {
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help"))
            return i;
        const char *v;
        const cdem_cli_option *o = h ? cdem_cli_find_option(h, argv[i], &v) : NULL;
        if (o && o->arg && !v)
            i++; /* the next argument is this option's value */
    }
    return 0;
}
