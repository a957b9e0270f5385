/* wedge: see wedge.h. */
#include "wedge.h"

#include "surface.h"

#include <gsl/gsl_fit.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static const double rad2deg = 180.0 / 3.14159265358979323846;

/* Inner face (min x - r) of the moving wall elements right of x_mid; NaN when none. */
static double moving_wall_face(const cdem_state *s, double x_mid) {
    double face = NAN;
    for (size_t i = 0; i < s->n; i++)
        if ((s->flags[i] & CDEM_FLAG_MOVING) && (s->flags[i] & CDEM_FLAGS_BOUNDARY) &&
            isfinite(s->x[i]) && s->x[i] > x_mid) {
            const double f = s->x[i] - s->radius[i];
            if (!(face <= f))
                face = f;
        }
    return face;
}

/* Extent of the free elements of a state. */
typedef struct {
    double left;   /* m, min (x - r); +inf when there are none */
    double right;  /* m, max (x + r); -inf when there are none */
    double bottom; /* m, min (y - r); +inf when there are none */
    double rmax;   /* m, largest radius, >= 0 */
    double rmean;  /* m, mean radius, >= 0 */
    size_t n;      /* free elements counted */
} extent;

static extent free_extent(const cdem_state *s) {
    extent e = {INFINITY, -INFINITY, INFINITY, 0.0, 0.0, 0};
    double rsum = 0.0;
    for (size_t i = 0; i < s->n; i++)
        if (cdem_surface_is_free(s, i)) {
            e.left = fmin(e.left, s->x[i] - s->radius[i]);
            e.right = fmax(e.right, s->x[i] + s->radius[i]);
            e.bottom = fmin(e.bottom, s->y[i] - s->radius[i]);
            e.rmax = fmax(e.rmax, s->radius[i]);
            rsum += s->radius[i];
            e.n++;
        }
    e.rmean = e.n ? rsum / (double)e.n : 0.0;
    return e;
}

/* Area under the column tops (above y_base) between the faces xl and xr; columns are
 * clipped to [xl, xr], empty columns count 0. */
static double profile_area(const cdem_wedge_ref *r, const cdem_state *s, const size_t *top,
                           double xl, double xr) {
    double a = 0.0;
    for (size_t c = 0; c < r->n_columns; c++) {
        if (top[c] == SIZE_MAX)
            continue;
        const double c0 = r->x_left + (double)c * r->column_width;
        const double w = fmin(c0 + r->column_width, xr) - fmax(c0, xl);
        if (w > 0)
            a += w * (s->y[top[c]] + s->radius[top[c]] - r->y_base);
    }
    return a;
}

cdem_status cdem_wedge_reference(const cdem_state *ref, const cdem_wedge_options *opt,
                                 cdem_wedge_ref *r, cdem_error *err) {
    if (!ref || !r)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "wedge: NULL argument");
    memset(r, 0, sizeof *r);
    const double thr = opt ? opt->threshold : 0.0;
    if (!isfinite(thr) || thr < 0)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "wedge: threshold = %g m: must be a finite number >= 0 (0 = one mean "
                         "element diameter)",
                         thr);
    const extent e = free_extent(ref);
    if (e.n == 0)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "wedge: the reference state has no free (non-wall) elements (%zu "
                         "elements)",
                         ref->n);
    const double wall = moving_wall_face(ref, 0.5 * (e.left + e.right));
    if (!isfinite(wall) || !(wall > e.left))
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "wedge: no moving wall (CDEM_FLAG_MOVING wall elements) right of the "
                         "material's middle x = %g m; the wedge measurement needs a detachment "
                         "run (boundary.mode = detachment)",
                         0.5 * (e.left + e.right));
    r->x_left = e.left;
    r->column_width = 2.0 * e.rmax;
    const double span = (wall - e.left) / r->column_width;
    if (!(span < 1e7))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "wedge: the material spans %g m, over 1e7 columns of %g m", wall - e.left,
                         r->column_width);
    r->n_columns = (size_t)ceil(span);
    if (r->n_columns == 0)
        r->n_columns = 1;
    r->y_base = e.bottom;
    r->wall_x0 = wall;
    r->length0 = wall - e.left;
    r->threshold = thr > 0 ? thr : 2.0 * e.rmean;
    size_t *top = malloc(r->n_columns * sizeof *top);
    if (!top)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "wedge: no memory for %zu columns", r->n_columns);
    cdem_surface_column_tops(ref, r->x_left, r->column_width, r->n_columns, -INFINITY, wall, top);
    double sum = 0.0;
    size_t m = 0;
    for (size_t c = 0; c < r->n_columns; c++)
        if (top[c] != SIZE_MAX) {
            const double t = ref->y[top[c]] + ref->radius[top[c]];
            sum += t;
            r->top0 = m ? fmax(r->top0, t) : t;
            m++;
        }
    r->area0 = profile_area(r, ref, top, e.left, wall);
    free(top);
    if (m == 0)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "wedge: no free element left of the moving wall face x = %g m", wall);
    r->surface0 = sum / (double)m;
    r->thickness0 = r->surface0 - r->y_base;
    return CDEM_OK;
}

cdem_status cdem_wedge_measure(const cdem_wedge_ref *r, const cdem_state *ref,
                               const cdem_state *cur, cdem_wedge_row *row, cdem_error *err) {
    if (!r || !ref || !cur || !row)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "wedge: NULL argument");
    const extent e = free_extent(cur);
    if (e.n == 0)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "wedge: the state has no free (non-wall) elements (%zu elements)", cur->n);
    const double wall = moving_wall_face(cur, 0.5 * (r->x_left + r->wall_x0));
    if (!isfinite(wall))
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "wedge: the state has no moving wall element right of x = %g m",
                         0.5 * (r->x_left + r->wall_x0));
    const size_t nc = r->n_columns;
    size_t *top = malloc(nc * sizeof *top), *top0 = malloc(nc * sizeof *top0),
           *cnt = calloc(nc, sizeof *cnt);
    double *usum = calloc(nc, sizeof *usum);
    cdem_id_map map = {0};
    cdem_status st = CDEM_OK;
    if (!top || !top0 || !cnt || !usum)
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "wedge: no memory for %zu columns", nc);
    if (st == CDEM_OK)
        st = cdem_id_map_build(&map, ref, err);
    if (st != CDEM_OK) {
        free(top);
        free(top0);
        free(cnt);
        free(usum);
        return st;
    }
    /* surface profiles: the current one left of the wall face, the reference one */
    cdem_surface_column_tops(cur, r->x_left, r->column_width, nc, -INFINITY, wall, top);
    cdem_surface_column_tops(ref, r->x_left, r->column_width, nc, -INFINITY, r->wall_x0, top0);
    /* mean displacement magnitude of each column's elements present in the reference */
    const cdem_grid cols = {.x0 = r->x_left, .y0 = 0.0, .cell = r->column_width, .nx = nc, .ny = 1};
    for (size_t i = 0; i < cur->n; i++) {
        if (!cdem_surface_is_free(cur, i) || !(cur->x[i] < wall))
            continue;
        size_t c = 0;
        if (!cdem_grid_col_inside(&cols, cur->x[i], &c))
            continue;
        const size_t j = cdem_id_map_find(&map, cur->id[i]);
        if (j == SIZE_MAX)
            continue;
        usum[c] += hypot(cur->x[i] - ref->x[j], cur->y[i] - ref->y[j]);
        cnt[c]++;
    }
    double hmax = -INFINITY;
    size_t front = SIZE_MAX, front_t = SIZE_MAX;
    for (size_t c = 0; c < nc; c++) {
        if (top[c] == SIZE_MAX)
            continue;
        const double t = cur->y[top[c]] + cur->radius[top[c]];
        hmax = fmax(hmax, t);
        const int moved = cnt[c] > 0 && usum[c] / (double)cnt[c] > r->threshold;
        const int rose =
            top0[c] != SIZE_MAX && t - (ref->y[top0[c]] + ref->radius[top0[c]]) > r->threshold;
        if (front == SIZE_MAX && (moved || rose))
            front = c;
        if (front_t == SIZE_MAX && rose)
            front_t = c;
    }
    memset(row, 0, sizeof *row);
    row->wall_x = wall;
    row->height = isfinite(hmax) ? hmax - r->top0 : NAN;
    row->front_x = NAN;
    row->taper_deg = NAN;
    if (front != SIZE_MAX) {
        row->front_x = fmax(r->x_left + (double)front * r->column_width, e.left);
        row->length = fmax(0.0, wall - row->front_x);
    }
    if (front_t != SIZE_MAX) {
        const double xt = fmax(r->x_left + (double)front_t * r->column_width, e.left);
        row->length_thickened = fmax(0.0, wall - xt);
        double *fx = (double *)usum, *fy = malloc(nc * sizeof *fy); /* usum is free now */
        size_t m = 0;
        if (!fy)
            st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "wedge: no memory for %zu columns", nc);
        /* the column the wall face cuts counts only when at least half of it lies left of
         * the face: in a sliver of it the top is whatever element is squeezed at the wall's
         * foot (examples/wedge: a top near the base, 3 degrees off the taper) */
        const double half = 0.5 * r->column_width;
        for (size_t c = front_t; c < nc && fy; c++)
            if (top[c] != SIZE_MAX && wall - (r->x_left + (double)c * r->column_width) >= half) {
                fx[m] = cur->x[top[c]];
                fy[m] = cur->y[top[c]] + cur->radius[top[c]];
                m++;
            }
        if (fy && m >= 2) {
            double c0, c1, c00, c01, c11, ss;
            gsl_fit_linear(fx, 1, fy, 1, m, &c0, &c1, &c00, &c01, &c11, &ss);
            row->taper_deg = atan(c1) * rad2deg;
            row->n_fitted = m;
        }
        free(fy);
    }
    const double area = profile_area(r, cur, top, e.left, wall);
    row->area_change = area - r->area0;
    row->area_change_percent = r->area0 > 0 ? 100.0 * row->area_change / r->area0 : NAN;
    row->wall_force_x = row->wall_force_y = row->base_force_x = row->base_force_y = NAN;
    row->left_wall_force_x = row->left_wall_force_y = NAN;
    row->right_wall_force_x = row->right_wall_force_y = NAN;
    cdem_id_map_free(&map);
    free(top);
    free(top0);
    free(cnt);
    free(usum);
    return st;
}

/* The series columns cdem_wedge_forces averages, and where each mean goes in a row. */
typedef struct {
    size_t sample; /* offsetof(cdem_series_sample, ...) */
    size_t row;    /* offsetof(cdem_wedge_row, ...) */
} force_column;
#define FORCE(s, r)                                                                                \
    { offsetof(cdem_series_sample, s), offsetof(cdem_wedge_row, r) }
static const force_column force_columns[] = {
    FORCE(boundary_force_x, wall_force_x),
    FORCE(boundary_force_y, wall_force_y),
    FORCE(base_force_x, base_force_x),
    FORCE(base_force_y, base_force_y),
    FORCE(left_wall_force_x, left_wall_force_x),
    FORCE(left_wall_force_y, left_wall_force_y),
    FORCE(right_wall_force_x, right_wall_force_x),
    FORCE(right_wall_force_y, right_wall_force_y),
};
#undef FORCE
#define N_FORCES (sizeof force_columns / sizeof force_columns[0])

static double sample_value(const cdem_series_sample *q, size_t c) {
    double v;
    memcpy(&v, (const char *)q + force_columns[c].sample, sizeof v);
    return v;
}

void cdem_wedge_forces(const cdem_series_sample *smp, size_t n, long step_from, long step_to,
                       cdem_wedge_row *row) {
    double s[N_FORCES] = {0};
    size_t m = 0, nearest = SIZE_MAX;
    long best = 0;
    for (size_t k = 0; k < n; k++) {
        const long st = (long)smp[k].step;
        const long d = labs(st - step_to);
        if (nearest == SIZE_MAX || d < best) {
            nearest = k;
            best = d;
        }
        if (st > step_from && st <= step_to) {
            for (size_t c = 0; c < N_FORCES; c++)
                s[c] += sample_value(&smp[k], c);
            m++;
        }
    }
    if (m == 0 && nearest != SIZE_MAX) {
        for (size_t c = 0; c < N_FORCES; c++)
            s[c] = sample_value(&smp[nearest], c);
        m = 1;
    }
    const double inv = m ? 1.0 / (double)m : NAN;
    for (size_t c = 0; c < N_FORCES; c++) {
        const double mean = m ? s[c] * inv : NAN;
        memcpy((char *)row + force_columns[c].row, &mean, sizeof mean);
    }
}

cdem_status cdem_wedge_analyse(cdem_analysis *a, const cdem_wedge_options *opt, size_t first,
                               size_t last, cdem_wedge_row **rows, size_t *n_rows,
                               cdem_wedge_ref *ref, cdem_error *err) {
    if (!a || !rows || !n_rows || !ref)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "wedge: NULL argument");
    *rows = NULL;
    *n_rows = 0;
    const size_t count = cdem_analysis_count(a), e = cdem_analysis_equil_index(a);
    if (count == 0 || last >= count || first > last)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "wedge: increments %zu..%zu (indices) outside the file's 0..%zu", first,
                         last, count ? count - 1 : 0);
    const cdem_params *prm = cdem_analysis_params(a);
    if (prm->mode != CDEM_MODE_DETACHMENT)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "wedge: the run is a '%s' run (boundary.mode); the wedge measurement "
                         "needs boundary.mode = detachment",
                         cdem_mode_name(prm->mode));
    if (!cdem_analysis_equil_known(a))
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "wedge: the wedge is measured from the end of equilibration, which is not "
                         "reached: %s (its last increment, %d, is of the equilibration phase)",
                         cdem_analysis_equil_why(a), (int)cdem_analysis_info(a, count - 1)->number);
    if (first < e)
        first = e;
    if (last < e)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "wedge: increment %d is before the end of equilibration (increment "
                         "%d); the wedge is measured from there on",
                         (int)cdem_analysis_info(a, last)->number,
                         (int)cdem_analysis_info(a, e)->number);
    cdem_state r0 = {0};
    const cdem_state *s;
    CDEM_TRY(cdem_analysis_state(a, e, &s, err));
    CDEM_TRY(cdem_state_copy(&r0, s, err));
    cdem_series_sample *smp = NULL;
    size_t ns = 0;
    cdem_status st = cdem_wedge_reference(&r0, opt, ref, err);
    cdem_h5_reader *rd = cdem_analysis_reader(a);
    if (st == CDEM_OK && rd)
        st = cdem_h5_reader_read_series(rd, &smp, &ns, err);
    cdem_wedge_row *out = NULL;
    if (st == CDEM_OK && !(out = calloc(last - first + 1, sizeof *out)))
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "wedge: no memory for %zu rows", last - first + 1);
    for (size_t k = first; k <= last && st == CDEM_OK; k++) {
        const cdem_increment_info *in = cdem_analysis_info(a, k);
        cdem_wedge_row *row = &out[k - first];
        st = cdem_analysis_state(a, k, &s, err);
        if (st == CDEM_OK)
            st = cdem_wedge_measure(ref, &r0, s, row, err);
        if (st != CDEM_OK) { /* where: the messages of the state code name no increment */
            cdem_error_prefix(err, "increment %d against increment %d (the end of equilibration)",
                              (int)in->number, (int)cdem_analysis_info(a, e)->number);
            break;
        }
        row->number = (int)in->number;
        row->step = (long)in->step;
        row->shortening = in->net_displacement;
        row->shortening_percent = 100.0 * in->net_displacement / ref->length0;
        const long prev = k > 0 ? (long)cdem_analysis_info(a, k - 1)->step : -1;
        cdem_wedge_forces(smp, ns, prev, (long)in->step, row);
    }
    free(smp);
    cdem_state_free(&r0);
    if (st != CDEM_OK) {
        free(out);
        return st;
    }
    *rows = out;
    *n_rows = last - first + 1;
    return CDEM_OK;
}

static const char csv_header[] =
    "increment,step,shortening_m,shortening_percent,height_m,length_m,length_thickened_m,"
    "taper_deg,"
    "area_change_m2,area_change_percent,wall_force_x_N,wall_force_y_N,base_force_x_N,"
    "base_force_y_N,front_x_m,wall_x_m,n_fitted,left_wall_force_x_N,left_wall_force_y_N,"
    "right_wall_force_x_N,right_wall_force_y_N";

const char *cdem_wedge_csv_header(void) {
    return csv_header;
}

/* %.10g, or "nan" for any non-finite value. */
static void put(FILE *f, double v, const char *sep) {
    if (isfinite(v))
        fprintf(f, "%.10g%s", v, sep);
    else
        fprintf(f, "nan%s", sep);
}

cdem_status cdem_wedge_write_csv(FILE *f, const cdem_wedge_row *rows, size_t n, cdem_error *err) {
    if (!f || (n && !rows))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "wedge: NULL argument");
    fprintf(f, "%s\n", csv_header);
    for (size_t k = 0; k < n; k++) {
        const cdem_wedge_row *r = &rows[k];
        fprintf(f, "%d,%ld,", r->number, r->step);
        const double v[] = {r->shortening,       r->shortening_percent,
                            r->height,           r->length,
                            r->length_thickened, r->taper_deg,
                            r->area_change,      r->area_change_percent,
                            r->wall_force_x,     r->wall_force_y,
                            r->base_force_x,     r->base_force_y,
                            r->front_x,          r->wall_x};
        for (size_t j = 0; j < sizeof v / sizeof v[0]; j++)
            put(f, v[j], ",");
        fprintf(f, "%zu,", r->n_fitted);
        const double w[] = {r->left_wall_force_x, r->left_wall_force_y, r->right_wall_force_x,
                            r->right_wall_force_y};
        for (size_t j = 0; j < sizeof w / sizeof w[0]; j++)
            put(f, w[j], j + 1 < sizeof w / sizeof w[0] ? "," : "\n");
    }
    if (ferror(f))
        return CDEM_FAIL(err, CDEM_ERR_IO, "wedge: error writing the CSV output");
    return CDEM_OK;
}
