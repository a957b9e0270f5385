/* raster: the direct rasteriser of render.c for image targets.
 *
 * cairo fills and strokes tens of thousands of small circles slowly (each arc becomes Bezier
 * curves, then polygons, then coverage), so on a plain ARGB32/RGB24 image surface with an
 * identity transform the discs and lines are written straight into the pixels: coverage from
 * the distance of the pixel centre to the circle or segment (one-pixel anti-aliasing ramp),
 * blended OVER in premultiplied form, clipped to the plot area. Vector targets (PDF, SVG,
 * recording surfaces) take the cairo path instead (render.c). It knows nothing of the
 * render layout: render.c turns model positions into device pixels.
 * Ownership: a target borrows its surface. Thread safety: one target per thread.
 * Units: device pixels. */
#ifndef CDEM_RASTER_H
#define CDEM_RASTER_H

#include "colormap.h"

#include <cairo.h>

typedef struct {
    cairo_surface_t *surface; /* the target image surface (borrowed) */
    unsigned char *data;      /* its pixels */
    int stride;               /* bytes per row */
    int opaque;               /* 1: RGB24, alpha byte ignored */
    int x0, y0, x1, y1;       /* clip rectangle in pixels, half-open */
} cdem_raster_target;

/* Fills rt for drawing into cr's target, clipped to the rectangle at (x, y) of size w x h
 * (device units; the plot area): 1 when the target is an image surface the rasteriser can
 * write (then flushed), 0 when it must take cairo. */
int cdem_raster_target_get(cairo_t *cr, double x, double y, double w, double h,
                           cdem_raster_target *rt);

/* Anti-aliased segment of the given width (device units), round ends. */
void cdem_raster_segment(const cdem_raster_target *rt, double x0, double y0, double x1, double y1,
                         double width, const cdem_rgba *c);

/* Disc (ring_width == 0) or ring of that width centred on the circle of centre (cx, cy) and
 * radius r. */
void cdem_raster_disc(const cdem_raster_target *rt, double cx, double cy, double r,
                      const cdem_rgba *c, double ring_width);

#endif
