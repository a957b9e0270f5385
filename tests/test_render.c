/* Tests of analysis/render: pixels that must hold on small hand-made states (wall, layer,
 * growth, weak, biaxial edge, footwall, highlighted, undefined and coloured elements), the
 * colour bar ends, vectors and axes, image sizes, PNG/PDF/SVG files, colour parsing and the
 * error messages for bad input. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render.h"
#include "scratch.h"

/* Elements of the hand-made scene (index = element). View box x 0..10, y 0..5 m. */
enum {
    E_WALL,      /* (1, 1) wall */
    E_LAYER1,    /* (3, 1) layer 1: pre-growth band 0 (yellow) */
    E_LAYER2,    /* (5, 1) layer 2: pre-growth band 1 (red) */
    E_WEAK,      /* (7, 1) layer 1, weak: semi-transparent yellow */
    E_EDGE,      /* (9, 1) biaxial edge: green */
    E_GROWTH1A,  /* (1, 3) layer 25: growth sequence 1, band 0 */
    E_GROWTH1B,  /* (3, 3) layer 26: growth sequence 1, band 1 (magenta) */
    E_GROWTH2,   /* (5, 3) layer 35: growth sequence 2 */
    E_FOOTWALL,  /* (7, 3) footwall display element */
    E_HIGHLIGHT, /* (9, 3) layer 5, inside the highlighted range 5..6 */
    E_N
};

static void make_state(cdem_state *s) {
    static const struct {
        double x, y;
        int32_t layer;
        uint32_t flags;
    } el[E_N] = {
        {1, 1, 0, CDEM_FLAG_WALL},         {3, 1, 1, 0},  {5, 1, 2, 0},  {7, 1, 1, CDEM_FLAG_WEAK},
        {9, 1, 3, CDEM_FLAG_BIAXIAL_EDGE}, {1, 3, 25, 0}, {3, 3, 26, 0}, {5, 3, 35, 0},
        {7, 3, 4, CDEM_FLAG_FOOTWALL},     {9, 3, 5, 0},
    };
    cdem_error err;
    assert_int_equal(cdem_state_init(s, E_N, 0, &err), CDEM_OK);
    for (int i = 0; i < E_N; i++)
        assert_int_equal(cdem_state_append(s, -1, el[i].x, el[i].y, 0.45, 1.0, el[i].layer,
                                           el[i].flags, 0, NULL, &err),
                         CDEM_OK);
}

static void make_options(cdem_render_options *o) {
    cdem_render_options_default(o);
    o->has_zoom = 1;
    o->zoom_xmin = 0;
    o->zoom_xmax = 10;
    o->zoom_ymin = 0;
    o->zoom_ymax = 5;
    o->growth1_layers = 10;
    o->highlight_first = 5;
    o->highlight_last = 6;
}

typedef struct {
    cairo_surface_t *surf;
    cdem_render_layout lay;
} image;

static void render_image(image *im, const cdem_render_scene *sc, const cdem_render_options *o,
                         int w, int h) {
    im->surf = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h);
    cdem_error err;
    cdem_error_clear(&err);
    cdem_status st = cdem_render_to_surface(im->surf, sc, o, &err);
    if (st != CDEM_OK)
        fail_msg("render failed: %s", err.msg);
    assert_int_equal(cdem_render_layout_compute(sc, o, w, h, &im->lay, &err), CDEM_OK);
}

/* Unpremultiplied 0..255 channels of pixel (x, y). */
static void pixel_at(const image *im, double x, double y, int rgba[4]) {
    int px = (int)floor(x), py = (int)floor(y);
    assert_true(px >= 0 && px < cairo_image_surface_get_width(im->surf));
    assert_true(py >= 0 && py < cairo_image_surface_get_height(im->surf));
    const unsigned char *d = cairo_image_surface_get_data(im->surf);
    uint32_t p = ((const uint32_t *)(const void *)(d + (size_t)py * cairo_image_surface_get_stride(
                                                                        im->surf)))[px];
    int a = (int)(p >> 24);
    rgba[3] = a;
    for (int k = 0; k < 3; k++) {
        int v = (int)((p >> (16 - 8 * k)) & 255);
        rgba[k] = a ? (v * 255 + a / 2) / a : 0;
    }
}

static void model_pixel(const image *im, double x, double y, int rgba[4]) {
    double dx, dy;
    cdem_render_layout_to_device(&im->lay, x, y, &dx, &dy);
    pixel_at(im, dx, dy, rgba);
}

static void assert_near_colour(const int got[4], cdem_rgba want, int tol) {
    int w[3] = {(int)lround(want.r * 255), (int)lround(want.g * 255), (int)lround(want.b * 255)};
    for (int k = 0; k < 3; k++)
        if (abs(got[k] - w[k]) > tol)
            fail_msg("pixel (%d, %d, %d) differs from expected (%d, %d, %d) by more than %d",
                     got[0], got[1], got[2], w[0], w[1], w[2], tol);
}

static void test_render_layer_and_flag_colours(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    cdem_render_options o;
    make_options(&o);
    cdem_render_scene sc = {0};
    sc.state = &s;
    image im;
    render_image(&im, &sc, &o, 400, 240);
    int px[4];
    static const double pos[E_N][2] = {{1, 1}, {3, 1}, {5, 1}, {7, 1}, {9, 1},
                                       {1, 3}, {3, 3}, {5, 3}, {7, 3}, {9, 3}};
    const cdem_rgba *want[E_N] = {&o.wall,         &o.pregrowth[0], &o.pregrowth[1], NULL,
                                  &o.biaxial_edge, &o.growth1[0],   &o.growth1[1],   &o.growth2[0],
                                  &o.footwall,     &o.highlight};
    for (int i = 0; i < E_N; i++) {
        if (!want[i])
            continue;
        model_pixel(&im, pos[i][0], pos[i][1], px);
        assert_int_equal(px[3], 255);
        assert_near_colour(px, *want[i], 1);
    }
    /* the weak element is its layer colour blended over the white background */
    model_pixel(&im, 7, 1, px);
    cdem_rgba blend = o.pregrowth[0];
    blend.r = o.weak_alpha * blend.r + (1 - o.weak_alpha);
    blend.g = o.weak_alpha * blend.g + (1 - o.weak_alpha);
    blend.b = o.weak_alpha * blend.b + (1 - o.weak_alpha);
    assert_near_colour(px, blend, 2);
    assert_true(abs(px[2] - (int)lround(o.pregrowth[0].b * 255)) > 100); /* not opaque */
    /* background between elements */
    model_pixel(&im, 2, 2, px);
    assert_near_colour(px, o.background, 0);
    /* the default growth sequence 1 odd band is magenta, the pre-growth bands yellow/red */
    assert_true(o.growth1[1].r > 0.7 && o.growth1[1].b > 0.7 && o.growth1[1].g < 0.2);
    assert_true(o.pregrowth[0].r > 0.9 && o.pregrowth[0].g > 0.7 && o.pregrowth[0].b < 0.2);
    assert_true(o.pregrowth[1].r > 0.7 && o.pregrowth[1].g < 0.3);
    cairo_surface_destroy(im.surf);

    /* wider bands: layers 1 and 2 share band 0 */
    o.band_layers = 2;
    render_image(&im, &sc, &o, 400, 240);
    model_pixel(&im, 5, 1, px);
    assert_near_colour(px, o.pregrowth[0], 1);
    cairo_surface_destroy(im.surf);
    cdem_state_free(&s);
}

/* Salt elements (CDEM_FLAG_SALT, salt.layer) are drawn as their own material: lilac bands
 * alternating by pre-growth layer, distinct from the cover's yellow and red. */
static void test_render_salt_colours(void **state) {
    (void)state;
    cdem_state s;
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    static const struct {
        double x;
        int32_t layer;
        uint32_t flags;
    } el[] = {{1, 1, CDEM_FLAG_SALT}, {3, 2, CDEM_FLAG_SALT}, {5, 1, 0}, {7, 2, 0}};
    for (int i = 0; i < 4; i++)
        assert_int_equal(cdem_state_append(&s, -1, el[i].x, 1, 0.45, 1.0, el[i].layer, el[i].flags,
                                           0, NULL, &err),
                         CDEM_OK);
    cdem_render_options o;
    make_options(&o);
    cdem_render_scene sc = {0};
    sc.state = &s;
    image im;
    render_image(&im, &sc, &o, 400, 240);
    const cdem_rgba *want[4] = {&o.salt[0], &o.salt[1], &o.pregrowth[0], &o.pregrowth[1]};
    int px[4];
    for (int i = 0; i < 4; i++) {
        model_pixel(&im, el[i].x, 1, px);
        assert_int_equal(px[3], 255);
        assert_near_colour(px, *want[i], 1);
    }
    /* lilac: red and blue above green, unlike every cover colour */
    assert_true(o.salt[0].b > o.salt[0].g && o.salt[0].r > o.salt[0].g);
    assert_true(o.salt[1].b > o.salt[1].g && o.salt[0].b != o.salt[1].b);
    cairo_surface_destroy(im.surf);
    cdem_state_free(&s);
}

static void test_render_values_colours_and_undefined(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    cdem_render_options o;
    make_options(&o);
    double v[E_N];
    for (int i = 0; i < E_N; i++)
        v[i] = 0.5;
    v[E_LAYER1] = NAN; /* undefined: neutral grey */
    v[E_LAYER2] = 2.0; /* vmax: red */
    v[E_GROWTH1A] = 0.0;
    v[E_GROWTH1B] = 1.0;  /* middle: green */
    v[E_HIGHLIGHT] = 0.1; /* below 0.1 x max when that mode is on */
    v[E_GROWTH2] = 0.2;   /* exactly 0.1 x max: not above it */
    cdem_render_scene sc = {0};
    sc.state = &s;
    sc.values = v;
    sc.vmin = 0.0;
    sc.vmax = 2.0;
    sc.kind = CDEM_COLORMAP_MAGNITUDE;
    sc.quantity = "Total displacement";
    sc.unit = "m";
    image im;
    render_image(&im, &sc, &o, 500, 240);
    int px[4];
    model_pixel(&im, 3, 1, px);
    assert_near_colour(px, o.undefined, 1);
    model_pixel(&im, 5, 1, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 1.0), 1);
    model_pixel(&im, 1, 3, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.0), 1);
    model_pixel(&im, 3, 3, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.5), 1);
    model_pixel(&im, 9, 3, px); /* 0.1 / 2 = 0.05 */
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.05), 3);
    model_pixel(&im, 5, 3, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.1), 3);
    /* walls, biaxial edges and footwall keep their colours */
    model_pixel(&im, 1, 1, px);
    assert_near_colour(px, o.wall, 1);
    model_pixel(&im, 9, 1, px);
    assert_near_colour(px, o.biaxial_edge, 1);
    model_pixel(&im, 7, 3, px);
    assert_near_colour(px, o.footwall, 1);

    /* colour bar: bottom end = low colour, top end = high colour, middle = middle */
    const cdem_render_layout *L = &im.lay;
    assert_true(L->bar_w > 4 && L->bar_h > 40);
    pixel_at(&im, L->bar_x + 0.5 * L->bar_w, L->bar_y + L->bar_h - 1.0, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.0), 12);
    pixel_at(&im, L->bar_x + 0.5 * L->bar_w, L->bar_y + 1.0, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 1.0), 12);
    pixel_at(&im, L->bar_x + 0.5 * L->bar_w, L->bar_y + 0.5 * L->bar_h, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.5), 12);
    cairo_surface_destroy(im.surf);

    /* only above 0.1 x max: the small value falls back to its layer (highlight) colour */
    sc.above_tenth_max = 1;
    render_image(&im, &sc, &o, 500, 240);
    model_pixel(&im, 9, 3, px);
    assert_near_colour(px, o.highlight, 1);
    model_pixel(&im, 5, 3, px);
    assert_near_colour(px, o.growth2[0], 1);
    model_pixel(&im, 3, 3, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.5), 1);
    cairo_surface_destroy(im.surf);

    /* colours toggled off: layer colours, no colour bar */
    sc.above_tenth_max = 0;
    o.show_colours = 0;
    render_image(&im, &sc, &o, 500, 240);
    model_pixel(&im, 5, 1, px);
    assert_near_colour(px, o.pregrowth[1], 1);
    assert_true(im.lay.bar_w == 0);
    cairo_surface_destroy(im.surf);
    cdem_state_free(&s);
}

static void test_render_signed_colour_bar(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    cdem_render_options o;
    make_options(&o);
    double v[E_N];
    for (int i = 0; i < E_N; i++)
        v[i] = 0.0; /* zero: white */
    v[E_LAYER2] = -0.004;
    cdem_render_scene sc = {0};
    sc.state = &s;
    sc.values = v;
    sc.vmin = -0.004;
    sc.vmax = 0.001;
    sc.kind = CDEM_COLORMAP_SIGNED;
    sc.quantity = "Dilation";
    image im;
    render_image(&im, &sc, &o, 500, 240);
    int px[4];
    model_pixel(&im, 3, 1, px);
    assert_near_colour(px, (cdem_rgba){1, 1, 1, 1}, 1);
    model_pixel(&im, 5, 1, px);
    assert_near_colour(px, (cdem_rgba){0, 0, 1, 1}, 1);
    const cdem_render_layout *L = &im.lay;
    pixel_at(&im, L->bar_x + 0.5 * L->bar_w, L->bar_y + L->bar_h - 1.0, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 0.0), 12);
    pixel_at(&im, L->bar_x + 0.5 * L->bar_w, L->bar_y + 1.0, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 1.0), 12);
    pixel_at(&im, L->bar_x + 0.5 * L->bar_w, L->bar_y + 0.5 * L->bar_h, px);
    assert_near_colour(px, (cdem_rgba){1, 1, 1, 1}, 6);
    cairo_surface_destroy(im.surf);
    cdem_state_free(&s);
}

/* colour_bar_space: a picture in layer colours keeps the colour bar's room, so it gets the
 * layout (plot area, scale, model position, automatic height) of the same view coloured
 * by a quantity with its colour bar; the room stays background. Without it the plot area
 * is wider and the model larger. */
static void test_render_colour_bar_space(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    cdem_render_options o;
    make_options(&o);
    double v[E_N];
    for (int i = 0; i < E_N; i++)
        v[i] = (double)i;
    cdem_render_scene coloured = {0}, layers = {0};
    coloured.state = layers.state = &s;
    coloured.values = v;
    coloured.vmin = 0;
    coloured.vmax = E_N - 1;
    coloured.kind = CDEM_COLORMAP_MAGNITUDE;
    coloured.quantity = "Value";
    coloured.label = layers.label = "Increment 1";
    cdem_error err;
    int h_coloured, h_layers, h_plain;
    assert_int_equal(cdem_render_auto_height(&coloured, &o, &h_coloured, &err), CDEM_OK);
    assert_int_equal(cdem_render_auto_height(&layers, &o, &h_plain, &err), CDEM_OK);
    cdem_render_layout plain;
    assert_int_equal(cdem_render_layout_compute(&layers, &o, 600, h_plain, &plain, &err), CDEM_OK);
    o.colour_bar_space = 1;
    assert_int_equal(cdem_render_auto_height(&layers, &o, &h_layers, &err), CDEM_OK);
    assert_int_equal(h_layers, h_coloured);
    assert_true(h_plain > h_coloured); /* o.height = 0: 1200 wide, the wider plot is taller */
    image a, b;
    render_image(&a, &coloured, &o, 600, 300);
    render_image(&b, &layers, &o, 600, 300);
    const cdem_render_layout *A = &a.lay, *B = &b.lay;
    assert_true(A->bar_w > 0 && B->bar_w == 0);
    assert_true(A->plot_x == B->plot_x && A->plot_y == B->plot_y && A->plot_w == B->plot_w &&
                A->plot_h == B->plot_h);
    assert_true(A->scale == B->scale && A->ox == B->ox && A->oy == B->oy);
    assert_true(plain.scale > A->scale); /* without the room: a larger model */
    int px[4];
    model_pixel(&b, 3, 1, px); /* layer 1: yellow */
    assert_near_colour(px, o.pregrowth[0], 2);
    pixel_at(&a, A->bar_x + 0.5 * A->bar_w, A->bar_y + 0.5 * A->bar_h, px);
    assert_near_colour(px, cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.5), 12);
    pixel_at(&b, A->bar_x + 0.5 * A->bar_w, A->bar_y + 0.5 * A->bar_h, px);
    assert_near_colour(px, o.background, 0);
    cairo_surface_destroy(a.surf);
    cairo_surface_destroy(b.surf);
    cdem_state_free(&s);
}

static void test_render_vectors_axes_outline(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    cdem_render_options o;
    make_options(&o);
    o.vector = (cdem_rgba){0, 0, 0, 1};
    o.axis[0] = (cdem_rgba){0, 0, 1, 1};
    o.axis[1] = (cdem_rgba){1, 0, 0, 1};
    o.line_width = 3.0;
    double ux[E_N] = {0}, uy[E_N] = {0};
    ux[E_LAYER1] = 0.2; /* x 5 = 1 m to the right of (3, 1): ends at (4, 1) */
    uy[E_GROWTH2] = NAN;
    double ax[1] = {5.0}, ay[1] = {4.5}, aa[1] = {0.0};
    cdem_render_scene sc = {0};
    sc.state = &s;
    sc.ux = ux;
    sc.uy = uy;
    sc.vector_scale = 5.0;
    sc.axis_x = ax;
    sc.axis_y = ay;
    sc.axis_angle = aa;
    sc.n_axes = 1;
    sc.axis_length = 1.0;
    image im;
    render_image(&im, &sc, &o, 400, 240);
    int px[4];
    model_pixel(&im, 3.7, 1.0, px); /* on the vector, outside the disc (r = 0.45) */
    assert_near_colour(px, o.vector, 30);
    model_pixel(&im, 3.7, 1.3, px); /* beside it */
    assert_near_colour(px, o.background, 0);
    model_pixel(&im, 5.3, 4.5, px); /* on the horizontal axis */
    assert_near_colour(px, o.axis[0], 30);
    model_pixel(&im, 5.0, 4.8, px); /* no perpendicular set yet */
    assert_near_colour(px, o.background, 0);
    cairo_surface_destroy(im.surf);

    sc.axis_perpendicular = 1;
    aa[0] = M_PI / 2; /* vertical first set, horizontal second set */
    render_image(&im, &sc, &o, 400, 240);
    model_pixel(&im, 5.0, 4.8, px);
    assert_near_colour(px, o.axis[0], 30);
    model_pixel(&im, 5.3, 4.5, px);
    assert_near_colour(px, o.axis[1], 30);
    cairo_surface_destroy(im.surf);

    /* vectors and axes toggled off */
    o.show_vectors = 0;
    o.show_axes = 0;
    render_image(&im, &sc, &o, 400, 240);
    model_pixel(&im, 3.7, 1.0, px);
    assert_near_colour(px, o.background, 0);
    model_pixel(&im, 5.3, 4.5, px);
    assert_near_colour(px, o.background, 0);
    cairo_surface_destroy(im.surf);

    /* fill off: the centre shows the background, the outline stays */
    o.show_fill = 0;
    o.show_outline = 0;
    o.outline = (cdem_rgba){0, 0, 0, 1};
    o.outline_width = 3.0;
    render_image(&im, &sc, &o, 400, 240);
    model_pixel(&im, 1, 1, px);
    assert_near_colour(px, o.background, 0);
    model_pixel(&im, 1.45, 1, px);
    assert_true(px[0] < 128 && px[1] < 128 && px[2] < 128);
    cairo_surface_destroy(im.surf);
    cdem_state_free(&s);
}

/* The direct rasteriser (image targets) and the cairo path (vector targets, here replayed
 * from a recording surface) draw the same picture: same colours at element centres and on
 * vectors and axes, and a small mean difference over the whole image. */
static void test_render_raster_matches_cairo_path(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    cdem_render_options o;
    make_options(&o);
    o.line_width = 2.0;
    o.axis[1] = (cdem_rgba){1, 0, 0, 1};
    double v[E_N], ux[E_N] = {0}, uy[E_N] = {0};
    for (int i = 0; i < E_N; i++)
        v[i] = 0.2 * i;
    v[E_LAYER1] = NAN;
    ux[E_LAYER2] = 0.25;
    double ax[1] = {5.0}, ay[1] = {4.5}, aa[1] = {0.3};
    cdem_render_scene sc = {0};
    sc.state = &s;
    sc.values = v;
    sc.vmin = 0;
    sc.vmax = 2;
    sc.quantity = "Maximum shear strain";
    sc.ux = ux;
    sc.uy = uy;
    sc.vector_scale = 5;
    sc.axis_x = ax;
    sc.axis_y = ay;
    sc.axis_angle = aa;
    sc.n_axes = 1;
    sc.axis_length = 1.0;
    sc.axis_perpendicular = 1;
    const int w = 480, h = 260;
    image direct;
    render_image(&direct, &sc, &o, w, h);

    cairo_rectangle_t ext = {0, 0, w, h};
    cairo_surface_t *rec = cairo_recording_surface_create(CAIRO_CONTENT_COLOR_ALPHA, &ext);
    cairo_t *cr = cairo_create(rec);
    cdem_error err;
    assert_int_equal(cdem_render_draw(cr, w, h, &sc, &o, &err), CDEM_OK);
    cairo_destroy(cr);
    image viacairo = {cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h), direct.lay};
    cr = cairo_create(viacairo.surf);
    cairo_set_source_surface(cr, rec, 0, 0);
    cairo_paint(cr);
    cairo_destroy(cr);
    cairo_surface_flush(viacairo.surf);
    cairo_surface_destroy(rec);

    static const double pts[][2] = {{1, 1}, {3, 1}, {5, 1}, {7, 1}, {9, 1},   {1, 3},
                                    {3, 3}, {5, 3}, {7, 3}, {9, 3}, {5.8, 1}, {5, 4.5}};
    for (size_t k = 0; k < sizeof pts / sizeof pts[0]; k++) {
        int a[4], b[4];
        model_pixel(&direct, pts[k][0], pts[k][1], a);
        model_pixel(&viacairo, pts[k][0], pts[k][1], b);
        for (int c = 0; c < 4; c++)
            if (abs(a[c] - b[c]) > 40)
                fail_msg("point %zu (%g, %g): direct (%d %d %d %d) vs cairo (%d %d %d %d)", k,
                         pts[k][0], pts[k][1], a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]);
    }
    double sum = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int a[4], b[4];
            pixel_at(&direct, x, y, a);
            pixel_at(&viacairo, x, y, b);
            for (int c = 0; c < 3; c++)
                sum += abs(a[c] - b[c]);
        }
    double mean = sum / (3.0 * w * h);
    assert_true(mean < 2.0);
    cairo_surface_destroy(direct.surf);
    cairo_surface_destroy(viacairo.surf);
    cdem_state_free(&s);
}

static void test_render_scale_bar_and_label(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    cdem_render_options o;
    make_options(&o);
    cdem_render_scene sc = {0};
    sc.state = &s;
    sc.label = "Increment 282   Net displacement 1127 m";
    image im;
    render_image(&im, &sc, &o, 400, 260);
    const cdem_render_layout *L = &im.lay;
    /* scale bar: a filled bar of the text colour just below the plot area, at its left */
    double fs = L->font_size;
    int px[4];
    pixel_at(&im, L->plot_x + 0.5 * fs + 2, L->plot_y + L->plot_h + 0.8 * fs, px);
    assert_near_colour(px, o.text, 1);
    /* the label puts dark pixels somewhere in the band above the plot */
    int dark = 0;
    for (int y = 0; y < (int)L->plot_y; y++)
        for (int x = 0; x < 400; x++) {
            pixel_at(&im, x, y, px);
            dark += px[0] < 100;
        }
    assert_true(dark > 20);
    cairo_surface_destroy(im.surf);
    /* no label, no scale bar: the bands are empty */
    o.show_label = 0;
    o.show_scale_bar = 0;
    render_image(&im, &sc, &o, 400, 260);
    dark = 0;
    for (int y = 0; y < 260; y++)
        for (int x = 0; x < 400; x++) {
            double mx = (x - im.lay.ox) / im.lay.scale, my = 5 - (y - im.lay.oy) / im.lay.scale;
            if (mx >= 0 && mx <= 10 && my >= 0 && my <= 5)
                continue;
            pixel_at(&im, x, y, px);
            dark += px[0] < 100;
        }
    assert_int_equal(dark, 0);
    cairo_surface_destroy(im.surf);
    cdem_state_free(&s);
}

static void test_render_rgba_matches_surface(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    cdem_render_options o;
    make_options(&o);
    o.background = (cdem_rgba){1, 1, 1, 0}; /* transparent */
    cdem_render_scene sc = {0};
    sc.state = &s;
    image im;
    render_image(&im, &sc, &o, 300, 200);
    uint8_t *rgba = malloc(300 * 200 * 4);
    assert_non_null(rgba);
    cdem_error err;
    assert_int_equal(cdem_render_to_rgba(rgba, 300, 200, &sc, &o, &err), CDEM_OK);
    double wx[2] = {3, 7};
    for (int k = 0; k < 2; k++) {
        double dx, dy;
        cdem_render_layout_to_device(&im.lay, wx[k], 1, &dx, &dy);
        int px[4];
        pixel_at(&im, dx, dy, px);
        const uint8_t *p = rgba + ((size_t)floor(dy) * 300 + (size_t)floor(dx)) * 4;
        for (int c = 0; c < 4; c++)
            assert_true(abs(p[c] - px[c]) <= 1);
    }
    /* the weak element over a transparent background is itself partly transparent */
    double dx, dy;
    cdem_render_layout_to_device(&im.lay, 7, 1, &dx, &dy);
    const uint8_t *p = rgba + ((size_t)floor(dy) * 300 + (size_t)floor(dx)) * 4;
    assert_true(abs(p[3] - (int)lround(o.weak_alpha * 255)) <= 1);
    assert_true(abs(p[0] - 255) <= 2 && abs(p[1] - (int)lround(o.pregrowth[0].g * 255)) <= 3);
    free(rgba);
    cairo_surface_destroy(im.surf);
    cdem_state_free(&s);
}

static long file_read(const char *path, char *buf, size_t cap) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    size_t n = fread(buf, 1, cap - 1, f);
    buf[n] = 0;
    fclose(f);
    return (long)n;
}

static void test_render_files_png_pdf_svg(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    cdem_render_options o;
    cdem_render_options_default(&o); /* fitted view box */
    double v[E_N];
    for (int i = 0; i < E_N; i++)
        v[i] = i;
    cdem_render_scene sc = {0};
    sc.state = &s;
    sc.values = v;
    sc.vmin = 0;
    sc.vmax = E_N - 1;
    sc.quantity = "Maximum shear strain";
    sc.label = "Increment 3";
    char path[512];
    cdem_error err;
    cdem_error_clear(&err);

    /* PNG, explicit size */
    o.width = 320;
    o.height = 200;
    snprintf(path, sizeof path, "%s/render_test.png", scratch_root());
    assert_int_equal(cdem_render_to_file(path, &sc, &o, &err), CDEM_OK);
    cairo_surface_t *png = cairo_image_surface_create_from_png(path);
    assert_int_equal(cairo_surface_status(png), CAIRO_STATUS_SUCCESS);
    assert_int_equal(cairo_image_surface_get_width(png), 320);
    assert_int_equal(cairo_image_surface_get_height(png), 200);
    cairo_surface_destroy(png);
    remove(path);

    /* PNG, automatic height follows the aspect of the 10 x 3 element box */
    o.height = 0;
    int h = 0;
    assert_int_equal(cdem_render_auto_height(&sc, &o, &h, &err), CDEM_OK);
    assert_true(h > 100 && h < 320);
    assert_int_equal(cdem_render_to_file(path, &sc, &o, &err), CDEM_OK);
    png = cairo_image_surface_create_from_png(path);
    assert_int_equal(cairo_image_surface_get_width(png), 320);
    assert_int_equal(cairo_image_surface_get_height(png), h);
    cairo_surface_destroy(png);
    remove(path);

    static char buf[1 << 20];
    snprintf(path, sizeof path, "%s/render_test.pdf", scratch_root());
    assert_int_equal(cdem_render_to_file(path, &sc, &o, &err), CDEM_OK);
    assert_true(file_read(path, buf, sizeof buf) > 100);
    assert_memory_equal(buf, "%PDF-", 5);
    remove(path);

    snprintf(path, sizeof path, "%s/render_test.SVG", scratch_root());
    assert_int_equal(cdem_render_to_file(path, &sc, &o, &err), CDEM_OK);
    assert_true(file_read(path, buf, sizeof buf) > 100);
    assert_memory_equal(buf, "<?xml", 5);
    assert_non_null(strstr(buf, "<svg"));
    assert_non_null(strstr(buf, "</svg>"));
    remove(path);

    /* unsupported extension, unwritable directory */
    snprintf(path, sizeof path, "%s/render_test.jpg", scratch_root());
    assert_int_equal(cdem_render_to_file(path, &sc, &o, &err), CDEM_ERR_UNSUPPORTED);
    assert_non_null(strstr(err.msg, ".jpg"));
    assert_non_null(strstr(err.msg, ".png, .pdf or .svg"));
    assert_int_equal(cdem_render_to_file("no_extension", &sc, &o, &err), CDEM_ERR_UNSUPPORTED);
    assert_non_null(strstr(err.msg, "(none)"));
    const char *bad[] = {"/nonexistent-dir-cdem/x.png", "/nonexistent-dir-cdem/x.pdf",
                         "/nonexistent-dir-cdem/x.svg"};
    for (int k = 0; k < 3; k++) {
        cdem_error_clear(&err);
        assert_int_equal(cdem_render_to_file(bad[k], &sc, &o, &err), CDEM_ERR_IO);
        assert_non_null(strstr(err.msg, bad[k]));
    }
    cdem_state_free(&s);
}

static void test_render_parse_colour(void **state) {
    (void)state;
    cdem_rgba c;
    cdem_error err;
    assert_int_equal(cdem_render_parse_colour("#8b5a2b", &c, &err), CDEM_OK);
    assert_true(fabs(c.r - 0x8b / 255.0) < 1e-12 && fabs(c.g - 0x5a / 255.0) < 1e-12 &&
                fabs(c.b - 0x2b / 255.0) < 1e-12 && c.a == 1.0);
    assert_int_equal(cdem_render_parse_colour("#FF00FF80", &c, &err), CDEM_OK);
    assert_true(c.r == 1.0 && c.g == 0.0 && c.b == 1.0 && fabs(c.a - 128 / 255.0) < 1e-12);
    static const char *bad[] = {"red", "#12345", "8b5a2b", "#8b5a2bff00", "", "#zz0000"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        cdem_error_clear(&err);
        assert_int_equal(cdem_render_parse_colour(bad[k], &c, &err), CDEM_ERR_PARSE);
        assert_non_null(strstr(err.msg, "#rrggbb"));
        char quoted[64];
        snprintf(quoted, sizeof quoted, "'%s'", bad[k]);
        assert_non_null(strstr(err.msg, quoted));
    }
    assert_int_equal(cdem_render_parse_colour(NULL, &c, &err), CDEM_ERR_PARSE);
    cdem_render_format f;
    assert_int_equal(cdem_render_format_from_path("a/b.c/pic.Png", &f, &err), CDEM_OK);
    assert_int_equal(f, CDEM_RENDER_PNG);
    assert_int_equal(cdem_render_format_from_path("a.pdf/pic", &f, &err), CDEM_ERR_UNSUPPORTED);
}

static void test_render_options_view(void **state) {
    (void)state;
    cdem_render_options o;
    cdem_render_options_default(&o);
    o.highlight_first = 5;
    o.highlight_last = 8;
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    assert_non_null(f);
    cdem_render_options_view(&o, f);
    fclose(f);
    assert_non_null(strstr(text, "render.width = 1200\n"));
    assert_non_null(strstr(text, "render.height = 0 (automatic)\n"));
    assert_non_null(strstr(text, "render.pregrowth_layers = 24\n"));
    assert_non_null(strstr(text, "render.highlight = 5..8\n"));
    assert_non_null(strstr(text, "render.colour_bar_space = 0\n"));
    assert_non_null(strstr(text, "render.colour.wall = #8b5a2bff\n"));
    assert_non_null(strstr(text, "render.colour.undefined = #999999ff\n"));
    /* every colour line reads back (within rounding) with cdem_render_parse_colour */
    const char *line = strstr(text, "render.colour.outline = ");
    assert_non_null(line);
    char hex[10];
    memcpy(hex, line + strlen("render.colour.outline = "), 9);
    hex[9] = 0;
    cdem_rgba c;
    cdem_error err;
    assert_int_equal(cdem_render_parse_colour(hex, &c, &err), CDEM_OK);
    assert_true(fabs(c.r - o.outline.r) <= 0.5 / 255 + 1e-12);
    assert_true(fabs(c.a - o.outline.a) <= 0.5 / 255 + 1e-12);
    free(text);
}

static void test_render_bad_input_fails_cleanly(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    /* non-finite coordinates and radii are skipped, not drawn and not crashing */
    s.x[E_LAYER1] = NAN;
    s.radius[E_LAYER2] = -1.0;
    s.y[E_WEAK] = INFINITY;
    s.x[E_EDGE] = 1e300; /* far outside the zoom box */
    cdem_render_options o;
    make_options(&o);
    cdem_render_scene sc = {0};
    sc.state = &s;
    image im;
    render_image(&im, &sc, &o, 200, 120);
    int px[4];
    model_pixel(&im, 5, 1, px);
    assert_near_colour(px, o.background, 0);
    cairo_surface_destroy(im.surf);

    /* absurd sizes (a disc and axes far larger than the image) draw without overflow */
    s.radius[E_WALL] = 1e300;
    double ax[1] = {5.0}, ay[1] = {2.0}, aa[1] = {0.7};
    sc.axis_x = ax;
    sc.axis_y = ay;
    sc.axis_angle = aa;
    sc.n_axes = 1;
    sc.axis_length = 1e300;
    render_image(&im, &sc, &o, 200, 120);
    model_pixel(&im, 5, 4, px);
    assert_near_colour(px, o.wall, 1); /* the giant wall disc covers the view */
    cairo_surface_destroy(im.surf);
    s.radius[E_WALL] = 0.45;
    sc.n_axes = 0;

    cdem_error err;
    cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 100, 100);
    static const struct {
        const char *what; /* case */
        cdem_status code; /* expected status */
        const char *text; /* expected in the message */
    } cases[] = {
        {"null state", CDEM_ERR_INVALID, "scene.state"},
        {"vmin > vmax", CDEM_ERR_RANGE, "vmin = 3"},
        {"nan limit", CDEM_ERR_RANGE, "vmax = nan"},
        {"vector scale", CDEM_ERR_RANGE, "vector exaggeration = 0"},
        {"zoom", CDEM_ERR_RANGE, "zoom box x 5..5"},
        {"weak alpha", CDEM_ERR_RANGE, "weak_alpha = 1.5"},
        {"highlight", CDEM_ERR_RANGE, "highlighted layers 4..2"},
        {"band", CDEM_ERR_RANGE, "band_layers = 0"},
        {"axes", CDEM_ERR_INVALID, "1 axes"},
        {"colour", CDEM_ERR_RANGE, "channels must be in 0..1"},
    };
    double v[E_N] = {0}, ux[E_N] = {0};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        cdem_render_scene b = {0};
        b.state = &s;
        cdem_render_options bo;
        make_options(&bo);
        switch (k) {
        case 0:
            b.state = NULL;
            break;
        case 1:
            b.values = v;
            b.vmin = 3;
            b.vmax = 1;
            break;
        case 2:
            b.values = v;
            b.vmin = 0;
            b.vmax = NAN;
            break;
        case 3:
            b.ux = ux;
            b.uy = ux;
            b.vector_scale = 0;
            break;
        case 4:
            bo.zoom_xmin = 5;
            bo.zoom_xmax = 5;
            break;
        case 5:
            bo.weak_alpha = 1.5;
            break;
        case 6:
            bo.highlight_first = 4;
            bo.highlight_last = 2;
            break;
        case 7:
            bo.band_layers = 0;
            break;
        case 8:
            b.n_axes = 1;
            break;
        case 9:
            bo.wall.g = 2.0;
            break;
        }
        cdem_error_clear(&err);
        cdem_status st = cdem_render_to_surface(surf, &b, &bo, &err);
        if (st != cases[k].code || !strstr(err.msg, cases[k].text))
            fail_msg("case '%s': status %d, message '%s'", cases[k].what, (int)st, err.msg);
    }
    /* sizes out of range */
    cdem_render_options bo;
    make_options(&bo);
    cdem_render_scene b = {0};
    b.state = &s;
    cairo_surface_t *tiny = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 8, 8);
    assert_int_equal(cdem_render_to_surface(tiny, &b, &bo, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "8 x 8"));
    cairo_surface_destroy(tiny);
    bo.width = 5;
    char path[512];
    snprintf(path, sizeof path, "%s/render_small.png", scratch_root());
    assert_int_equal(cdem_render_to_file(path, &b, &bo, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "width = 5"));
    assert_int_equal(cdem_render_to_surface(NULL, &b, &bo, &err), CDEM_ERR_INVALID);
    assert_int_equal(cdem_render_to_rgba(NULL, 100, 100, &b, &bo, &err), CDEM_ERR_INVALID);
    cairo_surface_destroy(surf);

    /* an empty state renders (background only), and zero-width colour limits are fine */
    cdem_state e;
    assert_int_equal(cdem_state_init(&e, 4, 0, &err), CDEM_OK);
    cdem_render_options_default(&bo);
    b.state = &e;
    b.values = v;
    b.vmin = b.vmax = 0.0;
    render_image(&im, &b, &bo, 100, 80);
    cairo_surface_destroy(im.surf);
    cdem_state_free(&e);
    cdem_state_free(&s);
}

static void test_render_fit_box(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    double box[4];
    cdem_render_fit_box(&s, 0.0, box);
    assert_true(fabs(box[0] - 0.55) < 1e-12 && fabs(box[1] - 9.45) < 1e-12);
    assert_true(fabs(box[2] - 0.55) < 1e-12 && fabs(box[3] - 3.45) < 1e-12);
    cdem_render_fit_box(&s, 0.1, box);
    assert_true(fabs(box[0] - (0.55 - 0.89)) < 1e-12 && fabs(box[3] - (3.45 + 0.89)) < 1e-12);
    s.n = 0;
    cdem_render_fit_box(&s, 0.0, box);
    assert_true(box[0] == -0.5 && box[1] == 0.5 && box[2] == -0.5 && box[3] == 0.5);
    s.n = E_N;
    cdem_state_free(&s);
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
        cmocka_unit_test(test_render_layer_and_flag_colours),
        cmocka_unit_test(test_render_salt_colours),
        cmocka_unit_test(test_render_values_colours_and_undefined),
        cmocka_unit_test(test_render_signed_colour_bar),
        cmocka_unit_test(test_render_colour_bar_space),
        cmocka_unit_test(test_render_vectors_axes_outline),
        cmocka_unit_test(test_render_raster_matches_cairo_path),
        cmocka_unit_test(test_render_scale_bar_and_label),
        cmocka_unit_test(test_render_rgba_matches_surface),
        cmocka_unit_test(test_render_files_png_pdf_svg),
        cmocka_unit_test(test_render_parse_colour),
        cmocka_unit_test(test_render_options_view),
        cmocka_unit_test(test_render_bad_input_fails_cleanly),
        cmocka_unit_test(test_render_fit_box),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    cairo_debug_reset_static_data(); /* drop cairo's font caches before LeakSanitizer looks */
    return failed;
}
