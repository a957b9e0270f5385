/* analysis: see analysis.h. The cache holds CACHE_SLOTS increments, evicting the least
 * recently used; one request touches at most three increments at a time (current,
 * reference, birth reference), so with four slots a state fetched inside a request is never
 * evicted before the request re-fetches the current state it returns. Cumulative strain is a
 * running sum advanced pair by pair (each pair computed once while k increases; going back
 * restarts from the end of equilibration; none of them while the end is not known, which a run
 * still in equilibration has not reached). Limits spanning many increments (stress over all
 * increments, total displacement at the last increment) are computed once and cached. */
#include "analysis.h"

#include "displacement.h"
#include "strain.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CACHE_SLOTS 4
#define N_STRESS    7
#define N_DISP      4 /* x, y, mag, uplift */

typedef struct {
    int used;            /* 1 when state holds increment index */
    size_t index;        /* increment index held */
    unsigned long stamp; /* last use, for LRU */
    cdem_state state;    /* the loaded increment */
} cache_slot;

struct cdem_analysis {
    cdem_analysis_source src;      /* where increments come from */
    void *ctx;                     /* source context */
    cdem_params params;            /* the run's parameters */
    size_t n;                      /* increments */
    cdem_increment_info *infos;    /* n infos */
    size_t equil;                  /* end-of-equilibration index (when equil_known) */
    int equil_known;               /* 0: the run has not left equilibration (see open) */
    char equil_why[80];            /* when not known: why ("the run stopped during ...") */
    cache_slot slot[CACHE_SLOTS];  /* LRU cache */
    unsigned long clock;           /* use counter for LRU */
    cdem_strain_cum cum;           /* running cumulative sums */
    size_t cum_at;                 /* index the sums reach (SIZE_MAX = not started) */
    int have_stress_lim[N_STRESS]; /* cached stress limits present */
    cdem_limits stress_lim[N_STRESS];
    int have_total_lim[N_DISP]; /* cached total-displacement limits present */
    cdem_limits total_lim[N_DISP];
    char *name; /* the run in messages (its file), or NULL */
};

/* ---------------------------------------------------------------- memory source */
typedef struct {
    const cdem_state *states;
    const cdem_increment_info *infos;
    size_t n;
} mem_source;

static size_t mem_count(void *ctx) {
    return ((mem_source *)ctx)->n;
}
static cdem_status mem_info(void *ctx, size_t index, cdem_increment_info *info, cdem_error *err) {
    (void)err;
    *info = ((mem_source *)ctx)->infos[index];
    return CDEM_OK;
}
static cdem_status mem_load(void *ctx, size_t index, cdem_state *s, cdem_error *err) {
    return cdem_state_copy(s, &((mem_source *)ctx)->states[index], err);
}
static void mem_close(void *ctx) {
    free(ctx);
}

static const cdem_analysis_source mem_ops = {
    mem_count, /* count */
    mem_info,  /* info */
    mem_load,  /* load */
    mem_close, /* close */
    NULL,      /* reader: no file behind memory states */
};

/* ---------------------------------------------------------------- lifecycle */

/* Why a run has no increment to analyse, or what is wrong with it (the reader refuses a
 * closed file whose stop reason says increments were written and that lists none). */
static cdem_status no_increments(cdem_h5_reader *r, cdem_error *err) {
    if (!r)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "analysis: no increments to analyse");
    const char *stop = cdem_h5_reader_stop_reason(r);
    if (!strcmp(stop, "running") && cdem_h5_reader_writer_alive(r) == 1)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "the run is being written and has no increment yet (increment 0 is "
                         "written when its assembly is done): try again in a moment");
    if (!strcmp(stop, "running") || !stop[0])
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "the file holds no increment: its writer stopped before writing "
                         "increment 0 (killed or crashed; no writer holds the file)");
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                     "the file holds no increment: the run stopped (stop reason \"%s\"%s%.300s) "
                     "before writing increment 0",
                     stop, cdem_h5_reader_stop_detail(r)[0] ? ": " : "",
                     cdem_h5_reader_stop_detail(r));
}
cdem_status cdem_analysis_open_source(const cdem_analysis_source *src, void *ctx,
                                      const cdem_params *params, cdem_analysis **out,
                                      cdem_error *err) {
    *out = NULL;
    cdem_analysis *a = calloc(1, sizeof *a);
    if (!a) {
        if (src->close)
            src->close(ctx);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "analysis: out of memory");
    }
    a->src = *src;
    a->ctx = ctx;
    if (params)
        a->params = *params;
    else
        cdem_params_defaults(&a->params);
    if (!(a->params.total_strain_max > 0.0))
        a->params.total_strain_max = 2.0;
    a->n = src->count(ctx);
    a->cum_at = SIZE_MAX;
    cdem_strain_cum_init(&a->cum);
    a->infos = calloc(a->n ? a->n : 1, sizeof *a->infos);
    if (!a->infos) {
        cdem_analysis_close(a);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "analysis: out of memory for %zu increments", a->n);
    }
    for (size_t i = 0; i < a->n; i++) {
        cdem_status st = src->info(ctx, i, &a->infos[i], err);
        if (st != CDEM_OK) {
            cdem_analysis_close(a);
            return st;
        }
    }
    cdem_h5_reader *r = src->reader ? src->reader(ctx) : NULL;
    if (a->n == 0) {
        const cdem_status st = no_increments(r, err); /* before the close closes r */
        cdem_analysis_close(a);
        return st;
    }
    /* The end of equilibration is the last increment of that phase once a later phase has
     * begun (or the run completed); a run that stopped, was killed or still runs in
     * equilibration has not written it yet (its last increment was 42 where the end was 56),
     * and totals are then not defined: never guessed (docs/analysis.md). A run without
     * equilibration increments measures from its first. */
    size_t last_eq = SIZE_MAX;
    for (size_t i = 0; i < a->n; i++)
        if (a->infos[i].phase == CDEM_PHASE_EQUILIBRATION)
            last_eq = i;
    a->equil = last_eq == SIZE_MAX ? 0 : last_eq;
    a->equil_known = 1;
    if (last_eq == a->n - 1 && (!r || strcmp(cdem_h5_reader_stop_reason(r), "completed") != 0)) {
        a->equil_known = 0;
        snprintf(a->equil_why, sizeof a->equil_why, "%s",
                 !r ? "the increments end in equilibration"
                 : cdem_h5_reader_writer_alive(r) == 1 &&
                         !strcmp(cdem_h5_reader_stop_reason(r), "running")
                     ? "the run is still in equilibration"
                     : "the run stopped during equilibration");
    }
    *out = a;
    return CDEM_OK;
}

cdem_status cdem_analysis_open_states(const cdem_state *states, const cdem_increment_info *infos,
                                      size_t n, const cdem_params *params, cdem_analysis **out,
                                      cdem_error *err) {
    mem_source *m = malloc(sizeof *m);
    if (!m)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "analysis: out of memory");
    m->states = states;
    m->infos = infos;
    m->n = n;
    return cdem_analysis_open_source(&mem_ops, m, params, out, err);
}

void cdem_analysis_close(cdem_analysis *a) {
    if (!a)
        return;
    for (int k = 0; k < CACHE_SLOTS; k++)
        cdem_state_free(&a->slot[k].state);
    cdem_strain_cum_free(&a->cum);
    free(a->infos);
    free(a->name);
    if (a->src.close)
        a->src.close(a->ctx);
    free(a);
}

void cdem_analysis_set_name(cdem_analysis *a, const char *name) {
    if (!a)
        return;
    free(a->name);
    a->name = name ? strdup(name) : NULL;
}

size_t cdem_analysis_count(const cdem_analysis *a) {
    return a->n;
}
const cdem_increment_info *cdem_analysis_info(const cdem_analysis *a, size_t index) {
    return index < a->n ? &a->infos[index] : NULL;
}
size_t cdem_analysis_equil_index(const cdem_analysis *a) {
    return a->equil;
}
int cdem_analysis_equil_known(const cdem_analysis *a) {
    return a->equil_known;
}
const char *cdem_analysis_equil_why(const cdem_analysis *a) {
    return a->equil_known ? "" : a->equil_why;
}
int cdem_analysis_from_equil(const cdem_quantity *q) {
    return q->family == CDEM_QF_TOTAL_DISP || q->family == CDEM_QF_TOTAL_STRAIN ||
           q->family == CDEM_QF_CUM_STRAIN;
}

/* A computation on increment index against increment ref failed (ref == index: on index
 * alone): its message, from code that sees only states ("duplicate element id 7 at slots 0
 * and 1"), is prefixed with the run and the increments, so it names where (issue 35, item
 * 10). The loads before it name their file and increment themselves. */
static cdem_status in_increments(const cdem_analysis *a, cdem_status st, size_t index, size_t ref,
                                 cdem_error *err) {
    if (st == CDEM_OK || st == CDEM_ERR_NOMEM)
        return st;
    char against[64] = "";
    if (ref != index)
        snprintf(against, sizeof against, " against increment %d", (int)a->infos[ref].number);
    cdem_error_prefix(err, "%s%sincrement %d%s", a->name ? a->name : "", a->name ? ": " : "",
                      (int)a->infos[index].number, against);
    return st;
}

/* CDEM_ERR_NOTFOUND: what (a quantity at an increment, ...) is measured from the end of
 * equilibration, which the run has not reached. */
static cdem_status equil_not_known(const cdem_analysis *a, const char *what, cdem_error *err) {
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                     "%s%s%s is not defined yet: it is measured from the end of equilibration, "
                     "which is not reached: %s (its last increment, %d, is of the equilibration "
                     "phase)",
                     a->name ? a->name : "", a->name ? ": " : "", what, a->equil_why,
                     (int)a->infos[a->n - 1].number);
}
const cdem_params *cdem_analysis_params(const cdem_analysis *a) {
    return &a->params;
}
cdem_h5_reader *cdem_analysis_reader(const cdem_analysis *a) {
    return a->src.reader ? a->src.reader(a->ctx) : NULL;
}

cdem_status cdem_analysis_find(const cdem_analysis *a, const char *spec, size_t *index,
                               cdem_error *err) {
    if (!spec || !*spec)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "increment: empty specification (use a number, "
                         "first, last or equil)");
    /* a run file whose commit record has a damaged row refuses that row's increment by
     * number, and "last" when it is the last row (issue 46): said as the reader says it */
    cdem_h5_reader *r = cdem_analysis_reader(a);
    if (r && strcmp(spec, "first") != 0 && strcmp(spec, "equil") != 0) {
        cdem_error e;
        cdem_error_clear(&e);
        size_t k = 0;
        if (cdem_h5_reader_find_increment(r, spec, &k, &e) == CDEM_ERR_FORMAT) {
            if (err)
                *err = e;
            return CDEM_ERR_FORMAT;
        }
    }
    if (strcmp(spec, "last") == 0) {
        *index = a->n - 1;
        return CDEM_OK;
    }
    if (strcmp(spec, "first") == 0) {
        *index = 0;
        return CDEM_OK;
    }
    if (strcmp(spec, "equil") == 0) {
        if (!a->equil_known)
            return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                             "%s%sincrement 'equil': the end of equilibration is not reached: %s "
                             "(its last increment, %d, is of the equilibration phase; the end is "
                             "known once an increment of the deformation phase follows)",
                             a->name ? a->name : "", a->name ? ": " : "", a->equil_why,
                             (int)a->infos[a->n - 1].number);
        *index = a->equil;
        return CDEM_OK;
    }
    char *end;
    long v = strtol(spec, &end, 10);
    if (*end || end == spec)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "increment '%.40s' is not a number, first, last or equil", spec);
    for (size_t i = 0; i < a->n; i++)
        if (a->infos[i].number == v) {
            *index = i;
            return CDEM_OK;
        }
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                     "%s%sincrement %ld does not exist (the run has %d..%d)",
                     a->name ? a->name : "", a->name ? ": " : "", v, (int)a->infos[0].number,
                     (int)a->infos[a->n - 1].number);
}

cdem_status cdem_analysis_state(cdem_analysis *a, size_t index, const cdem_state **s,
                                cdem_error *err) {
    if (index >= a->n)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "increment index %zu out of range (0..%zu)", index,
                         a->n - 1);
    a->clock++;
    int victim = 0;
    for (int k = 0; k < CACHE_SLOTS; k++) {
        if (a->slot[k].used && a->slot[k].index == index) {
            a->slot[k].stamp = a->clock;
            *s = &a->slot[k].state;
            return CDEM_OK;
        }
        if (!a->slot[k].used || (a->slot[victim].used && a->slot[k].stamp < a->slot[victim].stamp))
            victim = k;
    }
    cache_slot *v = &a->slot[victim];
    v->used = 0;
    cdem_state_free(&v->state);
    CDEM_TRY(a->src.load(a->ctx, index, &v->state, err));
    v->used = 1;
    v->index = index;
    v->stamp = a->clock;
    *s = &v->state;
    return CDEM_OK;
}

/* ---------------------------------------------------------------- values */
static size_t incr_ref(size_t index) {
    return index >= CDEM_ANALYSIS_INCR_LAG ? index - CDEM_ANALYSIS_INCR_LAG : 0;
}

/* Index of the first increment numbered >= number (a->n when none). */
static size_t index_at_or_after(const cdem_analysis *a, int32_t number) {
    for (size_t i = 0; i < a->n; i++)
        if (a->infos[i].number >= number)
            return i;
    return a->n;
}

static void pick_disp(const double *ux, const double *uy, size_t n, int comp, double *out) {
    for (size_t i = 0; i < n; i++)
        out[i] = comp == CDEM_QC_X ? ux[i] : comp == CDEM_QC_Y ? uy[i] : hypot(ux[i], uy[i]);
}

static double pick_strain(const cdem_strain_measures *m, int comp) {
    switch (comp) {
    case CDEM_QC_E1:
        return m->e1;
    case CDEM_QC_E3NEG:
        return m->e3_neg;
    case CDEM_QC_MAXSHEAR:
        return m->max_shear;
    case CDEM_QC_DILATION:
        return m->dilation;
    case CDEM_QC_ANGLE1:
        return m->angle1;
    default:
        return m->rotation;
    }
}

/* Total rule: for each reference group (equil, then each birth increment after it), run
 * pair(ref, cur, select) . cur is re-fetched by the caller afterwards. */
typedef cdem_status (*pair_fn)(const cdem_state *ref, const cdem_state *cur,
                               const unsigned char *select, void *user, cdem_error *err);

static cdem_status for_total_groups(cdem_analysis *a, size_t index, pair_fn fn, void *user,
                                    cdem_error *err) {
    const cdem_state *cur, *ref;
    CDEM_TRY(cdem_analysis_state(a, index, &cur, err));
    const size_t n = cur->n;
    unsigned char *sel = malloc(n ? n : 1);
    size_t *group = malloc((n ? n : 1) * sizeof *group);
    if (!sel || !group) {
        free(sel);
        free(group);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "analysis: out of memory for %zu elements", n);
    }
    const int32_t equil_number = a->infos[a->equil].number;
    for (size_t i = 0; i < n; i++)
        group[i] = cur->born[i] > equil_number ? index_at_or_after(a, cur->born[i]) : a->equil;
    cdem_status st = CDEM_OK;
    size_t done_below = 0; /* groups are processed in ascending reference index */
    for (;;) {
        size_t g = SIZE_MAX;
        for (size_t i = 0; i < n; i++)
            if (group[i] >= done_below && group[i] <= index && group[i] < g)
                g = group[i];
        if (g == SIZE_MAX)
            break;
        st = cdem_analysis_state(a, index, &cur, err);
        if (st == CDEM_OK)
            st = cdem_analysis_state(a, g, &ref, err);
        if (st == CDEM_OK)
            st = cdem_analysis_state(a, index, &cur, err); /* keep cur most recent */
        if (st != CDEM_OK)
            break;
        for (size_t i = 0; i < n; i++)
            sel[i] = group[i] == g;
        st = in_increments(a, fn(ref, cur, sel, user, err), index, g, err);
        if (st != CDEM_OK)
            break;
        done_below = g + 1;
    }
    free(sel);
    free(group);
    return st;
}

typedef struct {
    double *ux, *uy;         /* displacement output */
    cdem_strain_measures *m; /* strain output */
} pair_out;

static cdem_status disp_pair(const cdem_state *ref, const cdem_state *cur,
                             const unsigned char *select, void *user, cdem_error *err) {
    pair_out *o = user;
    return cdem_displacement_compute(ref, cur, select, o->ux, o->uy, err);
}

static cdem_status strain_pair(const cdem_state *ref, const cdem_state *cur,
                               const unsigned char *select, void *user, cdem_error *err) {
    pair_out *o = user;
    cdem_strain_measures *tmp = malloc((cur->n ? cur->n : 1) * sizeof *tmp);
    if (!tmp)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "analysis: out of memory for %zu elements", cur->n);
    cdem_status st = cdem_strain_compute(ref, cur, select, 0.0, tmp, err);
    if (st == CDEM_OK)
        for (size_t i = 0; i < cur->n; i++)
            if (select[i])
                o->m[i] = tmp[i];
    free(tmp);
    return st;
}

static void fill_nan_measures(cdem_strain_measures *m, size_t n) {
    for (size_t i = 0; i < n; i++)
        m[i].e1 = m[i].e3_neg = m[i].max_shear = m[i].dilation = m[i].rotation = m[i].angle1 = NAN;
}

/* Advances the cumulative sums to `index` (>= equil). */
static cdem_status cum_advance(cdem_analysis *a, size_t index, cdem_error *err) {
    if (a->cum_at == SIZE_MAX || a->cum_at > index) {
        cdem_strain_cum_reset(&a->cum);
        a->cum_at = a->equil;
    }
    cdem_strain_measures *m = NULL;
    size_t mcap = 0;
    cdem_status st = CDEM_OK;
    while (a->cum_at < index) {
        const cdem_state *prev, *cur;
        size_t k = a->cum_at + 1;
        st = cdem_analysis_state(a, k - 1, &prev, err);
        if (st == CDEM_OK)
            st = cdem_analysis_state(a, k, &cur, err);
        if (st != CDEM_OK)
            break;
        if (cur->n > mcap) {
            free(m);
            mcap = cur->n;
            m = malloc(mcap * sizeof *m);
            if (!m) {
                st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "analysis: out of memory for %zu elements",
                               mcap);
                break;
            }
        }
        st = in_increments(a, cdem_strain_compute(prev, cur, NULL, 0.0, m, err), k, k - 1, err);
        if (st == CDEM_OK)
            st = in_increments(a, cdem_strain_cum_add(&a->cum, cur, m, err), k, k - 1, err);
        if (st != CDEM_OK) {
            cdem_strain_cum_reset(&a->cum);
            a->cum_at = SIZE_MAX;
            break;
        }
        a->cum_at = k;
    }
    free(m);
    return st;
}

cdem_status cdem_analysis_values(cdem_analysis *a, size_t index, const cdem_quantity *q,
                                 const cdem_state **s, double **values, cdem_error *err) {
    *values = NULL;
    const cdem_state *cur;
    CDEM_TRY(cdem_analysis_state(a, index, &cur, err));
    const size_t n = cur->n;
    double *v = malloc((n ? n : 1) * sizeof *v);
    double *ux = malloc((n ? n : 1) * sizeof *ux), *uy = malloc((n ? n : 1) * sizeof *uy);
    cdem_strain_measures *m = malloc((n ? n : 1) * sizeof *m);
    cdem_status st = CDEM_OK;
    if (!v || !ux || !uy || !m) {
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "analysis: out of memory for %zu elements", n);
        goto done;
    }
    for (size_t i = 0; i < n; i++)
        v[i] = ux[i] = uy[i] = NAN;
    fill_nan_measures(m, n);
    if (cdem_analysis_from_equil(q) && !a->equil_known) {
        char what[160];
        snprintf(what, sizeof what, "%s at increment %d", q->name, (int)a->infos[index].number);
        st = equil_not_known(a, what, err);
        goto done;
    }
    pair_out o = {ux, uy, m};
    switch (q->family) {
    case CDEM_QF_INCR_DISP: {
        const cdem_state *ref;
        st = cdem_analysis_state(a, incr_ref(index), &ref, err);
        if (st == CDEM_OK)
            st = cdem_analysis_state(a, index, &cur, err);
        if (st == CDEM_OK)
            st = in_increments(a, cdem_displacement_compute(ref, cur, NULL, ux, uy, err), index,
                               incr_ref(index), err);
        if (st == CDEM_OK)
            pick_disp(ux, uy, n, q->component, v);
        break;
    }
    case CDEM_QF_TOTAL_DISP:
        if (index >= a->equil) {
            st = for_total_groups(a, index, disp_pair, &o, err);
            if (st == CDEM_OK)
                pick_disp(ux, uy, n, q->component, v);
        }
        break;
    case CDEM_QF_INCR_STRAIN: {
        const cdem_state *ref;
        st = cdem_analysis_state(a, incr_ref(index), &ref, err);
        if (st == CDEM_OK)
            st = cdem_analysis_state(a, index, &cur, err);
        if (st == CDEM_OK)
            st = in_increments(a, cdem_strain_compute(ref, cur, NULL, 0.0, m, err), index,
                               incr_ref(index), err);
        if (st == CDEM_OK)
            for (size_t i = 0; i < n; i++)
                v[i] = pick_strain(&m[i], q->component);
        break;
    }
    case CDEM_QF_TOTAL_STRAIN:
        if (index >= a->equil) {
            st = for_total_groups(a, index, strain_pair, &o, err);
            if (st == CDEM_OK)
                for (size_t i = 0; i < n; i++)
                    v[i] = pick_strain(&m[i], q->component);
        }
        break;
    case CDEM_QF_CUM_STRAIN:
        if (index >= a->equil) {
            st = cum_advance(a, index, err);
            if (st == CDEM_OK)
                st = cdem_analysis_state(a, index, &cur, err);
            if (st == CDEM_OK) {
                /* 0 at the end of equilibration itself; afterwards an element with no
                 * defined pair (always too few neighbours, or just born) is NaN */
                cdem_strain_cum_get(&a->cum, cur, index == a->equil, m);
                for (size_t i = 0; i < n; i++)
                    v[i] = pick_strain(&m[i], q->component);
            }
        }
        break;
    case CDEM_QF_STRESS:
        if (!cur->has_stress) {
            st = CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                           "quantity '%s' needs stress, but increment %d stores none (run with "
                           "physics.calculate_stress = on)",
                           q->name, (int)a->infos[index].number);
            break;
        }
        for (size_t i = 0; i < n; i++) {
            cdem_stress_principal p;
            cdem_stress_principal_from(cur->sxx[i], cur->syy[i], cur->sxy[i], &p);
            const double vals[N_STRESS] = {cur->sxx[i], cur->syy[i], cur->sxy[i], p.sigma1,
                                           p.sigma3,    p.max_shear, p.angle1};
            v[i] = vals[q->component];
        }
        break;
    }
    if (st == CDEM_OK)
        st = cdem_analysis_state(a, index, &cur, err); /* the pointer returned is current */
done:
    free(ux);
    free(uy);
    free(m);
    if (st != CDEM_OK) {
        free(v);
        return st;
    }
    *s = cur;
    *values = v;
    return CDEM_OK;
}

/* ---------------------------------------------------------------- limits */
static cdem_status limits_of(cdem_analysis *a, size_t index, const cdem_quantity *q,
                             cdem_limits *lim, cdem_error *err) {
    const cdem_state *s;
    double *v;
    CDEM_TRY(cdem_analysis_values(a, index, q, &s, &v, err));
    for (size_t i = 0; i < s->n; i++)
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            v[i] = NAN; /* colour limits come from the assembly, not from the walls */
    cdem_status st =
        cdem_limits_from_values(v, s->n, 0.01, 0.99, q->scale == CDEM_SCALE_SIGNED, 0.0, lim, err);
    free(v);
    return st;
}

cdem_status cdem_analysis_limits(cdem_analysis *a, size_t index, const cdem_quantity *q,
                                 cdem_limits *lim, cdem_error *err) {
    if (index >= a->n)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "increment index %zu out of range (0..%zu)", index,
                         a->n - 1);
    if (cdem_analysis_from_equil(q) && !a->equil_known)
        return equil_not_known(a, q->name, err); /* no scale for values that do not exist */
    const int sym = q->scale == CDEM_SCALE_SIGNED;
    const double tsm = a->params.total_strain_max;
    if (strcmp(q->unit, "deg") == 0) { /* directions: the whole half circle */
        *lim = cdem_limits_fixed(-90.0, 90.0);
        return CDEM_OK;
    }
    switch (q->family) {
    case CDEM_QF_INCR_DISP:
        return limits_of(a, index, q, lim, err);
    case CDEM_QF_TOTAL_DISP: {
        const int slot = sym ? 3 : q->component;
        if (!a->have_total_lim[slot]) {
            CDEM_TRY(limits_of(a, a->n - 1, q, &a->total_lim[slot], err));
            a->have_total_lim[slot] = 1;
        }
        *lim = a->total_lim[slot];
        return CDEM_OK;
    }
    case CDEM_QF_INCR_STRAIN:
        *lim = cdem_limits_fixed(sym ? -0.1 : 0.0, 0.1);
        return CDEM_OK;
    case CDEM_QF_TOTAL_STRAIN:
    case CDEM_QF_CUM_STRAIN:
        *lim = cdem_limits_fixed(sym ? -tsm : 0.0, tsm);
        return CDEM_OK;
    case CDEM_QF_STRESS:
        break;
    }
    const int c = q->component;
    if (!a->have_stress_lim[c]) {
        double *pool = NULL;
        size_t np = 0, cap = 0;
        cdem_status st = CDEM_OK;
        for (size_t k = 0; k < a->n && st == CDEM_OK; k++) {
            if (!a->infos[k].has_stress)
                continue;
            const cdem_state *s;
            double *v;
            st = cdem_analysis_values(a, k, q, &s, &v, err);
            if (st != CDEM_OK)
                break;
            if (np + s->n > cap) {
                size_t nc = cap ? cap : 1024;
                while (nc < np + s->n)
                    nc *= 2;
                double *p = realloc(pool, nc * sizeof *p);
                if (!p) {
                    free(v);
                    st = CDEM_FAIL(err, CDEM_ERR_NOMEM,
                                   "stress limits: out of memory pooling %zu values", nc);
                    break;
                }
                pool = p;
                cap = nc;
            }
            for (size_t i = 0; i < s->n; i++)
                if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY))
                    pool[np++] = v[i];
            free(v);
        }
        if (st == CDEM_OK)
            st = cdem_limits_from_values(pool, np, 0.01, 0.99, 0, CDEM_LIMITS_STRESS_CAP,
                                         &a->stress_lim[c], err);
        free(pool);
        if (st != CDEM_OK)
            return st;
        a->have_stress_lim[c] = 1;
    }
    *lim = a->stress_lim[c];
    return CDEM_OK;
}

/* ---------------------------------------------------------------- vectors and axes */
cdem_status cdem_analysis_vectors(cdem_analysis *a, size_t index, int total, const cdem_state **s,
                                  double **ux, double **uy, cdem_error *err) {
    size_t count;
    const cdem_quantity *t = cdem_quantity_table(&count);
    const char *nx = total ? "total-disp-x" : "incr-disp-x";
    const char *ny = total ? "total-disp-y" : "incr-disp-y";
    const cdem_quantity *qx = NULL, *qy = NULL;
    for (size_t i = 0; i < count; i++) {
        if (strcmp(t[i].name, nx) == 0)
            qx = &t[i];
        if (strcmp(t[i].name, ny) == 0)
            qy = &t[i];
    }
    CDEM_TRY(cdem_analysis_values(a, index, qx, s, ux, err));
    cdem_status st = cdem_analysis_values(a, index, qy, s, uy, err);
    if (st != CDEM_OK) {
        free(*ux);
        *ux = NULL;
    }
    return st;
}

cdem_status cdem_analysis_axes(cdem_analysis *a, size_t index, cdem_axes_kind kind, cdem_axes *out,
                               cdem_error *err) {
    memset(out, 0, sizeof *out);
    const cdem_state *cur, *ref;
    if (kind == CDEM_AXES_STRESS) {
        CDEM_TRY(cdem_analysis_state(a, index, &cur, err));
        return in_increments(a, cdem_axes_stress(cur, 0.0, out, err), index, index, err);
    }
    if (kind == CDEM_AXES_TOTAL_STRAIN && !a->equil_known)
        return equil_not_known(a, "the total strain axes", err);
    size_t r = kind == CDEM_AXES_INCR_STRAIN ? incr_ref(index) : a->equil;
    if (kind == CDEM_AXES_TOTAL_STRAIN && index < a->equil)
        return CDEM_OK; /* no total strain during equilibration: no axes (n = 0) */
    CDEM_TRY(cdem_analysis_state(a, r, &ref, err));
    CDEM_TRY(cdem_analysis_state(a, index, &cur, err));
    return in_increments(a, cdem_axes_strain(ref, cur, 0.0, out, err), index, r, err);
}
