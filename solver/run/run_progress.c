/* run_progress: the progress display of a run and the log line that ends it (run_ctx.h).
 * Progress goes to opt->log only (never stdout); the wall clock is read here for the display,
 * never for results. On a terminal one line is redrawn (at most 4 times a second), else a log line
 * every tenth of the run or 30 s. */
#include "run_ctx.h"
#include "xdmf.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

double run_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int run_logging(const run_ctx *r) {
    return !r->opt->quiet && r->opt->log;
}

void run_end_progress_line(run_ctx *r) {
    if (r->prog.tty_line_open && r->opt->log) {
        fputc('\n', r->opt->log);
        r->prog.tty_line_open = 0;
    }
}

/* Books the steps and time since the last call to the phase the run is in now (called every
 * 64 steps, so a phase change is attributed to within 64 steps). */
static void account_phase(run_ctx *r, double t) {
    const int k = run_phase_of(r, r->step) == CDEM_PHASE_EQUILIBRATION ? 0 : 1;
    r->prog.phase_time[k] += t - r->prog.t_mark;
    r->prog.phase_steps[k] += r->step - r->prog.mark_step;
    r->prog.t_mark = t;
    r->prog.mark_step = r->step;
}

/* Steps per second of phase k (0 equilibration, 1 deformation), or `fallback` before that
 * phase has run for a second. */
static double phase_rate(const run_ctx *r, int k, double fallback) {
    return r->prog.phase_time[k] >= 1.0 ? (double)r->prog.phase_steps[k] / r->prog.phase_time[k]
                                        : fallback;
}

/* Seconds left: the equilibration steps left at equilibration's measured speed, the rest at
 * deformation's (equilibration's until deformation has been measured). */
static double time_left(const run_ctx *r, double overall) {
    const long eq_end = r->m.equil_steps, total = r->m.total_steps;
    const double eq_rate = phase_rate(r, 0, overall);
    const double def_rate = phase_rate(r, 1, eq_rate);
    const long eq_left = r->step < eq_end ? eq_end - r->step : 0;
    const long def_left = total - (r->step > eq_end ? r->step : eq_end);
    return (eq_rate > 0.0 ? (double)eq_left / eq_rate : 0.0) +
           (def_rate > 0.0 && def_left > 0 ? (double)def_left / def_rate : 0.0);
}

/* The progress line; ending NULL: "N s left", else the text that replaces it on the last
 * line ("completed", "stopped early", "interrupted"), so a run never ends on a time left.
 * The speed shown is the current phase's. */
void run_progress_line(run_ctx *r, int force, const char *ending) {
    if (!run_logging(r))
        return;
    const double t = run_now();
    account_phase(r, t);
    const long total = r->m.total_steps;
    const double elapsed = t - r->prog.t_start;
    const double overall = elapsed > 0.0 ? (double)(r->step - r->prog.step0) / elapsed : 0.0;
    const int k = run_phase_of(r, r->step) == CDEM_PHASE_EQUILIBRATION ? 0 : 1;
    const double rate = phase_rate(r, k, overall);
    const double left = time_left(r, overall);
    const double net = cdem_bc_net_displacement(&r->bc);
    const int inc_done = r->next_inc - 1;
    char tail[64];
    if (ending)
        snprintf(tail, sizeof tail, "%s after %.0f s", ending, elapsed);
    else
        snprintf(tail, sizeof tail, "%.0f s left", left);
    if (r->opt->progress_is_tty) {
        /* the first line at once (a user sees the run start, and a short run still shows
         * its phases), then at most 4 redraws a second */
        if (!force && r->prog.tty_drawn && t - r->prog.t_last_log < 0.25)
            return;
        r->prog.tty_drawn = 1;
        fprintf(r->opt->log,
                "\r\033[K%s, increment %d (0..%d), net displacement %.1f m, %zu elements, %.0f "
                "steps/s, %s",
                run_phase_name(run_phase_of(r, r->step)), inc_done, r->m.n_increments_total, net,
                r->s.n, rate, tail);
        fflush(r->opt->log);
        r->prog.tty_line_open = 1;
    } else {
        const long tenth = total / 10 > 0 ? total / 10 : 1;
        if (!force && r->step - r->prog.last_log_step < tenth && t - r->prog.t_last_log < 30.0)
            return;
        fprintf(r->opt->log,
                "cdem-run: %s, step %ld/%ld, increment %d (0..%d), net displacement %.1f m, %zu "
                "elements, %.0f steps/s, %s\n",
                run_phase_name(run_phase_of(r, r->step)), r->step, total, inc_done,
                r->m.n_increments_total, net, r->s.n, rate, tail);
        fflush(r->opt->log);
        r->prog.last_log_step = r->step;
    }
    r->prog.t_last_log = t;
}

void run_progress(run_ctx *r, int force) {
    run_progress_line(r, force, NULL);
}

/* The last line of a run's log: the file, its size, the increments it holds, the speed, the
 * threads and the pair kernel (avx2 or scalar: the same bits, not the same speed), and how the
 * run ended, with how to continue one that stopped early. */
void run_log_wrote(const run_ctx *r, cdem_status st, int had_writer) {
    if (!run_logging(r) || !had_writer || !r->opt->output_path)
        return;
    struct stat sb;
    const double mb = stat(r->opt->output_path, &sb) == 0 ? (double)sb.st_size / 1e6 : NAN;
    const char *how = st == CDEM_OK && r->stop_kind ? r->stop_kind
                      : st == CDEM_ERR_INTERRUPTED  ? "interrupted"
                      : st == CDEM_ERR_NUMERIC      ? "numerical-failure"
                      : st == CDEM_ERR_IO           ? "write-failure"
                                                    : "error";
    char hint[CDEM_PATH_MAX + 160] = "";
    if (st == CDEM_OK && r->stop_kind && !strcmp(r->stop_kind, "stopped-early"))
        run_resume_hint(r, hint, sizeof hint);
    const double wall = run_now() - r->prog.t_start;
    const long steps = r->step - r->prog.step0;
    /* the threads: N, and the share of the steps the governor ran on one (governor.h) */
    const int nthreads = r->gov_started ? r->gov.allowed : 1;
    char threads[192];
    int len = snprintf(threads, sizeof threads, "%d thread%s", nthreads, nthreads == 1 ? "" : "s");
    if (r->gov_started && r->gov.steps_on_one > 0 && steps > 0)
        snprintf(threads + len, sizeof threads - (size_t)len,
                 ", 1 for %.0f %% of the steps, where 1 measured faster (" GOVERNOR_WHY_ONE ")",
                 100.0 * (double)r->gov.steps_on_one / (double)steps);
    /* the sidecar as ParaView opens it: "./NAME.xmf", never a bare name (xdmf.h) */
    char *xmf = cdem_xdmf_path_for(r->opt->output_path);
    char kernel[96];
    cdem_force_path_describe(&r->it.force, cdem_law_name(r->p->granular_law), kernel,
                             sizeof kernel);
    fprintf(r->opt->log,
            "cdem-run: wrote %s (%.1f MB; %d increments, numbered 0..%d; %zu elements at the end; "
            "%ld steps in %.1f s wall time, %.3g element-steps/s on %s; pair kernel %s; stop "
            "reason: %s%s); ParaView: %s%s\n",
            r->opt->output_path, mb, r->next_inc, r->next_inc - 1, r->s.n, steps, wall,
            wall > 0.0 ? r->prog.element_steps / wall : 0.0, threads, kernel, how, hint,
            xmf ? cdem_xdmf_open_prefix(xmf) : "", xmf ? xmf : "?");
    free(xmf);
}

/* "; continue it with: cdem-run --resume FILE" when the file holds a checkpoint to continue
 * from, else why it cannot be continued; "" without a file. */
void run_resume_hint(const run_ctx *r, char *buf, size_t cap) {
    buf[0] = '\0';
    if (!r->opt->output_path)
        return;
    if (!r->ckpt.off && r->p->checkpoint_interval > 0)
        snprintf(buf, cap, "; continue it with: cdem-run --resume %s", r->opt->output_path);
    else
        snprintf(buf, cap,
                 "; it cannot be continued (no checkpoints: output.checkpoint_interval = %d)",
                 r->p->checkpoint_interval);
}
