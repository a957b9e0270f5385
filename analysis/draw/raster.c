/* raster: see raster.h. */
#include "raster.h"

#include <math.h>
#include <stdint.h>

int cdem_raster_target_get(cairo_t *cr, double x, double y, double w, double h,
                           cdem_raster_target *rt) {
    cairo_surface_t *t = cairo_get_target(cr);
    if (cairo_surface_get_type(t) != CAIRO_SURFACE_TYPE_IMAGE)
        return 0;
    cairo_format_t f = cairo_image_surface_get_format(t);
    if (f != CAIRO_FORMAT_ARGB32 && f != CAIRO_FORMAT_RGB24)
        return 0;
    cairo_matrix_t m;
    cairo_get_matrix(cr, &m);
    double dx = 0, dy = 0;
    cairo_surface_get_device_offset(t, &dx, &dy);
    if (m.xx != 1 || m.yy != 1 || m.xy != 0 || m.yx != 0 || m.x0 != 0 || m.y0 != 0 || dx != 0 ||
        dy != 0)
        return 0;
    cairo_surface_flush(t);
    rt->surface = t;
    rt->data = cairo_image_surface_get_data(t);
    rt->stride = cairo_image_surface_get_stride(t);
    rt->opaque = f == CAIRO_FORMAT_RGB24;
    const int sw = cairo_image_surface_get_width(t), sh = cairo_image_surface_get_height(t);
    rt->x0 = (int)fmax(0.0, ceil(x - 0.5));
    rt->y0 = (int)fmax(0.0, ceil(y - 0.5));
    rt->x1 = (int)fmin((double)sw, floor(x + w + 0.5));
    rt->y1 = (int)fmin((double)sh, floor(y + h + 0.5));
    return rt->data != NULL;
}

/* floor/ceil result v as an int clamped to lo..hi (NaN gives lo): no overflowing casts for
 * huge coordinates. */
static int clamp_px(double v, int lo, int hi) {
    if (!(v > lo))
        return lo;
    if (v > hi)
        return hi;
    return (int)v;
}

/* OVER-blends colour c at coverage cov (0..1] into the premultiplied pixel *p. */
static void blend_pixel(const cdem_raster_target *rt, uint32_t *p, const cdem_rgba *c, double cov) {
    uint32_t v = *p;
    double sa = c->a * cov, keep = 1.0 - sa;
    double da = rt->opaque ? 255.0 : (double)(v >> 24);
    double nr = c->r * sa * 255.0 + ((v >> 16) & 255) * keep;
    double ng = c->g * sa * 255.0 + ((v >> 8) & 255) * keep;
    double nb = c->b * sa * 255.0 + (v & 255) * keep;
    double na = rt->opaque ? 255.0 : 255.0 * sa + da * keep;
    *p = ((uint32_t)(na + 0.5) << 24) | ((uint32_t)(nr + 0.5) << 16) | ((uint32_t)(ng + 0.5) << 8) |
         (uint32_t)(nb + 0.5);
}

void cdem_raster_segment(const cdem_raster_target *rt, double x0, double y0, double x1, double y1,
                         double width, const cdem_rgba *c) {
    double reach = 0.5 * width + 1.0;
    int px0 = clamp_px(floor(fmin(x0, x1) - reach), rt->x0, rt->x1);
    int px1 = clamp_px(ceil(fmax(x0, x1) + reach), rt->x0, rt->x1);
    int py0 = clamp_px(floor(fmin(y0, y1) - reach), rt->y0, rt->y1);
    int py1 = clamp_px(ceil(fmax(y0, y1) + reach), rt->y0, rt->y1);
    double vx = x1 - x0, vy = y1 - y0, vv = vx * vx + vy * vy;
    double half = 0.5 * width;
    for (int py = py0; py < py1; py++) {
        uint32_t *row = (uint32_t *)(void *)(rt->data + (size_t)py * rt->stride);
        double yc = py + 0.5;
        /* parameter range of the segment within reach of this row, then its x extent */
        double ta = 0.0, tb = 1.0;
        if (vy != 0.0) {
            ta = (yc - reach - y0) / vy;
            tb = (yc + reach - y0) / vy;
            if (ta > tb) {
                double t = ta;
                ta = tb;
                tb = t;
            }
            ta = fmax(ta, 0.0);
            tb = fmin(tb, 1.0);
            if (ta > tb)
                continue;
        } else if (fabs(yc - y0) > reach) {
            continue;
        }
        double xa = fmin(x0 + ta * vx, x0 + tb * vx) - reach;
        double xb = fmax(x0 + ta * vx, x0 + tb * vx) + reach;
        int qa = clamp_px(floor(xa), px0, px1), qb = clamp_px(ceil(xb), px0, px1);
        for (int px = qa; px < qb; px++) {
            double wx = px + 0.5 - x0, wy = yc - y0;
            double t = vv > 0 ? (wx * vx + wy * vy) / vv : 0.0;
            t = t < 0 ? 0 : (t > 1 ? 1 : t);
            double ex = wx - t * vx, ey = wy - t * vy;
            double d = sqrt(ex * ex + ey * ey);
            double cov = fmin(width, half + 0.5 - d);
            if (cov <= 0.0)
                continue;
            blend_pixel(rt, row + px, c, cov > 1.0 ? 1.0 : cov);
        }
    }
}

void cdem_raster_disc(const cdem_raster_target *rt, double cx, double cy, double r,
                      const cdem_rgba *c, double ring_width) {
    double reach = r + 0.5 * ring_width + 1.0;
    int px0 = clamp_px(floor(cx - reach), rt->x0, rt->x1);
    int px1 = clamp_px(ceil(cx + reach), rt->x0, rt->x1);
    int py0 = clamp_px(floor(cy - reach), rt->y0, rt->y1);
    int py1 = clamp_px(ceil(cy + reach), rt->y0, rt->y1);
    double small = ring_width > 0 ? fmin(1.0, ring_width) : fmin(1.0, 2.0 * r);
    double half = 0.5 * ring_width;
    double outer = r + half + 0.5;                       /* coverage is zero beyond */
    double inner = ring_width > 0 ? r - half - 0.5 : -1; /* ring: zero inside this */
    for (int py = py0; py < py1; py++) {
        uint32_t *row = (uint32_t *)(void *)(rt->data + (size_t)py * rt->stride);
        double ddy = py + 0.5 - cy;
        if (fabs(ddy) >= outer)
            continue;
        double span = sqrt(outer * outer - ddy * ddy);
        int xa = clamp_px(floor(cx - span - 0.5), px0, px1);
        int xb = clamp_px(ceil(cx + span + 0.5), px0, px1);
        int hole_a = xb, hole_b = xb; /* pixels [hole_a, hole_b) lie inside the ring's hole */
        if (inner > 0 && fabs(ddy) < inner) {
            double ispan = sqrt(inner * inner - ddy * ddy);
            hole_a = clamp_px(ceil(cx - ispan + 0.5), xa, xb);
            hole_b = clamp_px(floor(cx + ispan - 0.5), xa, xb);
            if (hole_b <= hole_a)
                hole_a = hole_b = xb; /* empty hole: nothing to skip */
        }
        for (int px = xa; px < xb; px++) {
            if (px == hole_a) {
                px = hole_b - 1;
                continue;
            }
            double ddx = px + 0.5 - cx;
            double d = sqrt(ddx * ddx + ddy * ddy);
            double cov;
            if (ring_width > 0)
                cov = fmin(ring_width, half + 0.5 - fabs(d - r));
            else
                cov = (r + 0.5 - d) * small;
            if (cov <= 0.0)
                continue;
            if (cov > 1.0)
                cov = 1.0;
            blend_pixel(rt, row + px, c, cov);
        }
    }
}
