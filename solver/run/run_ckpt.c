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

/* The setting lines of a parameter file's text (n bytes), without its comments and blank
 * lines, into a malloc'd string: what a checkpoint's parameter set is compared by. The
 * comments are help text; a build that words them differently runs the same model. */
static char *settings_of(const char *text, size_t n) {
    char *out = malloc(n + 1);
    if (!out)
        return NULL;
    size_t o = 0;
    for (size_t i = 0; i < n;) {
        size_t end = i;
        while (end < n && text[end] != '\n')
            end++;
        size_t first = i;
        while (first < end && (text[first] == ' ' || text[first] == '\t'))
            first++;
        if (first < end && text[first] != '#') {
            memcpy(out + o, text + i, end - i);
            o += end - i;
            out[o++] = '\n';
        }
        i = end + 1;
    }
    out[o] = '\0';
    return out;
}

/* The checkpoint's parameter text (n bytes) read over the defaults and written again, as
 * this build writes a parameter set: a key added to the table after the checkpoint was
 * written (salt.*, physics.damping_mode) then takes its default, which is what that run had.
 * NULL when out of memory; the text itself when it does not parse (the comparison then
 * names the difference). */
static char *rewritten(const char *text, size_t n) {
    char *copy = malloc(n + 1), *out = NULL;
    if (!copy)
        return NULL;
    memcpy(copy, text, n);
    copy[n] = '\0';
    cdem_params q;
    cdem_params_defaults(&q);
    cdem_error err;
    if (cdem_params_parse_text(&q, copy, "checkpoint", &err) != CDEM_OK)
        return copy;
    size_t len = 0;
    FILE *f = open_memstream(&out, &len);
    if (f) {
        cdem_params_write(&q, f);
        fclose(f);
    }
    free(copy);
    return out;
}

/* The checkpoint's parameter set (run.params) has this run's settings. */
static cdem_status check_params(const cdem_snapshot *snap, const char *expected, cdem_error *err) {
    const cdem_snapshot_array *a = NULL;
    CDEM_TRY(cdem_ckpt_get_array(snap, "run", "params", CDEM_SNAP_U8, SIZE_MAX, &a, err));
    char *stored = rewritten(a->data, a->count);
    char *have = stored ? settings_of(stored, strlen(stored)) : NULL;
    char *want = settings_of(expected, strlen(expected));
    free(stored);
    cdem_status st = CDEM_OK;
    if (!have || !want) {
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory comparing a checkpoint's parameters");
    } else if (strcmp(have, want) != 0) {
        size_t k = 0;
        while (have[k] && have[k] == want[k])
            k++;
        size_t b = k;
        while (b > 0 && want[b - 1] != '\n')
            b--;
        size_t end = b;
        while (want[end] && want[end] != '\n' && end - b < 80)
            end++;
        st = CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                       "checkpoint run.params: the parameter set of the checkpoint differs from "
                       "this run's (first difference in \"%.*s\")",
                       (int)(end - b), want + b);
    }
    free(have);
    free(want);
    return st;
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
    CDEM_TRY(check_params(snap, r->ckpt.params_eff, err));
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
