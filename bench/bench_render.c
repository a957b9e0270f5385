/* bench_render: times the renderer and measures animated-GIF sizes on synthetic states.
 *
 * Build and run from the repository root (see docs/performance.md, "Rendering"):
 *   make build/libcdemanalysis.a build/libcdem.a
 *   cc -O2 -std=c17 -D_DEFAULT_SOURCE -Icommon -Ianalysis $(pkg-config --cflags cairo) \
 *      bench/bench_render.c build/libcdemanalysis.a build/libcdem.a \
 *      $(pkg-config --libs cairo) -lgif -lm -o build/bench_render
 *   ./build/bench_render [outdir] [all|render|gif]
 * The states are hexagonal packings of the four element radii (seeded LCG, no clock), 24
 * layers, walls at the base and sides, a weak interval and a 60-degree normal fault whose
 * hanging wall moves 4 m per increment (282 increments = 1128 m, as the default model). */
#include "gif.h"
#include "render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct {
    cdem_state base; /* undeformed state */
    cdem_state cur;  /* deformed copy for one increment */
    double *ux, *uy; /* total displacement of cur, m */
    double *mag;     /* |u|, m */
    double width_m;  /* model width, m */
    double height_m; /* model height, m */
    double box[4];   /* fixed view box for all frames */
    cdem_render_options ro;
    int coloured; /* 1: colour frames by displacement magnitude */
} bench;

static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static unsigned long lcg(unsigned long *s) {
    *s = *s * 6364136223846793005UL + 1442695040888963407UL;
    return *s >> 33;
}

/* Hexagonal rows of spacing 2 x 100 m (unit scaling 1000 m) holding radii 50..125 m. */
static void build(bench *b, double width_m, double height_m) {
    const double radii[4] = {50.0, 75.0, 100.0, 125.0};
    const double dx = 165.0, dy = 165.0 * sqrt(3.0) / 2.0; /* 2121 elements in 10 x 5 km */
    unsigned long seed = 12345;
    cdem_error err;
    cdem_state_init(&b->base, 1024, 0, &err);
    int rows = (int)(height_m / dy), cols = (int)(width_m / dx);
    for (int j = 0; j < rows; j++)
        for (int i = 0; i < cols; i++) {
            double x = (i + 0.5 * (j % 2)) * dx, y = j * dy;
            int wall = j == 0 || i == 0 || i == cols - 1;
            double r = wall ? 100.0 : radii[lcg(&seed) % 4];
            int layer = wall ? 0 : 1 + (int)(24.0 * y / height_m);
            uint32_t flags = wall ? CDEM_FLAG_WALL : 0;
            if (!wall && layer >= 3 && layer <= 4)
                flags |= CDEM_FLAG_WEAK;
            cdem_state_append(&b->base, -1, x, y, r, 1.0, layer, flags, 0, NULL, &err);
        }
    b->width_m = width_m;
    b->height_m = height_m;
    cdem_state_copy(&b->cur, &b->base, &err);
    size_t n = b->base.n;
    b->ux = calloc(n, sizeof *b->ux);
    b->uy = calloc(n, sizeof *b->uy);
    b->mag = calloc(n, sizeof *b->mag);
    cdem_render_fit_box(&b->base, 0.0, b->box);
    b->box[3] += 0.08 * height_m; /* room for uplift */
    b->box[2] -= 0.08 * height_m;
}

/* Hanging wall (right of a 60-degree fault through x = 0.4 W at the base) moved by d. */
static void deform(bench *b, double d) {
    const double dip = 60.0 * M_PI / 180.0;
    for (size_t i = 0; i < b->base.n; i++) {
        double x = b->base.x[i], y = b->base.y[i];
        int hw = !(b->base.flags[i] & CDEM_FLAG_WALL) && x > 0.4 * b->width_m + y / tan(dip);
        double f = hw ? 1.0 : 0.0;
        /* smooth drag zone near the fault */
        double dist = x - (0.4 * b->width_m + y / tan(dip));
        if (!(b->base.flags[i] & CDEM_FLAG_WALL) && fabs(dist) < 600.0)
            f = 0.5 + 0.5 * dist / 600.0;
        b->ux[i] = f * d * cos(dip);
        b->uy[i] = -f * d * sin(dip);
        b->cur.x[i] = x + b->ux[i];
        b->cur.y[i] = y + b->uy[i];
        b->mag[i] = hypot(b->ux[i], b->uy[i]);
    }
}

static cdem_status frame(void *user, size_t index, uint8_t *rgba, int w, int h, cdem_error *err) {
    bench *b = user;
    deform(b, 4.0 * (double)index);
    char label[128];
    snprintf(label, sizeof label, "Increment %zu   Net displacement %.0f m", index,
             4.0 * (double)index);
    cdem_render_scene sc = {0};
    sc.state = &b->cur;
    sc.label = label;
    if (b->coloured) {
        sc.values = b->mag;
        sc.vmin = 0.0;
        sc.vmax = 1128.0;
        sc.quantity = "Total displacement";
        sc.unit = "m";
    }
    return cdem_render_to_rgba(rgba, w, h, &sc, &b->ro, err);
}

static void free_bench(bench *b) {
    cdem_state_free(&b->base);
    cdem_state_free(&b->cur);
    free(b->ux);
    free(b->uy);
    free(b->mag);
}

static void time_render(const char *outdir, double width_m, double height_m, int width_px) {
    bench b;
    memset(&b, 0, sizeof b);
    build(&b, width_m, height_m);
    deform(&b, 1128.0);
    cdem_render_options_default(&b.ro);
    b.ro.width = width_px;
    b.ro.has_zoom = 1;
    b.ro.zoom_xmin = b.box[0];
    b.ro.zoom_xmax = b.box[1];
    b.ro.zoom_ymin = b.box[2];
    b.ro.zoom_ymax = b.box[3];
    int h = 0;
    cdem_error err;
    cdem_render_scene sc = {0};
    sc.state = &b.cur;
    sc.label = "Increment 282   Net displacement 1128 m";
    /* axes on a grid spaced 2 x the largest radius, angle varying smoothly */
    size_t na = 0, cap = (size_t)(width_m / 250.0 + 1) * (size_t)(height_m / 250.0 + 1);
    double *ax = malloc(cap * sizeof *ax), *ay = malloc(cap * sizeof *ay),
           *aa = malloc(cap * sizeof *aa);
    for (double y = 250.0; y < height_m - 250.0; y += 250.0)
        for (double x = 250.0; x < width_m - 250.0 && na < cap; x += 250.0) {
            ax[na] = x;
            ay[na] = y;
            aa[na] = 0.3 * sin(x / 3000.0) + 0.2;
            na++;
        }
    static const char *names[] = {"layer colours", "coloured by value + colour bar",
                                  "value + vectors + axes"};
    for (int mode = 0; mode < 3; mode++) {
        sc.values = mode >= 1 ? b.mag : NULL;
        sc.vmin = 0;
        sc.vmax = 1128.0;
        sc.quantity = "Total displacement";
        sc.unit = "m";
        sc.ux = mode == 2 ? b.ux : NULL;
        sc.uy = mode == 2 ? b.uy : NULL;
        sc.vector_scale = 1.0;
        sc.axis_x = ax;
        sc.axis_y = ay;
        sc.axis_angle = aa;
        sc.n_axes = mode == 2 ? na : 0;
        sc.axis_perpendicular = 1;
        cdem_render_auto_height(&sc, &b.ro, &h, &err);
        cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width_px, h);
        double best = 1e30;
        for (int rep = 0; rep < 3; rep++) {
            double t0 = now_s();
            if (cdem_render_to_surface(surf, &sc, &b.ro, &err) != CDEM_OK) {
                fprintf(stderr, "render failed: %s\n", err.msg);
                exit(1);
            }
            best = fmin(best, now_s() - t0);
        }
        char path[1024];
        snprintf(path, sizeof path, "%s/bench_render_%zu_%d.png", outdir, b.cur.n, mode);
        double t0 = now_s();
        cairo_surface_write_to_png(surf, path);
        double t_png = now_s() - t0;
        t0 = now_s();
        b.ro.height = h;
        cdem_render_to_file(path, &sc, &b.ro, &err);
        double t_file = now_s() - t0;
        double t_vec[2];
        long sz_vec[2];
        for (int v = 0; v < 2; v++) {
            snprintf(path, sizeof path, "%s/bench_render_%zu_%d.%s", outdir, b.cur.n, mode,
                     v ? "svg" : "pdf");
            t0 = now_s();
            cdem_render_to_file(path, &sc, &b.ro, &err);
            t_vec[v] = now_s() - t0;
            FILE *f = fopen(path, "rb");
            fseek(f, 0, SEEK_END);
            sz_vec[v] = ftell(f);
            fclose(f);
        }
        b.ro.height = 0;
        printf("render %6zu elements, %d x %d px, %-32s draw %.3f s, PNG encode %.3f s, "
               "PNG to_file %.3f s, PDF %.2f s (%.1f MB), SVG %.2f s (%.1f MB)\n",
               b.cur.n, width_px, h, names[mode], best, t_png, t_file, t_vec[0], sz_vec[0] / 1e6,
               t_vec[1], sz_vec[1] / 1e6);
        cairo_surface_destroy(surf);
    }
    free(ax);
    free(ay);
    free(aa);
    free_bench(&b);
}

static void gif_size(const char *outdir, int width_px, int coloured, double scale, int odd) {
    bench b;
    memset(&b, 0, sizeof b);
    build(&b, 10000.0, 5000.0);
    b.coloured = coloured;
    cdem_render_options_default(&b.ro);
    b.ro.width = width_px;
    b.ro.has_zoom = 1;
    b.ro.zoom_xmin = b.box[0];
    b.ro.zoom_xmax = b.box[1];
    b.ro.zoom_ymin = b.box[2];
    b.ro.zoom_ymax = b.box[3];
    cdem_render_scene sc = {0};
    sc.state = &b.cur;
    sc.label = "x";
    sc.values = coloured ? b.mag : NULL;
    sc.vmin = 0;
    sc.vmax = 1;
    int h = 0;
    cdem_error err;
    cdem_render_auto_height(&sc, &b.ro, &h, &err);
    cdem_gif_options go;
    cdem_gif_options_default(&go);
    go.scale = scale;
    go.selection = odd ? CDEM_GIF_ODD : CDEM_GIF_ALL;
    char path[1024];
    snprintf(path, sizeof path, "%s/bench_movie_%d_%d.gif", outdir, width_px, coloured);
    double t0 = now_s();
    if (cdem_gif_write(path, 283, width_px, h, frame, &b, &go, &err) != CDEM_OK) {
        fprintf(stderr, "gif failed: %s\n", err.msg);
        exit(1);
    }
    double t = now_s() - t0;
    FILE *f = fopen(path, "rb");
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fclose(f);
    printf("gif %zu elements, 283 increments%s, frames %d x %d px, scale %.2f, %s: %.2f MB "
           "in %.1f s\n",
           b.base.n, odd ? " (odd only)" : "", width_px, h, scale,
           coloured ? "coloured by total displacement" : "layer colours", size / 1e6, t);
    free_bench(&b);
}

int main(int argc, char **argv) {
    const char *outdir = argc > 1 ? argv[1] : "/tmp";
    const char *what = argc > 2 ? argv[2] : "all";
    if (strcmp(what, "gif") != 0) {
        time_render(outdir, 10000.0, 5000.0, 1920);  /* default model size */
        time_render(outdir, 48600.0, 24300.0, 1920); /* ~50,000 elements */
    }
    if (strcmp(what, "render") != 0) {
        gif_size(outdir, 1200, 0, 1.0, 0);
        gif_size(outdir, 1200, 1, 1.0, 0);
        gif_size(outdir, 1200, 0, 0.5, 1);
    }
    return 0;
}
