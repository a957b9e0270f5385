/* process_registry: the table of the processes, made from the rows of common/processes.def
 * (adding a process is one folder plus one row there), and the loops over the processes a
 * run turns on (process.h). */
#include "process.h"

#include <stdlib.h>
#include <string.h>

static const cdem_process_ops *const *const registry[] = {
#define CDEM_PROCESS(ID, id, word) &cdem_process_##id,
#define CDEM_TEST_PROCESS          CDEM_PROCESS
#include "processes.def"
#undef CDEM_PROCESS
#undef CDEM_TEST_PROCESS
};

#define N_PROCESSES (sizeof registry / sizeof registry[0])

void cdem_processes_rules(const cdem_params *p, cdem_rule_log *log) {
    for (size_t k = 0; k < N_PROCESSES; k++)
        if ((*registry[k])->rules)
            (*registry[k])->rules(p, log);
}

void cdem_processes_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    for (size_t k = 0; k < N_PROCESSES; k++) {
        const cdem_process_ops *o = *registry[k];
        if (o->active(p) && o->describe)
            o->describe(p, m, out);
    }
}

double cdem_processes_time_scale(const cdem_params *p, const cdem_model *m, const char **word) {
    *word = NULL;
    for (size_t k = 0; k < N_PROCESSES; k++) {
        const cdem_process_ops *o = *registry[k];
        const double s = o->active(p) && o->time_scale ? o->time_scale(p, m) : 0.0;
        if (s > 0.0) {
            *word = o->word;
            return s;
        }
    }
    return 0.0;
}

cdem_status cdem_processes_add(cdem_processes *ps, const cdem_process_ops *ops, cdem_error *err) {
    if (ps->n == (int)(sizeof ps->ops / sizeof ps->ops[0]))
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "too many processes at once (%d)", ps->n);
    ps->ctx[ps->n] = calloc(1, ops->state_size);
    if (!ps->ctx[ps->n])
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the %s process", ops->word);
    ps->ops[ps->n++] = ops;
    return CDEM_OK;
}

cdem_status cdem_processes_init(cdem_processes *ps, const cdem_params *p, cdem_error *err) {
    memset(ps, 0, sizeof *ps);
    for (size_t k = 0; k < N_PROCESSES; k++) {
        if (!(*registry[k])->active(p))
            continue;
        cdem_status st = cdem_processes_add(ps, *registry[k], err);
        if (st != CDEM_OK) {
            cdem_processes_free(ps);
            return st;
        }
    }
    return CDEM_OK;
}

cdem_status cdem_processes_place(cdem_processes *ps, const cdem_params *p, const cdem_model *m,
                                 cdem_state *s, FILE *log, cdem_error *err) {
    for (int k = 0; k < ps->n; k++)
        if (ps->ops[k]->place)
            CDEM_TRY(ps->ops[k]->place(ps->ctx[k], p, m, s, log, err));
    return CDEM_OK;
}

cdem_status cdem_processes_configure(cdem_processes *ps, const cdem_params *p, const cdem_model *m,
                                     cdem_integrator *it, cdem_error *err) {
    for (int k = 0; k < ps->n; k++)
        if (ps->ops[k]->configure)
            CDEM_TRY(ps->ops[k]->configure(ps->ctx[k], p, m, it, err));
    return CDEM_OK;
}

int cdem_processes_gravity(const cdem_processes *ps, long k, double *gx, double *gy) {
    int turned = 0;
    for (int j = 0; j < ps->n; j++)
        if (ps->ops[j]->gravity) {
            ps->ops[j]->gravity(ps->ctx[j], k, gx, gy);
            turned = 1;
        }
    return turned;
}

void cdem_processes_increment(cdem_processes *ps, cdem_state *s) {
    for (int k = 0; k < ps->n; k++)
        if (ps->ops[k]->increment)
            ps->ops[k]->increment(ps->ctx[k], s);
}

void cdem_processes_sample(const cdem_processes *ps, const cdem_state *s, cdem_series_sample *q) {
    for (int k = 0; k < ps->n; k++)
        if (ps->ops[k]->sample)
            ps->ops[k]->sample(ps->ctx[k], s, q);
}

void cdem_processes_finish(const cdem_processes *ps, FILE *log) {
    for (int k = 0; k < ps->n; k++)
        if (ps->ops[k]->finish)
            ps->ops[k]->finish(ps->ctx[k], log);
}

void cdem_processes_free(cdem_processes *ps) {
    if (!ps)
        return;
    for (int k = 0; k < ps->n; k++) {
        if (ps->ops[k]->free)
            ps->ops[k]->free(ps->ctx[k]);
        free(ps->ctx[k]);
    }
    memset(ps, 0, sizeof *ps);
}
