/* gif: see gif.h. Palette layout: index = r * 42 + g * 6 + b for cube levels r, b in 0..5
 * (value 51 k) and g in 0..6 (value round(255 k / 6)); 252..254 are the greys 51, 153,
 * 204 (the renderer's highlight, undefined and footwall greys land on them exactly);
 * 255 is transparent. The nearest colour is the better of the rounded cube cell and the
 * nearest grey, in plain RGB distance. */
#include "gif.h"

#include "outfile.h"

#include <gif_lib.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <errno.h>
#include <fcntl.h>
#include <unistd.h>

static const uint8_t gif_greys[3] = {51, 153, 204};
#define GIF_CUBE 252

struct cdem_gif {
    GifFileType *file;    /* giflib handle, NULL once closed */
    char *path;           /* copy of the output path (deleted by cdem_gif_free) */
    int in_w, in_h;       /* frame size as given, px */
    int out_w, out_h;     /* written size, px */
    cdem_gif_options opt; /* effective options */
    size_t frames;        /* frames written so far */
    uint8_t *cur, *prev;  /* indexed frames, out_w x out_h */
    GifPixelType *row;    /* one output row for EGifPutLine */
};

void cdem_gif_options_default(cdem_gif_options *o) {
    memset(o, 0, sizeof *o);
    o->delay_cs = 10;
    o->order = CDEM_GIF_FORWARD;
    o->selection = CDEM_GIF_ALL;
    o->scale = 1.0;
    o->optimise = 1;
    o->loop_count = 0;
}

void cdem_gif_options_view(const cdem_gif_options *o, FILE *f) {
    fprintf(f, "gif.delay = %d cs\n", o->delay_cs);
    fprintf(f, "gif.order = %s\n", o->order == CDEM_GIF_BACKWARD ? "backward" : "forward");
    fprintf(f, "gif.frames = %s\n", o->selection == CDEM_GIF_ODD ? "odd" : "all");
    fprintf(f, "gif.scale = %g\n", o->scale);
    fprintf(f, "gif.optimise = %d\n", o->optimise);
    if (o->loop_count == 0)
        fprintf(f, "gif.loop = forever\n");
    else
        fprintf(f, "gif.loop = %d\n", o->loop_count);
    fprintf(f, "gif.palette = 6x7x6 cube + greys 51, 153, 204 + transparent (fixed)\n");
}

size_t cdem_gif_frame_order(size_t n, const cdem_gif_options *o, size_t *indices) {
    size_t count = 0;
    for (size_t k = 0; k < n; k++) {
        size_t i = o->order == CDEM_GIF_BACKWARD ? n - 1 - k : k;
        if (o->selection == CDEM_GIF_ODD && i % 2 == 0)
            continue;
        if (indices)
            indices[count] = i;
        count++;
    }
    return count;
}

static int green_level(int k) {
    return (255 * k + 3) / 6;
}

void cdem_gif_palette_colour(int index, uint8_t rgb[3]) {
    if (index >= 0 && index < GIF_CUBE) {
        rgb[0] = (uint8_t)(51 * (index / 42));
        rgb[1] = (uint8_t)green_level((index / 6) % 7);
        rgb[2] = (uint8_t)(51 * (index % 6));
    } else if (index >= GIF_CUBE && index < GIF_CUBE + 3) {
        rgb[0] = rgb[1] = rgb[2] = gif_greys[index - GIF_CUBE];
    } else {
        rgb[0] = rgb[1] = rgb[2] = 0;
    }
}

uint8_t cdem_gif_palette_index(uint8_t r, uint8_t g, uint8_t b) {
    int ri = (r + 25) / 51, gi = (g * 6 + 127) / 255, bi = (b + 25) / 51;
    int dr = r - 51 * ri, dg = g - green_level(gi), db = b - 51 * bi;
    int best = ri * 42 + gi * 6 + bi;
    int best_d = dr * dr + dg * dg + db * db;
    for (int k = 0; k < 3; k++) {
        int v = gif_greys[k];
        int d = (r - v) * (r - v) + (g - v) * (g - v) + (b - v) * (b - v);
        if (d < best_d) {
            best_d = d;
            best = GIF_CUBE + k;
        }
    }
    return (uint8_t)best;
}

static cdem_status gif_fail(cdem_error *err, const char *what, const char *path, int code) {
    return CDEM_FAIL(err, CDEM_ERR_IO, "gif '%s': %s failed: %s", path, what,
                     GifErrorString(code) ? GifErrorString(code) : "unknown giflib error");
}

cdem_status cdem_gif_open(cdem_gif **out, const char *path, int width, int height,
                          const cdem_gif_options *o, cdem_error *err) {
    *out = NULL;
    if (!path || !o)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "gif: path and options must not be NULL");
    if (!(o->scale >= 0.05 && o->scale <= 1.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "gif '%s': scale = %g: must be in 0.05..1 (fraction of the frame size)",
                         path, o->scale);
    if (o->delay_cs < 1 || o->delay_cs > 65535)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "gif '%s': delay = %d cs: must be in 1..65535", path,
                         o->delay_cs);
    if (o->loop_count < 0 || o->loop_count > 65535)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "gif '%s': loop_count = %d: must be 0 (forever) or 1..65535", path,
                         o->loop_count);
    if (o->order != CDEM_GIF_FORWARD && o->order != CDEM_GIF_BACKWARD)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "gif '%s': order = %d: must be forward or backward",
                         path, (int)o->order);
    if (o->selection != CDEM_GIF_ALL && o->selection != CDEM_GIF_ODD)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "gif '%s': selection = %d: must be all or odd", path,
                         (int)o->selection);
    long ow = lround(width * o->scale), oh = lround(height * o->scale);
    if (width < 1 || height < 1 || ow < 1 || oh < 1 || ow > CDEM_GIF_MAX_SIZE ||
        oh > CDEM_GIF_MAX_SIZE)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "gif '%s': frame %d x %d at scale %g gives %ld x %ld: each side must "
                         "be in 1..%d",
                         path, width, height, o->scale, ow, oh, CDEM_GIF_MAX_SIZE);
    cdem_gif *g = calloc(1, sizeof *g);
    if (!g)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "gif '%s': out of memory", path);
    g->in_w = width;
    g->in_h = height;
    g->out_w = (int)ow;
    g->out_h = (int)oh;
    g->opt = *o;
    size_t npx = (size_t)ow * (size_t)oh;
    g->path = malloc(strlen(path) + 1);
    g->cur = malloc(npx);
    g->prev = malloc(npx);
    g->row = malloc((size_t)ow * sizeof *g->row);
    if (!g->path || !g->cur || !g->prev || !g->row) {
        cdem_gif_free(g);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "gif '%s': out of memory for %ld x %ld frames", path,
                         ow, oh);
    }
    strcpy(g->path, path);
    int code = 0;
    /* Open the file ourselves: giflib's EGifOpenFileName creates it mode 0600, but a movie
     * is an ordinary output file (0666 less the umask, like every other file we write). */
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0666);
    if (fd < 0) {
        cdem_status st = CDEM_FAIL(err, CDEM_ERR_IO, "gif '%s': cannot create the file: %s", path,
                                   strerror(errno));
        free(g->path);
        g->path = NULL; /* nothing was created: do not delete anything */
        cdem_gif_free(g);
        return st;
    }
    g->file = EGifOpenFileHandle(fd, &code);
    if (!g->file) {
        close(fd);
        cdem_status st = gif_fail(err, "opening the file", path, code);
        free(g->path);
        g->path = NULL; /* nothing was created: do not delete anything */
        cdem_gif_free(g);
        return st;
    }
    EGifSetGifVersion(g->file, true);
    GifColorType colours[256];
    for (int k = 0; k < 256; k++) {
        uint8_t c[3];
        cdem_gif_palette_colour(k, c);
        colours[k].Red = c[0];
        colours[k].Green = c[1];
        colours[k].Blue = c[2];
    }
    ColorMapObject *cmap = GifMakeMapObject(256, colours);
    if (!cmap) {
        cdem_gif_free(g);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "gif '%s': out of memory for the palette", path);
    }
    int rc = EGifPutScreenDesc(g->file, g->out_w, g->out_h, 8, 0, cmap);
    GifFreeMapObject(cmap);
    if (rc == GIF_ERROR) {
        cdem_status st = gif_fail(err, "writing the header", path, g->file->Error);
        cdem_gif_free(g);
        return st;
    }
    unsigned char loop[3] = {1, (unsigned char)(o->loop_count & 255),
                             (unsigned char)(o->loop_count >> 8)};
    if (EGifPutExtensionLeader(g->file, APPLICATION_EXT_FUNC_CODE) == GIF_ERROR ||
        EGifPutExtensionBlock(g->file, 11, "NETSCAPE2.0") == GIF_ERROR ||
        EGifPutExtensionBlock(g->file, 3, loop) == GIF_ERROR ||
        EGifPutExtensionTrailer(g->file) == GIF_ERROR) {
        cdem_status st = gif_fail(err, "writing the loop extension", path, g->file->Error);
        cdem_gif_free(g);
        return st;
    }
    *out = g;
    return CDEM_OK;
}

void cdem_gif_output_size(const cdem_gif *g, int *width, int *height) {
    *width = g->out_w;
    *height = g->out_h;
}

/* Box-filters rgba down to the output size, composites over white and quantises. */
static void quantise(cdem_gif *g, const uint8_t *rgba) {
    for (int oy = 0; oy < g->out_h; oy++) {
        int y0 = (int)((long)oy * g->in_h / g->out_h);
        int y1 = (int)((long)(oy + 1) * g->in_h / g->out_h);
        if (y1 <= y0)
            y1 = y0 + 1;
        for (int ox = 0; ox < g->out_w; ox++) {
            int x0 = (int)((long)ox * g->in_w / g->out_w);
            int x1 = (int)((long)(ox + 1) * g->in_w / g->out_w);
            if (x1 <= x0)
                x1 = x0 + 1;
            unsigned long sr = 0, sg = 0, sb = 0, cnt = 0;
            for (int y = y0; y < y1; y++) {
                const uint8_t *p = rgba + ((size_t)y * g->in_w + x0) * 4;
                for (int x = x0; x < x1; x++, p += 4) {
                    unsigned a = p[3], w = 255 - a;
                    sr += (p[0] * a + 255 * w + 127) / 255;
                    sg += (p[1] * a + 255 * w + 127) / 255;
                    sb += (p[2] * a + 255 * w + 127) / 255;
                    cnt++;
                }
            }
            g->cur[(size_t)oy * g->out_w + ox] = cdem_gif_palette_index(
                (uint8_t)((sr + cnt / 2) / cnt), (uint8_t)((sg + cnt / 2) / cnt),
                (uint8_t)((sb + cnt / 2) / cnt));
        }
    }
}

cdem_status cdem_gif_add_frame(cdem_gif *g, const uint8_t *rgba, cdem_error *err) {
    if (!g || !g->file || !rgba)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "gif: add_frame needs an open writer and a frame");
    quantise(g, rgba);
    int left = 0, top = 0, w = g->out_w, h = g->out_h;
    int diff = g->frames > 0 && g->opt.optimise;
    if (diff) {
        int x0 = g->out_w, x1 = -1, y0 = g->out_h, y1 = -1;
        for (int y = 0; y < g->out_h; y++) {
            const uint8_t *c = g->cur + (size_t)y * g->out_w, *p = g->prev + (size_t)y * g->out_w;
            for (int x = 0; x < g->out_w; x++) {
                if (c[x] != p[x]) {
                    if (x < x0)
                        x0 = x;
                    if (x > x1)
                        x1 = x;
                    if (y < y0)
                        y0 = y;
                    y1 = y;
                }
            }
        }
        if (x1 < 0) { /* identical frame: one transparent pixel keeps the timing */
            x0 = x1 = y0 = y1 = 0;
        }
        left = x0;
        top = y0;
        w = x1 - x0 + 1;
        h = y1 - y0 + 1;
    }
    GraphicsControlBlock gcb;
    gcb.DisposalMode = DISPOSE_DO_NOT;
    gcb.UserInputFlag = false;
    gcb.DelayTime = g->opt.delay_cs;
    gcb.TransparentColor = diff ? CDEM_GIF_TRANSPARENT : NO_TRANSPARENT_COLOR;
    GifByteType ext[4];
    size_t len = EGifGCBToExtension(&gcb, ext);
    if (EGifPutExtension(g->file, GRAPHICS_EXT_FUNC_CODE, (int)len, ext) == GIF_ERROR)
        return gif_fail(err, "writing a frame delay", g->path, g->file->Error);
    if (EGifPutImageDesc(g->file, left, top, w, h, false, NULL) == GIF_ERROR)
        return gif_fail(err, "writing a frame header", g->path, g->file->Error);
    for (int y = top; y < top + h; y++) {
        const uint8_t *c = g->cur + (size_t)y * g->out_w, *p = g->prev + (size_t)y * g->out_w;
        for (int x = 0; x < w; x++) {
            uint8_t v = c[left + x];
            g->row[x] = (diff && v == p[left + x]) ? CDEM_GIF_TRANSPARENT : v;
        }
        if (EGifPutLine(g->file, g->row, w) == GIF_ERROR)
            return gif_fail(err, "writing frame pixels", g->path, g->file->Error);
    }
    uint8_t *t = g->prev;
    g->prev = g->cur;
    g->cur = t;
    g->frames++;
    return CDEM_OK;
}

static void gif_release(cdem_gif *g) {
    free(g->path);
    free(g->cur);
    free(g->prev);
    free(g->row);
    free(g);
}

cdem_status cdem_gif_close(cdem_gif *g, cdem_error *err) {
    if (!g)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "gif: close needs an open writer");
    cdem_status st = CDEM_OK;
    if (g->frames == 0) {
        st = CDEM_FAIL(err, CDEM_ERR_INVALID, "gif '%s': no frames were added", g->path);
        cdem_gif_free(g);
        return st;
    }
    int code = 0;
    if (EGifCloseFile(g->file, &code) == GIF_ERROR) {
        st = gif_fail(err, "finishing the file", g->path, code);
        remove(g->path);
    }
    g->file = NULL;
    gif_release(g);
    return st;
}

void cdem_gif_free(cdem_gif *g) {
    if (!g)
        return;
    if (g->file) {
        int code = 0;
        EGifCloseFile(g->file, &code);
        if (g->path)
            remove(g->path);
    }
    gif_release(g);
}

cdem_status cdem_gif_write(const char *path, size_t n_frames, int width, int height,
                           cdem_gif_frame_fn fn, void *user, const cdem_gif_options *o,
                           cdem_error *err) {
    if (!fn || !o)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "gif: frame callback and options must be given");
    size_t count = cdem_gif_frame_order(n_frames, o, NULL);
    if (count == 0)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "gif '%s': %zu frames with selection '%s' leave nothing to write "
                         "(odd frames need at least 2)",
                         path ? path : "(null)", n_frames,
                         o->selection == CDEM_GIF_ODD ? "odd" : "all");
    if (width < 1 || height < 1)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "gif '%s': frame size %d x %d: must be positive",
                         path ? path : "(null)", width, height);
    size_t *order = malloc(count * sizeof *order);
    uint8_t *rgba = malloc((size_t)width * (size_t)height * 4);
    if (!order || !rgba) {
        free(order);
        free(rgba);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "gif '%s': out of memory for %d x %d frames",
                         path ? path : "(null)", width, height);
    }
    cdem_gif_frame_order(n_frames, o, order);
    cdem_gif *g = NULL;
    cdem_outfile of; /* written to path.tmp, renamed on success (outfile.h) */
    cdem_status st = cdem_outfile_begin(&of, path, err);
    if (st == CDEM_OK)
        st = cdem_gif_open(&g, of.tmp, width, height, o, err);
    for (size_t k = 0; st == CDEM_OK && k < count; k++) {
        st = fn(user, order[k], rgba, width, height, err);
        if (st != CDEM_OK)
            cdem_error_prefix(err, "gif '%s': frame %zu", path, order[k]);
        else
            st = cdem_gif_add_frame(g, rgba, err);
    }
    if (st == CDEM_OK)
        st = cdem_gif_close(g, err);
    else
        cdem_gif_free(g);
    if (of.active)
        st = cdem_outfile_end(&of, st, err);
    free(order);
    free(rgba);
    return st;
}
