/* Tests of analysis/gif: palette round trip, frame order and selection, movies read back
 * with giflib's DGifSlurp (frame count, order, size, delay, loop extension), exact
 * reconstruction of optimised (difference) frames, scaling, rendered frames, and errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <gif_lib.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "gif.h"
#include "render.h"
#include "scratch.h"

static long file_size(const char *path) {
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

static GifFileType *slurp(const char *path) {
    int code = 0;
    GifFileType *g = DGifOpenFileName(path, &code);
    if (!g)
        fail_msg("cannot open %s: %s", path, GifErrorString(code));
    if (DGifSlurp(g) != GIF_OK)
        fail_msg("cannot read %s: %s", path, GifErrorString(g->Error));
    return g;
}

static void unslurp(GifFileType *g) {
    int code;
    DGifCloseFile(g, &code);
}

/* Composites frame k of a slurped movie onto canvas (indices, SWidth x SHeight), following
 * the transparency and "do not dispose" semantics the writer uses. */
static void composite(const GifFileType *g, int k, uint8_t *canvas) {
    const SavedImage *im = &g->SavedImages[k];
    GraphicsControlBlock gcb;
    int transparent = NO_TRANSPARENT_COLOR;
    if (DGifSavedExtensionToGCB((GifFileType *)g, k, &gcb) == GIF_OK)
        transparent = gcb.TransparentColor;
    const GifImageDesc *d = &im->ImageDesc;
    for (int y = 0; y < d->Height; y++)
        for (int x = 0; x < d->Width; x++) {
            uint8_t v = im->RasterBits[y * d->Width + x];
            if (v != transparent)
                canvas[(d->Top + y) * g->SWidth + d->Left + x] = v;
        }
}

/* Frame callback: a solid frame whose colour encodes the frame index (palette colours). */
static cdem_status solid_frame(void *user, size_t index, uint8_t *rgba, int w, int h,
                               cdem_error *err) {
    (void)user;
    (void)err;
    uint8_t c[3];
    cdem_gif_palette_colour((int)(index * 7 % 252), c);
    for (int i = 0; i < w * h; i++) {
        rgba[4 * i + 0] = c[0];
        rgba[4 * i + 1] = c[1];
        rgba[4 * i + 2] = c[2];
        rgba[4 * i + 3] = 255;
    }
    return CDEM_OK;
}

/* Frame callback: white with a 6 x 6 dark-red square moving right by 3 px per frame. */
static cdem_status moving_square(void *user, size_t index, uint8_t *rgba, int w, int h,
                                 cdem_error *err) {
    (void)user;
    (void)err;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            uint8_t *p = rgba + 4 * (y * w + x);
            int in = x >= 2 + 3 * (int)index && x < 8 + 3 * (int)index && y >= 10 && y < 16;
            p[0] = in ? 150 : 255;
            p[1] = in ? 20 : 255;
            p[2] = in ? 20 : 255;
            p[3] = 255;
        }
    return CDEM_OK;
}

static cdem_status failing_frame(void *user, size_t index, uint8_t *rgba, int w, int h,
                                 cdem_error *err) {
    if (index == 2)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "increment %zu is missing", index);
    return solid_frame(user, index, rgba, w, h, err);
}

static void test_gif_palette_round_trip(void **state) {
    (void)state;
    for (int k = 0; k < 255; k++) {
        uint8_t c[3];
        cdem_gif_palette_colour(k, c);
        assert_int_equal(cdem_gif_palette_index(c[0], c[1], c[2]), k);
    }
    assert_int_equal(cdem_gif_palette_index(0, 0, 0), 0);
    assert_int_equal(cdem_gif_palette_index(255, 255, 255), 251);
    uint8_t c[3];
    cdem_gif_palette_colour(cdem_gif_palette_index(153, 153, 153), c); /* neutral grey exact */
    assert_true(c[0] == 153 && c[1] == 153 && c[2] == 153);
    /* the chosen index is the nearest palette colour (brute force over all 255) */
    for (int r = 0; r < 256; r += 15)
        for (int g = 0; g < 256; g += 17)
            for (int b = 0; b < 256; b += 13) {
                cdem_gif_palette_colour(cdem_gif_palette_index(r, g, b), c);
                int d = (c[0] - r) * (c[0] - r) + (c[1] - g) * (c[1] - g) + (c[2] - b) * (c[2] - b);
                for (int k = 0; k < 255; k++) {
                    uint8_t q[3];
                    cdem_gif_palette_colour(k, q);
                    int dk =
                        (q[0] - r) * (q[0] - r) + (q[1] - g) * (q[1] - g) + (q[2] - b) * (q[2] - b);
                    assert_true(d <= dk);
                }
            }
}

static void test_gif_frame_order(void **state) {
    (void)state;
    static const struct {
        size_t n;
        cdem_gif_order order;
        cdem_gif_selection sel;
        size_t count;
        size_t first3[3];
    } cases[] = {
        {6, CDEM_GIF_FORWARD, CDEM_GIF_ALL, 6, {0, 1, 2}},
        {6, CDEM_GIF_BACKWARD, CDEM_GIF_ALL, 6, {5, 4, 3}},
        {6, CDEM_GIF_FORWARD, CDEM_GIF_ODD, 3, {1, 3, 5}},
        {7, CDEM_GIF_BACKWARD, CDEM_GIF_ODD, 3, {5, 3, 1}},
        {283, CDEM_GIF_FORWARD, CDEM_GIF_ODD, 141, {1, 3, 5}},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        cdem_gif_options o;
        cdem_gif_options_default(&o);
        o.order = cases[k].order;
        o.selection = cases[k].sel;
        size_t idx[300];
        assert_int_equal(cdem_gif_frame_order(cases[k].n, &o, NULL), cases[k].count);
        assert_int_equal(cdem_gif_frame_order(cases[k].n, &o, idx), cases[k].count);
        for (int j = 0; j < 3; j++)
            assert_int_equal(idx[j], cases[k].first3[j]);
    }
}

static void check_order(const char *path, const size_t *want, int n) {
    GifFileType *g = slurp(path);
    assert_int_equal(g->ImageCount, n);
    uint8_t *canvas = calloc((size_t)g->SWidth * g->SHeight, 1);
    assert_non_null(canvas);
    for (int k = 0; k < n; k++) {
        composite(g, k, canvas);
        uint8_t c[3];
        cdem_gif_palette_colour((int)(want[k] * 7 % 252), c);
        assert_int_equal(canvas[0], cdem_gif_palette_index(c[0], c[1], c[2]));
        assert_int_equal(canvas[g->SWidth * g->SHeight - 1], canvas[0]);
    }
    free(canvas);
    unslurp(g);
}

static void test_gif_order_read_back(void **state) {
    (void)state;
    char path[512];
    scratch_path(path, sizeof path, "gif_order.gif");
    cdem_gif_options o;
    cdem_gif_options_default(&o);
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_gif_write(path, 5, 40, 30, solid_frame, NULL, &o, &err), CDEM_OK);
    const size_t fwd[] = {0, 1, 2, 3, 4};
    check_order(path, fwd, 5);
    o.order = CDEM_GIF_BACKWARD;
    assert_int_equal(cdem_gif_write(path, 5, 40, 30, solid_frame, NULL, &o, &err), CDEM_OK);
    const size_t bwd[] = {4, 3, 2, 1, 0};
    check_order(path, bwd, 5);
    o.selection = CDEM_GIF_ODD;
    assert_int_equal(cdem_gif_write(path, 5, 40, 30, solid_frame, NULL, &o, &err), CDEM_OK);
    const size_t odd[] = {3, 1};
    check_order(path, odd, 2);

    /* header: size, delay of every frame, endless loop */
    o.delay_cs = 25;
    o.selection = CDEM_GIF_ALL;
    assert_int_equal(cdem_gif_write(path, 3, 40, 30, solid_frame, NULL, &o, &err), CDEM_OK);
    GifFileType *g = slurp(path);
    assert_int_equal(g->SWidth, 40);
    assert_int_equal(g->SHeight, 30);
    assert_non_null(g->SColorMap);
    assert_int_equal(g->SColorMap->ColorCount, 256);
    for (int k = 0; k < g->ImageCount; k++) {
        GraphicsControlBlock gcb;
        assert_int_equal(DGifSavedExtensionToGCB(g, k, &gcb), GIF_OK);
        assert_int_equal(gcb.DelayTime, 25);
    }
    int found = 0;
    const SavedImage *im = &g->SavedImages[0];
    for (int k = 0; k + 1 < im->ExtensionBlockCount; k++) {
        const ExtensionBlock *b = &im->ExtensionBlocks[k];
        if (b->Function == APPLICATION_EXT_FUNC_CODE && b->ByteCount == 11 &&
            memcmp(b->Bytes, "NETSCAPE2.0", 11) == 0) {
            const ExtensionBlock *c = &im->ExtensionBlocks[k + 1];
            assert_int_equal(c->ByteCount, 3);
            assert_int_equal(c->Bytes[0], 1);
            assert_int_equal(c->Bytes[1] | (c->Bytes[2] << 8), 0); /* forever */
            found = 1;
        }
    }
    assert_true(found);
    unslurp(g);
    remove(path);
}

static void test_gif_optimised_frames_reconstruct(void **state) {
    (void)state;
    char path[512], path_full[512];
    scratch_path(path, sizeof path, "gif_opt.gif");
    scratch_path(path_full, sizeof path_full, "gif_full.gif");
    const int w = 64, h = 32, n = 8;
    cdem_gif_options o;
    cdem_gif_options_default(&o);
    cdem_error err;
    assert_int_equal(cdem_gif_write(path, n, w, h, moving_square, NULL, &o, &err), CDEM_OK);
    o.optimise = 0;
    assert_int_equal(cdem_gif_write(path_full, n, w, h, moving_square, NULL, &o, &err), CDEM_OK);
    assert_true(file_size(path) < file_size(path_full));

    GifFileType *g = slurp(path);
    assert_int_equal(g->ImageCount, n);
    /* later frames hold only the changed rectangle */
    assert_true(g->SavedImages[1].ImageDesc.Width < w);
    assert_true(g->SavedImages[1].ImageDesc.Height < h);
    uint8_t *canvas = calloc((size_t)w * h, 1);
    uint8_t *rgba = malloc((size_t)w * h * 4);
    assert_non_null(canvas);
    assert_non_null(rgba);
    for (int k = 0; k < n; k++) {
        composite(g, k, canvas);
        moving_square(NULL, (size_t)k, rgba, w, h, &err);
        for (int i = 0; i < w * h; i++)
            assert_int_equal(canvas[i],
                             cdem_gif_palette_index(rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2]));
    }
    free(canvas);
    free(rgba);
    unslurp(g);
    remove(path);
    remove(path_full);
}

static void test_gif_scale_and_identical_frames(void **state) {
    (void)state;
    char path[512];
    scratch_path(path, sizeof path, "gif_scale.gif");
    const int w = 40, h = 20;
    uint8_t *rgba = malloc((size_t)w * h * 4);
    assert_non_null(rgba);
    /* left half black, right half white, a 2-px-wide mid-grey-averaging column pair */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            uint8_t v = x < w / 2 ? 0 : 255;
            uint8_t *p = rgba + 4 * (y * w + x);
            p[0] = p[1] = p[2] = v;
            p[3] = 255;
        }
    cdem_gif_options o;
    cdem_gif_options_default(&o);
    o.scale = 0.5;
    cdem_gif *gw = NULL;
    cdem_error err;
    assert_int_equal(cdem_gif_open(&gw, path, w, h, &o, &err), CDEM_OK);
    int ow, oh;
    cdem_gif_output_size(gw, &ow, &oh);
    assert_int_equal(ow, 20);
    assert_int_equal(oh, 10);
    assert_int_equal(cdem_gif_add_frame(gw, rgba, &err), CDEM_OK);
    assert_int_equal(cdem_gif_add_frame(gw, rgba, &err), CDEM_OK); /* identical frame */
    assert_int_equal(cdem_gif_close(gw, &err), CDEM_OK);
    GifFileType *g = slurp(path);
    assert_int_equal(g->SWidth, 20);
    assert_int_equal(g->SHeight, 10);
    assert_int_equal(g->ImageCount, 2);
    assert_int_equal(g->SavedImages[1].ImageDesc.Width, 1); /* only a transparent pixel */
    assert_int_equal(g->SavedImages[1].RasterBits[0], CDEM_GIF_TRANSPARENT);
    const uint8_t *px = g->SavedImages[0].RasterBits;
    assert_int_equal(px[0], cdem_gif_palette_index(0, 0, 0));
    assert_int_equal(px[19], cdem_gif_palette_index(255, 255, 255));
    unslurp(g);
    free(rgba);
    remove(path);
}

typedef struct {
    cdem_state *state;          /* shared state, moved per frame */
    cdem_render_options *ropts; /* render options */
} render_ctx;

static cdem_status render_frame(void *user, size_t index, uint8_t *rgba, int w, int h,
                                cdem_error *err) {
    render_ctx *c = user;
    c->state->x[1] = 3.0 + 0.5 * (double)index;
    cdem_render_scene sc = {0};
    sc.state = c->state;
    sc.label = "frame";
    return cdem_render_to_rgba(rgba, w, h, &sc, c->ropts, err);
}

static void test_gif_rendered_frames(void **state) {
    (void)state;
    cdem_state s;
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    assert_int_equal(
        cdem_state_append(&s, -1, 1.0, 1.0, 0.45, 1.0, 0, CDEM_FLAG_WALL, 0, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 3.0, 1.0, 0.45, 1.0, 1, 0, 0, NULL, &err), CDEM_OK);
    cdem_render_options ro;
    cdem_render_options_default(&ro);
    ro.has_zoom = 1;
    ro.zoom_xmin = 0;
    ro.zoom_xmax = 10;
    ro.zoom_ymin = 0;
    ro.zoom_ymax = 5;
    ro.wall = (cdem_rgba){0.6, 0.4, 0.2, 1.0}; /* 153, 102, 51 in 8 bits */
    render_ctx ctx = {&s, &ro};
    char path[512];
    scratch_path(path, sizeof path, "gif_render.gif");
    cdem_gif_options o;
    cdem_gif_options_default(&o);
    const int w = 200, h = 120;
    assert_int_equal(cdem_gif_write(path, 4, w, h, render_frame, &ctx, &o, &err), CDEM_OK);
    GifFileType *g = slurp(path);
    assert_int_equal(g->ImageCount, 4);
    uint8_t *canvas = calloc((size_t)w * h, 1);
    assert_non_null(canvas);
    cdem_render_scene sc = {0};
    sc.state = &s;
    sc.label = "frame";
    cdem_render_layout lay;
    assert_int_equal(cdem_render_layout_compute(&sc, &ro, w, h, &lay, &err), CDEM_OK);
    for (int k = 0; k < 4; k++) {
        composite(g, k, canvas);
        double dx, dy;
        cdem_render_layout_to_device(&lay, 1.0, 1.0, &dx, &dy); /* the wall, still */
        assert_int_equal(canvas[(int)dy * w + (int)dx], cdem_gif_palette_index(153, 102, 51));
        cdem_render_layout_to_device(&lay, 3.0 + 0.5 * k, 1.0, &dx, &dy); /* moving element */
        assert_int_equal(canvas[(int)dy * w + (int)dx], cdem_gif_palette_index(255, 217, 0));
    }
    free(canvas);
    unslurp(g);
    remove(path);
    cdem_state_free(&s);
}

static void test_gif_options_view(void **state) {
    (void)state;
    cdem_gif_options o;
    cdem_gif_options_default(&o);
    o.order = CDEM_GIF_BACKWARD;
    o.selection = CDEM_GIF_ODD;
    o.scale = 0.5;
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    assert_non_null(f);
    cdem_gif_options_view(&o, f);
    fclose(f);
    assert_non_null(strstr(text, "gif.delay = 10 cs\n"));
    assert_non_null(strstr(text, "gif.order = backward\n"));
    assert_non_null(strstr(text, "gif.frames = odd\n"));
    assert_non_null(strstr(text, "gif.scale = 0.5\n"));
    assert_non_null(strstr(text, "gif.loop = forever\n"));
    free(text);
}

static void test_gif_errors(void **state) {
    (void)state;
    char path[512];
    scratch_path(path, sizeof path, "gif_err.gif");
    cdem_gif_options o;
    cdem_gif_options_default(&o);
    cdem_error err;
    cdem_gif *g = NULL;

    o.scale = 2.0;
    cdem_error_clear(&err);
    assert_int_equal(cdem_gif_open(&g, path, 40, 30, &o, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "scale = 2"));
    assert_null(g);
    o.scale = 1.0;
    o.delay_cs = 0;
    assert_int_equal(cdem_gif_open(&g, path, 40, 30, &o, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "delay = 0 cs"));
    o.delay_cs = 10;
    assert_int_equal(cdem_gif_open(&g, path, 0, 30, &o, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "frame 0 x 30"));

    const char *bad = "/nonexistent-dir-cdem/movie.gif";
    assert_int_equal(cdem_gif_write(bad, 3, 40, 30, solid_frame, NULL, &o, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, bad));

    o.selection = CDEM_GIF_ODD;
    assert_int_equal(cdem_gif_write(path, 1, 40, 30, solid_frame, NULL, &o, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "nothing to write"));
    o.selection = CDEM_GIF_ALL;

    /* a failing frame aborts the movie, names the frame and leaves no file behind */
    remove(path);
    assert_int_equal(cdem_gif_write(path, 5, 40, 30, failing_frame, NULL, &o, &err),
                     CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "frame 2"));
    assert_non_null(strstr(err.msg, "increment 2 is missing"));
    assert_int_equal(file_size(path), -1);

    /* closing a movie without frames is an error and removes the file */
    assert_int_equal(cdem_gif_open(&g, path, 40, 30, &o, &err), CDEM_OK);
    assert_int_equal(cdem_gif_close(g, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "no frames"));
    assert_int_equal(file_size(path), -1);
    cdem_gif_free(NULL);
}

/* fontconfig, which cairo's text uses, keeps a process-lifetime configuration that only
 * FcFini releases (and fontconfig is not linked directly). LeakSanitizer reads this hook
 * in the asan build; in other builds it is an unused function. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) {
    return "leak:libfontconfig.so\n";
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gif_palette_round_trip),
        cmocka_unit_test(test_gif_frame_order),
        cmocka_unit_test(test_gif_order_read_back),
        cmocka_unit_test(test_gif_optimised_frames_reconstruct),
        cmocka_unit_test(test_gif_scale_and_identical_frames),
        cmocka_unit_test(test_gif_rendered_frames),
        cmocka_unit_test(test_gif_options_view),
        cmocka_unit_test(test_gif_errors),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    cairo_debug_reset_static_data(); /* drop cairo's font caches before LeakSanitizer looks */
    return failed;
}
