/* fault_file: the curve of a listric or irregular fault, as a polyline in the model frame
 * (origin at the bottom-left inner corner, x right, y up; the base surface is y = 0).
 * Sources: an irregular-fault vertex file (cdem_fault_file_read: one "x y" per line in m,
 * whitespace or comma separated, '#' comments, blank lines and CRLF accepted; plain decimal
 * numbers; first point at (fault location x width, 0), every later one at lower x and higher
 * y, every segment dipping at least CDEM_FAULT_MIN_DIP), or the listric
 * curve (cdem_fault_file_listric: dip(y) = d0 + (90 - d0) (y / H)^k, k = 1, i.e. the dip
 * grows linearly with height from d0 at the base to 90 at the top of the assembly H; its
 * horizontal extent is H ln(1 / sin d0) / (90 - d0 in radians)). Both dip toward +x.
 * Ownership: a cdem_fault_polyline owns its arrays; cdem_fault_file_free releases them (NULL
 * accepted). Thread safety: reentrant, no shared state. Units: m, degrees. */
#ifndef CDEM_FAULT_FILE_H
#define CDEM_FAULT_FILE_H

#include "cdem_error.h"

#include <stddef.h>

/* Exponent k of the listric dip law dip(y) = d0 + (90 - d0) (y / H)^k. */
#define CDEM_LISTRIC_EXPONENT 1.0
/* Smallest dip (degrees) of a segment of a vertex file. */
#define CDEM_FAULT_MIN_DIP 1.0
/* Segments of the listric polyline built by bc_listric (equal heights). */
#define CDEM_LISTRIC_SEGMENTS 200

typedef struct {
    size_t n;      /* number of vertices, >= 2 */
    double *x, *y; /* m, vertices from the base up-dip: x strictly decreasing, y increasing */
    long *line;    /* line of each vertex in its vertex file (NULL for the listric curve) */
} cdem_fault_polyline;

/* Reads the vertex file `path`. x0 (m) is where the first vertex must lie (fault location x
 * width, at y = 0), within tol (m, > 0; half the smallest radius). Errors (CDEM_ERR_IO,
 * CDEM_ERR_PARSE, CDEM_ERR_RANGE) name the file and line. On failure pl is left empty. */
cdem_status cdem_fault_file_read(const char *path, double x0, double tol, cdem_fault_polyline *pl,
                                 cdem_error *err);

/* Checks a polyline read from path against the model it is used in, naming the line of the
 * first vertex or segment that fails (CDEM_ERR_RANGE): every vertex at 0 <= x and y <= y_max
 * (m; a vertex at y = 1e9 m once laid fault elements up to it: 5 GB of memory; the caller
 * chooses y_max from the model's height), and every segment at least min_segment (m) long. */
cdem_status cdem_fault_file_check_extent(const cdem_fault_polyline *pl, const char *path,
                                         double y_max, double min_segment, cdem_error *err);

/* Builds the listric curve from (x0, 0) up to y = height (m, > 0) with basal dip dip0_deg
 * (degrees, (0, 90]) in n_seg >= 1 segments of equal height (midpoint dips). */
cdem_status cdem_fault_file_listric(double x0, double height, double dip0_deg, size_t n_seg,
                                    cdem_fault_polyline *pl, cdem_error *err);

/* x of the curve at height y (m): linear between vertices; below the first vertex along the
 * first segment, above the last one vertical (x of the last vertex). */
double cdem_fault_file_x_at(const cdem_fault_polyline *pl, double y);

/* Shortest distance (m) from (px, py) to the polyline. */
double cdem_fault_file_distance(const cdem_fault_polyline *pl, double px, double py);

/* Releases the arrays; pl may be NULL. Leaves pl empty. */
void cdem_fault_file_free(cdem_fault_polyline *pl);

#endif
