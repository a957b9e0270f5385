/* cmd_support: see cmd_support.h. */
#include "cmd_support.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int cdem_cmd_usage(const cdem_cli_help *h, const char *what) {
    cdem_cli_usage_print(stderr, h, what);
    return CDEM_EXIT_USAGE;
}

cdem_cmd_arg cdem_cmd_next_arg(const cdem_cli_help *h, int argc, char **argv, int *i,
                               const cdem_cli_option **opt, const char **val) {
    const char *arg = argv[*i];
    *val = NULL;
    *opt = cdem_cli_find_option(h, arg, val);
    char msg[256];
    if (!*opt) {
        if (arg[0] != '-' || !arg[1])
            return CDEM_CMD_ARG_POSITIONAL;
        char near[64];
        const char *s = cdem_cli_suggest_option(h, arg, near, sizeof near);
        snprintf(msg, sizeof msg, "unknown option '%.100s'%s%s%s", arg, s ? "; did you mean '" : "",
                 s ? s : "", s ? "'?" : "");
        cdem_cmd_usage(h, msg);
        return CDEM_CMD_ARG_USAGE;
    }
    if ((*opt)->arg && !*val) {
        if (*i + 1 >= argc) {
            snprintf(msg, sizeof msg, "option %.100s needs a value (%s)", arg, (*opt)->arg);
            cdem_cmd_usage(h, msg);
            return CDEM_CMD_ARG_USAGE;
        }
        *val = argv[++*i];
    }
    return CDEM_CMD_ARG_OPTION;
}

int cdem_cmd_fail(const char *cmd, const char *file, const cdem_error *err) {
    const char *m = err->msg[0] ? err->msg : "unknown error";
    const size_t len = cmd ? strlen(cmd) : 0;
    if (cmd && !strncmp(m, cmd, len) && m[len] == ':' && m[len + 1] == ' ')
        m += len + 2; /* "wedge: ..." from the library: the prefix already names it */
    const int name_file = file && !strstr(m, file);
    for (int first = 1; *m; first = 0) {
        const char *nl = strchr(m, '\n');
        const int n = nl ? (int)(nl - m) : (int)strlen(m);
        fprintf(stderr, "cdem-strain%s%s: %s%s%.*s\n", cmd ? " " : "", cmd ? cmd : "",
                first && name_file ? file : "", first && name_file ? ": " : "", n, m);
        m += n + (nl != NULL);
    }
    return CDEM_EXIT_ERROR;
}

int cdem_cmd_parse_number(const char *text, double *out) {
    char *end;
    errno = 0;
    const double v = strtod(text, &end);
    if (errno || end == text || *end || !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

int cdem_cmd_parse_int(const char *text, int lo, int hi, int *out) {
    char *end;
    errno = 0;
    const long v = strtol(text, &end, 10);
    if (errno || end == text || *end || v < lo || v > hi)
        return 0;
    *out = (int)v;
    return 1;
}

const char *cdem_cmd_base_name(const char *path) {
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

cdem_status cdem_cmd_output_open(cdem_cmd_output *o, const char *path, cdem_error *err) {
    o->f = stdout;
    o->of.active = 0;
    return path ? cdem_outfile_open_text(&o->of, path, &o->f, err) : CDEM_OK;
}

cdem_status cdem_cmd_output_close(cdem_cmd_output *o, cdem_status st, cdem_error *err) {
    if (o->of.active) /* the file: closed, renamed or removed */
        return cdem_outfile_close_text(&o->of, o->f, st, err);
    if (st == CDEM_OK && ferror(o->f))
        st = CDEM_FAIL(err, CDEM_ERR_IO, "error writing stdout");
    return st;
}
