/* run_ckpt: the checkpoints of a run (run_ctx.h, docs/reliability.md): cdem_run_capture
 * (every module under its own prefix), the restore of a set-up run, and the periodic
 * checkpoint after the step of every checkpoint_interval-th increment and the checkpoint of
 * a stop. cdem_run_resume, which reads a file's newest checkpoint and drives the run from
 * it, is in run.c beside cdem_run. */
#include "run_ctx.h"

#include "checkpoint.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Layout of the solver's checkpoint arrays (docs/reliability.md); bumped when a module stores
 * something new or changes a meaning, so a checkpoint of another layout is refused. */
#define CKPT_LAYOUT 1

cdem_status cdem_run_capture(const cdem_run_ctx *r, cdem_snapshot *snap, cdem_error *err) {
    if (!r || !snap)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_run_capture: NULL argument");
    cdem_snapshot_clear(snap);
    const char *P = "run";
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "layout", CKPT_LAYOUT, err));
    CDEM_TRY(cdem_ckpt_put_text(snap, P, "version", CDEM_VERSION, err));
    CDEM_TRY(cdem_ckpt_put_text(snap, P, "params", r->ckpt.params_eff, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "step", r->step, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "next_inc", r->next_inc, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "next_inc_step", r->next_inc_step, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "last_written_step", r->last_written_step, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "last_ckpt_inc", r->ckpt.last_inc, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "removed", r->removed, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "eroded", r->eroded, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "k_def", r->k_def, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "erosion_y", r->erosion_y, err));
    CDEM_TRY(cdem_ckpt_state_put(&r->s, r->ckpt.boundary_forces, snap, err));
    CDEM_TRY(cdem_integrator_snapshot_put(&r->it, r->ckpt.boundary_forces, snap, err));
    CDEM_TRY(cdem_bc_snapshot_put(&r->bc, snap, err));
    return cdem_sediment_snapshot_put(&r->sed, snap, err);
}

/* The checkpoint's parameter set (run.params, the effective parameter file of the run that
 * wrote it) has this run's values: compared by value, parameter by parameter, after parsing
 * it over the defaults. Not by its text: the help comments are reworded between builds, and
 * a parameter added since reads as its default, which is the value the earlier build ran
 * with (the torn-index evidence of issue 35 was written before two such changes). */
static cdem_status check_params(const cdem_snapshot *snap, const cdem_params *p,
                                const char *params_eff, cdem_error *err) {
    const cdem_snapshot_array *a = NULL;
    CDEM_TRY(cdem_ckpt_get_array(snap, "run", "params", CDEM_SNAP_U8, SIZE_MAX, &a, err));
    if ((int)p->mode >= CDEM_MODE_WORDS) {
        /* a fixture of the tests (common/modes.def) has no word a parameter file can hold, so
         * its set cannot be parsed back: it resumes (in memory, by the tests) only from a
         * checkpoint whose text is this run's own */
        if (a->count == strlen(params_eff) && memcmp(a->data, params_eff, a->count) == 0)
            return CDEM_OK;
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "checkpoint run.params: a run in the tests' mode %s resumes only from "
                         "a checkpoint of the same parameter text",
                         cdem_mode_name(p->mode));
    }
    char *text = malloc(a->count + 1);
    if (!text)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory comparing a checkpoint's parameters");
    memcpy(text, a->data, a->count);
    text[a->count] = '\0';
    cdem_params stored;
    cdem_params_defaults(&stored);
    cdem_error perr;
    cdem_error_clear(&perr);
    cdem_status st = cdem_params_parse_text(&stored, text, "checkpoint run.params", &perr);
    free(text);
    if (st != CDEM_OK)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "checkpoint run.params: its parameter set does not parse with this "
                         "cdem-run: %.600s",
                         perr.msg);
    size_t count = 0;
    const cdem_param_def *table = cdem_params_table(&count);
    for (size_t i = 0; i < count; i++) {
        char want[2 * CDEM_PATH_MAX + 64], have[2 * CDEM_PATH_MAX + 64];
        cdem_params_format_value(p, &table[i], want, sizeof want);
        cdem_params_format_value(&stored, &table[i], have, sizeof have);
        if (strcmp(want, have) != 0)
            return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                             "checkpoint run.params: the parameter set of the checkpoint differs "
                             "from this run's ([%s] %s = %.200s in the checkpoint, %.200s here)",
                             table[i].section, table[i].key, have, want);
    }
    return CDEM_OK;
}

/* Replaces the state of a set-up run by the checkpoint's. */
cdem_status run_restore(run_ctx *r, const cdem_snapshot *snap, cdem_error *err) {
    const char *P = "run";
    int64_t layout = 0;
    CDEM_TRY(cdem_ckpt_get_i64(snap, P, "layout", &layout, err));
    if (layout != CKPT_LAYOUT)
        return CDEM_FAIL(err, CDEM_ERR_VERSION,
                         "checkpoint layout %lld: this cdem-run (%s) reads layout %d only; resume "
                         "with the version that wrote the file",
                         (long long)layout, CDEM_VERSION, CKPT_LAYOUT);
    const cdem_snapshot_array *ver = NULL;
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "version", CDEM_SNAP_U8, SIZE_MAX, &ver, err));
    if (ver->count != strlen(CDEM_VERSION) || memcmp(ver->data, CDEM_VERSION, ver->count) != 0)
        return CDEM_FAIL(err, CDEM_ERR_VERSION,
                         "the checkpoint was written by cdem-run %.*s, this is cdem-run %s: a run "
                         "resumes bit-identically only with the version that started it",
                         (int)(ver->count > 64 ? 64 : ver->count), (const char *)ver->data,
                         CDEM_VERSION);
    CDEM_TRY(check_params(snap, r->p, r->ckpt.params_eff, err));
    const long total = r->m.total_steps;
    int64_t step = 0, next_inc = 0, next_inc_step = 0, lws = 0, lci = 0, removed = 0, eroded = 0,
            k_def = 0;
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "step", 0, total, &step, err));
    CDEM_TRY(
        cdem_ckpt_get_range(snap, P, "next_inc", 1, r->m.n_increments_total + 1, &next_inc, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "next_inc_step", 0, INT64_MAX, &next_inc_step, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "last_written_step", -1, step, &lws, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "last_ckpt_inc", 0, next_inc, &lci, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "removed", 0, INT64_MAX, &removed, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "eroded", 0, INT64_MAX, &eroded, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "k_def", 0, step, &k_def, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "erosion_y", &r->erosion_y, err));
    CDEM_TRY(cdem_ckpt_state_get(&r->s, snap, err));
    CDEM_TRY(cdem_integrator_snapshot_get(&r->it, snap, &r->s, &r->ckpt.boundary_forces, err));
    if (r->it.step != (long)step)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "checkpoint run.step = %lld but it.step = %ld (corrupt checkpoint)",
                         (long long)step, r->it.step);
    CDEM_TRY(cdem_bc_snapshot_get(&r->bc, snap, err));
    CDEM_TRY(cdem_sediment_snapshot_get(&r->sed, snap, err));
    r->step = r->prog.step0 = r->prog.mark_step = (long)step;
    r->next_inc = (int)next_inc;
    r->next_inc_step = (long)next_inc_step;
    r->last_written_step = (long)lws;
    r->ckpt.last_inc = (int)lci;
    r->removed = (long)removed;
    r->eroded = (long)eroded;
    r->k_def = (long)k_def;
    return CDEM_OK;
}

/* Captures the run and stores it in the file as the checkpoint of the increment written last.
 * scheduled = 1: a periodic checkpoint (it records itself in last_ckpt_inc, which sets the
 * schedule of the next); 0: the checkpoint of a stop (signal, max_steps), which leaves the
 * schedule as it is so a resumed run writes the same periodic checkpoints. */
cdem_status run_write_checkpoint(run_ctx *r, int scheduled, cdem_error *err) {
    if (!r->ckpt.snap)
        CDEM_TRY(cdem_snapshot_alloc(&r->ckpt.snap, err));
    const int saved = r->ckpt.last_inc;
    if (scheduled)
        r->ckpt.last_inc = r->next_inc - 1; /* the checkpoint records itself */
    cdem_status st = cdem_run_capture(r, r->ckpt.snap, err);
    if (st == CDEM_OK)
        st = cdem_h5_writer_write_checkpoint(r->w, r->ckpt.snap, err);
    if (st == CDEM_ERR_UNSUPPORTED) {
        /* a file layer without checkpoints: say so once and run on without them */
        r->ckpt.off = 1;
        if (run_logging(r)) {
            run_end_progress_line(r);
            fprintf(r->opt->log, "cdem-run: no checkpoints will be written: %s\n",
                    err ? err->msg : "unsupported");
        }
        if (err)
            cdem_error_clear(err);
        st = CDEM_OK;
    }
    if (st != CDEM_OK) {
        r->ckpt.last_inc = saved;
        return st;
    }
    return CDEM_OK;
}
