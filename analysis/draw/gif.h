/* gif: animated GIF encoder (giflib) for sequences of RGBA frames, e.g. rendered increments.
 *
 * Streaming: frames are quantised and written one at a time, so a 283-frame movie never
 * holds more than two indexed frames in memory. That needs a palette known before the
 * first frame: a fixed global palette of a 6 x 7 x 6 colour cube (252 colours; green gets
 * the extra level because the eye resolves it best) plus the greys 51, 153, 204, with
 * index 255 reserved as the transparent colour. Pixels map to the nearest palette colour
 * (no dithering: flat areas stay flat and compress well). Each frame after the first holds
 * only the rectangle that changed, with unchanged pixels transparent (disposal "do not
 * dispose"), which is what keeps the file small. Frames are composited over white when
 * partly transparent. The movie loops forever (NETSCAPE2.0 extension) unless told not to.
 * Ownership: cdem_gif owns its file handle and buffers until cdem_gif_close (which writes
 * the file) or cdem_gif_free (which abandons and deletes it). Thread safety: one writer per
 * thread. Units: sizes in pixels, delay in 1/100 s. */
#ifndef CDEM_GIF_H
#define CDEM_GIF_H

#include "cdem_error.h"

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#define CDEM_GIF_TRANSPARENT 255   /* palette index reserved for "unchanged pixel" */
#define CDEM_GIF_MAX_SIZE    16384 /* largest output width or height, px (GIF limit 65535) */

typedef enum {
    CDEM_GIF_FORWARD = 0,  /* frames in increasing index order */
    CDEM_GIF_BACKWARD = 1, /* frames in decreasing index order */
} cdem_gif_order;

typedef enum {
    CDEM_GIF_ALL = 0, /* every frame */
    CDEM_GIF_ODD = 1, /* only odd frame indices (1, 3, 5, ...): half the size */
} cdem_gif_selection;

typedef struct {
    int delay_cs;                 /* delay per frame, 1/100 s, 1..65535; default 10 */
    cdem_gif_order order;         /* forward or backward; default forward */
    cdem_gif_selection selection; /* all or odd frames; default all */
    double scale;                 /* output size / frame size, 0.05..1 (box-filtered); default 1 */
    int optimise;   /* 1: write only changed rectangles with transparency; default 1 */
    int loop_count; /* 0 = loop forever (default), 1..65535 = number of repeats */
} cdem_gif_options;

typedef struct cdem_gif cdem_gif; /* an open writer; see gif.c */

/* Callback producing frame `index` (0-based, as given to cdem_gif_write) into rgba
 * (width x height x 4 bytes, R,G,B,A, row-major from the top). */
typedef cdem_status (*cdem_gif_frame_fn)(void *user, size_t index, uint8_t *rgba, int width,
                                         int height, cdem_error *err);

/* Defaults: 10 cs delay, forward, all frames, scale 1, optimised, loop forever. */
void cdem_gif_options_default(cdem_gif_options *o);

/* Writes the effective options to f, one "key = value" line each. */
void cdem_gif_options_view(const cdem_gif_options *o, FILE *f);

/* Frame indices to write for n frames, in output order, into indices (may be NULL to only
 * count; otherwise room for n). Returns their number. */
size_t cdem_gif_frame_order(size_t n, const cdem_gif_options *o, size_t *indices);

/* Opens path for frames of width x height (before scaling) and writes the header. */
cdem_status cdem_gif_open(cdem_gif **out, const char *path, int width, int height,
                          const cdem_gif_options *o, cdem_error *err);

/* Output size after scaling. */
void cdem_gif_output_size(const cdem_gif *g, int *width, int *height);

/* Quantises and appends one frame (width x height x 4 bytes RGBA, as given to open). */
cdem_status cdem_gif_add_frame(cdem_gif *g, const uint8_t *rgba, cdem_error *err);

/* Finishes the file and frees g (also when finishing fails). */
cdem_status cdem_gif_close(cdem_gif *g, cdem_error *err);

/* Abandons an unfinished writer: closes and deletes its file, frees g. g may be NULL. */
void cdem_gif_free(cdem_gif *g);

/* Whole movie: asks fn for frames 0..n_frames-1 in the order and selection of o. */
cdem_status cdem_gif_write(const char *path, size_t n_frames, int width, int height,
                           cdem_gif_frame_fn fn, void *user, const cdem_gif_options *o,
                           cdem_error *err);

/* Nearest palette index (0..254) of a colour, and the colour of a palette index. */
uint8_t cdem_gif_palette_index(uint8_t r, uint8_t g, uint8_t b);
void cdem_gif_palette_colour(int index, uint8_t rgb[3]);

#endif
