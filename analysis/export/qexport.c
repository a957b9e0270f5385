/* qexport: see qexport.h. Plain contiguous datasets: these files are small, written once
 * and read by h5py or numpy. */
#include "qexport.h"

#include "xdmf.h"

#include <hdf5.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

cdem_status cdem_qexport_csv_header(FILE *f, int with_increment, cdem_error *err) {
    if (fprintf(f, "%sid,x,y,value\n", with_increment ? "increment," : "") < 0)
        return CDEM_FAIL(err, CDEM_ERR_IO, "error writing the CSV header");
    return CDEM_OK;
}

cdem_status cdem_qexport_csv_rows(FILE *f, int with_increment, int32_t number, const cdem_state *s,
                                  const double *values, cdem_error *err) {
    for (size_t i = 0; i < s->n; i++) {
        if (with_increment)
            fprintf(f, "%d,", (int)number);
        if (isfinite(values[i]))
            fprintf(f, "%d,%.6f,%.6f,%.10g\n", (int)s->id[i], s->x[i], s->y[i], values[i]);
        else
            fprintf(f, "%d,%.6f,%.6f,nan\n", (int)s->id[i], s->x[i], s->y[i]);
    }
    if (ferror(f))
        return CDEM_FAIL(err, CDEM_ERR_IO, "error writing CSV rows of increment %d", (int)number);
    return CDEM_OK;
}

struct cdem_qexport_h5 {
    hid_t file;      /* the open file */
    hid_t groups;    /* /increments */
    char path[1024]; /* for messages */
};

static int put_string_attr(hid_t obj, const char *name, const char *value) {
    hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, strlen(value) + 1);
    hid_t sp = H5Screate(H5S_SCALAR);
    hid_t a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
    int ok = a >= 0 && H5Awrite(a, t, value) >= 0;
    if (a >= 0)
        H5Aclose(a);
    H5Sclose(sp);
    H5Tclose(t);
    return ok;
}

cdem_status cdem_qexport_h5_create(const char *path, const cdem_quantity *q, cdem_qexport_h5 **out,
                                   cdem_error *err) {
    *out = NULL;
    cdem_qexport_h5 *h = calloc(1, sizeof *h);
    if (!h)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    snprintf(h->path, sizeof h->path, "%s", path);
    H5E_BEGIN_TRY {
        h->file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    }
    H5E_END_TRY;
    if (h->file < 0) {
        free(h);
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot create %s", path);
    }
    h->groups = H5Gcreate2(h->file, "increments", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (h->groups < 0 || !put_string_attr(h->file, "quantity", q->name) ||
        !put_string_attr(h->file, "label", q->label) ||
        !put_string_attr(h->file, "unit", q->unit)) {
        cdem_qexport_h5_close(h, NULL);
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write the header of %s", path);
    }
    *out = h;
    return CDEM_OK;
}

static int put_dataset(hid_t g, const char *name, hid_t type, size_t n, const void *data) {
    hsize_t dims = n;
    hid_t sp = H5Screate_simple(1, &dims, NULL);
    hid_t d = H5Dcreate2(g, name, type, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int ok = d >= 0 && (n == 0 || H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0);
    if (d >= 0)
        H5Dclose(d);
    H5Sclose(sp);
    return ok;
}

cdem_status cdem_qexport_h5_write(cdem_qexport_h5 *h, int32_t number, double time,
                                  const cdem_state *s, const double *values, cdem_error *err) {
    char name[32];
    snprintf(name, sizeof name, "%06d", (int)number);
    hid_t g = H5Gcreate2(h->groups, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0)
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot create group increments/%s", h->path, name);
    hid_t sp = H5Screate(H5S_SCALAR);
    hid_t a = H5Acreate2(g, "number", H5T_NATIVE_INT32, sp, H5P_DEFAULT, H5P_DEFAULT);
    int ok = a >= 0 && H5Awrite(a, H5T_NATIVE_INT32, &number) >= 0;
    if (a >= 0)
        H5Aclose(a);
    a = H5Acreate2(g, "time", H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, H5P_DEFAULT);
    ok = ok && a >= 0 && H5Awrite(a, H5T_NATIVE_DOUBLE, &time) >= 0;
    if (a >= 0)
        H5Aclose(a);
    H5Sclose(sp);
    ok = ok && put_dataset(g, "id", H5T_NATIVE_INT32, s->n, s->id) &&
         put_dataset(g, "x", H5T_NATIVE_DOUBLE, s->n, s->x) &&
         put_dataset(g, "y", H5T_NATIVE_DOUBLE, s->n, s->y) &&
         put_dataset(g, "value", H5T_NATIVE_DOUBLE, s->n, values);
    if (ok) { /* (x, y) as one n x 2 view for the XDMF 3 sidecar; no storage (xdmf.h) */
        char xp[64], yp[64];
        snprintf(xp, sizeof xp, "/increments/%s/x", name);
        snprintf(yp, sizeof yp, "/increments/%s/y", name);
        hid_t xy = cdem_xdmf_create_xy_view(g, xp, yp, "xy", 0);
        ok = xy >= 0;
        if (xy >= 0)
            H5Dclose(xy);
    }
    H5Gclose(g);
    if (!ok)
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot write increment %d", h->path, (int)number);
    return CDEM_OK;
}

cdem_status cdem_qexport_h5_close(cdem_qexport_h5 *h, cdem_error *err) {
    if (!h)
        return CDEM_OK;
    int ok = 1;
    if (h->groups >= 0 && h->groups != 0)
        H5Gclose(h->groups);
    if (h->file >= 0 && h->file != 0)
        ok = H5Fclose(h->file) >= 0;
    char path[1024];
    memcpy(path, h->path, sizeof path);
    free(h);
    if (!ok)
        return CDEM_FAIL(err, CDEM_ERR_IO, "error closing %s", path);
    return CDEM_OK;
}

/* ---------------------------------------------------------------- XDMF sidecar */
typedef struct {
    int32_t number;
    double time;
    long long n;
    int has_xy;
    char name[32]; /* group name under /increments */
} qx_grid;

typedef struct {
    qx_grid *grids;
    size_t n, cap;
    hid_t groups;
    char dataset_paths[5][96]; /* the current grid's x, y, xy, value, id paths */
    const char *quantity;
} qx_ctx;

static herr_t qx_collect(hid_t loc, const char *name, const H5L_info_t *info, void *data) {
    (void)info;
    qx_ctx *c = data;
    if (c->n == c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 64;
        qx_grid *g = realloc(c->grids, cap * sizeof *g);
        if (!g)
            return -1;
        c->grids = g;
        c->cap = cap;
    }
    qx_grid *g = &c->grids[c->n];
    memset(g, 0, sizeof *g);
    snprintf(g->name, sizeof g->name, "%s", name);
    hid_t grp = H5Gopen2(loc, name, H5P_DEFAULT);
    if (grp < 0)
        return -1;
    hid_t a = H5Aopen(grp, "number", H5P_DEFAULT);
    int ok = a >= 0 && H5Aread(a, H5T_NATIVE_INT32, &g->number) >= 0;
    if (a >= 0)
        H5Aclose(a);
    g->time = g->number; /* files of before the time attribute: the increment number */
    if (H5Aexists(grp, "time") > 0) {
        a = H5Aopen(grp, "time", H5P_DEFAULT);
        ok = ok && a >= 0 && H5Aread(a, H5T_NATIVE_DOUBLE, &g->time) >= 0;
        if (a >= 0)
            H5Aclose(a);
    }
    hid_t d = H5Dopen2(grp, "value", H5P_DEFAULT);
    hsize_t n = 0;
    if (d >= 0) {
        hid_t sp = H5Dget_space(d);
        ok = ok && H5Sget_simple_extent_dims(sp, &n, NULL) == 1;
        H5Sclose(sp);
        H5Dclose(d);
    } else {
        ok = 0;
    }
    g->n = (long long)n;
    g->has_xy = H5Lexists(grp, "xy", H5P_DEFAULT) > 0;
    H5Gclose(grp);
    if (!ok)
        return -1;
    c->n++;
    return 0;
}

static int qx_grid_cb(void *ctx, size_t k, cdem_xdmf_grid *g) {
    qx_ctx *c = ctx;
    const qx_grid *q = &c->grids[k];
    g->number = q->number;
    g->time = q->time;
    g->n = q->n;
    /* the paths live in c until the next grid: the XML of this one is written before */
    static const char *const names[5] = {"x", "y", "xy", "value", "id"};
    for (int i = 0; i < 5; i++)
        snprintf(c->dataset_paths[i], sizeof c->dataset_paths[i], "/increments/%s/%s", q->name,
                 names[i]);
    g->x = (cdem_xdmf_data){c->dataset_paths[0], 0, q->n, "Float", 8};
    g->y = (cdem_xdmf_data){c->dataset_paths[1], 0, q->n, "Float", 8};
    g->xy = (cdem_xdmf_data){c->dataset_paths[2], 0, q->n, "Float", 8};
    g->n_attributes = 2;
    g->attribute_names[0] = c->quantity;
    g->attributes[0] = (cdem_xdmf_data){c->dataset_paths[3], 0, q->n, "Float", 8};
    g->attribute_names[1] = "id";
    g->attributes[1] = (cdem_xdmf_data){c->dataset_paths[4], 0, q->n, "Int", 4};
    return 0;
}

static int cmp_qx(const void *a, const void *b) {
    const qx_grid *x = a, *y = b;
    return (x->number > y->number) - (x->number < y->number);
}

cdem_status cdem_qexport_write_xdmf(const char *h5_path, const char *xmf_path, int flavour,
                                    int *written, cdem_error *err) {
    if (written)
        *written = 0;
    hid_t file = -1;
    H5E_BEGIN_TRY {
        file = H5Fopen(h5_path, H5F_ACC_RDONLY, H5P_DEFAULT);
    }
    H5E_END_TRY;
    if (file < 0)
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot open as HDF5", h5_path);
    qx_ctx c;
    memset(&c, 0, sizeof c);
    char quantity[256] = "value";
    cdem_status st = CDEM_OK;
    H5E_BEGIN_TRY {
        hid_t a = H5Aopen(file, "quantity", H5P_DEFAULT);
        if (a >= 0) {
            hid_t t = H5Aget_type(a);
            size_t len = H5Tget_size(t);
            char buf[256] = "";
            if (len < sizeof buf && H5Aread(a, t, buf) >= 0 && buf[0])
                snprintf(quantity, sizeof quantity, "%s", buf);
            H5Tclose(t);
            H5Aclose(a);
        } else {
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: not a compute --format h5 file (no root attribute 'quantity')",
                           h5_path);
        }
        c.groups = st == CDEM_OK ? H5Gopen2(file, "increments", H5P_DEFAULT) : -1;
        if (st == CDEM_OK && (c.groups < 0 || H5Literate(c.groups, H5_INDEX_NAME, H5_ITER_INC, NULL,
                                                         qx_collect, &c) < 0))
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: cannot list /increments (corrupt?)", h5_path);
    }
    H5E_END_TRY;
    int has_xy = 1;
    for (size_t k = 0; k < c.n; k++)
        has_xy &= c.grids[k].has_xy;
    if (c.n > 1)
        qsort(c.grids, c.n, sizeof *c.grids, cmp_qx);
    c.quantity = quantity;
    char *own = xmf_path ? NULL : cdem_xdmf_path_for(h5_path);
    const char *out = xmf_path ? xmf_path : own;
    char ref[4096];
    if (st == CDEM_OK && !out)
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    if (st == CDEM_OK)
        st = cdem_xdmf_reference(h5_path, out, ref, sizeof ref, err);
    if (st == CDEM_OK) {
        /* XDMF 3 needs the xy views (files of before them get XDMF 2) and a name the HDF5
         * reference syntax can hold */
        const cdem_xdmf_flavour fl =
            flavour == CDEM_XDMF3 && has_xy && !strpbrk(ref, ":|") ? CDEM_XDMF3 : CDEM_XDMF2;
        const cdem_xdmf_doc doc = {ref, fl, c.n, qx_grid_cb, &c};
        st = cdem_xdmf_write_file(out, &doc, err);
        if (st == CDEM_OK && written)
            *written = (int)fl;
    }
    free(own);
    free(c.grids);
    if (c.groups >= 0)
        H5Gclose(c.groups);
    H5Fclose(file);
    return st;
}
