/* axes: see axes.h. Nodes are visited row by row; the kept nodes are compacted in that
 * order, so the output is the same for any thread count. */
#include "axes.h"

#include "grid.h"
#include "strain.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cdem_axes_free(cdem_axes *a) {
    if (!a)
        return;
    free(a->x);
    free(a->y);
    free(a->angle1);
    free(a->angle3);
    free(a->shear_a);
    free(a->shear_b);
    free(a->value);
    memset(a, 0, sizeof *a);
}

static double wrap(double a) {
    while (a <= -90.0)
        a += 180.0;
    while (a > 90.0)
        a -= 180.0;
    return a;
}

static cdem_status alloc_axes(cdem_axes *a, size_t n, cdem_error *err) {
    memset(a, 0, sizeof *a);
    size_t m = n ? n : 1;
    a->x = malloc(m * sizeof(double));
    a->y = malloc(m * sizeof(double));
    a->angle1 = malloc(m * sizeof(double));
    a->angle3 = malloc(m * sizeof(double));
    a->shear_a = malloc(m * sizeof(double));
    a->shear_b = malloc(m * sizeof(double));
    a->value = malloc(m * sizeof(double));
    if (!a->x || !a->y || !a->angle1 || !a->angle3 || !a->shear_a || !a->shear_b || !a->value) {
        cdem_axes_free(a);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "axes: out of memory for %zu grid nodes", n);
    }
    return CDEM_OK;
}

/* The node grid of an axes computation: nx x ny nodes at (xmin + i spacing,
 * ymin + j spacing), numbered row by row. */
typedef struct {
    double xmin, ymin, spacing;
    double rmax; /* the largest radius: a node's nearest element must be this near */
    size_t nx, ny;
} axes_grid;

/* The node grid over cur's bounding box (spacing <= 0: 2 x the largest radius); g->nx = 0
 * when there is nothing to fit (no elements, no finite position, no usable spacing). Refuses
 * an absurd extent (never thrash). */
static cdem_status axes_grid_of(const cdem_state *cur, double spacing, axes_grid *g,
                                cdem_error *err) {
    memset(g, 0, sizeof *g);
    const double rmax = cdem_strain_max_radius(cur);
    if (!(spacing > 0.0))
        spacing = 2.0 * rmax;
    if (!(spacing > 0.0) || !isfinite(spacing) || cur->n == 0)
        return CDEM_OK;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (size_t i = 0; i < cur->n; i++) {
        if (!isfinite(cur->x[i]) || !isfinite(cur->y[i]))
            continue;
        xmin = fmin(xmin, cur->x[i]);
        xmax = fmax(xmax, cur->x[i]);
        ymin = fmin(ymin, cur->y[i]);
        ymax = fmax(ymax, cur->y[i]);
    }
    if (!(xmax >= xmin))
        return CDEM_OK;
    const double span_x = floor((xmax - xmin) / spacing) + 1,
                 span_y = floor((ymax - ymin) / spacing) + 1;
    if (span_x * span_y > 4.0 * (double)cur->n + 1e4) /* absurd extent: refuse, never thrash */
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "axes: grid of %.0f x %.0f nodes at spacing %g m is too large", span_x,
                         span_y, spacing);
    *g = (axes_grid){.xmin = xmin,
                     .ymin = ymin,
                     .spacing = spacing,
                     .rmax = rmax,
                     .nx = (size_t)span_x,
                     .ny = (size_t)span_y};
    return CDEM_OK;
}

/* What the per-node fits read. */
typedef struct {
    const cdem_state *cur;
    const double *ref_x, *ref_y;  /* strain axes: reference position of each element of cur
                                     (NaN when absent from the reference) */
    const cdem_grid_index *index; /* cur's elements binned at the grid spacing */
    int stress;                   /* 1 stress axes, 0 strain axes */
} axes_input;

/* The axes at node (px, py): the direction of S1 (or sigma1) into *angle1 and the maximum
 * shear into *value; 0 when the node is left out (axes.h: no non-wall element nearest
 * within the largest radius, no element to fit, or an undefined or isotropic fit). */
static int node_axes(const axes_input *in, const axes_grid *g, double px, double py, double *angle1,
                     double *value) {
    const cdem_state *cur = in->cur;
    const cdem_grid_index *index = in->index;
    const double *ux = in->ref_x, *uy = in->ref_y;
    const double spacing = g->spacing, rmax = g->rmax;
    cdem_grid_box box;
    if (!cdem_grid_index_range(index, px, py, spacing, &box))
        return 0;
    double X[64], Y[64], U[64], V[64];
    size_t m = 0, nearest = SIZE_MAX;
    double dnear = INFINITY, s_xx = 0, s_yy = 0, s_xy = 0, mx = 0, my = 0;
    for (size_t cy = box.y_lo; cy <= box.y_hi; cy++)
        for (size_t cx = box.x_lo; cx <= box.x_hi; cx++) {
            const size_t c = cy * index->grid.nx + cx;
            for (int32_t q = index->start[c]; q < index->start[c + 1]; q++) {
                const size_t j = (size_t)index->items[q];
                const double dx = cur->x[j] - px, dy = cur->y[j] - py, d2 = dx * dx + dy * dy;
                if (d2 > spacing * spacing)
                    continue;
                if (d2 < dnear) {
                    dnear = d2;
                    nearest = j;
                }
                if (cur->flags[j] & CDEM_FLAGS_BOUNDARY)
                    continue;
                if (in->stress) {
                    s_xx += cur->sxx[j];
                    s_yy += cur->syy[j];
                    s_xy += cur->sxy[j];
                    m++;
                } else if (isfinite(ux[j]) && m < 64) {
                    X[m] = ux[j];
                    Y[m] = uy[j];
                    U[m] = cur->x[j] - ux[j];
                    V[m] = cur->y[j] - uy[j];
                    mx += X[m];
                    my += Y[m];
                    m++;
                }
            }
        }
    if (nearest == SIZE_MAX || (cur->flags[nearest] & CDEM_FLAGS_BOUNDARY) || dnear > rmax * rmax ||
        m == 0)
        return 0;
    double a1, val;
    if (in->stress) {
        cdem_stress_principal p;
        cdem_stress_principal_from(s_xx / (double)m, s_yy / (double)m, s_xy / (double)m, &p);
        a1 = p.angle1;
        val = p.max_shear;
    } else {
        mx /= (double)m;
        my /= (double)m;
        for (size_t q = 0; q < m; q++) {
            X[q] -= mx;
            Y[q] -= my;
        }
        double grad[4];
        if (!cdem_strain_fit(m, X, Y, U, V, grad, NULL))
            return 0;
        cdem_strain_measures sm;
        cdem_strain_measures_from_gradient(grad, &sm);
        a1 = sm.angle1;
        val = sm.max_shear;
    }
    if (!isfinite(a1))
        return 0;
    *angle1 = a1;
    *value = val;
    return 1;
}

/* The nodes k of all with keep[k] set, in node order, into out (allocated here). */
static cdem_status kept_nodes(const cdem_axes *all, const unsigned char *keep, size_t nn,
                              double spacing, cdem_axes *out, cdem_error *err) {
    size_t kept = 0;
    for (size_t k = 0; k < nn; k++)
        kept += keep[k];
    CDEM_TRY(alloc_axes(out, kept, err));
    out->spacing = spacing;
    for (size_t k = 0; k < nn; k++) {
        if (!keep[k])
            continue;
        size_t j = out->n++;
        out->x[j] = all->x[k];
        out->y[j] = all->y[k];
        out->angle1[j] = all->angle1[k];
        out->angle3[j] = all->angle3[k];
        out->shear_a[j] = all->shear_a[k];
        out->shear_b[j] = all->shear_b[k];
        out->value[j] = all->value[k];
    }
    return CDEM_OK;
}

/* Shared driver: stress = 0 for strain axes (ref required), 1 for stress axes. The nodes
 * are fitted in parallel, each into its own slot of `all`; kept_nodes then compacts them. */
static cdem_status axes_run(const cdem_state *ref, const cdem_state *cur, double spacing,
                            int stress, cdem_axes *out, cdem_error *err) {
    memset(out, 0, sizeof *out);
    axes_grid g;
    CDEM_TRY(axes_grid_of(cur, spacing, &g, err));
    if (g.nx == 0)
        return alloc_axes(out, 0, err);
    const size_t nx = g.nx, nn = g.nx * g.ny;

    cdem_id_map ref_map = {0};
    double *ux = NULL, *uy = NULL;
    cdem_grid_index grid = {0};
    cdem_axes all = {0};
    unsigned char *keep = NULL;
    cdem_status st = alloc_axes(&all, nn, err);
    if (st != CDEM_OK)
        return st;
    keep = calloc(nn, 1);
    ux = malloc(cur->n * sizeof *ux);
    uy = malloc(cur->n * sizeof *uy);
    if (!keep || !ux || !uy) {
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "axes: out of memory for %zu grid nodes", nn);
        goto done;
    }
    /* Reference positions of cur's elements (strain axes); NaN when absent. */
    if (!stress) {
        st = cdem_id_map_build(&ref_map, ref, err);
        if (st != CDEM_OK)
            goto done;
        for (size_t i = 0; i < cur->n; i++) {
            size_t r = cdem_id_map_find(&ref_map, cur->id[i]);
            ux[i] = r == SIZE_MAX ? NAN : ref->x[r];
            uy[i] = r == SIZE_MAX ? NAN : ref->y[r];
        }
    }
    st = cdem_grid_index_build(&grid, cur->x, cur->y, cur->n, NULL, g.spacing, err);
    if (st != CDEM_OK)
        goto done;
    const axes_input in = {.cur = cur, .ref_x = ux, .ref_y = uy, .index = &grid, .stress = stress};
    const long nnl = (long)nn;
#pragma omp parallel for schedule(static)
    for (long kk = 0; kk < nnl; kk++) {
        const size_t k = (size_t)kk;
        const double px = g.xmin + (double)(k % nx) * g.spacing,
                     py = g.ymin + (double)(k / nx) * g.spacing;
        double a1, val;
        if (!node_axes(&in, &g, px, py, &a1, &val))
            continue;
        keep[k] = 1;
        all.x[k] = px;
        all.y[k] = py;
        all.angle1[k] = a1;
        all.angle3[k] = wrap(a1 + 90.0);
        all.shear_a[k] = wrap(a1 + 45.0);
        all.shear_b[k] = wrap(a1 - 45.0);
        all.value[k] = val;
    }
    st = kept_nodes(&all, keep, nn, g.spacing, out, err);
done:
    cdem_axes_free(&all);
    free(keep);
    free(ux);
    free(uy);
    cdem_grid_index_free(&grid);
    cdem_id_map_free(&ref_map);
    return st;
}

cdem_status cdem_axes_strain(const cdem_state *ref, const cdem_state *cur, double spacing,
                             cdem_axes *out, cdem_error *err) {
    return axes_run(ref, cur, spacing, 0, out, err);
}

cdem_status cdem_axes_stress(const cdem_state *cur, double spacing, cdem_axes *out,
                             cdem_error *err) {
    if (!cur->has_stress) {
        memset(out, 0, sizeof *out);
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "stress axes: this increment stores no stress (run with "
                         "physics.calculate_stress = on)");
    }
    return axes_run(NULL, cur, spacing, 1, out, err);
}
