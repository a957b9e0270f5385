/* cdem_error: see cdem_error.h. A single reporter for every failure, so that every message
 * has the same shape and every failure has one breakpoint (cdem_error_set). */
#include "cdem_error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void cdem_error_clear(cdem_error *err) {
    if (!err)
        return;
    err->code = CDEM_OK;
    err->src_file = NULL;
    err->src_line = 0;
    err->msg[0] = '\0';
}

cdem_status cdem_error_set(cdem_error *err, cdem_status code, const char *src_file, int src_line,
                           const char *fmt, ...) {
    if (!err)
        return code;
    err->code = code;
    err->src_file = src_file;
    err->src_line = src_line;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    return code;
}

void cdem_error_prefix(cdem_error *err, const char *fmt, ...) {
    if (!err)
        return;
    char prefix[CDEM_ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    /* Build "prefix: message" by hand: the sum may exceed the buffer and is cut there. */
    char joined[CDEM_ERROR_MSG_MAX];
    size_t plen = strlen(prefix), mlen = strlen(err->msg), cap = sizeof joined - 1;
    size_t pos = plen < cap ? plen : cap;
    memcpy(joined, prefix, pos);
    for (const char *sep = ": "; *sep && pos < cap; sep++)
        joined[pos++] = *sep;
    size_t take = mlen < cap - pos ? mlen : cap - pos;
    memcpy(joined + pos, err->msg, take);
    joined[pos + take] = '\0';
    memcpy(err->msg, joined, sizeof joined);
}

const char *cdem_status_str(cdem_status code) {
    switch (code) {
    case CDEM_OK:
        return "ok";
    case CDEM_ERR_NOMEM:
        return "out of memory";
    case CDEM_ERR_IO:
        return "input/output error";
    case CDEM_ERR_PARSE:
        return "parse error";
    case CDEM_ERR_RANGE:
        return "value out of range";
    case CDEM_ERR_CONFLICT:
        return "conflicting options";
    case CDEM_ERR_FORMAT:
        return "invalid file";
    case CDEM_ERR_VERSION:
        return "unsupported format version";
    case CDEM_ERR_NOTFOUND:
        return "not found";
    case CDEM_ERR_INVALID:
        return "invalid argument";
    case CDEM_ERR_NUMERIC:
        return "numerical failure";
    case CDEM_ERR_INTERRUPTED:
        return "interrupted";
    case CDEM_ERR_UNSUPPORTED:
        return "unsupported";
    }
    return "unknown error";
}
