/* h5_sidecar: the run file's increments as XDMF grids, for the .xmf sidecar ParaView and
 * VisIt open (docs/format.md, "XDMF sidecar"). The XML itself is written by common/xdmf.c;
 * this file knows which datasets and rows make one increment. The writer rewrites the
 * sidecar after each increment (h5i_write_xmf); cdem_h5_write_xdmf rebuilds it from a file's
 * index (cdem-strain xdmf), so a renamed or copied pair can be repaired.
 * A sidecar failure never damages the run file: the message says what the run file keeps. */
#include "h5_internal.h"
#include "xdmf.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *xdmf_number_type(cdem_field_type t) {
    return t == CDEM_FIELD_I32 ? "Int" : t == CDEM_FIELD_U32 ? "UInt" : "Float";
}

/* The attributes of a grid, in sidecar order (names of h5i_element_fields). */
static const char *const xmf_attributes[] = {"radius", "layer", "id",  "flags",
                                             "born",   "sxx",   "syy", "sxy"};

static const element_field *element_field_named(const char *name) {
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        if (!strcmp(h5i_element_fields[k].name, name))
            return &h5i_element_fields[k];
    return NULL;
}

/* One increment of a version-2 file as an XDMF grid (xdmf.h): rows offset .. of the ragged
 * datasets, whose extents were data_ext and stress_ext when the sidecar was written. */
static void xmf_grid(cdem_xdmf_grid *g, const xmf_entry *e, hsize_t data_ext, hsize_t stress_ext) {
    g->number = e->number;
    g->time = e->time;
    g->n = e->n;
    const cdem_xdmf_data pos = {NULL, e->offset, (long long)data_ext, "Float", 8};
    g->x = g->y = g->xy = pos;
    g->x.dataset = "/increments/x";
    g->y.dataset = "/increments/y";
    g->xy.dataset = "/increments/xy";
    for (size_t a = 0; a < sizeof xmf_attributes / sizeof xmf_attributes[0]; a++) {
        const element_field *fd = element_field_named(xmf_attributes[a]);
        if (!fd || (fd->optional && !e->has_stress))
            continue;
        g->attribute_names[g->n_attributes] = fd->name;
        g->attributes[g->n_attributes++] =
            (cdem_xdmf_data){fd->path, fd->optional ? e->stress_offset : e->offset,
                             (long long)(fd->optional ? stress_ext : data_ext),
                             xdmf_number_type(fd->type), (int)cdem_field_type_size(fd->type)};
    }
}

/* XDMF 3 needs /increments/xy, and a file name the HDF5 reference syntax can hold. */
static cdem_xdmf_flavour xmf_flavour(int has_xy, const char *h5_ref, int wanted) {
    return wanted == CDEM_XDMF3 && has_xy && !strpbrk(h5_ref, ":|") ? CDEM_XDMF3 : CDEM_XDMF2;
}

static int writer_xmf_grid(void *ctx, size_t k, cdem_xdmf_grid *g) {
    const cdem_h5_writer *w = ctx;
    xmf_grid(g, &w->entries[k], w->data_ext, w->stress_ext);
    return 0;
}

/* Rewrites the sidecar from the list of increments (temp file, then rename). */
cdem_status h5i_write_xmf(cdem_h5_writer *w, cdem_error *err) {
    const cdem_xdmf_doc doc = {w->h5_name, xmf_flavour(w->has_xy, w->h5_name, CDEM_XDMF3),
                               w->n_entries, writer_xmf_grid, w};
    if (cdem_xdmf_write_file(w->xmf_path, &doc, err) != CDEM_OK) {
        /* A sidecar failure leaves the run file as it is: the message says so, names both
         * files and what the run file keeps (the sidecar only serves ParaView and VisIt). */
        char why[CDEM_ERROR_MSG_MAX];
        snprintf(why, sizeof why, "%s", err ? err->msg : "write error");
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: the run file keeps its %llu complete increments, but its XDMF "
                         "sidecar %s (for ParaView) could not be written: %.600s",
                         w->path, (unsigned long long)w->index_len, w->xmf_path, why);
    }
    w->xmf_written = w->n_entries;
    return CDEM_OK;
}

/* The sidecar of a closed or running file, rebuilt from its index (cdem-strain xdmf). */
typedef struct {
    const cdem_h5_reader *r;
    hsize_t data_ext, stress_ext;
} reader_xmf_ctx;

static int reader_xmf_grid(void *ctx, size_t k, cdem_xdmf_grid *g) {
    const reader_xmf_ctx *c = ctx;
    const incr_entry *e = &c->r->incr[k];
    const xmf_entry x = {e->info.number,     e->info.time, e->info.n_elements,
                         e->info.has_stress, e->offset,    e->stress_offset};
    xmf_grid(g, &x, c->data_ext, c->stress_ext);
    return 0;
}

cdem_status cdem_h5_write_xdmf(const char *h5_path, const char *xmf_path, int flavour, int *written,
                               cdem_error *err) {
    if (written)
        *written = 0;
    if (!h5_path || (flavour != CDEM_XDMF3 && flavour != CDEM_XDMF2))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_write_xdmf: a file and flavour 2 or 3");
    cdem_h5_reader *r = NULL;
    CDEM_TRY(cdem_h5_reader_open(h5_path, &r, err));
    char *own = xmf_path ? NULL : cdem_xdmf_path_for(h5_path);
    const char *out = xmf_path ? xmf_path : own;
    char ref[4096];
    cdem_status st = out ? CDEM_OK : CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    if (st == CDEM_OK && r->version != CDEM_FORMAT_VERSION)
        st = CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                       "%s: cdem format version %d has one group per increment; sidecars are "
                       "written for version %d files only",
                       h5_path, r->version, CDEM_FORMAT_VERSION);
    if (st == CDEM_OK)
        st = cdem_xdmf_reference(h5_path, out, ref, sizeof ref, err);
    if (st == CDEM_OK) {
        reader_xmf_ctx c = {r, h5i_extent_of(r->data[1]), h5i_extent_of(r->data[7])};
        for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
            hsize_t e = h5i_extent_of(r->data[k]);
            hsize_t *m = h5i_element_fields[k].optional ? &c.stress_ext : &c.data_ext;
            *m = e < *m ? e : *m;
        }
        const int has_xy = H5Lexists(r->file, "/increments/xy", H5P_DEFAULT) > 0;
        const cdem_xdmf_doc doc = {ref, xmf_flavour(has_xy, ref, flavour), r->n_incr,
                                   reader_xmf_grid, &c};
        st = cdem_xdmf_write_file(out, &doc, err);
        if (st == CDEM_OK && written)
            *written = (int)doc.flavour;
    }
    free(own);
    cdem_h5_reader_close(r);
    return st;
}
