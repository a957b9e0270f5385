/* fault_file: fault polylines from a vertex file or the listric law (see fault_file.h). */
#include "fault_file.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

void cdem_fault_file_free(cdem_fault_polyline *pl) {
    if (!pl)
        return;
    free(pl->x);
    free(pl->y);
    free(pl->line);
    memset(pl, 0, sizeof *pl);
}

static cdem_status pl_push(cdem_fault_polyline *pl, size_t *cap, double x, double y, long line,
                           cdem_error *err) {
    if (pl->n == *cap) {
        const size_t nc = *cap ? 2 * *cap : 16;
        double *nx = realloc(pl->x, nc * sizeof *nx);
        if (!nx)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "fault polyline: out of memory for %zu vertices",
                             nc);
        pl->x = nx;
        double *ny = realloc(pl->y, nc * sizeof *ny);
        if (!ny)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "fault polyline: out of memory for %zu vertices",
                             nc);
        pl->y = ny;
        long *nl = realloc(pl->line, nc * sizeof *nl);
        if (!nl)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "fault polyline: out of memory for %zu vertices",
                             nc);
        pl->line = nl;
        *cap = nc;
    }
    pl->x[pl->n] = x;
    pl->y[pl->n] = y;
    pl->line[pl->n] = line;
    pl->n++;
    return CDEM_OK;
}

/* Length of the plain decimal number at s ([+-]digits[.digits][e[+-]digits]), 0 if none.
 * strtod alone also reads hexadecimal ("0x1p-1074"), "inf" and "nan". */
static size_t decimal_length(const char *s) {
    const char *p = s;
    if (*p == '+' || *p == '-')
        p++;
    int digits = 0;
    for (; *p >= '0' && *p <= '9'; p++)
        digits++;
    if (*p == '.')
        for (p++; *p >= '0' && *p <= '9'; p++)
            digits++;
    if (!digits)
        return 0;
    if (*p == 'e' || *p == 'E') {
        const char *q = p + 1;
        if (*q == '+' || *q == '-')
            q++;
        if (*q >= '0' && *q <= '9') {
            while (*q >= '0' && *q <= '9')
                q++;
            p = q;
        }
    }
    return (size_t)(p - s);
}

/* Parses one number field of [*p, end); advances *p. 0 on success. */
static int parse_field(char **p, double *v) {
    char *s = *p;
    while (*s == ' ' || *s == '\t' || *s == ',')
        s++;
    if (*s == '\0')
        return 1; /* missing */
    char *e = NULL;
    errno = 0;
    const double d = strtod(s, &e);
    if (e == s || e != s + decimal_length(s) || errno == ERANGE || !isfinite(d) ||
        !(*e == '\0' || *e == ' ' || *e == '\t' || *e == ','))
        return 2; /* not a number */
    *v = d;
    *p = e;
    return 0;
}

static cdem_status read_lines(FILE *f, const char *path, double x0, double tol,
                              cdem_fault_polyline *pl, cdem_error *err) {
    char line[1024];
    long lineno = 0;
    size_t cap = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        size_t len = strlen(line);
        if (len == sizeof line - 1 && line[len - 1] != '\n' && !feof(f))
            return CDEM_FAIL(err, CDEM_ERR_PARSE,
                             "fault file %s, line %ld: line longer than %zu characters", path,
                             lineno, sizeof line - 2);
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        len = strlen(line);
        while (len > 0 && (line[len - 1] == '\n' || line[len - 1] == '\r' || line[len - 1] == ' ' ||
                           line[len - 1] == '\t'))
            line[--len] = '\0';
        char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\0')
            continue;
        double xy[2];
        for (int k = 0; k < 2; k++) {
            const int rc = parse_field(&p, &xy[k]);
            if (rc == 1)
                return CDEM_FAIL(err, CDEM_ERR_PARSE,
                                 "fault file %s, line %ld: '%s': expected two numbers x y (m), "
                                 "found only one",
                                 path, lineno, line);
            if (rc == 2)
                return CDEM_FAIL(err, CDEM_ERR_PARSE,
                                 "fault file %s, line %ld: '%s': field %d is not a number; "
                                 "expected two numbers x y (m)",
                                 path, lineno, line, k + 1);
        }
        while (*p == ' ' || *p == '\t' || *p == ',')
            p++;
        if (*p != '\0')
            return CDEM_FAIL(err, CDEM_ERR_PARSE,
                             "fault file %s, line %ld: '%s': extra field '%s'; expected exactly "
                             "two numbers x y (m)",
                             path, lineno, line, p);
        if (pl->n == 0) {
            if (fabs(xy[0] - x0) > tol || fabs(xy[1]) > tol)
                return CDEM_FAIL(err, CDEM_ERR_RANGE,
                                 "fault file %s, line %ld: first point (%g, %g) m must be at the "
                                 "fault location (x = %g m, y = 0) within %g m",
                                 path, lineno, xy[0], xy[1], x0, tol);
        } else {
            const double px = pl->x[pl->n - 1], py = pl->y[pl->n - 1];
            if (!(xy[0] < px && xy[1] > py))
                return CDEM_FAIL(err, CDEM_ERR_RANGE,
                                 "fault file %s, line %ld: point (%g, %g) m must have lower x "
                                 "and higher y than the previous point (%g, %g) m (the fault "
                                 "dips toward +x and is listed from the base up-dip)",
                                 path, lineno, xy[0], xy[1], px, py);
            /* the fault's x at a height is interpolated (and below the base extrapolated)
             * along a segment: a segment rising 5e-324 m over 1400 m gave x = inf */
            const double dip = atan2(xy[1] - py, px - xy[0]) * 180.0 / M_PI;
            if (!(dip >= CDEM_FAULT_MIN_DIP))
                return CDEM_FAIL(err, CDEM_ERR_RANGE,
                                 "fault file %s, line %ld: the segment from (%g, %g) m to (%g, "
                                 "%g) m dips %.3g degrees; every segment must dip at least %g "
                                 "degrees (a flatter one gives no position of the fault at a "
                                 "height)",
                                 path, lineno, px, py, xy[0], xy[1], dip, CDEM_FAULT_MIN_DIP);
        }
        CDEM_TRY(pl_push(pl, &cap, pl->n == 0 ? x0 : xy[0], pl->n == 0 ? 0.0 : xy[1], lineno, err));
    }
    if (ferror(f))
        return CDEM_FAIL(err, CDEM_ERR_IO, "fault file %s: read error after line %ld", path,
                         lineno);
    if (pl->n == 0)
        return CDEM_FAIL(err, CDEM_ERR_PARSE,
                         "fault file %s: empty (%ld lines, no x y point); expected at least two "
                         "points from the base up-dip",
                         path, lineno);
    if (pl->n < 2)
        return CDEM_FAIL(err, CDEM_ERR_PARSE,
                         "fault file %s, line %ld: only one point; expected at least two points "
                         "from the base up-dip",
                         path, lineno);
    return CDEM_OK;
}

cdem_status cdem_fault_file_read(const char *path, double x0, double tol, cdem_fault_polyline *pl,
                                 cdem_error *err) {
    memset(pl, 0, sizeof *pl);
    if (!path || !*path)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "fault file: no path given");
    if (!(tol > 0.0) || !isfinite(x0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "fault file %s: x0 = %g m, tol = %g m: need a "
                         "finite x0 and tol > 0",
                         path, x0, tol);
    /* Opened without waiting (a FIFO would block the open until a writer came: --summary and
     * the run hung, issue 35, item 6), then refused unless it is a regular file (a folder
     * opens, and then every read fails with a bare "read error"; /dev/zero never ends). */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return CDEM_FAIL(err, CDEM_ERR_IO, "fault file %s: cannot open: %s", path, strerror(errno));
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        const int is_dir = S_ISDIR(sb.st_mode);
        close(fd);
        return CDEM_FAIL(
            err, CDEM_ERR_IO,
            "fault file %s: is %s, not a text file of x y points (boundary.fault_file)", path,
            is_dir                 ? "a folder"
            : S_ISFIFO(sb.st_mode) ? "a pipe (FIFO)"
            : S_ISCHR(sb.st_mode)  ? "a device"
                                   : "not a regular file");
    }
    FILE *f = fdopen(fd, "r");
    if (!f) {
        close(fd);
        return CDEM_FAIL(err, CDEM_ERR_IO, "fault file %s: cannot open: %s", path, strerror(errno));
    }
    /* A NUL byte would end a line early without notice (fgets): refuse binary files. */
    char chunk[4096];
    size_t got, offset = 0;
    while ((got = fread(chunk, 1, sizeof chunk, f)) > 0) {
        const char *nul = memchr(chunk, '\0', got);
        if (nul) {
            fclose(f);
            return CDEM_FAIL(err, CDEM_ERR_PARSE,
                             "fault file %s: byte %zu is a NUL byte: not a text file of x y "
                             "points",
                             path, offset + (size_t)(nul - chunk) + 1);
        }
        offset += got;
    }
    rewind(f);
    const cdem_status st = read_lines(f, path, x0, tol, pl, err);
    fclose(f);
    if (st != CDEM_OK)
        cdem_fault_file_free(pl);
    return st;
}

cdem_status cdem_fault_file_check_extent(const cdem_fault_polyline *pl, const char *path,
                                         double y_max, double min_segment, cdem_error *err) {
    for (size_t k = 0; k < pl->n; k++) {
        const long line = pl->line ? pl->line[k] : (long)k + 1;
        if (pl->x[k] < 0.0)
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "fault file %s, line %ld: point (%g, %g) m lies left of the model "
                             "(x must be >= 0 m, the inner side of its left wall)",
                             path, line, pl->x[k], pl->y[k]);
        if (pl->y[k] > y_max)
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "fault file %s, line %ld: point (%g, %g) m lies far above the "
                             "model (y must be <= %g m: twice the top of its walls and assembly "
                             "plus the whole displacement; above its last point the fault goes "
                             "on vertically anyway)",
                             path, line, pl->x[k], pl->y[k], y_max);
        if (k > 0) {
            const double len = hypot(pl->x[k] - pl->x[k - 1], pl->y[k] - pl->y[k - 1]);
            if (!(len >= min_segment))
                return CDEM_FAIL(err, CDEM_ERR_RANGE,
                                 "fault file %s, line %ld: the segment from (%g, %g) m to (%g, "
                                 "%g) m is %g m long; segments must be at least %g m (half the "
                                 "smallest element radius: the precision the first point is "
                                 "held to; fault elements are laid one radius apart)",
                                 path, line, pl->x[k - 1], pl->y[k - 1], pl->x[k], pl->y[k], len,
                                 min_segment);
        }
    }
    return CDEM_OK;
}

cdem_status cdem_fault_file_listric(double x0, double height, double dip0_deg, size_t n_seg,
                                    cdem_fault_polyline *pl, cdem_error *err) {
    memset(pl, 0, sizeof *pl);
    if (!(dip0_deg > 0.0 && dip0_deg <= 90.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "listric fault: boundary.fault_dip = %g degrees: must be in (0, 90]",
                         dip0_deg);
    if (!(height > 0.0 && isfinite(height)) || !isfinite(x0) || n_seg < 1 || n_seg > 100000)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "listric fault: height = %g m, x0 = %g m, %zu segments: need height > "
                         "0 and 1-100000 segments",
                         height, x0, n_seg);
    pl->x = malloc((n_seg + 1) * sizeof *pl->x);
    pl->y = malloc((n_seg + 1) * sizeof *pl->y);
    if (!pl->x || !pl->y) {
        cdem_fault_file_free(pl);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "listric fault: out of memory for %zu vertices",
                         n_seg + 1);
    }
    pl->n = n_seg + 1;
    pl->x[0] = x0;
    pl->y[0] = 0.0;
    const double dy = height / (double)n_seg;
    for (size_t k = 1; k <= n_seg; k++) {
        const double eta = ((double)k - 0.5) / (double)n_seg;
        const double dip = dip0_deg + (90.0 - dip0_deg) * pow(eta, CDEM_LISTRIC_EXPONENT);
        pl->y[k] = (double)k * dy;
        pl->x[k] = pl->x[k - 1] - dy / tan(dip * M_PI / 180.0);
    }
    return CDEM_OK;
}

double cdem_fault_file_x_at(const cdem_fault_polyline *pl, double y) {
    if (y >= pl->y[pl->n - 1])
        return pl->x[pl->n - 1];
    size_t k = 1;
    while (k < pl->n - 1 && pl->y[k] < y)
        k++;
    const double t = (y - pl->y[k - 1]) / (pl->y[k] - pl->y[k - 1]);
    return pl->x[k - 1] + t * (pl->x[k] - pl->x[k - 1]);
}

double cdem_fault_file_distance(const cdem_fault_polyline *pl, double px, double py) {
    double best = INFINITY;
    for (size_t k = 1; k < pl->n; k++) {
        const double ax = pl->x[k - 1], ay = pl->y[k - 1];
        const double ex = pl->x[k] - ax, ey = pl->y[k] - ay;
        const double l2 = ex * ex + ey * ey;
        double t = l2 > 0.0 ? ((px - ax) * ex + (py - ay) * ey) / l2 : 0.0;
        t = fmin(1.0, fmax(0.0, t));
        best = fmin(best, hypot(px - ax - t * ex, py - ay - t * ey));
    }
    return best;
}
