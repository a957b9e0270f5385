/* qexport: see qexport.h. Plain contiguous datasets: these files are small, written once
 * and read by h5py or numpy. */
#include "qexport.h"

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

cdem_status cdem_qexport_h5_write(cdem_qexport_h5 *h, int32_t number, const cdem_state *s,
                                  const double *values, cdem_error *err) {
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
    H5Sclose(sp);
    ok = ok && put_dataset(g, "id", H5T_NATIVE_INT32, s->n, s->id) &&
         put_dataset(g, "x", H5T_NATIVE_DOUBLE, s->n, s->x) &&
         put_dataset(g, "y", H5T_NATIVE_DOUBLE, s->n, s->y) &&
         put_dataset(g, "value", H5T_NATIVE_DOUBLE, s->n, values);
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
