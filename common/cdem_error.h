/* cdem_error: the project-wide status codes and the error record that carries a message.
 *
 * Library code never prints and never exits: a function that can fail returns a
 * cdem_status and, on failure, fills the caller's cdem_error with the code, the source
 * location where the failure was first detected and a message that names the offending
 * file, line, key or value. Only main() of cdem-run and cdem-strain prints it.
 * To catch any failure in a debugger, break on cdem_error_set.
 * Thread safety: a cdem_error belongs to one caller; no shared state. */
#ifndef CDEM_ERROR_H
#define CDEM_ERROR_H

#include <stddef.h>

typedef enum {
    CDEM_OK = 0,           /* success */
    CDEM_ERR_NOMEM,        /* allocation failed */
    CDEM_ERR_IO,           /* a file could not be opened, read, written or flushed */
    CDEM_ERR_PARSE,        /* malformed input text (parameter file, vertex file, cdem2D file) */
    CDEM_ERR_RANGE,        /* a value outside its allowed range or set of values */
    CDEM_ERR_CONFLICT,     /* options that exclude each other were combined */
    CDEM_ERR_FORMAT,       /* a file is not a valid cdem file, or is truncated or corrupt */
    CDEM_ERR_VERSION,      /* a cdem file of an unsupported format version */
    CDEM_ERR_NOTFOUND,     /* a requested increment, element, key or dataset does not exist */
    CDEM_ERR_INVALID,      /* a bad argument from the caller (a programming or usage error) */
    CDEM_ERR_NUMERIC,      /* the simulation produced NaN/Inf or blew up */
    CDEM_ERR_INTERRUPTED,  /* stopped by a signal (SIGINT/SIGTERM); output is valid */
    CDEM_ERR_UNSUPPORTED,  /* a combination or feature this build does not provide */
} cdem_status;

#define CDEM_ERROR_MSG_MAX 1024

typedef struct {
    cdem_status code;            /* CDEM_OK when no error has been recorded */
    const char *src_file;        /* source file where the failure was detected */
    int src_line;                /* source line where the failure was detected */
    char msg[CDEM_ERROR_MSG_MAX]; /* human-readable message, complete sentence(s) */
} cdem_error;

/* Resets err to "no error". err may be NULL. */
void cdem_error_clear(cdem_error *err);

/* Records code, location and a printf-style message in err (which may be NULL) and
 * returns code. Use through CDEM_FAIL. */
cdem_status cdem_error_set(cdem_error *err, cdem_status code, const char *src_file, int src_line,
                           const char *fmt, ...) __attribute__((format(printf, 5, 6)));

/* Prepends "prefix: " to an already recorded message (adds context on the way up). */
void cdem_error_prefix(cdem_error *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Short name of a status code ("parse error", "out of range", ...). */
const char *cdem_status_str(cdem_status code);

#define CDEM_FAIL(err, code, ...) cdem_error_set((err), (code), __FILE__, __LINE__, __VA_ARGS__)

/* Propagates a failure in one line: CDEM_TRY(cdem_state_read(path, &st, err)); */
#define CDEM_TRY(expr)                                                                             \
    do {                                                                                           \
        cdem_status cdem_try_status_ = (expr);                                                     \
        if (cdem_try_status_ != CDEM_OK)                                                           \
            return cdem_try_status_;                                                               \
    } while (0)

#endif
