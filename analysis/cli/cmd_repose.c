/* cmd_repose: `cdem-strain repose`; its help (below) says what it does. */
#include "cmd_plot.h"
#include "cmd_support.h"
#include "commands.h"
#include "render.h"
#include "repose.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char *const repose_forms[] = {
    "RUN.h5 [--increment K|last|equil|first] [-o OUT.png|.pdf|.svg] [--width N] [--height N]",
    "RUN1.h5 RUN2.h5 ... [--increment K|last|equil|first] [--include-poor-fits]", NULL};
static const cdem_cli_option repose_options[] = {
    {"--increment", "K|last|equil|first", "the increment (default last)"},
    {"--include-poor-fits", NULL,
     "several runs: count the runs with a poor fit in the mean too (by default they are left "
     "out, and the mean with them is printed beside)"},
    {"-o, --output", "OUT.png|.pdf|.svg", "the free surface with the fitted flanks"},
    CDEM_PLOT_WIDTH_OPTION,
    CDEM_PLOT_HEIGHT_OPTION,
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain repose",
    .forms = repose_forms,
    .about = "Angle of repose: the slope of the free surface of a repose-collapse run, fitted "
             "on each flank, with the fit's quality (a curved, rough or uncertain slope is a "
             "poor fit) and whether the slope has settled (at rest in the last increment, its "
             "angle within 2 deg over the last third of the run); both warnings also go to "
             "stderr. One collapse's angle depends on its packing (a standard deviation of "
             "2-3 deg): given several runs of one material (other assembly.seed), it reports "
             "each and then the mean, standard deviation, standard error and range of the runs "
             "measured with a good fit, the material's angle of repose (and the mean with the "
             "poor fits beside; --include-poor-fits counts them). Each run counts once: a file "
             "given twice, also by another path, is refused. A run whose mode is not repose is "
             "not measured (docs/rendering.md, \"cdem-strain repose\").",
    .options = repose_options,
    .exit_status = "0 every run given measured (a poor fit or a slope still moving is warned "
                   "about), 1 a run that cannot be read or measured, or is not a "
                   "repose-collapse run, or several runs without a good fit to average, 2 "
                   "usage error.",
};

static cdem_status repose_figure(const cdem_plot_args *a, const cdem_state *s, int number,
                                 const cdem_repose_result *res, int moving, cdem_error *err) {
    cdem_render_format fmt;
    CDEM_TRY(cdem_render_format_from_path(a->out, &fmt, err));
    cdem_render_options o;
    cdem_render_options_default(&o);
    o.width = a->width ? a->width : 1200;
    o.height = a->height;
    char label[160];
    snprintf(label, sizeof label, "Increment %d   Angle of repose %.1f deg%s%s", number,
             res->angle_deg, res->poor ? "   (poor fit)" : "", moving ? "   (still moving)" : "");
    cdem_render_scene sc = {.state = s, .label = label};
    int h = o.height;
    if (!h)
        CDEM_TRY(cdem_render_auto_height(&sc, &o, &h, err));
    cdem_render_layout lay;
    CDEM_TRY(cdem_render_layout_compute(&sc, &o, o.width, h, &lay, err));
    cdem_render_target t;
    CDEM_TRY(cdem_render_target_open(&t, a->out, fmt, o.width, h, a->cmd, err));
    cairo_t *cr = cairo_create(t.surf);
    cdem_status st = cdem_render_draw(cr, o.width, h, &sc, &o, err);
    for (int side = 0; side < 2 && st == CDEM_OK; side++) {
        /* each fitted flank's line, extended by one column at both ends */
        const cdem_repose_flank *f = &res->flank[side];
        if (f->n < 2)
            continue;
        double x0 = f->x_first - res->column_width, x1 = f->x_last + res->column_width;
        double d0x, d0y, d1x, d1y;
        cdem_render_layout_to_device(&lay, x0, f->intercept + f->slope * x0, &d0x, &d0y);
        cdem_render_layout_to_device(&lay, x1, f->intercept + f->slope * x1, &d1x, &d1y);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_set_line_width(cr, fmax(2.0, o.width / 400.0));
        cairo_move_to(cr, d0x, d0y);
        cairo_line_to(cr, d1x, d1y);
        cairo_stroke(cr);
    }
    cairo_destroy(cr);
    return cdem_render_target_close(&t, st, err);
}

/* Prints the measure of increment `info` and each fitted flank with its fit quality; a poor
 * fit is also a warning on stderr. */
static void print_measure(const char *file, const cdem_repose_result *res,
                          const cdem_increment_info *info) {
    printf("angle of repose = %.2f deg (increment %d, %zu surface elements fitted, columns "
           "%.4g m wide)\n",
           res->angle_deg, (int)info->number, res->n_fitted, res->column_width);
    for (int side = 0; side < 2; side++) {
        const cdem_repose_flank *f = &res->flank[side];
        if (f->n < 2)
            continue;
        const char *name = side ? "right" : "left";
        printf(
            "  %s flank: %.2f deg +- %.2g deg (95 %%), %zu elements, x %.4g .. %.4g m, rms misfit "
            "%.4g m; upper half %.1f deg, lower half %.1f deg\n",
            name, f->angle_deg, f->angle_ci_deg, f->n, f->x_first, f->x_last, f->residual_rms,
            f->angle_upper_deg, f->angle_lower_deg);
        char why[512];
        cdem_repose_poor_text(f, res->r_max, why, sizeof why);
        if (f->poor) {
            printf("  %s flank: poor fit: %s\n", name, why);
            fprintf(stderr, "cdem-strain repose: warning: %s: poor fit of the %s flank: %s\n", file,
                    name, why);
        } else
            printf("  %s flank: good fit (a straight slope)\n", name);
    }
}

/* Walks back from increment index k (state s) while the slope was at rest in each
 * increment (the motion from the one before under CDEM_REPOSE_REST_FRACTION x r_max, none
 * lost), down to the first increment after ke: *since = the index from which it has been at
 * rest (k + 1 when it moved in the last increment); *last = the motion in the last one. */
static cdem_status rest_since(cdem_h5_reader *r, size_t ke, size_t k, const cdem_state *s,
                              double r_max, size_t *since, cdem_repose_motion *last,
                              cdem_error *err) {
    cdem_state later = {0}, earlier = {0};
    CDEM_TRY(cdem_state_copy(&later, s, err));
    cdem_status st = CDEM_OK;
    *since = k + 1;
    for (size_t q = k; q > ke && st == CDEM_OK; q--) {
        cdem_repose_motion m;
        st = cdem_h5_reader_load_increment(r, q - 1, &earlier, NULL, err);
        if (st == CDEM_OK)
            st = cdem_repose_motion_between(&earlier, &later, &m, err);
        if (st != CDEM_OK)
            break;
        if (q == k)
            *last = m;
        if (!(m.mean < CDEM_REPOSE_REST_FRACTION * r_max && m.n_matched == m.n_before))
            break;
        *since = q;
        cdem_state tmp = later;
        later = earlier;
        earlier = tmp;
    }
    cdem_state_free(&later);
    cdem_state_free(&earlier);
    return st;
}

/* Judges whether the slope of increment index k has settled: its motion since the previous
 * increment, and its angle over the last third of the run (the increments after the end of
 * equilibration whose time is at least 2/3 t_k; t counts from the start of the run). Prints the
 * judgement (a warning on stderr when the slope still moves) and sets *moving. */
static cdem_status judge_settling(cdem_h5_reader *r, const char *file, size_t k,
                                  const cdem_state *s, const cdem_increment_info *info,
                                  const cdem_repose_result *res, int *moving, cdem_error *err) {
    *moving = 0;
    size_t ke;
    if (cdem_h5_reader_find_increment(r, "equil", &ke, err) != CDEM_OK || k <= ke) {
        printf("  settling: not judged (increment %d is not after the end of equilibration)\n",
               (int)info->number);
        return CDEM_OK;
    }
    cdem_increment_info ie, ip;
    cdem_state se = {0};
    cdem_repose_motion lost, last;
    size_t since;
    cdem_status st = cdem_h5_reader_load_increment(r, ke, &se, &ie, err);
    if (st == CDEM_OK)
        st = cdem_repose_motion_between(&se, s, &lost, err);
    cdem_state_free(&se);
    if (st == CDEM_OK)
        st = cdem_h5_reader_increment_info(r, k - 1, &ip, err);
    if (st == CDEM_OK)
        st = rest_since(r, ke, k, s, res->r_max, &since, &last, err);
    CDEM_TRY(st);
    double t_from = info->time * 2.0 / 3.0;
    size_t k0 = k;
    while (k0 > ke + 1) { /* the first increment of the window */
        cdem_increment_info ii;
        CDEM_TRY(cdem_h5_reader_increment_info(r, k0 - 1, &ii, err));
        if (ii.time < t_from)
            break;
        k0--;
    }
    double *angles = malloc((k - k0 + 1) * sizeof *angles);
    if (!angles)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "repose: no memory for %zu angles", k - k0 + 1);
    cdem_increment_info i0 = *info;
    for (size_t q = k0; q <= k && st == CDEM_OK; q++) {
        if (q == k) {
            angles[q - k0] = res->angle_deg;
            continue;
        }
        cdem_state sq = {0};
        cdem_increment_info iq;
        cdem_repose_result rq;
        cdem_error ignored;
        st = cdem_h5_reader_load_increment(r, q, &sq, &iq, err);
        if (q == k0)
            i0 = iq;
        if (st == CDEM_OK)
            angles[q - k0] =
                cdem_repose_measure(&sq, &rq, &ignored) == CDEM_OK ? rq.angle_deg : NAN;
        cdem_state_free(&sq);
    }
    cdem_repose_settling v;
    if (st == CDEM_OK)
        cdem_repose_settled(angles, k - k0 + 1, &last, res->r_max, &v);
    free(angles);
    CDEM_TRY(st);
    long gone = (long)lost.n_before - (long)lost.n_matched;
    printf("  free elements: %zu at the end of equilibration (increment %d), %zu now; %ld left "
           "the model\n",
           lost.n_before, (int)ie.number, lost.n_after, gone);
    printf("  motion in the last increment (%d to %d): mean %.3g m, largest %.3g m: %s (the "
           "limit is %g %% of the largest radius, %.4g m)\n",
           (int)ip.number, (int)info->number, last.mean, last.max, v.at_rest ? "at rest" : "moving",
           100.0 * CDEM_REPOSE_REST_FRACTION, res->r_max);
    if (since <= k) {
        cdem_increment_info is;
        CDEM_TRY(cdem_h5_reader_increment_info(r, since, &is, err));
        printf("  at rest since increment %d (%.0f s, %.0f s after the end of equilibration)\n",
               (int)is.number, is.time, is.time - ie.time);
    }
    printf("  angle over the last third of the run (increments %d to %d, %.0f to %.0f s): "
           "%.2f to %.2f deg: %s\n",
           (int)i0.number, (int)info->number, i0.time, info->time, v.angle_min, v.angle_max,
           v.stable  ? "stable (within 2 deg)"
           : v.n < 2 ? "not judged (fewer than 2 increments)"
                     : "changing (more than 2 deg, or an increment without a slope)");
    *moving = !(v.at_rest && v.stable);
    if (*moving) {
        printf("  slope: still moving: the angle is not yet the angle of repose\n");
        fprintf(stderr,
                "cdem-strain repose: warning: %s: the slope is still moving at increment %d "
                "(%s; angle %.2f to %.2f deg over the last third of the run)\n",
                file, (int)info->number,
                v.at_rest ? "at rest in the last increment" : "moving in the last increment",
                v.angle_min, v.angle_max);
    } else
        printf("  slope: settled\n");
    return CDEM_OK;
}

/* Measures one run (file, the increment of a) and prints its report: its angle (NaN when it
 * cannot be measured), whether a flank is a poor fit and whether the slope still moves; the
 * picture when a->out is given. */
static cdem_status measure_run(const cdem_plot_args *a, const char *file, double *angle, int *poor,
                               int *moving, cdem_error *err) {
    cdem_plot_args one = *a;
    one.files[0] = file;
    one.n_files = 1;
    cdem_h5_reader *r;
    cdem_state s = {0};
    cdem_increment_info info;
    cdem_repose_result res;
    *angle = NAN;
    *poor = *moving = 0;
    cdem_status st = cdem_cmd_plot_open_increment(&one, &r, &s, &info, err);
    cdem_params prm;
    cdem_error ignored;
    if (st == CDEM_OK && cdem_h5_reader_params(r, &prm, &ignored) == CDEM_OK &&
        prm.mode != CDEM_MODE_REPOSE)
        st = CDEM_FAIL(err, CDEM_ERR_INVALID,
                       "a '%s' run (boundary.mode = %s), not a repose-collapse run "
                       "(boundary.mode = repose): not measured",
                       cdem_mode_name(prm.mode), cdem_mode_name(prm.mode));
    if (st == CDEM_OK)
        st = cdem_repose_measure(&s, &res, err);
    if (st == CDEM_OK) {
        print_measure(file, &res, &info);
        *angle = res.angle_deg;
        *poor = res.poor != 0;
        size_t k;
        st = cdem_h5_reader_find_increment(r, a->increment ? a->increment : "last", &k, err);
        if (st == CDEM_OK)
            st = judge_settling(r, file, k, &s, &info, &res, moving, err);
    }
    if (st == CDEM_OK && a->out)
        st = repose_figure(a, &s, (int)info.number, &res, *moving, err);
    cdem_state_free(&s);
    cdem_h5_reader_close(r);
    return st;
}

/* One line of a spread: the mean, and the standard deviation, standard error and range of
 * two or more runs. */
static void print_mean(const char *lead, const cdem_repose_spread *sp) {
    printf("%sover %zu run%s: angle of repose %.2f deg (mean)", lead, sp->n, sp->n == 1 ? "" : "s",
           sp->mean_deg);
    if (sp->n >= 2)
        printf(", standard deviation %.2f deg, standard error of the mean %.2f deg, range %.2f "
               "to %.2f deg",
               sp->sd_deg, sp->se_deg, sp->min_deg, sp->max_deg);
    printf("\n");
}

/* The spread of the angles of several runs (packings of one material): a material's angle
 * of repose is their mean, not one collapse's. Counted: the runs measured (angle finite),
 * of them the good fits unless include_poor. *none: 1 when there is no mean to give. */
static cdem_status print_spread(const double *angles, const int *poor, const int *moving, size_t n,
                                int include_poor, int *none, cdem_error *err) {
    double good_angles[CDEM_PLOT_MAX_FILES];
    size_t settled = 0;
    for (size_t k = 0; k < n; k++) {
        good_angles[k] = poor[k] ? NAN : angles[k];
        settled += isfinite(angles[k]) && !moving[k];
    }
    cdem_repose_spread all, good;
    CDEM_TRY(cdem_repose_spread_of(angles, n, &all, err));
    CDEM_TRY(cdem_repose_spread_of(good_angles, n, &good, err));
    const size_t n_poor = all.n - good.n;
    *none = 0;
    if (!all.n) {
        printf("\nover %zu runs given: none measured (their errors are on stderr)\n", n);
        *none = 1;
        return CDEM_OK;
    }
    if (!include_poor && !good.n) {
        printf("\nno good fit among the %zu run%s measured: no angle of repose (a poor fit's "
               "angle depends on where the line is fitted); with the poor fits (give "
               "--include-poor-fits to count them):\n",
               all.n, all.n == 1 ? "" : "s");
        print_mean("  ", &all);
        *none = 1;
    } else {
        print_mean("\n", include_poor ? &all : &good);
        if (n_poor && !include_poor) {
            printf("  left out: %zu poor fit%s (--include-poor-fits counts them); with them:\n",
                   n_poor, n_poor == 1 ? "" : "s");
            print_mean("  ", &all);
        } else if (n_poor) {
            printf("  poor fits counted (--include-poor-fits): %zu; the good fits alone:\n",
                   n_poor);
            if (good.n)
                print_mean("  ", &good);
            else
                printf("  none\n");
        }
    }
    printf("  good fits: %zu of %zu runs measured; settled: %zu of %zu runs measured\n", good.n,
           all.n, settled, all.n);
    if (all.n < n)
        printf("  not measured: %zu of %zu runs given (their errors are on stderr)\n", n - all.n,
               n);
    return CDEM_OK;
}

/* Each run once: a file given twice, also by another path (a link, ./, ..), is the same
 * device and inode. 0, or the usage error's exit status (printed). */
static int refuse_duplicates(const cdem_plot_args *a) {
    struct stat st[CDEM_PLOT_MAX_FILES];
    int known[CDEM_PLOT_MAX_FILES];
    for (size_t k = 0; k < a->n_files; k++) {
        known[k] = stat(a->files[k], &st[k]) == 0; /* one that cannot be read fails later */
        for (size_t j = 0; j < k && known[k]; j++)
            if (known[j] && st[j].st_dev == st[k].st_dev && st[j].st_ino == st[k].st_ino) {
                char msg[800];
                snprintf(msg, sizeof msg,
                         "%.300s (run %zu) is the same file as %.300s (run %zu): each run counts "
                         "once; give each file once",
                         a->files[k], k + 1, a->files[j], j + 1);
                return cdem_cmd_usage(a->help, msg);
            }
    }
    return 0;
}

int cdem_cmd_plot_repose(int argc, char **argv) {
    cdem_plot_args a = {.cmd = "repose", .help = &help};
    int rc = cdem_cmd_plot_parse(argc, argv, &a);
    if (rc)
        return rc;
    if (a.n_files == 0)
        return cdem_cmd_usage(a.help, "need a run file (RUN.h5), or several runs of one material");
    if (a.n_files > 1 && a.out)
        return cdem_cmd_usage(a.help, "-o draws one run: give one RUN.h5 with -o");
    if (a.include_poor && a.n_files == 1)
        return cdem_cmd_usage(a.help, "--include-poor-fits counts poor fits in the mean of "
                                      "several runs: give two or more RUN.h5");
    rc = refuse_duplicates(&a);
    if (rc)
        return rc;
    cdem_error err;
    cdem_render_format fmt;
    if (a.out && cdem_render_format_from_path(a.out, &fmt, &err) != CDEM_OK)
        return cdem_cmd_fail(a.cmd, NULL, &err);
    double angles[CDEM_PLOT_MAX_FILES];
    int poor[CDEM_PLOT_MAX_FILES], moving[CDEM_PLOT_MAX_FILES];
    rc = 0;
    for (size_t k = 0; k < a.n_files; k++) {
        if (a.n_files > 1)
            printf("%srun %s:\n", k ? "\n" : "", a.files[k]);
        fflush(stdout); /* the report and a failure's message in the order they happen */
        if (measure_run(&a, a.files[k], &angles[k], &poor[k], &moving[k], &err) != CDEM_OK) {
            angles[k] = NAN; /* a run whose report failed half-way is not counted either */
            rc = cdem_cmd_fail(a.cmd, a.files[k], &err);
        }
    }
    int none = 0;
    if (a.n_files > 1 &&
        print_spread(angles, poor, moving, a.n_files, a.include_poor, &none, &err) != CDEM_OK)
        rc = cdem_cmd_fail(a.cmd, NULL, &err);
    if (none && !rc) {
        fprintf(stderr,
                "cdem-strain repose: no good fit among the %zu runs: no angle of repose "
                "(--include-poor-fits counts the poor fits)\n",
                a.n_files);
        rc = CDEM_EXIT_ERROR;
    }
    return rc;
}

const cdem_command cdem_command_repose = {"repose", "angle of repose of the free surface", &help,
                                          cdem_cmd_plot_repose};
