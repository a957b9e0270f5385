/* faults: see faults.h. */
#include "faults.h"

#include "surface.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Grid cells at most (the cell grows for huge models, as in voids.c). */
#define FAULTS_MAX_CELLS 20000000.0

typedef struct {
    int row;
    double x;      /* m, value-weighted centre of the run */
    double weight; /* sum of the run's cell values */
    double mean, max;
    int zone; /* zone it joined, -1 before linking */
} pick;

typedef struct {
    int last;      /* index of its lowest pick so far */
    int first;     /* index of its highest pick */
    int taken_row; /* the row in which it last received a pick */
} chain;

typedef struct {
    double d;
    int pick, chain;
} link_candidate;

void cdem_faults_default_options(cdem_faults_options *o) {
    o->threshold = 0.0; /* from the field: outlier_threshold */
    o->bin = 0.0;
    o->min_rows = 4;
    o->max_shift = 3.0;
    o->include_salt = 0;
}

/* 1 when element i takes part: free, with a value, and not salt unless asked for. */
static int counts(const cdem_state *s, const double *v, size_t i, int include_salt) {
    return cdem_surface_is_free(s, i) && isfinite(v[i]) &&
           (include_salt || !(s->flags[i] & CDEM_FLAG_SALT));
}

void cdem_faults_free(cdem_faults_result *res) {
    if (!res)
        return;
    free(res->zone);
    res->zone = NULL;
    res->n = 0;
}

static int cmp_candidate(const void *a, const void *b) {
    const link_candidate *p = a, *q = b;
    if (p->d != q->d)
        return p->d < q->d ? -1 : 1;
    if (p->pick != q->pick)
        return p->pick < q->pick ? -1 : 1;
    return (p->chain > q->chain) - (p->chain < q->chain);
}

static int cmp_zone(const void *a, const void *b) {
    const cdem_fault_zone *p = a, *q = b;
    return (p->x_top > q->x_top) - (p->x_top < q->x_top);
}

/* Bins the free elements' values (mean per cell, NaN where empty) and smooths each row 1-2-1
 * over the cells that have a value. */
static void bin_values(const cdem_state *s, const double *v, int include_salt, double x0, double y0,
                       double h, long nx, long ny, double *sum, double *cnt, double *out) {
    const cdem_grid g = {.x0 = x0, .y0 = y0, .cell = h, .nx = (size_t)nx, .ny = (size_t)ny};
    for (size_t i = 0; i < s->n; i++) {
        if (!counts(s, v, i, include_salt))
            continue;
        const size_t c = cdem_grid_cell(&g, s->x[i], s->y[i]);
        sum[c] += v[i];
        cnt[c] += 1.0;
    }
    for (long c = 0; c < nx * ny; c++)
        sum[c] = cnt[c] > 0.0 ? sum[c] / cnt[c] : NAN;
    for (long j = 0; j < ny; j++)
        for (long i = 0; i < nx; i++) {
            const double *row = sum + j * nx;
            if (!isfinite(row[i])) {
                out[j * nx + i] = NAN;
                continue;
            }
            double w = 2.0, acc = 2.0 * row[i];
            if (i > 0 && isfinite(row[i - 1])) {
                acc += row[i - 1];
                w += 1.0;
            }
            if (i + 1 < nx && isfinite(row[i + 1])) {
                acc += row[i + 1];
                w += 1.0;
            }
            out[j * nx + i] = acc / w;
        }
}

static int cmp_double(const void *a, const void *b) {
    const double p = *(const double *)a, q = *(const double *)b;
    return (p > q) - (p < q);
}

/* The median of the n values of v (sorted in place). */
static double median_of(double *v, long n) {
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The default threshold: the outlier bound of the cells' values, median + 3 robust standard
 * deviations (1.4826 x the median absolute deviation: the standard deviation for normal
 * values, unmoved by the fault zones themselves, which are the outliers; 3 is the usual
 * cut-off, Leys et al. 2013). A fixed strain (the old default 1) missed the weaker
 * antithetic fault of the default model's graben (its cells reach 0.64) and says nothing
 * early in a run; the bound follows each field. A field without spread gives a bound just
 * above its median (by 1e-9 of it, or of 1), so a uniform field has no zone. tmp holds nx * ny
 * doubles. */
static double outlier_threshold(const double *g, long ncells, double *tmp) {
    long n = 0;
    for (long c = 0; c < ncells; c++)
        if (isfinite(g[c]))
            tmp[n++] = g[c];
    if (n == 0)
        return INFINITY;
    const double med = median_of(tmp, n);
    for (long k = 0; k < n; k++)
        tmp[k] = fabs(tmp[k] - med);
    const double bound = med + 3.0 * 1.4826 * median_of(tmp, n);
    return bound > med ? bound : med + 1e-9 * fmax(fabs(med), 1.0);
}

/* Appends the runs of row j at or above the threshold as picks; returns the new count or -1
 * when memory runs out. */
static long row_picks(const double *g, long nx, long j, double x0, double h, double thr, pick **p,
                      long n, long *cap) {
    const double *row = g + j * nx;
    for (long i = 0; i < nx;) {
        if (!(row[i] >= thr)) {
            i++;
            continue;
        }
        double w = 0.0, wx = 0.0, mx = 0.0;
        long k = i;
        for (; k < nx && row[k] >= thr; k++) {
            w += row[k];
            wx += row[k] * (x0 + (k + 0.5) * h);
            mx = row[k] > mx ? row[k] : mx;
        }
        if (n == *cap) {
            long nc = *cap ? 2 * *cap : 256;
            pick *q = realloc(*p, (size_t)nc * sizeof *q);
            if (!q)
                return -1;
            *p = q;
            *cap = nc;
        }
        (*p)[n++] = (pick){.row = (int)j,
                           .x = wx / w,
                           .weight = w,
                           .mean = w / (double)(k - i),
                           .max = mx,
                           .zone = -1};
        i = k;
    }
    return n;
}

/* Links the picks (ordered by row, top row first) into chains, nearest pairs first. */
static int link_picks(pick *p, long np, double max_dx, chain **chains, long *nchains) {
    long cap = 64, nc = 0;
    chain *c = malloc((size_t)cap * sizeof *c);
    link_candidate *cand = NULL;
    long cand_cap = 0;
    if (!c)
        return 0;
    for (long a = 0; a < np;) {
        long b = a;
        while (b < np && p[b].row == p[a].row)
            b++;
        const int row = p[a].row;
        long ncand = 0;
        for (long k = a; k < b; k++)
            for (long z = 0; z < nc; z++) {
                const pick *last = &p[c[z].last];
                if (last->row - row > 2 || c[z].taken_row == row)
                    continue;
                const double d = fabs(p[k].x - last->x);
                if (d > max_dx * (double)(last->row - row))
                    continue;
                if (ncand == cand_cap) {
                    long ncap = cand_cap ? 2 * cand_cap : 256;
                    link_candidate *q = realloc(cand, (size_t)ncap * sizeof *q);
                    if (!q) {
                        free(cand);
                        free(c);
                        return 0;
                    }
                    cand = q;
                    cand_cap = ncap;
                }
                cand[ncand++] = (link_candidate){d, (int)k, (int)z};
            }
        if (ncand > 1)
            qsort(cand, (size_t)ncand, sizeof *cand, cmp_candidate);
        for (long q = 0; q < ncand; q++) {
            pick *pk = &p[cand[q].pick];
            chain *ch = &c[cand[q].chain];
            if (pk->zone >= 0 || ch->taken_row == row)
                continue;
            pk->zone = cand[q].chain;
            ch->last = cand[q].pick;
            ch->taken_row = row;
        }
        for (long k = a; k < b; k++) {
            if (p[k].zone >= 0)
                continue;
            if (nc == cap) {
                chain *q = realloc(c, (size_t)(2 * cap) * sizeof *q);
                if (!q) {
                    free(cand);
                    free(c);
                    return 0;
                }
                c = q;
                cap *= 2;
            }
            c[nc] = (chain){.last = (int)k, .first = (int)k, .taken_row = row};
            p[k].zone = (int)nc++;
        }
        a = b;
    }
    free(cand);
    *chains = c;
    *nchains = nc;
    return 1;
}

/* Fits the zone of chain z (its picks in p) and stores it in *out. */
static void fit_zone(const pick *p, long np, int z, const chain *ch, double y0, double h,
                     cdem_fault_zone *out) {
    double sw = 0, sy = 0, sx = 0, syy = 0, sxy = 0, vsum = 0, vmax = 0;
    long k = 0;
    for (long q = ch->first; q < np; q++) {
        if (p[q].zone != z)
            continue;
        const double y = y0 + (p[q].row + 0.5) * h, w = p[q].weight;
        sw += w;
        sy += w * y;
        sx += w * p[q].x;
        syy += w * y * y;
        sxy += w * y * p[q].x;
        vsum += p[q].mean;
        vmax = p[q].max > vmax ? p[q].max : vmax;
        k++;
    }
    const double my = sy / sw, mx = sx / sw, vy = syy / sw - my * my, cxy = sxy / sw - mx * my;
    const double slope = vy > 0.0 ? cxy / vy : 0.0; /* dx/dy */
    const pick *top = &p[ch->first], *bot = &p[ch->last];
    out->y_top = y0 + (top->row + 0.5) * h;
    out->y_bottom = y0 + (bot->row + 0.5) * h;
    out->x_top = mx + slope * (out->y_top - my);
    out->x_bottom = mx + slope * (out->y_bottom - my);
    out->dip_deg = atan2(1.0, fabs(slope)) * 180.0 / M_PI;
    out->dips_right = slope < 0.0;
    out->rows = top->row - bot->row + 1;
    out->mean_value = vsum / (double)k;
    out->max_value = vmax;
}

cdem_status cdem_faults_pick(const cdem_state *s, const double *v, const cdem_faults_options *o,
                             cdem_faults_result *res, cdem_error *err) {
    memset(res, 0, sizeof *res);
    if (!(o->threshold >= 0.0) || !isfinite(o->threshold))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "faults: threshold %g must be > 0 (or 0: from the field)", o->threshold);
    if (o->min_rows < 2 || !(o->max_shift > 0.0) || !isfinite(o->max_shift) || !(o->bin >= 0.0) ||
        !isfinite(o->bin))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "faults: min_rows %d must be >= 2, max_shift %g > 0, bin %g >= 0",
                         o->min_rows, o->max_shift, o->bin);
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY, rmax = 0.0;
    size_t nfree = 0;
    for (size_t i = 0; i < s->n; i++) {
        if (!counts(s, v, i, o->include_salt))
            continue;
        nfree++;
        xmin = fmin(xmin, s->x[i]);
        xmax = fmax(xmax, s->x[i]);
        ymin = fmin(ymin, s->y[i]);
        ymax = fmax(ymax, s->y[i]);
        rmax = fmax(rmax, s->radius[i]);
    }
    if (nfree == 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "faults: no free element has a value%s",
                         o->include_salt ? "" : " (salt elements left out: --include-salt)");
    double h = o->bin > 0.0 ? o->bin : 2.0 * rmax;
    while (((xmax - xmin) / h + 1.0) * ((ymax - ymin) / h + 1.0) > FAULTS_MAX_CELLS)
        h *= 2.0;
    const long nx = (long)floor((xmax - xmin) / h) + 1, ny = (long)floor((ymax - ymin) / h) + 1;
    double *sum = calloc((size_t)(nx * ny), sizeof *sum);
    double *cnt = calloc((size_t)(nx * ny), sizeof *cnt);
    double *g = malloc((size_t)(nx * ny) * sizeof *g);
    pick *p = NULL;
    chain *ch = NULL;
    long np = 0, cap = 0, nch = 0;
    cdem_status st = CDEM_OK;
    if (!sum || !cnt || !g) {
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "faults: out of memory for %ld x %ld cells", nx, ny);
        goto done;
    }
    bin_values(s, v, o->include_salt, xmin, ymin, h, nx, ny, sum, cnt, g);
    /* sum is free after binning: the scratch of the threshold's medians */
    const double thr = o->threshold > 0.0 ? o->threshold : outlier_threshold(g, nx * ny, sum);
    for (long j = ny - 1; j >= 0 && np >= 0; j--)
        np = row_picks(g, nx, j, xmin, h, thr, &p, np, &cap);
    if (np < 0 || !link_picks(p, np, o->max_shift * h, &ch, &nch)) {
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "faults: out of memory linking picks");
        goto done;
    }
    res->zone = malloc((size_t)(nch ? nch : 1) * sizeof *res->zone);
    if (!res->zone) {
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "faults: out of memory for %ld zones", nch);
        goto done;
    }
    for (long z = 0; z < nch; z++)
        if (p[ch[z].first].row - p[ch[z].last].row + 1 >= o->min_rows)
            fit_zone(p, np, (int)z, &ch[z], ymin, h, &res->zone[res->n++]);
    if (res->n > 1)
        qsort(res->zone, res->n, sizeof *res->zone, cmp_zone);
    res->bin = h;
    res->threshold = thr;
done:
    free(sum);
    free(cnt);
    free(g);
    free(p);
    free(ch);
    if (st != CDEM_OK)
        cdem_faults_free(res);
    return st;
}
