/* salt: see salt.h. The salt's constants (cdem_salt_model_derive), the placement and what
 * it measures (cdem_salt_place, _measure, _configure), what is sized at list builds (the
 * grid, the scratch, the salt's pairs), the force evaluation (P2G, velocity gradient and stress,
 * G2P, the pair law) and the area update. The parameter rules are in salt_rules.c. */
#include "salt.h"

#include "grid.h"
#include "salt_law.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- constants */

cdem_status cdem_salt_model_derive(const cdem_params *p, const cdem_model *m, cdem_salt_model *sm,
                                   cdem_error *err) {
    memset(sm, 0, sizeof *sm);
    if (p->salt_layer == CDEM_SALT_OFF)
        return CDEM_OK;
    sm->on = 1;
    sm->density = p->salt_density;
    for (int i = 0; i < CDEM_NUM_RADII; i++)
        sm->mass[i] = p->salt_density * M_PI * m->radius[i] * m->radius[i];
    sm->viscosity_geological = p->salt_viscosity;
    sm->rate = p->salt_rate * 1e-3 / CDEM_SECONDS_PER_YEAR;
    sm->time_scale = isnan(p->salt_time_scale) ? m->boundary_speed / sm->rate : p->salt_time_scale;
    sm->viscosity = p->salt_viscosity / sm->time_scale;
    sm->bulk_modulus = p->salt_bulk_modulus;
    sm->grid_spacing = p->salt_grid_spacing * m->average_radius;
    sm->reach = p->salt_reach;
    sm->dashpot_fraction = p->salt_dashpot_fraction;
    if (!(sm->viscosity > 0.0) || !isfinite(sm->viscosity))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "cannot derive the model: salt.viscosity = %g Pa s over the time "
                         "scale %g gives a model viscosity of %g Pa s",
                         p->salt_viscosity, sm->time_scale, sm->viscosity);
    return CDEM_OK;
}

/* ---------------------------------------------------------------- placement */

/* The band of centres [lo + a (hi - lo), lo + b (hi - lo)] of salt.layer, as fractions a, b
 * of the span of free-element centres (basal: from below the lowest). */
static void band_fractions(const cdem_params *p, double *a, double *b) {
    if (p->salt_layer == CDEM_SALT_BASAL) {
        *a = -INFINITY;
        *b = p->salt_thickness_percent / 100.0;
    } else {
        *a = p->salt_interval_bottom_percent / 100.0;
        *b = p->salt_interval_top_percent / 100.0;
    }
}

cdem_status cdem_salt_place(const cdem_params *p, const cdem_model *m, const cdem_salt_model *sm,
                            cdem_state *s, cdem_salt_layer *layer, cdem_error *err) {
    memset(layer, 0, sizeof *layer);
    if (!p || !m || !sm || !s)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_salt_place: NULL argument");
    if (p->salt_layer == CDEM_SALT_OFF)
        return CDEM_OK;
    double lo, hi;
    cdem_state_free_y_range(s, &lo, &hi);
    if (!(hi > lo))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "salt.layer: the assembly has no span of free "
                         "elements to place the salt in");
    double a, b;
    band_fractions(p, &a, &b);
    const double y_lo = lo + a * (hi - lo), y_hi = lo + b * (hi - lo);
    double xmin = INFINITY, xmax = -INFINITY, bottom = INFINITY;
    long count = 0, cover = 0;
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        if (!(s->y[i] >= y_lo && s->y[i] <= y_hi)) {
            cover++;
            continue;
        }
        int cls = 0;
        while (cls + 1 < CDEM_NUM_RADII && s->radius[i] > m->radius[cls])
            cls++;
        s->flags[i] |= CDEM_FLAG_SALT;
        s->mass[i] = sm->mass[cls];
        s->area_ratio[i] = 1.0;
        xmin = fmin(xmin, s->x[i] - s->radius[i]);
        xmax = fmax(xmax, s->x[i] + s->radius[i]);
        bottom = fmin(bottom, s->y[i] - s->radius[i]);
        count++;
    }
    if (count == 0 || cover == 0)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "salt.layer = %s: the salt's band (%.6g to %.6g m of the element "
                         "centres' %.6g to %.6g m) holds %s: make it %s",
                         p->salt_layer == CDEM_SALT_BASAL ? "basal" : "interval", y_lo, y_hi, lo,
                         hi, count == 0 ? "no element" : "every element",
                         count == 0 ? "thicker" : "thinner (the salt must leave a cover)");
    /* the region the salt fills: from the base's surface (basal) or the band's foot up to the
     * cut between the salt's centres and the cover's, across the salt's width */
    const double foot = p->salt_layer == CDEM_SALT_BASAL ? bottom : y_lo;
    CDEM_TRY(cdem_salt_measure(s, (xmax - xmin) * (y_hi - foot), sm->reach, layer, err));
    layer->band_lo = foot;
    layer->band_hi = y_hi;
    return CDEM_OK;
}

cdem_status cdem_salt_measure(const cdem_state *s, double region_area, double reach,
                              cdem_salt_layer *layer, cdem_error *err) {
    layer->elements = 0;
    layer->disc_area = layer->phi = layer->beta = 0.0;
    layer->max_pairs = 0;
    unsigned char *salt = malloc(s->n ? s->n : 1);
    int *pairs = calloc(s->n ? s->n : 1, sizeof *pairs);
    if (!salt || !pairs) {
        free(salt);
        free(pairs);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "salt: out of memory for %zu elements", s->n);
    }
    double rmax = 0.0;
    for (size_t i = 0; i < s->n; i++) {
        salt[i] = (s->flags[i] & CDEM_FLAG_SALT) != 0;
        if (!salt[i])
            continue;
        layer->elements++;
        layer->disc_area += M_PI * s->radius[i] * s->radius[i];
        rmax = fmax(rmax, s->radius[i]);
    }
    if (layer->elements == 0 || !(region_area > 0.0)) {
        free(salt);
        free(pairs);
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "salt: no salt elements or no area to measure (%ld elements, %g m^2)",
                         layer->elements, region_area);
    }
    layer->phi = layer->disc_area / region_area;
    cdem_grid_index ix;
    cdem_status st = cdem_grid_index_build(&ix, s->x, s->y, s->n, salt, 2.0 * reach * rmax, err);
    if (st != CDEM_OK) {
        free(salt);
        free(pairs);
        return st;
    }
    /* sum over salt pairs of w d^2 / 8: the dissipation of a central dashpot network in an
     * affine simple shear of an isotropic fabric (docs/solver.md, "Salt") */
    double sum = 0.0;
    for (size_t i = 0; i < s->n; i++) {
        if (!salt[i])
            continue;
        cdem_grid_box box;
        if (!cdem_grid_index_range(&ix, s->x[i], s->y[i], 2.0 * reach * rmax, &box))
            continue;
        for (size_t cy = box.y_lo; cy <= box.y_hi; cy++)
            for (size_t cx = box.x_lo; cx <= box.x_hi; cx++) {
                const size_t c = cy * ix.grid.nx + cx;
                for (int32_t k = ix.start[c]; k < ix.start[c + 1]; k++) {
                    const size_t j = (size_t)ix.items[k];
                    if (j <= i)
                        continue;
                    const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
                    const double r = sqrt(dx * dx + dy * dy), R = s->radius[i] + s->radius[j];
                    const double w = cdem_salt_law_weight(r, R, reach);
                    if (!(w > 0.0) || r <= 0.0)
                        continue;
                    sum += w * r * r / 8.0;
                    pairs[i]++;
                    pairs[j]++;
                }
            }
    }
    for (size_t i = 0; i < s->n; i++)
        if (pairs[i] > layer->max_pairs)
            layer->max_pairs = pairs[i];
    layer->beta = sum > 0.0 ? region_area / sum : 0.0;
    cdem_grid_index_free(&ix);
    free(salt);
    free(pairs);
    return CDEM_OK;
}

double cdem_salt_dashpot(const cdem_salt_model *sm, const cdem_salt_layer *layer, double min_mass,
                         double dt) {
    const double c = sm->dashpot_fraction * layer->beta * sm->viscosity;
    const int z = layer->max_pairs > 1 ? layer->max_pairs : 1;
    const double cap = 0.25 * min_mass / ((double)z * dt);
    return c < cap ? c : cap;
}

cdem_status cdem_salt_configure(cdem_salt *salt, const cdem_model *m, const cdem_salt_model *sm,
                                const cdem_params *p, const cdem_salt_layer *layer, double skin,
                                cdem_error *err) {
    cdem_salt_free(salt);
    if (!sm->on)
        return CDEM_OK;
    if (!layer || !(layer->phi > 0.0) || layer->elements <= 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "salt: the module needs the placed salt's packing fraction");
    salt->on = 1;
    salt->viscosity = sm->viscosity;
    salt->bulk_modulus = sm->bulk_modulus;
    salt->h = sm->grid_spacing;
    salt->reach = sm->reach;
    salt->phi = layer->phi;
    salt->kn = m->kn;
    salt->contact_damping = m->contact_damping;
    salt->dashpot = cdem_salt_dashpot(sm, layer, m->min_mass, m->dt);
    salt->skin = skin;
    salt->join = (p->salt_cover_contact == CDEM_SALT_NO_SLIP ? CDEM_SALT_JOIN_COVER : 0u) |
                 (p->salt_base_contact == CDEM_SALT_NO_SLIP ? CDEM_SALT_JOIN_BASE : 0u) |
                 (p->salt_wall_contact == CDEM_SALT_NO_SLIP ? CDEM_SALT_JOIN_WALLS : 0u);
    if (!(salt->h > 0.0) || !(salt->reach >= 1.0) || !(salt->viscosity > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "salt: grid spacing %g m, reach %g and viscosity %g Pa s must be "
                         "positive (reach >= 1)",
                         salt->h, salt->reach, salt->viscosity);
    return CDEM_OK;
}

void cdem_salt_free(cdem_salt *salt) {
    if (!salt)
        return;
    free(salt->gm);
    free(salt->gmx);
    free(salt->gmy);
    free(salt->gfx);
    free(salt->gfy);
    free(salt->gbm);
    free(salt->gbx);
    free(salt->gby);
    free(salt->gsalt);
    free(salt->lxx);
    free(salt->lxy);
    free(salt->lyx);
    free(salt->lyy);
    free(salt->sxx);
    free(salt->syy);
    free(salt->sxy);
    free(salt->members);
    free(salt->pi);
    free(salt->pj);
    memset(salt, 0, sizeof *salt);
}

/* ---------------------------------------------------------------- list builds */

/* Reallocates *p to c items of size sz; 0 (and *p kept) when out of memory. */
static int resize(void **p, size_t c, size_t sz) {
    void *q = realloc(*p, (c ? c : 1) * sz);
    if (!q)
        return 0;
    *p = q;
    return 1;
}

/* The per-element scratch for n elements (geometric growth, at builds only). */
static cdem_status grow_elements(cdem_salt *salt, size_t n, cdem_error *err) {
    if (salt->ecap >= n)
        return CDEM_OK;
    const size_t c = n + n / 2 + 16;
    const int ok = resize((void **)&salt->lxx, c, sizeof(double)) &&
                   resize((void **)&salt->lxy, c, sizeof(double)) &&
                   resize((void **)&salt->lyx, c, sizeof(double)) &&
                   resize((void **)&salt->lyy, c, sizeof(double)) &&
                   resize((void **)&salt->sxx, c, sizeof(double)) &&
                   resize((void **)&salt->syy, c, sizeof(double)) &&
                   resize((void **)&salt->sxy, c, sizeof(double)) &&
                   resize((void **)&salt->members, c, sizeof(int32_t));
    if (!ok) /* the arrays that grew stay valid; ecap stays the smallest capacity */
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "salt: out of memory for %zu elements", n);
    salt->ecap = c;
    return CDEM_OK;
}

/* Room for one more salt pair (geometric growth, at builds only). */
static int grow_pairs(cdem_salt *salt) {
    if (salt->pcap > salt->np)
        return 1;
    const size_t c = salt->np + salt->np / 2 + 64;
    if (!resize((void **)&salt->pi, c, sizeof(int32_t)) ||
        !resize((void **)&salt->pj, c, sizeof(int32_t)))
        return 0;
    salt->pcap = c;
    return 1;
}

/* 1 when element i (not salt) joins the grid (salt.*_contact = no-slip). */
static int joins(const cdem_salt *salt, uint32_t f) {
    if (f & (CDEM_FLAG_SALT | CDEM_FLAG_FOOTWALL))
        return 0;
    if (!(f & CDEM_FLAGS_BOUNDARY))
        return (salt->join & CDEM_SALT_JOIN_COVER) != 0;
    if (f & (CDEM_FLAG_BASE | CDEM_FLAG_FAULT | CDEM_FLAG_MYLAR))
        return (salt->join & CDEM_SALT_JOIN_BASE) != 0;
    return (salt->join & CDEM_SALT_JOIN_WALLS) != 0;
}

/* The salt's pairs: every pair within reach x R + skin with a salt element and no footwall
 * display element, each once, in the order of the salt element (ascending) and of the cell
 * scan: the same list for any thread count. */
static cdem_status list_pairs(cdem_salt *salt, const cdem_state *s, const double *x,
                              const double *y, double xmin, double xmax, double ymin, double ymax,
                              cdem_error *err) {
    salt->np = 0;
    double rmax = 0.0;
    for (size_t i = 0; i < s->n; i++)
        rmax = fmax(rmax, s->radius[i]);
    const double cut = 2.0 * salt->reach * rmax + salt->skin;
    unsigned char *near = malloc(s->n ? s->n : 1);
    if (!near)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "salt: out of memory for %zu elements", s->n);
    for (size_t i = 0; i < s->n; i++)
        near[i] = !(s->flags[i] & CDEM_FLAG_FOOTWALL) && x[i] >= xmin - cut && x[i] <= xmax + cut &&
                  y[i] >= ymin - cut && y[i] <= ymax + cut;
    cdem_grid_index ix;
    cdem_status st = cdem_grid_index_build(&ix, x, y, s->n, near, cut, err);
    free(near);
    CDEM_TRY(st);
    for (size_t i = 0; i < s->n && st == CDEM_OK; i++) {
        if (!(s->flags[i] & CDEM_FLAG_SALT))
            continue;
        cdem_grid_box box;
        if (!cdem_grid_index_range(&ix, x[i], y[i], cut, &box))
            continue;
        for (size_t cy = box.y_lo; cy <= box.y_hi && st == CDEM_OK; cy++)
            for (size_t cx = box.x_lo; cx <= box.x_hi; cx++) {
                const size_t c = cy * ix.grid.nx + cx;
                for (int32_t k = ix.start[c]; k < ix.start[c + 1]; k++) {
                    const size_t j = (size_t)ix.items[k];
                    if (j == i || ((s->flags[j] & CDEM_FLAG_SALT) && j < i))
                        continue; /* a salt-salt pair is listed by its first element */
                    const double dx = x[j] - x[i], dy = y[j] - y[i];
                    const double reach = salt->reach * (s->radius[i] + s->radius[j]) + salt->skin;
                    if (dx * dx + dy * dy >= reach * reach)
                        continue;
                    if (!grow_pairs(salt)) {
                        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "salt: out of memory for %zu pairs",
                                       salt->np + 1);
                        break;
                    }
                    salt->pi[salt->np] = (int32_t)i;
                    salt->pj[salt->np] = (int32_t)j;
                    salt->np++;
                }
            }
    }
    cdem_grid_index_free(&ix);
    return st;
}

cdem_status cdem_salt_after_build(cdem_salt *salt, const cdem_neighbour *nb, const cdem_state *s,
                                  cdem_error *err) {
    if (!salt->on)
        return CDEM_OK;
    if (nb->n != s->n)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "salt: the pair list holds %zu elements, the state %zu", nb->n, s->n);
    CDEM_TRY(grow_elements(salt, s->n, err));
    const double *x = nb->x0, *y = nb->y0; /* the positions of the build */
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        if (!(s->flags[i] & CDEM_FLAG_SALT))
            continue;
        xmin = fmin(xmin, x[i]);
        xmax = fmax(xmax, x[i]);
        ymin = fmin(ymin, y[i]);
        ymax = fmax(ymax, y[i]);
    }
    salt->gnx = salt->gny = 0;
    salt->np = 0;
    if (!(xmax >= xmin))
        return CDEM_OK; /* no salt left */
    /* three cells of margin: the stencil reaches 1.5 cells, the elements move less than half
     * the skin before the next build */
    const double h = salt->h;
    salt->gx0 = (long)floor(xmin / h) - 3;
    salt->gy0 = (long)floor(ymin / h) - 3;
    salt->gnx = (size_t)((long)floor(xmax / h) + 4 - salt->gx0);
    salt->gny = (size_t)((long)floor(ymax / h) + 4 - salt->gy0);
    const size_t nodes = salt->gnx * salt->gny;
    if (salt->gcap < nodes) {
        const size_t c = nodes + nodes / 2 + 16;
        int ok = 1;
        double **arrays[] = {&salt->gm,  &salt->gmx, &salt->gmy, &salt->gfx,
                             &salt->gfy, &salt->gbm, &salt->gbx, &salt->gby};
        for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++) {
            double *q = realloc(*arrays[k], c * sizeof(double));
            if (q)
                *arrays[k] = q;
            ok = ok && q;
        }
        unsigned char *g = realloc(salt->gsalt, c);
        if (g)
            salt->gsalt = g;
        if (!ok || !g)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "salt: out of memory for a grid of %zu nodes",
                             nodes);
        salt->gcap = c;
    }
    return list_pairs(salt, s, x, y, xmin, xmax, ymin, ymax, err);
}

/* ---------------------------------------------------------------- the force evaluation */

/* Quadratic B-spline weights w and derivatives dw (per metre) of the three nodes
 * base, base + 1, base + 2 (node k at k h) for the coordinate x. */
static inline long bspline(double x, double h, double w[3], double dw[3]) {
    const double u = x / h;
    const long base = (long)floor(u - 0.5);
    const double f = u - (double)base; /* in [0.5, 1.5): the distance from node base in h */
    w[0] = 0.5 * (1.5 - f) * (1.5 - f);
    w[1] = 0.75 - (f - 1.0) * (f - 1.0);
    w[2] = 0.5 * (f - 0.5) * (f - 0.5);
    dw[0] = -(1.5 - f) / h;
    dw[1] = -2.0 * (f - 1.0) / h;
    dw[2] = (f - 0.5) / h;
    return base;
}

/* The stencil of an element: its nine nodes' grid indices (-1 off the grid) and weights. */
typedef struct {
    long node[9];
    double w[9], gx[9], gy[9];
} stencil;

static inline void stencil_of(const cdem_salt *salt, double x, double y, stencil *st) {
    double wx[3], wy[3], dx[3], dy[3];
    const long bx = bspline(x, salt->h, wx, dx) - salt->gx0;
    const long by = bspline(y, salt->h, wy, dy) - salt->gy0;
    for (int b = 0; b < 3; b++)
        for (int a = 0; a < 3; a++) {
            const int k = 3 * b + a;
            const long ia = bx + a, ib = by + b;
            st->node[k] = ia >= 0 && ib >= 0 && (size_t)ia < salt->gnx && (size_t)ib < salt->gny
                              ? ib * (long)salt->gnx + ia
                              : -1;
            st->w[k] = wx[a] * wy[b];
            st->gx[k] = dx[a] * wy[b];
            st->gy[k] = wx[a] * dy[b];
        }
}

/* Adds the mass and momentum of element i to its nodes (m, mx, my: one body's arrays). */
static inline void to_grid(double *gm, double *gmx, double *gmy, const cdem_state *s, size_t i,
                           const stencil *st) {
    const double m = s->mass[i], vx = s->vx[i], vy = s->vy[i];
    for (int k = 0; k < 9; k++) {
        if (st->node[k] < 0)
            continue;
        const double wm = st->w[k] * m;
        gm[st->node[k]] += wm;
        gmx[st->node[k]] += wm * vx;
        gmy[st->node[k]] += wm * vy;
    }
}

/* 1 when a node belongs to the non-salt elements that join the grid (the cover, base, faults,
 * walls, plates): their mass on it outweighs the salt's, or it lies within half a cell of one's
 * surface (near: flag 4 of gsalt). It moves with them (a velocity node of the salt: the salt
 * sticks to them), and its whole force goes to them, the reaction on a prescribed-velocity
 * element, the salt's traction on a cover element (docs/solver.md, section 9.5). */
static inline int owned(double m_free, double m_bound, int near) {
    return m_bound > 0.0 && (m_bound >= m_free || near);
}

/* The continuum part: P2G, stress, node forces, G2P (into ex, ey). */
static void grid_forces(cdem_salt *salt, const cdem_state *s, double *ex, double *ey) {
    const size_t nodes = salt->gnx * salt->gny;
    double *const arrays[] = {salt->gm,  salt->gmx, salt->gmy, salt->gfx,
                              salt->gfy, salt->gbm, salt->gbx, salt->gby};
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
        memset(arrays[k], 0, nodes * sizeof(double));
    memset(salt->gsalt, 0, nodes);
    stencil st;
    size_t nm = 0;
    for (size_t i = 0; i < s->n; i++) { /* the salt first */
        if (!(s->flags[i] & CDEM_FLAG_SALT))
            continue;
        stencil_of(salt, s->x[i], s->y[i], &st);
        to_grid(salt->gm, salt->gmx, salt->gmy, s, i, &st);
        for (int k = 0; k < 9; k++)
            if (st.node[k] >= 0 && st.w[k] > 0.0)
                salt->gsalt[st.node[k]] = 1;
        salt->members[nm++] = (int32_t)i;
    }
    const size_t n_salt = nm;
    const double lo_x = (double)salt->gx0 * salt->h, hi_x = lo_x + (double)salt->gnx * salt->h;
    const double lo_y = (double)salt->gy0 * salt->h, hi_y = lo_y + (double)salt->gny * salt->h;
    for (size_t i = 0; i < s->n; i++) { /* then its neighbours that join the grid */
        if (!joins(salt, s->flags[i]) ||
            !(s->x[i] > lo_x && s->x[i] < hi_x && s->y[i] > lo_y && s->y[i] < hi_y))
            continue;
        stencil_of(salt, s->x[i], s->y[i], &st);
        int touches = 0;
        for (int k = 0; k < 9 && !touches; k++)
            touches = st.node[k] >= 0 && st.w[k] > 0.0 && (salt->gsalt[st.node[k]] & 1);
        if (!touches)
            continue;
        to_grid(salt->gbm, salt->gbx, salt->gby, s, i, &st);
        /* its nodes nearer than half a cell to its surface (or inside it) */
        const double reach = s->radius[i] + 0.5 * salt->h;
        for (int k = 0; k < 9; k++) {
            const long g = st.node[k];
            if (g < 0)
                continue;
            const double dx = (double)(salt->gx0 + g % (long)salt->gnx) * salt->h - s->x[i];
            const double dy = (double)(salt->gy0 + g / (long)salt->gnx) * salt->h - s->y[i];
            if (dx * dx + dy * dy <= reach * reach)
                salt->gsalt[g] |= 4;
        }
        salt->members[nm++] = (int32_t)i;
    }
    salt->n_members = nm;
    /* each node's velocity (into gmx, gmy) and the divisors of its force's shares: the
     * non-salt elements' mass on a node they own (gbm), else the salt's (gm) */
    for (size_t g = 0; g < nodes; g++) {
        if (owned(salt->gm[g], salt->gbm[g], (salt->gsalt[g] & 4) != 0)) {
            salt->gmx[g] = salt->gbx[g] / salt->gbm[g];
            salt->gmy[g] = salt->gby[g] / salt->gbm[g];
            salt->gm[g] = 0.0;
        } else {
            salt->gmx[g] = salt->gm[g] > 0.0 ? salt->gmx[g] / salt->gm[g] : 0.0;
            salt->gmy[g] = salt->gm[g] > 0.0 ? salt->gmy[g] / salt->gm[g] : 0.0;
            salt->gbm[g] = 0.0;
        }
    }
    /* the salt's stress and the node forces */
    const double eta = salt->viscosity, inv_phi = 1.0 / salt->phi;
    for (size_t q = 0; q < n_salt; q++) {
        const size_t i = (size_t)salt->members[q];
        stencil_of(salt, s->x[i], s->y[i], &st);
        double lxx = 0.0, lxy = 0.0, lyx = 0.0, lyy = 0.0; /* L_ab = d v_a / d x_b */
        for (int k = 0; k < 9; k++) {
            const long g = st.node[k];
            if (g < 0 || !(salt->gm[g] > 0.0 || salt->gbm[g] > 0.0))
                continue;
            const double vx = salt->gmx[g], vy = salt->gmy[g];
            lxx += vx * st.gx[k];
            lxy += vx * st.gy[k];
            lyx += vy * st.gx[k];
            lyy += vy * st.gy[k];
        }
        const double half_tr = 0.5 * (lxx + lyy);
        const double p = cdem_salt_pressure(salt->bulk_modulus, s->area_ratio[i]);
        const double sxx = 2.0 * eta * (lxx - half_tr) - p;
        const double syy = 2.0 * eta * (lyy - half_tr) - p;
        const double sxy = eta * (lxy + lyx);
        salt->lxx[i] = lxx;
        salt->lxy[i] = lxy;
        salt->lyx[i] = lyx;
        salt->lyy[i] = lyy;
        salt->sxx[i] = -sxx; /* compression positive, as the Love-Weber stress */
        salt->syy[i] = -syy;
        salt->sxy[i] = -sxy;
        const double area = s->area_ratio[i] * M_PI * s->radius[i] * s->radius[i] * inv_phi;
        for (int k = 0; k < 9; k++) {
            const long g = st.node[k];
            if (g < 0)
                continue;
            salt->gfx[g] -= area * (sxx * st.gx[k] + sxy * st.gy[k]);
            salt->gfy[g] -= area * (sxy * st.gx[k] + syy * st.gy[k]);
        }
    }
    /* back to the elements, each its mass share of the forces of the nodes of its body */
    for (size_t q = 0; q < nm; q++) {
        const size_t i = (size_t)salt->members[q];
        const double *div = (s->flags[i] & CDEM_FLAG_SALT) ? salt->gm : salt->gbm;
        stencil_of(salt, s->x[i], s->y[i], &st);
        double fx = 0.0, fy = 0.0;
        for (int k = 0; k < 9; k++) {
            const long g = st.node[k];
            if (g < 0 || !(div[g] > 0.0))
                continue;
            const double share = st.w[k] * s->mass[i] / div[g];
            fx += share * salt->gfx[g];
            fy += share * salt->gfy[g];
        }
        ex[i] += fx;
        ey[i] += fy;
    }
}

/* The critical damping of a contact between i and j: 2 sqrt(Kn m_eff), a boundary element
 * counting as infinitely heavy. */
static inline double critical(const cdem_salt *salt, const cdem_state *s, size_t i, size_t j) {
    const int bi = (s->flags[i] & CDEM_FLAGS_BOUNDARY) != 0;
    const int bj = (s->flags[j] & CDEM_FLAGS_BOUNDARY) != 0;
    const double mi = s->mass[i], mj = s->mass[j];
    const double m = bi ? mj : bj ? mi : mi * mj / (mi + mj);
    return 2.0 * sqrt(salt->kn * m);
}

void cdem_salt_forces(cdem_salt *salt, const cdem_state *s, double *ex, double *ey) {
    if (!salt->on || salt->gnx == 0)
        return;
    grid_forces(salt, s, ex, ey);
    const double c = salt->dashpot, zeta = salt->contact_damping;
    for (size_t p = 0; p < salt->np; p++) {
        const size_t i = (size_t)salt->pi[p], j = (size_t)salt->pj[p];
        const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
        const double r2 = dx * dx + dy * dy, R = s->radius[i] + s->radius[j];
        const double reach = salt->reach * R;
        if (!(r2 < reach * reach) || !(r2 > 0.0))
            continue;
        const int both = (s->flags[i] & s->flags[j] & CDEM_FLAG_SALT) != 0;
        const double cc = zeta > 0.0 && !both && r2 < R * R ? zeta * critical(salt, s, i, j) : 0.0;
        double fx, fy;
        cdem_salt_law_pair(dx, dy, r2, R, s->vx[j] - s->vx[i], s->vy[j] - s->vy[i], both, salt->kn,
                           c, cc, salt->reach, &fx, &fy);
        ex[i] += fx;
        ey[i] += fy;
        ex[j] -= fx;
        ey[j] -= fy;
    }
}

void cdem_salt_project(cdem_salt *salt, cdem_state *s, double dt) {
    if (!salt->on || salt->gnx == 0)
        return;
    const size_t nodes = salt->gnx * salt->gny;
    /* gm, gmx, gmy: the salt's mass and affine (APIC) momentum; gbx, gby: its plain momentum,
     * which moves the salt and whose divergence J follows; gfx: its mass-weighted J */
    double *const arrays[] = {salt->gm, salt->gmx, salt->gmy, salt->gfx, salt->gbx, salt->gby};
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
        memset(arrays[k], 0, nodes * sizeof(double));
    stencil st;
    const double h = salt->h;
    for (size_t i = 0; i < s->n; i++) {
        if (!(s->flags[i] & CDEM_FLAG_SALT))
            continue;
        stencil_of(salt, s->x[i], s->y[i], &st);
        const double m = s->mass[i];
        for (int k = 0; k < 9; k++) {
            const long g = st.node[k];
            if (g < 0)
                continue;
            /* the node's offset from the element: node (a, b) at ((gx0 + a) h, (gy0 + b) h) */
            const double dx = (double)(salt->gx0 + g % (long)salt->gnx) * h - s->x[i];
            const double dy = (double)(salt->gy0 + g / (long)salt->gnx) * h - s->y[i];
            const double wm = st.w[k] * m;
            salt->gm[g] += wm;
            salt->gmx[g] += wm * (s->vx[i] + salt->lxx[i] * dx + salt->lxy[i] * dy);
            salt->gmy[g] += wm * (s->vy[i] + salt->lyx[i] * dx + salt->lyy[i] * dy);
            salt->gbx[g] += wm * s->vx[i];
            salt->gby[g] += wm * s->vy[i];
            salt->gfx[g] += wm * s->area_ratio[i]; /* the nodes' mean J */
        }
    }
    for (size_t i = 0; i < s->n; i++) {
        if (!(s->flags[i] & CDEM_FLAG_SALT))
            continue;
        stencil_of(salt, s->x[i], s->y[i], &st);
        double vx = 0.0, vy = 0.0, px = 0.0, py = 0.0, j = 0.0, w = 0.0, div = 0.0;
        for (int k = 0; k < 9; k++) {
            const long g = st.node[k];
            if (g < 0 || !(salt->gm[g] > 0.0))
                continue;
            const double inv_m = 1.0 / salt->gm[g];
            vx += st.w[k] * salt->gmx[g] * inv_m;
            vy += st.w[k] * salt->gmy[g] * inv_m;
            px += st.w[k] * salt->gbx[g] * inv_m;
            py += st.w[k] * salt->gby[g] * inv_m;
            div += (st.gx[k] * salt->gbx[g] + st.gy[k] * salt->gby[g]) * inv_m;
            j += st.w[k] * salt->gfx[g] * inv_m;
            w += st.w[k];
        }
        if (w > 0.0) {
            /* the drift moved it with v_half = v - (dt/2) F / m; it moves with the salt's plain
             * field, whose divergence J follows (the affine one carries the forces' L: moved
             * by it the salt spread unseen), and takes the affine field's velocity, which keeps
             * the shear the plain one would average away (docs/solver.md 9.5) */
            const double hvx = s->vx[i] - 0.5 * dt * s->fx[i] / s->mass[i];
            const double hvy = s->vy[i] - 0.5 * dt * s->fy[i] / s->mass[i];
            s->vx[i] = vx / w;
            s->vy[i] = vy / w;
            s->x[i] += dt * (px / w - hvx);
            s->y[i] += dt * (py / w - hvy);
            s->area_ratio[i] *= exp(dt * div);
            s->area_ratio[i] += CDEM_SALT_J_RELAX * (j / w - s->area_ratio[i]);
        }
    }
}

void cdem_salt_stress(const cdem_salt *salt, cdem_state *s) {
    if (!salt->on || !s->has_stress || salt->gnx == 0)
        return;
    for (size_t i = 0; i < s->n; i++)
        if (s->flags[i] & CDEM_FLAG_SALT) {
            s->sxx[i] = salt->sxx[i];
            s->syy[i] = salt->syy[i];
            s->sxy[i] = salt->sxy[i];
        }
}

void cdem_salt_measures(const cdem_state *s, double phi, double *area, double *top, long *count) {
    double a = 0.0, t = -INFINITY;
    long n = 0;
    for (size_t i = 0; i < s->n; i++) {
        if (!(s->flags[i] & CDEM_FLAG_SALT))
            continue;
        a += s->area_ratio[i] * M_PI * s->radius[i] * s->radius[i];
        t = fmax(t, s->y[i] + s->radius[i]);
        n++;
    }
    *area = phi > 0.0 ? a / phi : 0.0;
    *top = n > 0 ? t : NAN;
    *count = n;
}
