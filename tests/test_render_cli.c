/* test_render_cli: `cdem-strain render` end to end on a short real run made by cdem-run
 * ($CDEM_BUILD, default build/): one picture per format, all increments as prefix+number
 * files, an animated GIF with one frame per increment (and the odd-frame selection), and
 * the usage and error messages. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <gif_lib.h>

#include <dirent.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "scratch.h"

static scratch_dir g_scratch;
static char g_run[1100], g_strain[1100], g_bin[1024];
static int g_increments; /* increments in the run, from `cdem-strain info` */

static int run(const char *cmd, char *out, size_t n) {
    char full[8192];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    if (!p)
        return -1;
    size_t got = fread(out, 1, n - 1, p);
    out[got] = '\0';
    while (fread(full, 1, sizeof full, p) > 0) {
    }
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int setup(void **state) {
    (void)state;
    if (scratch_dir_make(&g_scratch, "render_cli") != 0)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    char *abs = realpath(b ? b : "build", NULL); /* tests cd elsewhere */
    if (!abs)
        return -1;
    snprintf(g_bin, sizeof g_bin, "%s", abs);
    free(abs);
    snprintf(g_strain, sizeof g_strain, "%s/cdem-strain", g_bin);
    snprintf(g_run, sizeof g_run, "%s/run.h5", g_scratch.dir);
    char cmd[4096], out[8192];
    /* A 10 x 2.5 unit planar normal fault, 200 s equilibration and 100 s of faulting, with
     * stress (whose colour limits read every increment). */
    snprintf(cmd, sizeof cmd,
             "'%s/cdem-run' -q -s assembly.height=2.5 -s time.equilibration=200 "
             "-s time.runtime=300 -s time.display_interval=20 -s physics.calculate_stress=on "
             "-o '%s'",
             g_bin, g_run);
    if (run(cmd, out, sizeof out) != 0) {
        fprintf(stderr, "cdem-run failed: %s\n", out);
        return -1;
    }
    snprintf(cmd, sizeof cmd, "'%s' info '%s'", g_strain, g_run);
    if (run(cmd, out, sizeof out) != 0)
        return -1;
    const char *line = strstr(out, "increments: ");
    if (!line || sscanf(line, "increments: %d", &g_increments) != 1)
        return -1;
    return 0;
}

static int teardown(void **state) {
    (void)state;
    return scratch_dir_remove(&g_scratch);
}

static void read_head(const char *path, char *buf, size_t n) {
    memset(buf, 0, n);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    size_t got = fread(buf, 1, n - 1, f);
    fclose(f);
    assert_true(got > 0);
}

/* Width and height of a PNG (big-endian at bytes 16 and 20 of the IHDR chunk). */
static void png_size(const char *path, unsigned *w, unsigned *h) {
    unsigned char ihdr[24];
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    assert_int_equal(fread(ihdr, 1, sizeof ihdr, f), sizeof ihdr);
    fclose(f);
    *w = (unsigned)ihdr[16] << 24 | (unsigned)ihdr[17] << 16 | (unsigned)ihdr[18] << 8 | ihdr[19];
    *h = (unsigned)ihdr[20] << 24 | (unsigned)ihdr[21] << 16 | (unsigned)ihdr[22] << 8 | ihdr[23];
}

static void test_render_cli_formats(void **state) {
    (void)state;
    assert_true(g_increments >= 10);
    static const struct {
        const char *ext;
        const char *magic;
    } cases[] = {{"png", "\x89PNG"}, {"pdf", "%PDF-"}, {"svg", "<svg"}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char cmd[4096], out[4096], path[1200], head[512];
        snprintf(path, sizeof path, "%s/shear.%s", g_scratch.dir, cases[i].ext);
        snprintf(cmd, sizeof cmd,
                 "'%s' render '%s' --increment last --color total-max-shear --vectors total "
                 "--axes total-strain --width 600 -o '%s'",
                 g_strain, g_run, path);
        assert_int_equal(run(cmd, out, sizeof out), 0);
        read_head(path, head, sizeof head);
        assert_non_null(strstr(head, cases[i].magic));
    }
    /* The PNG is as wide as asked. */
    char path[1200];
    unsigned width, height;
    snprintf(path, sizeof path, "%s/shear.png", g_scratch.dir);
    png_size(path, &width, &height);
    assert_int_equal(width, 600);
}

/* Colouring by a quantity draws the increment's own elements: a picture coloured by sxx
 * (whose limits read every increment, evicting the one drawn from the analysis cache) with
 * --no-colours is the picture in layer colours, byte for byte; with total displacement
 * vectors as well it is drawn (the vectors' state is the values'). Before, the state taken
 * with the values and kept across the limits pointed at another increment's elements
 * (Fig. 14's uplift at its first stages was drawn on an earlier increment's positions) and
 * the vectors were refused as "vectors and values refer to different states". */
static void test_render_cli_colour_keeps_the_increments_elements(void **state) {
    (void)state;
    static const struct {
        const char *args;
        int same; /* 1: the same picture as the layer colours' */
    } cases[] = {{"", 1},
                 {"--color sxx --no-colours", 1},
                 {"--color uplift --no-colours", 1},
                 {"--color sxx --vectors total", 0}};
    char first[1200] = "";
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char cmd[4096], out[4096], path[1200];
        snprintf(path, sizeof path, "%s/same%zu.png", g_scratch.dir, i);
        snprintf(cmd, sizeof cmd, "'%s' render '%s' --increment 3 --width 400 %s -o '%s'", g_strain,
                 g_run, cases[i].args, path);
        if (run(cmd, out, sizeof out) != 0)
            fail_msg("%s: %s", cmd, out);
        if (i == 0) {
            snprintf(first, sizeof first, "%s", path);
            continue;
        }
        snprintf(cmd, sizeof cmd, "cmp '%s' '%s'", first, path);
        if (cases[i].same && run(cmd, out, sizeof out) != 0)
            fail_msg("render %s differs from the layer colours: %s", cases[i].args, out);
    }
}

/* --colour-bar-space: a picture in layer colours of one --zoom box and --width gets the
 * height of the picture coloured by a quantity (the same layout, so the same scale: the
 * montage of examples/inversion); without it the plot area is wider and the picture taller. */
static void test_render_cli_colour_bar_space(void **state) {
    (void)state;
    static const char *const args[] = {"--color uplift", "--colour-bar-space",
                                       "--color uplift --no-colour-bar --colour-bar-space", ""};
    unsigned w[4], h[4];
    for (int i = 0; i < 4; i++) {
        char cmd[4096], out[4096], path[1200];
        snprintf(path, sizeof path, "%s/space%d.png", g_scratch.dir, i);
        snprintf(cmd, sizeof cmd,
                 "'%s' render '%s' --zoom 0,10000,-200,2800 --width 500 %s -o '%s'", g_strain,
                 g_run, args[i], path);
        if (run(cmd, out, sizeof out) != 0)
            fail_msg("%s: %s", cmd, out);
        png_size(path, &w[i], &h[i]);
        assert_int_equal(w[i], 500);
    }
    assert_int_equal(h[1], h[0]);
    assert_int_equal(h[2], h[0]);
    assert_true(h[3] > h[0]);
}

static void test_render_cli_all_increments(void **state) {
    (void)state;
    char cmd[4096], out[4096], dir[1200];
    snprintf(dir, sizeof dir, "%s/frames", g_scratch.dir);
    snprintf(cmd, sizeof cmd,
             "'%s' render '%s' --increment all --color incr-max-shear --width 200 --prefix inc "
             "-o '%s'",
             g_strain, g_run, dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    DIR *d = opendir(dir);
    assert_non_null(d);
    /* numbers zero-padded to the width of the last one, so the names sort in increment
     * order (issue 18: fr0, fr1, fr10 sorted fr10 before fr2) */
    char first[64];
    const int width = snprintf(NULL, 0, "%d", g_increments - 1);
    snprintf(first, sizeof first, "inc%0*d.png", width, 0);
    assert_true(width >= 2); /* the run has 10 increments or more: padding is exercised */
    int count = 0, has_first = 0;
    for (struct dirent *e; (e = readdir(d));) {
        if (!strncmp(e->d_name, "inc", 3) && strstr(e->d_name, ".png")) {
            count++;
            assert_int_equal(strlen(e->d_name), strlen(first));
        }
        if (!strcmp(e->d_name, first))
            has_first = 1;
    }
    closedir(d);
    assert_int_equal(count, g_increments);
    assert_true(has_first);
    /* into a folder that does not exist yet, two levels deep */
    snprintf(cmd, sizeof cmd,
             "'%s' render '%s' --increment all --width 100 -o '%s/album/a' --prefix fr", g_strain,
             g_run, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    snprintf(dir, sizeof dir, "%s/album/a/fr%0*d.png", g_scratch.dir, width, g_increments - 1);
    assert_int_equal(access(dir, R_OK), 0);
}

static int gif_frames(const char *path) {
    int error = 0;
    GifFileType *g = DGifOpenFileName(path, &error);
    assert_non_null(g);
    assert_int_equal(DGifSlurp(g), GIF_OK);
    int n = g->ImageCount;
    DGifCloseFile(g, &error);
    return n;
}

static void test_render_cli_gif(void **state) {
    (void)state;
    char cmd[4096], out[4096], path[1200];
    snprintf(path, sizeof path, "%s/movie.gif", g_scratch.dir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --width 240 --gif '%s'", g_strain, g_run, path);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_int_equal(gif_frames(path), g_increments);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --width 240 --odd --backward --gif '%s'", g_strain,
             g_run, path);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_int_equal(gif_frames(path), g_increments / 2);
}

static void test_render_cli_errors(void **state) {
    (void)state;
    static const struct {
        const char *args; /* after "render RUN" */
        int code;
        const char *message;
    } cases[] = {
        {"--color total-max-shaer -o x.png", 1, "did you mean 'total-max-shear'"},
        {"--increment 99999 -o x.png", 1, "99999"},
        {"", 2, "give -o OUTPUT"},
        {"--zoom 1,2,3 -o x.png", 2, "--zoom must be XMIN,XMAX,YMIN,YMAX"},
        {"--width 5 -o x.png", 2, "--width must be"},
        {"--vectors sideways -o x.png", 2, "--vectors must be incr or total"},
        {"--bogus -o x.png", 2, "unknown option '--bogus'"},
        {"-o x.tiff", 1, ".png"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char cmd[4096], out[8192];
        snprintf(cmd, sizeof cmd, "cd '%s' && '%s' render '%s' %s", g_scratch.dir, g_strain, g_run,
                 cases[i].args);
        int rc = run(cmd, out, sizeof out);
        if (rc != cases[i].code || !strstr(out, cases[i].message))
            fail_msg("case %zu (%s): exit %d, output: %s", i, cases[i].args, rc, out);
    }
    char cmd[4096], out[4096];
    snprintf(cmd, sizeof cmd, "'%s' render '%s/missing.h5' -o '%s/x.png'", g_strain, g_scratch.dir,
             g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "missing.h5"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_render_cli_formats),
        cmocka_unit_test(test_render_cli_colour_bar_space),
        cmocka_unit_test(test_render_cli_colour_keeps_the_increments_elements),
        cmocka_unit_test(test_render_cli_all_increments),
        cmocka_unit_test(test_render_cli_gif),
        cmocka_unit_test(test_render_cli_errors),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
