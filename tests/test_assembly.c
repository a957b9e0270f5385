/* Tests of the assembly generator (solver/packing/assembly.c): element counts against the original
 * program's figures, geometry (inside the box, no overlap, no large gaps, every disc
 * supported), walls, ordering, size distribution, determinism, the largest assembly and
 * every error path. Params and model are filled by hand (radii 50..125 m at unit scaling
 * 1000, halved for half radii; masses 2500 pi r^2) so the test depends on no other module. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "assembly.h"
#include "bc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const double unit_radii[CDEM_NUM_RADII] = {0.05, 0.075, 0.1, 0.125};

static void fill_model(cdem_model *m, double scaling, int half) {
    memset(m, 0, sizeof *m);
    for (int c = 0; c < CDEM_NUM_RADII; c++) {
        m->radius[c] = unit_radii[c] * scaling * (half ? 0.5 : 1.0);
        m->mass[c] = 2500.0 * M_PI * m->radius[c] * m->radius[c];
    }
    m->max_radius = m->radius[CDEM_NUM_RADII - 1];
    m->average_radius = 0.25 * (m->radius[0] + m->radius[1] + m->radius[2] + m->radius[3]);
}

static void fill_params(cdem_params *p, double w, double h, double scaling, int half, long seed) {
    memset(p, 0, sizeof *p);
    p->width = w;
    p->height = h;
    p->unit_scaling = scaling;
    p->half_radii = half;
    p->wall_height_multiplier = 1;
    p->base_spacing = 2.0;
    p->seed = seed;
}

/* Builds an assembly; fails the test on error. */
static void build(const cdem_params *p, const cdem_model *m, cdem_state *s,
                  cdem_assembly_info *info) {
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_state_init(s, 0, 0, &err), CDEM_OK);
    cdem_status st = cdem_assembly_build(p, m, s, info, &err);
    if (st != CDEM_OK)
        fail_msg("cdem_assembly_build failed: %s", err.msg);
}

/* A cell grid over the internal elements of a state (cells of 2 x max radius). */
typedef struct {
    double x0, y0, cell;
    int ncols, nrows;
    size_t *start; /* [ncols * nrows + 1] offsets into idx */
    size_t *idx;   /* element indices sorted by cell */
} grid;

static int gcol(const grid *g, double x) {
    int c = (int)floor((x - g->x0) / g->cell);
    return c < 0 ? 0 : (c >= g->ncols ? g->ncols - 1 : c);
}
static int grow(const grid *g, double y) {
    int r = (int)floor((y - g->y0) / g->cell);
    return r < 0 ? 0 : (r >= g->nrows ? g->nrows - 1 : r);
}

static void grid_build(grid *g, const cdem_state *s, double cell) {
    double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL;
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAG_WALL)
            continue;
        xmin = fmin(xmin, s->x[i]);
        xmax = fmax(xmax, s->x[i]);
        ymin = fmin(ymin, s->y[i]);
        ymax = fmax(ymax, s->y[i]);
    }
    g->x0 = xmin;
    g->y0 = ymin;
    g->cell = cell;
    g->ncols = (int)((xmax - xmin) / cell) + 1;
    g->nrows = (int)((ymax - ymin) / cell) + 1;
    size_t nc = (size_t)g->ncols * g->nrows;
    g->start = calloc(nc + 1, sizeof *g->start);
    g->idx = malloc((s->n + 1) * sizeof *g->idx);
    assert_non_null(g->start);
    assert_non_null(g->idx);
    for (size_t i = 0; i < s->n; i++)
        if (!(s->flags[i] & CDEM_FLAG_WALL))
            g->start[(size_t)grow(g, s->y[i]) * g->ncols + gcol(g, s->x[i]) + 1]++;
    for (size_t c = 0; c < nc; c++)
        g->start[c + 1] += g->start[c];
    size_t *fill = calloc(nc, sizeof *fill);
    assert_non_null(fill);
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAG_WALL)
            continue;
        size_t c = (size_t)grow(g, s->y[i]) * g->ncols + gcol(g, s->x[i]);
        g->idx[g->start[c] + fill[c]++] = i;
    }
    free(fill);
}

static void grid_free(grid *g) {
    free(g->start);
    free(g->idx);
}

/* Largest overlap (r_i + r_j - distance) between internal discs, as a fraction of the
 * smaller radius; also counts each disc's contacts (gap below tol x smaller radius). */
static double max_overlap_fraction(const cdem_state *s, const grid *g, int *contacts, double tol) {
    double worst = 0.0;
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAG_WALL)
            continue;
        int c0 = gcol(g, s->x[i]) - 1, c1 = gcol(g, s->x[i]) + 1;
        int r0 = grow(g, s->y[i]) - 1, r1 = grow(g, s->y[i]) + 1;
        for (int r = r0 < 0 ? 0 : r0; r <= r1 && r < g->nrows; r++)
            for (int c = c0 < 0 ? 0 : c0; c <= c1 && c < g->ncols; c++) {
                size_t cell = (size_t)r * g->ncols + c;
                for (size_t q = g->start[cell]; q < g->start[cell + 1]; q++) {
                    size_t j = g->idx[q];
                    if (j == i)
                        continue;
                    double d = hypot(s->x[j] - s->x[i], s->y[j] - s->y[i]);
                    double rs = fmin(s->radius[i], s->radius[j]);
                    double ov = (s->radius[i] + s->radius[j] - d) / rs;
                    worst = fmax(worst, ov);
                    if (contacts && fabs(ov) < tol)
                        contacts[i]++;
                }
            }
    }
    return worst;
}

/* 1 when disc i rests on the base, or when the upward vertical lies in the cone of two of
 * its contact normals (partner centre -> disc centre; lateral walls push horizontally), so
 * compressive contact forces alone can balance its weight. */
static int supported(const cdem_state *s, const grid *g, size_t i, double w) {
    double r = s->radius[i], nx[64], ny[64];
    int n = 0;
    if (fabs(s->y[i] - r) < 1e-6 * r)
        return 1;
    if (fabs(s->x[i] - r) < 1e-6 * r) {
        nx[n] = 1.0;
        ny[n++] = 0.0;
    }
    if (fabs(w - s->x[i] - r) < 1e-6 * r) {
        nx[n] = -1.0;
        ny[n++] = 0.0;
    }
    int c = gcol(g, s->x[i]), rr = grow(g, s->y[i]);
    for (int row = rr - 1; row <= rr + 1; row++)
        for (int col = c - 1; col <= c + 1; col++) {
            if (row < 0 || col < 0 || row >= g->nrows || col >= g->ncols)
                continue;
            size_t cell = (size_t)row * g->ncols + col;
            for (size_t q = g->start[cell]; q < g->start[cell + 1] && n < 64; q++) {
                size_t j = g->idx[q];
                double dx = s->x[i] - s->x[j], dy = s->y[i] - s->y[j];
                double d = hypot(dx, dy);
                if (j != i && fabs(d - r - s->radius[j]) < 1e-6 * fmin(r, s->radius[j])) {
                    nx[n] = dx / d;
                    ny[n++] = dy / d;
                }
            }
        }
    for (int a = 0; a < n; a++)
        for (int b = a + 1; b < n; b++) {
            double det = nx[a] * ny[b] - ny[a] * nx[b];
            if (fabs(det) < 1e-12)
                continue;
            double fa = -nx[b] / det, fb = nx[a] / det; /* (0, 1) = fa n_a + fb n_b */
            if (fa >= -1e-9 && fb >= -1e-9)
                return 1;
        }
    return 0;
}

/* ---------------------------------------------------------------- counts */

static void test_assembly_paper_counts(void **unused) {
    (void)unused;
    /* the original program's figures (Geosphere paper): width, height, half radii, count */
    const struct {
        double w, h;
        int half;
        long paper;
    } cases[] = {{10, 5, 0, 2121}, {10, 5, 1, 8342}, {15, 3, 1, 7600}, {25, 2.5, 1, 10520}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        cdem_params p;
        cdem_model m;
        fill_params(&p, cases[k].w, cases[k].h, 1000, cases[k].half, 1);
        fill_model(&m, 1000, cases[k].half);
        cdem_state s;
        cdem_assembly_info info;
        build(&p, &m, &s, &info);
        double dev = 100.0 * (double)(info.n_internal - cases[k].paper) / cases[k].paper;
        printf("    %g x %g units, half radii %d: %ld internal elements (paper %ld, %+.2f %%), "
               "%ld wall, area fraction %.4f, top mean %.0f m max %.0f m\n",
               cases[k].w, cases[k].h, cases[k].half, info.n_internal, cases[k].paper, dev,
               info.n_wall, info.area_fraction, info.top_mean, info.top_max);
        assert_true(fabs(dev) <= 3.0);
        /* the deposition never needed its numerical guards */
        assert_int_equal(info.n_guard_discards, 0);
        size_t n_int = 0;
        for (size_t i = 0; i < s.n; i++)
            n_int += !(s.flags[i] & CDEM_FLAG_WALL);
        assert_int_equal(n_int, info.n_internal);
        assert_int_equal(s.n, (size_t)(info.n_internal + info.n_wall));
        cdem_state_free(&s);
    }
}

/* The count is independent of the unit scaling (the packing is scale-free) within noise,
 * and cdem_assembly_count agrees with cdem_assembly_build. */
static void test_assembly_count_matches_build(void **unused) {
    (void)unused;
    cdem_params p;
    cdem_model m;
    fill_params(&p, 12, 4, 250, 0, 7);
    fill_model(&m, 250, 0);
    cdem_state s;
    cdem_assembly_info info;
    build(&p, &m, &s, &info);
    long ni = -1, nw = -1;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_assembly_count(&p, &m, &ni, &nw, &err), CDEM_OK);
    assert_int_equal(ni, info.n_internal);
    assert_int_equal(nw, info.n_wall);
    assert_int_equal(cdem_assembly_count(&p, &m, NULL, NULL, &err), CDEM_OK);
    /* same box at unit scaling 1000: same count within 1 % */
    cdem_params p2 = p;
    cdem_model m2;
    p2.unit_scaling = 1000;
    fill_model(&m2, 1000, 0);
    long ni2 = 0;
    assert_int_equal(cdem_assembly_count(&p2, &m2, &ni2, NULL, &err), CDEM_OK);
    printf("    12 x 4 units: %ld elements at 250 m, %ld at 1000 m\n", ni, ni2);
    assert_true(labs(ni - ni2) <= 0.01 * ni);
    cdem_state_free(&s);
}

/* Every corner of the parameter ranges (width 10-100, height 2.5-7.5 units, unit scaling
 * 100-1000 m, both radius sets, wall multiplier 1-4) builds a valid packing whose number
 * of elements per unit area stays within 3 % of the original program's (42.1 per unit^2,
 * the mean of its four figures in full-radius terms; 4 x that with half radii). */
static void test_assembly_density_across_ranges(void **unused) {
    (void)unused;
    const double widths[] = {10, 100}, heights[] = {2.5, 7.5};
    int k = 0;
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++)
            for (int half = 0; half <= 1; half++, k++) {
                if (a == 1 && b == 1 && half == 1)
                    continue; /* the largest case has its own test */
                cdem_params p;
                cdem_model m;
                double scaling = (k % 3 == 0) ? 100 : ((k % 3 == 1) ? 1000 : 617);
                fill_params(&p, widths[a], heights[b], scaling, half, 100 + k);
                p.wall_height_multiplier = 1 + k % 4;
                fill_model(&m, scaling, half);
                cdem_state s;
                cdem_assembly_info info;
                build(&p, &m, &s, &info);
                double density = info.n_internal / (p.width * p.height) / (half ? 4.0 : 1.0);
                grid g;
                grid_build(&g, &s, 2.0 * m.radius[3]);
                double worst = max_overlap_fraction(&s, &g, NULL, 0.0);
                double w = p.width * p.unit_scaling, tol = 1e-9 * w;
                long outside = 0;
                for (size_t i = 0; i < s.n; i++)
                    if (!(s.flags[i] & CDEM_FLAG_WALL))
                        outside += s.x[i] - s.radius[i] < -tol || s.x[i] + s.radius[i] > w + tol ||
                                   s.y[i] - s.radius[i] < -tol;
                printf("    %g x %g units, %g m, half %d: %ld elements, %.2f per unit^2 "
                       "(full-radius terms, original 42.1), max overlap %.1e\n",
                       p.width, p.height, scaling, half, info.n_internal, density, worst);
                assert_true(fabs(density / 42.1 - 1.0) < 0.03);
                assert_true(worst < 1e-6);
                assert_int_equal(outside, 0);
                grid_free(&g);
                cdem_state_free(&s);
            }
}

/* ---------------------------------------------------------------- geometry */

static const struct {
    double w, h, scaling;
    int half;
} geo_cases[] = {
    {10, 5, 1000, 0}, {10, 5, 1000, 1}, {25, 2.5, 1000, 1}, {10, 2.5, 100, 0}, {13.7, 7.5, 430, 1},
};

static void test_assembly_inside_box(void **unused) {
    (void)unused;
    for (size_t k = 0; k < sizeof geo_cases / sizeof geo_cases[0]; k++) {
        cdem_params p;
        cdem_model m;
        fill_params(&p, geo_cases[k].w, geo_cases[k].h, geo_cases[k].scaling, geo_cases[k].half, 3);
        fill_model(&m, p.unit_scaling, p.half_radii);
        cdem_state s;
        cdem_assembly_info info;
        build(&p, &m, &s, &info);
        double w = p.width * p.unit_scaling, h = p.height * p.unit_scaling;
        double tol = 1e-9 * w;
        long n_int = 0;
        for (size_t i = 0; i < s.n; i++) {
            if (s.flags[i] & CDEM_FLAG_WALL)
                continue;
            /* internal elements come first, with consecutive ids from 0 */
            assert_int_equal(s.id[i], (int32_t)i);
            n_int++;
            assert_true(s.x[i] - s.radius[i] >= -tol);
            assert_true(s.x[i] + s.radius[i] <= w + tol);
            assert_true(s.y[i] - s.radius[i] >= -tol);
            /* fill rule: the disc reaches down to the assembly height */
            assert_true(s.y[i] - s.radius[i] <= h + tol);
            assert_int_equal(s.layer[i], 0);
            assert_int_equal(s.flags[i], 0);
            assert_int_equal(s.born[i], 0);
            assert_true(s.vx[i] == 0.0 && s.vy[i] == 0.0);
            int cls = -1;
            for (int c = 0; c < CDEM_NUM_RADII; c++)
                if (s.radius[i] == m.radius[c])
                    cls = c;
            assert_true(cls >= 0);
            assert_true(s.mass[i] == m.mass[cls]);
        }
        assert_int_equal(n_int, info.n_internal);
        /* the surface lies about one to two mean radii above the height */
        assert_true(info.top_mean > h && info.top_mean < h + 4.0 * m.radius[3]);
        assert_true(info.top_max >= info.top_mean && info.top_max <= h + 2.0 * m.radius[3] + tol);
        cdem_state_free(&s);
    }
}

static void test_assembly_no_overlap_and_supported(void **unused) {
    (void)unused;
    for (size_t k = 0; k < sizeof geo_cases / sizeof geo_cases[0]; k++) {
        cdem_params p;
        cdem_model m;
        fill_params(&p, geo_cases[k].w, geo_cases[k].h, geo_cases[k].scaling, geo_cases[k].half, 5);
        fill_model(&m, p.unit_scaling, p.half_radii);
        cdem_state s;
        cdem_assembly_info info;
        build(&p, &m, &s, &info);
        grid g;
        grid_build(&g, &s, 2.0 * m.radius[3]);
        int *contacts = calloc(s.n, sizeof *contacts);
        assert_non_null(contacts);
        /* overlap: below 1e-6 of the smaller radius (deposition leaves exact tangencies) */
        double worst = max_overlap_fraction(&s, &g, contacts, 1e-6);
        if (k == 0) { /* cross-check the grid against all pairs on the small case */
            double all = 0.0;
            for (size_t i = 0; i < s.n; i++)
                for (size_t j = i + 1; j < s.n; j++) {
                    if ((s.flags[i] | s.flags[j]) & CDEM_FLAG_WALL)
                        continue;
                    double d = hypot(s.x[j] - s.x[i], s.y[j] - s.y[i]);
                    all =
                        fmax(all, (s.radius[i] + s.radius[j] - d) / fmin(s.radius[i], s.radius[j]));
                }
            assert_true(fabs(all - worst) < 1e-12);
        }
        /* supported: every disc rests on the base, or two of its contacts (discs or lateral
         * walls) can hold it against gravity with compressive forces */
        double w = p.width * p.unit_scaling;
        long unsupported = 0, sum_contacts = 0;
        for (size_t i = 0; i < s.n; i++) {
            if (s.flags[i] & CDEM_FLAG_WALL)
                continue;
            sum_contacts += contacts[i];
            if (!supported(&s, &g, i, w))
                unsupported++;
        }
        printf("    %g x %g units (%g m, half %d): %ld elements, max overlap %.2e of the smaller "
               "radius, mean contacts %.2f, unsupported %ld\n",
               p.width, p.height, p.unit_scaling, p.half_radii, info.n_internal, worst,
               (double)sum_contacts / info.n_internal, unsupported);
        assert_true(worst < 1e-6);
        assert_int_equal(unsupported, 0);
        free(contacts);
        grid_free(&g);
        cdem_state_free(&s);
    }
}

/* Largest empty circle: probes on a grid of spacing min radius / 2 inside the filled region
 * (0 <= x <= width, 0 <= y <= height - 2 x max radius), each measuring the distance to the
 * nearest disc surface or wall. The largest must stay below one max radius (a pore that
 * could not even take the largest element). */
static void test_assembly_no_large_gaps(void **unused) {
    (void)unused;
    for (size_t k = 0; k < 4; k++) {
        cdem_params p;
        cdem_model m;
        fill_params(&p, geo_cases[k].w, geo_cases[k].h, geo_cases[k].scaling, geo_cases[k].half,
                    11);
        fill_model(&m, p.unit_scaling, p.half_radii);
        cdem_state s;
        build(&p, &m, &s, NULL);
        double rmax = m.radius[3], w = p.width * p.unit_scaling, h = p.height * p.unit_scaling;
        grid g;
        grid_build(&g, &s, 2.0 * rmax);
        double step = 0.5 * m.radius[0], largest = 0.0;
        for (double y = 0.0; y <= h - 2.0 * rmax; y += step) {
            for (double x = 0.0; x <= w; x += step) {
                double empty = fmin(fmin(x, w - x), y); /* distance to the walls */
                int c = gcol(&g, x), r = grow(&g, y);
                for (int rr = r - 2; rr <= r + 2; rr++)
                    for (int cc = c - 2; cc <= c + 2; cc++) {
                        if (rr < 0 || cc < 0 || rr >= g.nrows || cc >= g.ncols)
                            continue;
                        size_t cell = (size_t)rr * g.ncols + cc;
                        for (size_t q = g.start[cell]; q < g.start[cell + 1]; q++) {
                            size_t j = g.idx[q];
                            empty = fmin(empty, hypot(s.x[j] - x, s.y[j] - y) - s.radius[j]);
                        }
                    }
                largest = fmax(largest, empty);
            }
        }
        printf("    %g x %g units (%g m, half %d): largest empty circle %.3f x max radius\n",
               p.width, p.height, p.unit_scaling, p.half_radii, largest / rmax);
        /* the search window (2 cells = 4 max radii) is wide enough for this bound */
        assert_true(largest < 1.0 * rmax);
        grid_free(&g);
        cdem_state_free(&s);
    }
}

/* Size distribution: number fractions 4:3:2:1 (smallest first) within 2 percentage points
 * (the exact bag composition is only perturbed by discards at the top surface). */
static void test_assembly_size_distribution(void **unused) {
    (void)unused;
    const double expect[CDEM_NUM_RADII] = {0.4, 0.3, 0.2, 0.1};
    for (int half = 0; half <= 1; half++) {
        cdem_params p;
        cdem_model m;
        fill_params(&p, 10, 5, 1000, half, 2);
        fill_model(&m, 1000, half);
        cdem_state s;
        cdem_assembly_info info;
        build(&p, &m, &s, &info);
        long count[CDEM_NUM_RADII] = {0};
        for (size_t i = 0; i < s.n; i++)
            if (!(s.flags[i] & CDEM_FLAG_WALL))
                for (int c = 0; c < CDEM_NUM_RADII; c++)
                    count[c] += s.radius[i] == m.radius[c];
        printf("    half %d fractions:", half);
        for (int c = 0; c < CDEM_NUM_RADII; c++) {
            double f = (double)count[c] / info.n_internal;
            printf(" %.3f", f);
            assert_true(fabs(f - expect[c]) < 0.02);
        }
        printf("\n");
        cdem_state_free(&s);
    }
}

/* Internal elements are ordered row-major by cells of 2 x max radius (bottom row first). */
static void test_assembly_sorted_by_cell(void **unused) {
    (void)unused;
    cdem_params p;
    cdem_model m;
    fill_params(&p, 25, 2.5, 1000, 1, 4);
    fill_model(&m, 1000, 1);
    cdem_state s;
    cdem_assembly_info info;
    build(&p, &m, &s, &info);
    double cell = 2.0 * m.radius[3];
    long ncols = (long)ceil(p.width * p.unit_scaling / cell) + 1, prev = -1;
    for (long i = 0; i < info.n_internal; i++) {
        long key = (long)floor(s.y[i] / cell) * ncols + (long)floor(s.x[i] / cell);
        assert_true(key >= prev);
        prev = key;
    }
    cdem_state_free(&s);
}

/* ---------------------------------------------------------------- walls */

/* Centres of the wall elements along one wall, sorted; checks spacing and extent. */
static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void check_wall_line(const double *pos, size_t n, double from, double to, double rw,
                            double spacing) {
    assert_true(n >= 2);
    assert_true(pos[0] <= from + 1e-9 * fabs(to));
    assert_true(pos[n - 1] >= to - 1e-9 * fabs(to));
    for (size_t i = 1; i < n; i++) {
        /* centres at most spacing wall radii apart (1: overlapping; 2: touching, no gap) */
        assert_true(pos[i] - pos[i - 1] <= spacing * rw * (1.0 + 1e-9));
        assert_true(pos[i] - pos[i - 1] > 0.5 * spacing * rw);
    }
}

static void test_assembly_walls_complete(void **unused) {
    (void)unused;
    for (int mult = 1; mult <= 4; mult += 3) {
        cdem_params p;
        cdem_model m;
        fill_params(&p, 10, 5, 1000, 0, 1);
        p.wall_height_multiplier = mult;
        p.base_spacing = mult == 1 ? 2.0 : 1.0; /* the rough (default) and the smooth base */
        fill_model(&m, 1000, 0);
        cdem_state s;
        cdem_assembly_info info;
        build(&p, &m, &s, &info);
        double w = p.width * p.unit_scaling, h = p.height * p.unit_scaling, rw = m.radius[0];
        assert_true(info.wall_radius == rw && info.wall_spacing == rw);
        assert_true(info.base_spacing <= p.base_spacing * rw * (1.0 + 1e-12) &&
                    info.base_spacing > 0.9 * p.base_spacing * rw);
        if (mult == 1) { /* the biaxial test's base row is a smooth platen, whatever is set:
                          * the mode's part of the model (its derive hook) says so */
            cdem_params pb = p;
            pb.mode = CDEM_MODE_BIAXIAL;
            const cdem_bc_ops *ops = NULL;
            cdem_error err;
            assert_int_equal(cdem_bc_find(CDEM_MODE_BIAXIAL, &ops, &err), CDEM_OK);
            cdem_model mb = m;
            mb.mode = cdem_model_mode_default();
            ops->derive(&pb, &mb.mode);
            cdem_state sb;
            cdem_assembly_info ib;
            build(&pb, &mb, &sb, &ib);
            assert_true(ib.base_spacing <= rw * (1.0 + 1e-12) && ib.base_spacing > 0.9 * rw);
            cdem_state_free(&sb);
        }
        double *base = malloc(s.n * sizeof *base), *left = malloc(s.n * sizeof *left),
               *right = malloc(s.n * sizeof *right);
        size_t nb = 0, nl = 0, nr = 0;
        long n_wall = 0;
        for (size_t i = 0; i < s.n; i++) {
            if (!(s.flags[i] & CDEM_FLAG_WALL))
                continue;
            n_wall++;
            /* the base row is also flagged base (material.base_*) */
            const int is_base = fabs(s.y[i] + rw) < 1e-9 * h;
            assert_int_equal(s.flags[i],
                             is_base ? CDEM_FLAG_WALL | CDEM_FLAG_BASE : CDEM_FLAG_WALL);
            assert_int_equal(s.layer[i], 0);
            assert_true(s.radius[i] == rw);
            assert_true(s.mass[i] == m.mass[0]);
            /* walls follow the internal elements */
            assert_true((long)i >= info.n_internal);
            if (fabs(s.y[i] + rw) < 1e-9 * h)
                base[nb++] = s.x[i];
            else if (fabs(s.x[i] + rw) < 1e-9 * w)
                left[nl++] = s.y[i];
            else if (fabs(s.x[i] - w - rw) < 1e-9 * w)
                right[nr++] = s.y[i];
            else
                fail_msg("wall element %zu at (%g, %g) is on no wall", i, s.x[i], s.y[i]);
        }
        assert_int_equal(n_wall, info.n_wall);
        qsort(base, nb, sizeof *base, cmp_double);
        qsort(left, nl, sizeof *left, cmp_double);
        qsort(right, nr, sizeof *right, cmp_double);
        /* the base runs under both lateral walls; lateral walls from the base corner up */
        check_wall_line(base, nb, -rw, w + rw, rw, p.base_spacing);
        check_wall_line(left, nl, 0.0, mult * h, rw, 1.0);
        check_wall_line(right, nr, 0.0, mult * h, rw, 1.0);
        assert_true(left[0] - (-rw) <= rw * (1.0 + 1e-9)); /* joined to the corner element */
        assert_true(left[nl - 1] <= mult * h + rw);
        /* a wall gap (spacing - 2 rw) never exceeds the smallest internal diameter */
        printf("    multiplier %d: %zu base, %zu left, %zu right wall elements\n", mult, nb, nl,
               nr);
        free(base);
        free(left);
        free(right);
        cdem_state_free(&s);
    }
}

/* ---------------------------------------------------------------- determinism, size */

/* In the repose test the base runs on past each removed wall by the assembly's width, at the
 * base's spacing, appended after the lateral walls; the packing and the other walls are
 * those of any other mode, element for element. */
static void test_assembly_repose_base_extends(void **unused) {
    (void)unused;
    cdem_params p;
    cdem_model m;
    fill_params(&p, 10, 5, 1000, 0, 1);
    fill_model(&m, 1000, 0);
    cdem_state s0;
    cdem_assembly_info i0;
    build(&p, &m, &s0, &i0); /* the default mode: the base ends under the lateral walls */
    const double w = p.width * p.unit_scaling, rw = m.radius[0];
    for (int both = 0; both < 2; both++) {
        cdem_params pr = p;
        pr.mode = CDEM_MODE_REPOSE;
        pr.repose_walls = both ? CDEM_WALLS_BOTH : CDEM_WALLS_RIGHT;
        /* the extension is the mode's (its derive hook): taken from the derived model */
        cdem_params full;
        cdem_params_defaults(&full);
        full.mode = pr.mode;
        full.repose_walls = pr.repose_walls;
        cdem_model derived, mr = m;
        cdem_error err;
        if (cdem_bc_derive_model(&full, &derived, &err) != CDEM_OK)
            fail_msg("%s", err.msg);
        mr.mode = derived.mode;
        assert_true(mr.mode.base_beyond_right == 1.0);
        assert_true(mr.mode.base_beyond_left == (both ? 1.0 : 0.0));
        cdem_state s;
        cdem_assembly_info info;
        build(&pr, &mr, &s, &info);
        assert_int_equal(info.n_internal, i0.n_internal);
        assert_true(s.n > s0.n);
        for (size_t i = 0; i < s0.n; i++) /* the same elements first */
            assert_true(s.x[i] == s0.x[i] && s.y[i] == s0.y[i] && s.flags[i] == s0.flags[i]);
        double lo = INFINITY, hi = -INFINITY;
        for (size_t i = s0.n; i < s.n; i++) { /* then base discs beyond the walls */
            assert_int_equal(s.flags[i], CDEM_FLAG_WALL | CDEM_FLAG_BASE);
            assert_true(s.y[i] == -rw && s.radius[i] == rw);
            assert_true(s.x[i] > w + rw || (both && s.x[i] < -rw));
            lo = fmin(lo, s.x[i]);
            hi = fmax(hi, s.x[i]);
        }
        assert_true(hi >= 2.0 * w + rw && hi < 2.0 * w + rw + i0.base_spacing * (1 + 1e-9));
        if (both)
            assert_true(lo <= -w - rw && lo > -w - rw - i0.base_spacing * (1 + 1e-9));
        else
            assert_true(lo > w + rw);
        assert_int_equal(s.n, (size_t)(info.n_internal + info.n_wall));
        /* the extension keeps the base's spacing: the whole row, sorted */
        double *base = malloc(s.n * sizeof *base);
        size_t nb = 0;
        for (size_t i = 0; i < s.n; i++)
            if (s.flags[i] & CDEM_FLAG_BASE)
                base[nb++] = s.x[i];
        qsort(base, nb, sizeof *base, cmp_double);
        check_wall_line(base, nb, both ? -w - rw : -rw, 2.0 * w + rw, rw, p.base_spacing);
        free(base);
        cdem_state_free(&s);
    }
    cdem_state_free(&s0);
}

static void test_assembly_deterministic_by_seed(void **unused) {
    (void)unused;
    cdem_params p;
    cdem_model m;
    fill_params(&p, 10, 5, 1000, 1, 42);
    fill_model(&m, 1000, 1);
    cdem_state a, b, c;
    build(&p, &m, &a, NULL);
    build(&p, &m, &b, NULL);
    assert_int_equal(a.n, b.n);
    assert_memory_equal(a.x, b.x, a.n * sizeof *a.x);
    assert_memory_equal(a.y, b.y, a.n * sizeof *a.y);
    assert_memory_equal(a.radius, b.radius, a.n * sizeof *a.radius);
    assert_memory_equal(a.mass, b.mass, a.n * sizeof *a.mass);
    assert_memory_equal(a.id, b.id, a.n * sizeof *a.id);
    assert_memory_equal(a.flags, b.flags, a.n * sizeof *a.flags);
    p.seed = 43;
    build(&p, &m, &c, NULL);
    size_t same = 0, n = a.n < c.n ? a.n : c.n;
    for (size_t i = 0; i < n; i++)
        same += a.x[i] == c.x[i] && a.y[i] == c.y[i] && !(a.flags[i] & CDEM_FLAG_WALL);
    /* a different seed gives a different packing (barring a few coincidences) */
    assert_true(same < n / 100);
    cdem_state_free(&a);
    cdem_state_free(&b);
    cdem_state_free(&c);
}

static void test_assembly_largest_builds(void **unused) {
    (void)unused;
    cdem_params p;
    cdem_model m;
    fill_params(&p, 100, 7.5, 1000, 1, 1);
    fill_model(&m, 1000, 1);
    cdem_state s;
    cdem_assembly_info info;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    build(&p, &m, &s, &info);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double sec = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    grid g;
    grid_build(&g, &s, 2.0 * m.radius[3]);
    double worst = max_overlap_fraction(&s, &g, NULL, 0.0);
    printf("    100 x 7.5 units, half radii: %ld internal + %ld wall elements in %.2f s "
           "(not asserted), area fraction %.4f, max overlap %.2e\n",
           info.n_internal, info.n_wall, sec, info.area_fraction, worst);
    assert_true(info.n_internal > 100000);
    assert_int_equal(info.n_guard_discards, 0);
    assert_true(worst < 1e-6);
    grid_free(&g);
    cdem_state_free(&s);
}

/* ---------------------------------------------------------------- errors */

static void expect_error(const cdem_params *p, const cdem_model *m, cdem_status code,
                         const char *text) {
    cdem_state s;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_state_init(&s, 0, 0, &err), CDEM_OK);
    cdem_assembly_info info = {.n_internal = 99, .n_wall = 99};
    assert_int_equal(cdem_assembly_build(p, m, &s, &info, &err), code);
    assert_int_equal(info.n_internal, 0);
    assert_int_equal(info.n_wall, 0);
    if (!strstr(err.msg, text))
        fail_msg("message \"%s\" lacks \"%s\"", err.msg, text);
    assert_int_equal(s.n, 0);
    cdem_state_free(&s);
    long n = 0;
    cdem_error_clear(&err);
    assert_int_equal(cdem_assembly_count(p, m, &n, NULL, &err), code);
    assert_non_null(strstr(err.msg, text));
}

static void test_assembly_errors(void **unused) {
    (void)unused;
    cdem_params good, p;
    cdem_model mgood, m;
    fill_params(&good, 10, 5, 1000, 0, 1);
    fill_model(&mgood, 1000, 0);

    p = good;
    p.width = 0.0;
    expect_error(&p, &mgood, CDEM_ERR_RANGE, "assembly.width = 0");
    p = good;
    p.height = NAN;
    expect_error(&p, &mgood, CDEM_ERR_RANGE, "assembly.height = nan");
    p = good;
    p.unit_scaling = -5;
    expect_error(&p, &mgood, CDEM_ERR_RANGE, "assembly.unit_scaling = -5");
    p = good;
    p.wall_height_multiplier = 0;
    expect_error(&p, &mgood, CDEM_ERR_RANGE, "wall_height_multiplier = 0: must be 1-4");
    p = good;
    p.width = 1e7; /* far too many elements: refused, not attempted */
    expect_error(&p, &mgood, CDEM_ERR_RANGE, "32-bit indices can number");
    p = good;
    p.width = 0.3; /* narrower than 4 max radii */
    expect_error(&p, &mgood, CDEM_ERR_RANGE, "too small for the largest element radius");

    m = mgood;
    m.radius[2] = 10.0;
    expect_error(&good, &m, CDEM_ERR_RANGE, "must be ascending");
    m = mgood;
    m.radius[0] = 0.0;
    expect_error(&good, &m, CDEM_ERR_RANGE, "radius[0] = 0 m");
    m = mgood;
    m.mass[3] = INFINITY;
    expect_error(&good, &m, CDEM_ERR_RANGE, "mass[3] = inf");

    /* a state that is not empty */
    cdem_state s;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_state_init(&s, 0, 0, &err), CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 0, 0, 1, 1, 0, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_assembly_build(&good, &mgood, &s, NULL, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "already holds 1 elements"));
    assert_int_equal(s.n, 1);
    cdem_state_free(&s);
    cdem_error_clear(&err);
    assert_int_equal(cdem_assembly_build(&good, NULL, &s, NULL, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "NULL model"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_assembly_paper_counts),
        cmocka_unit_test(test_assembly_count_matches_build),
        cmocka_unit_test(test_assembly_density_across_ranges),
        cmocka_unit_test(test_assembly_inside_box),
        cmocka_unit_test(test_assembly_no_overlap_and_supported),
        cmocka_unit_test(test_assembly_no_large_gaps),
        cmocka_unit_test(test_assembly_size_distribution),
        cmocka_unit_test(test_assembly_sorted_by_cell),
        cmocka_unit_test(test_assembly_walls_complete),
        cmocka_unit_test(test_assembly_repose_base_extends),
        cmocka_unit_test(test_assembly_deterministic_by_seed),
        cmocka_unit_test(test_assembly_largest_builds),
        cmocka_unit_test(test_assembly_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
