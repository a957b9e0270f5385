/* cmd_render: see cmd_render.h. One increment, all increments (prefix + number files) or
 * an animated GIF. Every frame of a series uses one fixed view box (the union of the first
 * and last increments' boxes) so pictures and animation frames line up. */
#include "cmd_render.h"
#include "params.h"

#include "cmd_support.h"
#include "commands.h"

#include "analysis.h"
#include "run_file.h"
#include "gif.h"
#include "outfile.h"
#include "render.h"
#include "runlock.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/stat.h>
#include <time.h>

typedef struct {
    const char *path;       /* run file */
    const char *increment;  /* "K", "last", "first", "equil" or "all" */
    const char *quantity;   /* colour-by quantity name, or NULL for layer colours */
    const char *output;     /* file (single), directory (all), or NULL */
    const char *gif;        /* animated GIF path, or NULL */
    const char *prefix;     /* file-name prefix for --increment all */
    const char *format;     /* extension for --increment all: png, pdf, svg */
    int vectors;            /* 0 none, 1 incremental, 2 total */
    int axes;               /* -1 none, else cdem_axes_kind */
    int axes_shear;         /* 1: draw maximum-shear directions instead of principal */
    int above_tenth;        /* 1: colour only values above 0.1 x the maximum */
    int zoom_given;         /* 1: zoom box given */
    double zoom[4];         /* xmin, xmax, ymin, ymax in m */
    int follow;             /* 1: --follow, re-render the newest increment of a growing file */
    double interval;        /* s, --interval between checks for a new increment (> 0) */
    cdem_render_options ro; /* drawing options */
    cdem_gif_options go;    /* GIF options */
} render_args;

/* The help of render (cli_help.h): --help, the usage errors, the man page and the bash
 * completion come from it; tests/test_help.c checks that parse_args accepts every option. */
static const char *const render_forms[] = {
    "RUN.h5 [--increment K|last|first|equil|all] [--color QUANTITY] [--vectors incr|total] "
    "[--axes incr-strain|total-strain|stress] [--shear-axes] [--above-tenth-max] [--no-fill] "
    "[--no-colours] [--no-scale-bar] [--no-colour-bar] [--colour-bar-space] [--no-label] "
    "[--width N] [--height N] "
    "[--zoom XMIN,XMAX,YMIN,YMAX] [--highlight FIRST-LAST] [--color-walls #RRGGBB] "
    "[--color-layers #RRGGBB,#RRGGBB] -o OUT.png|.pdf|.svg",
    "RUN.h5 --increment all [OPTIONS] -o DIR [--prefix P] [--format png|pdf|svg]",
    "RUN.h5 [OPTIONS] --gif OUT.gif [--backward] [--odd] [--gif-scale S] [--delay CS]",
    "RUN.h5 --follow [--interval SECONDS] [OPTIONS] [-o OUT.png]", NULL};

static const cdem_cli_option render_options[] = {
    {"--increment", "K|last|first|equil|all",
     "which increment (default last); all writes DIR/<prefix><number>.<format> for every "
     "increment, numbers zero-padded to one width (cdem000.png .. cdem282.png)"},
    {"--color, --colour", "QUANTITY",
     "colour by a quantity ('cdem-strain quantities'; default: layer colours)"},
    {"--above-tenth-max", NULL, "colour only elements whose value exceeds 0.1 x the maximum"},
    {"--vectors", "incr|total", "displacement vectors (incremental 5x exaggerated, total 1x)"},
    {"--axes", "incr-strain|total-strain|stress",
     "principal axes (S1 and the perpendicular S3) on a grid"},
    {"--shear-axes", NULL, "with --axes: the maximum-shear directions instead"},
    {"--no-fill", NULL, "outlines only (the manual's \"toggle elements\")"},
    {"--no-colours, --no-colors", NULL, "no colours by value"},
    {"--no-scale-bar", NULL, "no scale bar"},
    {"--no-colour-bar, --no-color-bar", NULL, "no colour bar"},
    {"--colour-bar-space, --color-bar-space", NULL,
     "keep the colour bar's room empty when there is no colour bar (layer colours, "
     "--no-colour-bar): with the same --zoom and --width such a picture has the scale and "
     "the place of the model of one with a colour bar"},
    {"--no-label", NULL, "no increment label"},
    {"--width", "N", "pixels (PNG) or points (PDF, SVG), 16 to 20000 (default 1200)"},
    {"--height", "N", "as --width (default: from the aspect ratio)"},
    {"--zoom", "XMIN,XMAX,YMIN,YMAX", "view box in metres (default: all elements)"},
    {"--highlight", "FIRST-LAST", "highlight the layers FIRST to LAST"},
    {"--color-walls, --colour-walls", "#RRGGBB", "wall colour (default brown)"},
    {"--color-layers, --colour-layers", "#RRGGBB,#RRGGBB",
     "the two pre-growth band colours (default yellow, red)"},
    {"-o, --output", "OUT",
     "picture (.png, .pdf, .svg), or a directory with --increment all (created when "
     "missing)"},
    {"--prefix", "P", "file-name prefix with --increment all (default cdem)"},
    {"--format", "png|pdf|svg", "picture format with --increment all (default png)"},
    {"--gif", "OUT.gif", "animated GIF of every increment"},
    {"--backward", NULL, "GIF frames from the last increment to the first"},
    {"--odd", NULL, "GIF of every other increment (a smaller file)"},
    {"--gif-scale", "S", "GIF size as a fraction of --width, 0.05 to 1 (default 1)"},
    {"--delay", "CS", "GIF frame delay in hundredths of a second (default 10)"},
    {"--follow", NULL,
     "re-render the newest increment of a run that cdem-run is still writing whenever a new "
     "one arrives, until the run stops (-o defaults to live.png)"},
    {"--interval", "SECONDS", "with --follow: seconds between checks (default 2)"},
    {NULL, NULL, NULL}};

static const cdem_cli_help help = {
    .program = "cdem-strain render",
    .forms = render_forms,
    .about = "Pictures of increments (PNG, PDF, SVG), albums and animated GIFs. Every picture "
             "of a series uses one view box, so frames line up. docs/rendering.md has the "
             "details.",
    .options = render_options,
};

static int usage(const char *what) {
    return cdem_cmd_usage(&help, what);
}

static int parse_args(int argc, char **argv, render_args *a) {
    memset(a, 0, sizeof *a);
    a->increment = "last";
    a->prefix = "cdem";
    a->format = "png";
    a->axes = -1;
    a->interval = 2.0;
    cdem_render_options_default(&a->ro);
    cdem_gif_options_default(&a->go);
    cdem_error err;
    cdem_error_clear(&err);
    for (int i = 1; i < argc; i++) {
        const cdem_cli_option *o;
        const char *next;
        const cdem_cmd_arg kind = cdem_cmd_next_arg(&help, argc, argv, &i, &o, &next);
        if (kind == CDEM_CMD_ARG_USAGE)
            return CDEM_EXIT_USAGE;
        if (kind == CDEM_CMD_ARG_POSITIONAL) {
            if (a->path) {
                char m[160];
                snprintf(m, sizeof m, "unexpected argument '%s'", argv[i]);
                return usage(m);
            }
            a->path = argv[i];
        } else if (cdem_cli_option_is(o, "--increment")) {
            a->increment = next;
        } else if (cdem_cli_option_is(o, "--color")) {
            a->quantity = next;
        } else if (cdem_cli_option_is(o, "-o")) {
            a->output = next;
        } else if (cdem_cli_option_is(o, "--gif")) {
            a->gif = next;
        } else if (cdem_cli_option_is(o, "--prefix")) {
            if (!cdem_params_prefix_ok(next))
                return usage("--prefix: " CDEM_PREFIX_RULE);
            a->prefix = next;
        } else if (cdem_cli_option_is(o, "--format")) {
            if (strcmp(next, "png") && strcmp(next, "pdf") && strcmp(next, "svg"))
                return usage("--format must be png, pdf or svg");
            a->format = next;
        } else if (cdem_cli_option_is(o, "--vectors")) {
            if (!strcmp(next, "incr"))
                a->vectors = 1;
            else if (!strcmp(next, "total"))
                a->vectors = 2;
            else
                return usage("--vectors must be incr or total");
        } else if (cdem_cli_option_is(o, "--axes")) {
            if (!strcmp(next, "incr-strain"))
                a->axes = CDEM_AXES_INCR_STRAIN;
            else if (!strcmp(next, "total-strain"))
                a->axes = CDEM_AXES_TOTAL_STRAIN;
            else if (!strcmp(next, "stress"))
                a->axes = CDEM_AXES_STRESS;
            else
                return usage("--axes must be incr-strain, total-strain or stress");
        } else if (cdem_cli_option_is(o, "--shear-axes")) {
            a->axes_shear = 1;
        } else if (cdem_cli_option_is(o, "--above-tenth-max")) {
            a->above_tenth = 1;
        } else if (cdem_cli_option_is(o, "--no-fill")) {
            a->ro.show_fill = 0;
        } else if (cdem_cli_option_is(o, "--no-colours")) {
            a->ro.show_colours = 0;
        } else if (cdem_cli_option_is(o, "--no-scale-bar")) {
            a->ro.show_scale_bar = 0;
        } else if (cdem_cli_option_is(o, "--no-colour-bar")) {
            a->ro.show_colour_bar = 0;
        } else if (cdem_cli_option_is(o, "--colour-bar-space")) {
            a->ro.colour_bar_space = 1;
        } else if (cdem_cli_option_is(o, "--no-label")) {
            a->ro.show_label = 0;
        } else if (cdem_cli_option_is(o, "--width")) {
            if (!cdem_cmd_parse_int(next, 16, CDEM_RENDER_MAX_SIZE, &a->ro.width))
                return usage("--width must be a whole number from 16 to 20000");
        } else if (cdem_cli_option_is(o, "--height")) {
            if (!cdem_cmd_parse_int(next, 16, CDEM_RENDER_MAX_SIZE, &a->ro.height))
                return usage("--height must be a whole number from 16 to 20000");
        } else if (cdem_cli_option_is(o, "--zoom")) {
            char buf[256];
            snprintf(buf, sizeof buf, "%s", next);
            char *save = NULL, *tok = strtok_r(buf, ",", &save);
            int k = 0;
            while (tok && k < 4 && cdem_cmd_parse_number(tok, &a->zoom[k])) {
                k++;
                tok = strtok_r(NULL, ",", &save);
            }
            if (k != 4 || tok || a->zoom[0] >= a->zoom[1] || a->zoom[2] >= a->zoom[3])
                return usage("--zoom must be XMIN,XMAX,YMIN,YMAX in metres with XMIN < XMAX "
                             "and YMIN < YMAX");
            a->zoom_given = 1;
        } else if (cdem_cli_option_is(o, "--highlight")) {
            if (sscanf(next, "%d-%d", &a->ro.highlight_first, &a->ro.highlight_last) != 2 ||
                a->ro.highlight_first < 1 || a->ro.highlight_last < a->ro.highlight_first)
                return usage("--highlight must be FIRST-LAST layers, e.g. 5-8");
        } else if (cdem_cli_option_is(o, "--color-walls")) {
            if (cdem_render_parse_colour(next, &a->ro.wall, &err) != CDEM_OK)
                return usage(err.msg);
        } else if (cdem_cli_option_is(o, "--color-layers")) {
            char buf[64];
            snprintf(buf, sizeof buf, "%s", next);
            char *comma = strchr(buf, ',');
            if (!comma)
                return usage("--color-layers needs two colours: #RRGGBB,#RRGGBB");
            *comma = '\0';
            if (cdem_render_parse_colour(buf, &a->ro.pregrowth[0], &err) != CDEM_OK ||
                cdem_render_parse_colour(comma + 1, &a->ro.pregrowth[1], &err) != CDEM_OK)
                return usage(err.msg);
        } else if (cdem_cli_option_is(o, "--backward")) {
            a->go.order = CDEM_GIF_BACKWARD;
        } else if (cdem_cli_option_is(o, "--odd")) {
            a->go.selection = CDEM_GIF_ODD;
        } else if (cdem_cli_option_is(o, "--gif-scale")) {
            if (!cdem_cmd_parse_number(next, &a->go.scale) || a->go.scale < 0.05 || a->go.scale > 1)
                return usage("--gif-scale must be between 0.05 and 1");
        } else if (cdem_cli_option_is(o, "--delay")) {
            if (!cdem_cmd_parse_int(next, 1, 65535, &a->go.delay_cs))
                return usage("--delay must be 1 to 65535 hundredths of a second");
        } else if (cdem_cli_option_is(o, "--follow")) {
            a->follow = 1;
        } else if (cdem_cli_option_is(o, "--interval")) {
            if (!cdem_cmd_parse_number(next, &a->interval) || !(a->interval > 0.0) ||
                a->interval > 86400.0)
                return usage("--interval: expected seconds > 0 (at most 86400)");
        }
    }
    if (!a->path)
        return usage("no run file given");
    if (a->follow && (a->gif || !strcmp(a->increment, "all")))
        return usage("--follow renders one picture: it cannot be combined with --gif or "
                     "--increment all");
    if (a->follow && !a->output)
        a->output = "live.png";
    if (!a->output && !a->gif)
        return usage("give -o OUTPUT (a picture, or a directory with --increment all) or --gif");
    return 0;
}

/* Everything one picture needs, owned here and released by scene_free. */
typedef struct {
    cdem_render_scene sc;
    double *values, *ux, *uy;
    cdem_axes axes;
    double *axis_angle;
    char label[256];
    char title[160];
} scene_data;

static void scene_free(scene_data *d) {
    free(d->values);
    free(d->ux);
    free(d->uy);
    free(d->axis_angle);
    cdem_axes_free(&d->axes);
    memset(d, 0, sizeof *d);
}

void cdem_render_increment_label(const cdem_analysis *an, size_t index, char *buf, size_t n) {
    const cdem_increment_info *info = cdem_analysis_info(an, index);
    const cdem_params *p = cdem_analysis_params(an);
    const cdem_h5_reader *r = cdem_analysis_reader(an);
    if (r && !strncmp(cdem_h5_reader_source(r), "cdem2d-import:", 14))
        /* a cdem2D folder gives positions per increment, no displacement or time: a label
         * "Net displacement 0.0 m" on every increment would be false */
        snprintf(buf, n, "Increment %d", (int)info->number);
    else if (cdem_mode_clock_of(p->mode) == CDEM_CLOCK_AXIAL_STRAIN)
        snprintf(buf, n, "Increment %d   Axial strain %.4f", (int)info->number, info->axial_strain);
    else if (cdem_mode_clock_of(p->mode) == CDEM_CLOCK_TIME)
        snprintf(buf, n, "Increment %d   Time %.0f s", (int)info->number, info->time);
    else
        snprintf(buf, n, "Increment %d   Net displacement %.1f m", (int)info->number,
                 info->net_displacement);
}

static cdem_status build_scene(cdem_analysis *an, size_t index, const render_args *a,
                               const cdem_quantity *q, scene_data *d, cdem_error *err) {
    memset(d, 0, sizeof *d);
    const cdem_state *s = NULL;
    CDEM_TRY(cdem_analysis_state(an, index, &s, err));
    d->sc.state = s;
    if (q) {
        cdem_limits lim;
        /* The limits first: they may read other increments (total displacement at the last
         * one with every deposit's reference, stress at every one), which can evict this
         * increment from the analysis cache and leave a state pointer taken before them
         * pointing at another increment's elements (the uplift of Fig. 14's first stages was
         * drawn on the positions of an earlier increment). The state the values come with is
         * then current. */
        CDEM_TRY(cdem_analysis_limits(an, index, q, &lim, err));
        CDEM_TRY(cdem_analysis_values(an, index, q, &s, &d->values, err));
        d->sc.state = s;
        d->sc.values = d->values;
        d->sc.vmin = lim.vmin;
        d->sc.vmax = lim.vmax;
        d->sc.kind = (cdem_colormap_kind)q->scale;
        snprintf(d->title, sizeof d->title, "%s", q->label);
        d->sc.quantity = d->title;
        d->sc.unit = q->unit;
        d->sc.above_tenth_max = a->above_tenth;
    }
    if (a->vectors) {
        const cdem_state *vs = NULL;
        CDEM_TRY(cdem_analysis_vectors(an, index, a->vectors == 2, &vs, &d->ux, &d->uy, err));
        if (vs != d->sc.state)
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "%s: increment %zu: vectors and values refer to different states",
                             a->path, index);
        d->sc.ux = d->ux;
        d->sc.uy = d->uy;
        d->sc.vector_scale = a->vectors == 1 ? 5.0 : 1.0;
    }
    if (a->axes >= 0) {
        CDEM_TRY(cdem_analysis_axes(an, index, (cdem_axes_kind)a->axes, &d->axes, err));
        d->axis_angle = malloc((d->axes.n ? d->axes.n : 1) * sizeof *d->axis_angle);
        if (!d->axis_angle)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for %zu axes", d->axes.n);
        const double *deg = a->axes_shear ? d->axes.shear_a : d->axes.angle1;
        for (size_t i = 0; i < d->axes.n; i++)
            d->axis_angle[i] = deg[i] * M_PI / 180.0;
        d->sc.axis_x = d->axes.x;
        d->sc.axis_y = d->axes.y;
        d->sc.axis_angle = d->axis_angle;
        d->sc.n_axes = d->axes.n;
        d->sc.axis_perpendicular = 1;
    }
    /* The state once more, after every call that may read other increments (the axes
     * too): the same increment's elements in the file's order, so the values and vectors
     * stay aligned with it. */
    CDEM_TRY(cdem_analysis_state(an, index, &s, err));
    d->sc.state = s;
    cdem_render_increment_label(an, index, d->label, sizeof d->label);
    d->sc.label = d->label;
    return CDEM_OK;
}

/* The view box shared by every picture of a series: first and last increments together. */
static cdem_status series_box(cdem_analysis *an, double margin, double box[4], cdem_error *err) {
    size_t n = cdem_analysis_count(an);
    const cdem_state *s = NULL;
    double b0[4], b1[4];
    CDEM_TRY(cdem_analysis_state(an, 0, &s, err));
    cdem_render_fit_box(s, margin, b0);
    CDEM_TRY(cdem_analysis_state(an, n - 1, &s, err));
    cdem_render_fit_box(s, margin, b1);
    box[0] = fmin(b0[0], b1[0]);
    box[1] = fmax(b0[1], b1[1]);
    box[2] = fmin(b0[2], b1[2]);
    box[3] = fmax(b0[3], b1[3]);
    return CDEM_OK;
}

static void set_zoom(cdem_render_options *o, const double box[4]) {
    o->has_zoom = 1;
    o->zoom_xmin = box[0];
    o->zoom_xmax = box[1];
    o->zoom_ymin = box[2];
    o->zoom_ymax = box[3];
}

static cdem_status render_one(cdem_analysis *an, size_t index, const render_args *a,
                              const cdem_quantity *q, const cdem_render_options *o,
                              const char *path, cdem_error *err) {
    scene_data d;
    cdem_status st = build_scene(an, index, a, q, &d, err);
    if (st == CDEM_OK)
        st = cdem_render_to_file(path, &d.sc, o, err);
    scene_free(&d);
    return st;
}

typedef struct {
    cdem_analysis *an;
    const render_args *a;
    const cdem_quantity *q;
    const cdem_render_options *o;
} gif_ctx;

static cdem_status gif_frame(void *user, size_t index, uint8_t *rgba, int width, int height,
                             cdem_error *err) {
    const gif_ctx *g = user;
    scene_data d;
    cdem_status st = build_scene(g->an, index, g->a, g->q, &d, err);
    if (st == CDEM_OK)
        st = cdem_render_to_rgba(rgba, width, height, &d.sc, g->o, err);
    scene_free(&d);
    return st;
}

static int run_render(const render_args *a) {
    cdem_error err;
    cdem_error_clear(&err);
    cdem_analysis *an = NULL;
    const cdem_quantity *q = NULL;
    if (a->quantity && cdem_quantity_find(a->quantity, &q, &err) != CDEM_OK)
        return cdem_cmd_fail("render", NULL, &err);
    if (cdem_analysis_open(a->path, &an, &err) != CDEM_OK)
        return cdem_cmd_fail("render", a->path, &err);
    int rc = 0;
    size_t n = cdem_analysis_count(an);
    cdem_render_options o = a->ro;
    o.growth1_layers = cdem_analysis_params(an)->growth_sequence1_layers;
    if (n == 0) {
        CDEM_FAIL(&err, CDEM_ERR_NOTFOUND, "%s: the file has no increments", a->path);
        rc = cdem_cmd_fail("render", a->path, &err);
        goto done;
    }
    int series = a->gif || !strcmp(a->increment, "all");
    if (a->zoom_given) {
        set_zoom(&o, a->zoom);
    } else if (series) {
        double box[4];
        if (series_box(an, o.margin, box, &err) != CDEM_OK) {
            rc = cdem_cmd_fail("render", a->path, &err);
            goto done;
        }
        set_zoom(&o, box);
    }
    if (a->gif) {
        /* Frame size from the first frame's layout, kept for every frame. */
        scene_data d;
        int height = o.height;
        if (build_scene(an, 0, a, q, &d, &err) != CDEM_OK ||
            (!height && cdem_render_auto_height(&d.sc, &o, &height, &err) != CDEM_OK)) {
            scene_free(&d);
            rc = cdem_cmd_fail("render", a->path, &err);
            goto done;
        }
        scene_free(&d);
        gif_ctx g = {an, a, q, &o};
        if (cdem_gif_write(a->gif, n, o.width, height, gif_frame, &g, &a->go, &err) != CDEM_OK) {
            rc = cdem_cmd_fail("render", a->path, &err);
            goto done;
        }
        printf("%s: %zu increments\n", a->gif, cdem_gif_frame_order(n, &a->go, NULL));
    }
    if (!a->output)
        goto done;
    if (!strcmp(a->increment, "all")) {
        if (cdem_outfile_make_dirs(a->output, &err) != CDEM_OK) {
            rc = cdem_cmd_fail("render", a->path, &err);
            goto done;
        }
        /* numbers zero-padded to the width of the largest, so the files sort in increment
         * order (fr000.png .. fr282.png; movie tools take them in name order) */
        const int width = snprintf(NULL, 0, "%d", (int)cdem_analysis_info(an, n - 1)->number);
        for (size_t i = 0; i < n && rc == 0; i++) {
            char path[4096];
            snprintf(path, sizeof path, "%s/%s%0*d.%s", a->output, a->prefix, width,
                     (int)cdem_analysis_info(an, i)->number, a->format);
            if (render_one(an, i, a, q, &o, path, &err) != CDEM_OK) {
                rc = cdem_cmd_fail("render", a->path, &err);
                /* no partial series that looks complete: remove this run's pictures */
                for (size_t j = 0; j < i; j++) {
                    snprintf(path, sizeof path, "%s/%s%0*d.%s", a->output, a->prefix, width,
                             (int)cdem_analysis_info(an, j)->number, a->format);
                    remove(path);
                }
            }
        }
        if (rc == 0)
            printf("%s: %zu pictures\n", a->output, n);
    } else {
        size_t index;
        if (cdem_analysis_find(an, a->increment, &index, &err) != CDEM_OK ||
            render_one(an, index, a, q, &o, a->output, &err) != CDEM_OK)
            rc = cdem_cmd_fail("render", a->path, &err);
        else
            printf("%s\n", a->output);
    }
done:
    cdem_analysis_close(an);
    return rc;
}

/* Renders the newest increment of path to a->output through a temporary file renamed
 * over it (a viewer never sees half a picture); *number receives its number. */
static cdem_status follow_render(const render_args *a, const cdem_quantity *q, int32_t *number,
                                 cdem_error *err) {
    cdem_analysis *an = NULL;
    CDEM_TRY(cdem_analysis_open(a->path, &an, err));
    cdem_status st = CDEM_OK;
    size_t n = cdem_analysis_count(an);
    if (n == 0) {
        *number = -1;
        cdem_analysis_close(an);
        return CDEM_OK;
    }
    /* a live run still in equilibration has no total quantities yet (they are measured from
     * its end): wait for them (*number = -2, err says why) rather than fail */
    const int from_equil =
        (q && cdem_analysis_from_equil(q)) || a->vectors == 2 || a->axes == CDEM_AXES_TOTAL_STRAIN;
    if (from_equil && !cdem_analysis_equil_known(an) &&
        cdem_h5_reader_writer_alive(cdem_analysis_reader(an)) == 1) {
        CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                  "%s: %s is measured from the end of equilibration, which the run has not "
                  "reached yet: waiting for it",
                  a->path, q && cdem_analysis_from_equil(q) ? q->name : "the total picture");
        *number = -2;
        cdem_analysis_close(an);
        return CDEM_OK;
    }
    cdem_render_options o = a->ro;
    o.growth1_layers = cdem_analysis_params(an)->growth_sequence1_layers;
    if (a->zoom_given)
        set_zoom(&o, a->zoom);
    char tmp[4200];
    const char *dot = strrchr(a->output, '.'), *slash = strrchr(a->output, '/');
    const char *ext = dot && (!slash || dot > slash) ? dot : "";
    snprintf(tmp, sizeof tmp, "%s.part%s", a->output, ext);
    st = render_one(an, n - 1, a, q, &o, tmp, err);
    if (st == CDEM_OK && rename(tmp, a->output) != 0)
        st = CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot rename %s to it: %s", a->output, tmp,
                       strerror(errno));
    if (st != CDEM_OK)
        remove(tmp);
    *number = cdem_analysis_info(an, n - 1)->number;
    cdem_analysis_close(an);
    return st;
}

/* Waits up to seconds for SIGINT/SIGTERM (blocked by the caller); 1 when one came. */
static int wait_for_stop(const sigset_t *set, double seconds) {
    struct timespec ts = {(time_t)seconds, (long)((seconds - (double)(time_t)seconds) * 1e9)};
    for (;;) {
        int sig = sigtimedwait(set, NULL, &ts);
        if (sig > 0)
            return 1;
        if (errno != EINTR)
            return 0; /* EAGAIN: the time is up */
    }
}

/* --follow: watches a run file that cdem-run is writing (SWMR read, docs/format.md) and
 * re-renders its newest increment whenever a new one arrives; ends when the run's stop
 * reason is no longer "running" (after rendering its last increment), when the run's
 * writer is gone without recording a stop (killed: its lock is free, runlock.h), or on
 * Ctrl-C. It does not wait for a resume: when the run can be continued, its last message
 * gives the --follow command for the resumed run. */
static int run_follow(const render_args *a) {
    cdem_error err;
    cdem_error_clear(&err);
    const cdem_quantity *q = NULL;
    if (a->quantity && cdem_quantity_find(a->quantity, &q, &err) != CDEM_OK)
        return cdem_cmd_fail("render", NULL, &err);
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigprocmask(SIG_BLOCK, &set, NULL);
    cdem_h5_reader *r = NULL;
    int rc = 0;
    /* The run may not have created its file yet: wait for it (at most 60 s). */
    for (double waited = 0.0; cdem_h5_reader_open(a->path, &r, &err) != CDEM_OK;
         waited += a->interval) {
        if (err.code != CDEM_ERR_NOTFOUND || waited >= 60.0)
            return cdem_cmd_fail("render", a->path, &err);
        if (wait_for_stop(&set, a->interval))
            return 0;
    }
    int32_t shown = -1;
    int waiting = 0;     /* 1: the note that the picture waits for the end of equilibration */
    int writer_gone = 0; /* 1: no live writer holds the file's lock (checked last time) */
    for (;;) {
        int stopped = strcmp(cdem_h5_reader_stop_reason(r), "running") != 0;
        size_t n = cdem_h5_reader_increment_count(r);
        cdem_increment_info last;
        if (n > 0 && cdem_h5_reader_increment_info(r, n - 1, &last, &err) == CDEM_OK &&
            last.number != shown) {
            int32_t number = -1;
            if (follow_render(a, q, &number, &err) != CDEM_OK) {
                rc = cdem_cmd_fail("render", a->path, &err);
                break;
            }
            if (number >= 0 && number != shown) {
                shown = number;
                printf("%s: increment %d\n", a->output, (int)number);
                fflush(stdout);
            } else if (number == -2 && !waiting) {
                waiting = 1; /* said once */
                fprintf(stderr, "cdem-strain render: note: %s\n", err.msg);
            }
        }
        /* --follow ends with its run: a run continued later (cdem-run --resume) is followed
         * by a new --follow, which the messages give (issue 46, item 13e: "writer is gone"
         * said nothing of following the resumed run) */
        if (stopped) {
            const char *why = cdem_h5_reader_stop_reason(r);
            const int resumable = !strcmp(why, "interrupted") || !strcmp(why, "stopped-early") ||
                                  !strcmp(why, "write-failure");
            printf("%s: the run stopped (%s), last increment %d\n", a->path, why, (int)shown);
            if (resumable)
                printf("%s: after cdem-run --resume %s, follow it again with cdem-strain render "
                       "%s --follow -o %s (and the same options): --follow does not wait for a "
                       "resume\n",
                       a->path, a->path, a->path, a->output);
            break;
        }
        if (writer_gone) { /* the file was read again after its writer's lock was free */
            fprintf(stderr,
                    "cdem-strain render: %s: its writer is gone without recording how the run "
                    "ended (killed?); the file keeps its %zu complete increments, the last one "
                    "rendered (%d); continue the run with cdem-run --resume %s, then follow it "
                    "again with cdem-strain render %s --follow -o %s (and the same options): "
                    "--follow does not wait for a resume\n",
                    a->path, n, (int)shown, a->path, a->path, a->output);
            rc = 1;
            break;
        }
        if (wait_for_stop(&set, a->interval))
            break;
        /* Asked before the file is read again, so that a run that has just finished is seen
         * finished (its stop reason is written before its lock is released). */
        writer_gone = cdem_h5_reader_unclosed(r) && cdem_runlock_probe(a->path, NULL, 0) == 0;
        if (!writer_gone && cdem_h5_reader_format_version(r) >= 2 && cdem_h5_reader_unclosed(r) &&
            cdem_h5_reader_refresh(r, NULL, &err) == CDEM_OK)
            continue;
        /* Not in SWMR-read mode (a version-1 file, or one opened before its writer entered
         * SWMR mode): open it again to see what is new. */
        cdem_h5_reader_close(r);
        r = NULL;
        if (cdem_h5_reader_open(a->path, &r, &err) != CDEM_OK) {
            rc = cdem_cmd_fail("render", a->path, &err);
            break;
        }
    }
    cdem_h5_reader_close(r);
    return rc;
}

static int run(int argc, char **argv) {
    render_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc;
    return a.follow ? run_follow(&a) : run_render(&a);
}

const cdem_command cdem_command_render = {
    "render", "pictures of increments (PNG, PDF, SVG), albums and animated GIFs", &help, run};
