/* h5format: see h5format.h; docs/format.md is the authority on the layout.
 *
 * Design notes a maintainer may question (docs/format.md has the measurements):
 *  - Files are V110 (superblock v3, object header v2): every piece of metadata carries a
 *    checksum, so flipped bytes fail a checksum instead of being parsed. Raw chunks carry
 *    Fletcher-32. Strings are fixed-length: variable-length ones live in the global heap,
 *    which has no checksum, and HDF5 1.10 crashes on a corrupt one.
 *  - A v3 superblock is marked "open for write" while the writer runs; a writer killed
 *    before close leaves the mark and a plain H5Fopen refuses the file. The reader reads
 *    the superblock itself first (also comparing its end-of-file address with the real
 *    size, which catches truncation before HDF5 parses anything) and opens a marked file
 *    with the "clear_status_flags" property h5clear uses (read-only: nothing is written).
 *  - Crash consistency between flushes: no metadata cache evictions (metadata is written
 *    only by the flush after each increment), compact links in /increments and unfiltered
 *    series chunks (nothing the last flushed metadata points to is freed and reused).
 *  - Object time stamps are off: same input, same bytes except the attribute "created".
 *  - HDF5's error printing is off; its error stack becomes part of cdem_error messages.
 *  - append_series is called from the time-step loop: it never allocates (fixed buffer). */
#include "h5format.h"

#include <hdf5.h>

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

/* Compression settings, chosen by measurement (docs/format.md, "Size"): deflate level 4
 * after byte shuffle; levels 6 and 9 saved 0.2 % more for 20-30 % more CPU. Per-increment
 * datasets are one chunk up to CHUNK_ELEMS elements (8192 doubles = 64 KiB). */
#define DEFLATE_LEVEL   4
#define CHUNK_ELEMS     8192
#define SERIES_CHUNK    512
#define SERIES_BUFFER   256
#define XMF_EVERY_LIMIT 1000
/* Largest element count a reader accepts (ids are int32). */
#define MAX_ELEMENTS ((hsize_t)INT32_MAX)
/* Largest element count an increment may have to be loaded (~2 GB of state; cdem-run's
 * largest model has ~10^5 elements): a corrupt count is refused before allocating. */
#define READER_MAX_ELEMENTS ((hsize_t)20000000)

/* ------------------------------------------------------------------ errors */

typedef struct {
    char text[400]; /* collected HDF5 error descriptions */
    int count;      /* descriptions collected so far */
} h5_err_text;

static herr_t collect_h5_error(unsigned n, const H5E_error2_t *e, void *data) {
    (void)n;
    h5_err_text *t = data;
    if (t->count >= 3 || !e->desc || !e->desc[0])
        return 0;
    size_t len = strlen(t->text);
    snprintf(t->text + len, sizeof t->text - len, "%s%s", t->count ? "; " : "", e->desc);
    for (char *c = t->text + len; *c; c++)
        if (*c == '\n' || *c == '\r')
            *c = ' '; /* one-line messages */
    t->count++;
    return 0;
}

/* Records code with a message "<what> (HDF5: <innermost descriptions>)" and clears the
 * HDF5 error stack. Use through H5FAIL. */
static cdem_status h5_fail_at(cdem_error *err, cdem_status code, const char *file, int line,
                              const char *fmt, ...) __attribute__((format(printf, 5, 6)));
static cdem_status h5_fail_at(cdem_error *err, cdem_status code, const char *file, int line,
                              const char *fmt, ...) {
    char what[CDEM_ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    h5_err_text t = {.text = "", .count = 0};
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, collect_h5_error, &t);
    H5Eclear2(H5E_DEFAULT);
    if (t.count)
        return cdem_error_set(err, code, file, line, "%s (HDF5: %s)", what, t.text);
    return cdem_error_set(err, code, file, line, "%s", what);
}
#define H5FAIL(err, code, ...) h5_fail_at((err), (code), __FILE__, __LINE__, __VA_ARGS__)

/* Cleanup calls after a failure would clear HDF5's error stack (every API call resets it):
 * set it aside first (keep_errors) and put it back after (restore_errors), so H5FAIL can
 * still report it. */
static hid_t keep_errors(int failed) {
    return failed ? H5Eget_current_stack() : -1;
}
static void restore_errors(hid_t saved) {
    if (saved >= 0)
        H5Eset_current_stack(saved);
}

static void quiet_hdf5(void) {
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static char *dup_str(const char *s) {
    size_t n = strlen(s ? s : "") + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s ? s : "", n);
    return d;
}

/* ------------------------------------------------------------------ tables */

typedef enum { COL_I64, COL_F64 } col_type;

typedef struct {
    const char *name; /* dataset name under /series */
    col_type type;    /* int64 or float64 */
    size_t offset;    /* offsetof(cdem_series_sample, field) */
} series_column;

#define SCOL(field, type)                                                                          \
    { #field, type, offsetof(cdem_series_sample, field) }
static const series_column series_columns[] = {
    SCOL(step, COL_I64),
    SCOL(time, COL_F64),
    SCOL(kinetic_energy, COL_F64),
    SCOL(contacts, COL_I64),
    SCOL(bonds, COL_I64),
    SCOL(n_elements, COL_I64),
    SCOL(net_displacement, COL_F64),
    SCOL(boundary_force_x, COL_F64),
    SCOL(boundary_force_y, COL_F64),
    SCOL(base_force_x, COL_F64),
    SCOL(base_force_y, COL_F64),
    SCOL(axial_strain, COL_F64),
    SCOL(differential_stress, COL_F64),
    SCOL(sea_level, COL_F64),
};
#undef SCOL
#define N_SERIES (sizeof series_columns / sizeof series_columns[0])

/* Per-element datasets of an increment. */
typedef enum { EL_I32, EL_U32, EL_F64 } el_type;
typedef struct {
    const char *name; /* dataset name in the increment group */
    el_type type;     /* stored and memory type */
    int optional;     /* 1: stress, present only with has_stress */
    const char *xdmf; /* XDMF NumberType */
} element_field;

static const element_field element_fields[] = {
    {"id", EL_I32, 0, "Int"},       {"x", EL_F64, 0, "Float"},   {"y", EL_F64, 0, "Float"},
    {"radius", EL_F64, 0, "Float"}, {"layer", EL_I32, 0, "Int"}, {"flags", EL_U32, 0, "UInt"},
    {"born", EL_I32, 0, "Int"},     {"sxx", EL_F64, 1, "Float"}, {"syy", EL_F64, 1, "Float"},
    {"sxy", EL_F64, 1, "Float"},
};
#define N_ELEMENT_FIELDS (sizeof element_fields / sizeof element_fields[0])

static void *element_array(const cdem_state *s, size_t k) {
    switch (k) {
    case 0:
        return s->id;
    case 1:
        return s->x;
    case 2:
        return s->y;
    case 3:
        return s->radius;
    case 4:
        return s->layer;
    case 5:
        return s->flags;
    case 6:
        return s->born;
    case 7:
        return s->sxx;
    case 8:
        return s->syy;
    default:
        return s->sxy;
    }
}

static hid_t el_file_type(el_type t) {
    return t == EL_I32 ? H5T_STD_I32LE : t == EL_U32 ? H5T_STD_U32LE : H5T_IEEE_F64LE;
}
static hid_t el_mem_type(el_type t) {
    return t == EL_I32 ? H5T_NATIVE_INT32 : t == EL_U32 ? H5T_NATIVE_UINT32 : H5T_NATIVE_DOUBLE;
}

/* ------------------------------------------------------------------ attribute helpers */

static hid_t vlen_string_type(void) {
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t < 0)
        return t;
    H5Tset_size(t, H5T_VARIABLE);
    H5Tset_cset(t, H5T_CSET_UTF8);
    return t;
}

/* Writes (creating or replacing) a scalar attribute. */
static int put_attr(hid_t obj, const char *name, hid_t ftype, hid_t mtype, const void *value) {
    if (H5Aexists(obj, name) > 0 && H5Adelete(obj, name) < 0)
        return -1;
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t a = H5Acreate2(obj, name, ftype, space, H5P_DEFAULT, H5P_DEFAULT);
    int ok = a >= 0 && H5Awrite(a, mtype, value) >= 0;
    hid_t es = keep_errors(!ok);
    if (a >= 0)
        H5Aclose(a);
    H5Sclose(space);
    restore_errors(es);
    return ok ? 0 : -1;
}

/* Strings are fixed-length (size strlen + 1, null-terminated, UTF-8): they live in the
 * checksummed object header. Variable-length strings would live in the global heap, which
 * has no checksum, and HDF5 1.10 crashes on a corrupt global heap. */
static hid_t fixed_string_type(size_t len) {
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t < 0)
        return t;
    H5Tset_size(t, len + 1);
    H5Tset_strpad(t, H5T_STR_NULLTERM);
    H5Tset_cset(t, H5T_CSET_UTF8);
    return t;
}

static int put_str_attr(hid_t obj, const char *name, const char *value) {
    const char *v = value ? value : "";
    hid_t t = fixed_string_type(strlen(v));
    int rc = t < 0 ? -1 : put_attr(obj, name, t, t, v);
    if (t >= 0)
        H5Tclose(t);
    return rc;
}

static int put_i32_attr(hid_t o, const char *n, int32_t v) {
    return put_attr(o, n, H5T_STD_I32LE, H5T_NATIVE_INT32, &v);
}
static int put_i64_attr(hid_t o, const char *n, int64_t v) {
    return put_attr(o, n, H5T_STD_I64LE, H5T_NATIVE_INT64, &v);
}
static int put_f64_attr(hid_t o, const char *n, double v) {
    return put_attr(o, n, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &v);
}

/* Reads a scalar numeric attribute converted to mtype. Returns 0, 1 when missing, -1 on a
 * bad type or read failure. */
static int get_num_attr(hid_t obj, const char *name, hid_t mtype, void *value) {
    htri_t ex = H5Aexists(obj, name);
    if (ex == 0)
        return 1;
    if (ex < 0)
        return -1;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a < 0)
        return -1;
    hid_t t = H5Aget_type(a), sp = H5Aget_space(a);
    H5T_class_t cls = t >= 0 ? H5Tget_class(t) : H5T_NO_CLASS;
    int ok = (cls == H5T_INTEGER || cls == H5T_FLOAT) && sp >= 0 &&
             H5Sget_simple_extent_npoints(sp) == 1 && H5Aread(a, mtype, value) >= 0;
    hid_t es = keep_errors(!ok);
    if (t >= 0)
        H5Tclose(t);
    if (sp >= 0)
        H5Sclose(sp);
    H5Aclose(a);
    restore_errors(es);
    return ok ? 0 : -1;
}

/* Reads a scalar string attribute (variable or fixed length) into a malloc'd string.
 * Returns 0, 1 when missing (*out = NULL), -1 on a bad type or read failure. */
static int get_str_attr(hid_t obj, const char *name, char **out) {
    *out = NULL;
    htri_t ex = H5Aexists(obj, name);
    if (ex == 0)
        return 1;
    if (ex < 0)
        return -1;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a < 0)
        return -1;
    int rc = -1;
    hid_t t = H5Aget_type(a), sp = H5Aget_space(a), mt = -1;
    if (t < 0 || sp < 0 || H5Tget_class(t) != H5T_STRING || H5Sget_simple_extent_npoints(sp) != 1)
        goto done;
    if (H5Tis_variable_str(t) > 0) {
        mt = vlen_string_type();
        char *v = NULL;
        if (mt >= 0 && H5Tset_cset(mt, H5Tget_cset(t)) >= 0 && H5Aread(a, mt, &v) >= 0) {
            *out = dup_str(v);
            rc = *out ? 0 : -1;
            H5Dvlen_reclaim(mt, sp, H5P_DEFAULT, &v);
        }
    } else {
        size_t size = H5Tget_size(t);
        if (size == 0 || size > ((size_t)1 << 30))
            goto done;
        mt = H5Tcopy(H5T_C_S1);
        char *buf = calloc(size + 1, 1);
        if (mt >= 0 && buf && H5Tset_size(mt, size + 1) >= 0 &&
            H5Tset_cset(mt, H5Tget_cset(t)) >= 0 && H5Aread(a, mt, buf) >= 0) {
            *out = buf;
            buf = NULL;
            rc = 0;
        }
        free(buf);
    }
done:;
    hid_t es = keep_errors(rc < 0);
    if (mt >= 0)
        H5Tclose(mt);
    if (t >= 0)
        H5Tclose(t);
    if (sp >= 0)
        H5Sclose(sp);
    H5Aclose(a);
    restore_errors(es);
    return rc;
}

/* ------------------------------------------------------------------ paths */

/* "dir/run.h5" -> "dir/run.xmf" (".h5"/".hdf5"/".hdf" replaced, otherwise appended). */
static char *xmf_path_for(const char *h5path) {
    size_t n = strlen(h5path);
    const char *slash = strrchr(h5path, '/');
    const char *dot = strrchr(h5path, '.');
    size_t stem = n;
    if (dot && (!slash || dot > slash) &&
        (!strcmp(dot, ".h5") || !strcmp(dot, ".hdf5") || !strcmp(dot, ".hdf")))
        stem = (size_t)(dot - h5path);
    char *p = malloc(stem + 5);
    if (!p)
        return NULL;
    memcpy(p, h5path, stem);
    memcpy(p + stem, ".xmf", 5);
    return p;
}

/* ------------------------------------------------------------------ writer */

typedef struct {
    int32_t number; /* increment number */
    double time;    /* s */
    int64_t n;      /* element count */
    int has_stress; /* 1: sxx, syy, sxy stored */
} xmf_entry;

struct cdem_h5_writer {
    hid_t file;                    /* open HDF5 file */
    hid_t increments;              /* /increments group */
    hid_t series[N_SERIES];        /* /series/<column> datasets */
    char *path;                    /* the .h5 path as given */
    char *xmf_path;                /* sidecar path */
    char *xmf_tmp;                 /* sidecar temp path (renamed over xmf_path) */
    const char *h5_name;           /* basename of path, referenced from the sidecar */
    cdem_series_sample *buf;       /* SERIES_BUFFER buffered samples */
    size_t nbuf;                   /* samples in buf */
    void *column;                  /* SERIES_BUFFER * 8 bytes: one column being written */
    hsize_t series_len;            /* samples already in the file */
    xmf_entry *entries;            /* one per written increment, in write order */
    size_t n_entries, cap_entries; /* used / allocated entries */
    size_t xmf_written;            /* entries in the sidecar on disk */
};

static cdem_status flush_file(cdem_h5_writer *w, cdem_error *err) {
    if (H5Fflush(w->file, H5F_SCOPE_GLOBAL) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot flush the file", w->path);
    return CDEM_OK;
}

/* Writes the buffered series samples (appending to every /series dataset). */
static cdem_status flush_series(cdem_h5_writer *w, cdem_error *err) {
    if (w->nbuf == 0)
        return CDEM_OK;
    hsize_t start = w->series_len, count = w->nbuf, total = start + count;
    for (size_t c = 0; c < N_SERIES; c++) {
        const series_column *col = &series_columns[c];
        for (size_t i = 0; i < w->nbuf; i++) {
            const char *src = (const char *)&w->buf[i] + col->offset;
            memcpy((char *)w->column + i * 8, src, 8);
        }
        hid_t fs = -1, ms = -1;
        int ok = H5Dset_extent(w->series[c], &total) >= 0 &&
                 (fs = H5Dget_space(w->series[c])) >= 0 &&
                 H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &count, NULL) >= 0 &&
                 (ms = H5Screate_simple(1, &count, NULL)) >= 0 &&
                 H5Dwrite(w->series[c], col->type == COL_I64 ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE,
                          ms, fs, H5P_DEFAULT, w->column) >= 0;
        hid_t es = keep_errors(!ok);
        if (fs >= 0)
            H5Sclose(fs);
        if (ms >= 0)
            H5Sclose(ms);
        restore_errors(es);
        if (!ok)
            return H5FAIL(err, CDEM_ERR_IO, "%s: cannot append %zu samples to /series/%s", w->path,
                          w->nbuf, col->name);
    }
    w->series_len = total;
    w->nbuf = 0;
    return CDEM_OK;
}

static void xml_escaped(FILE *f, const char *s) {
    for (; *s; s++) {
        switch (*s) {
        case '&':
            fputs("&amp;", f);
            break;
        case '<':
            fputs("&lt;", f);
            break;
        case '>':
            fputs("&gt;", f);
            break;
        case '"':
            fputs("&quot;", f);
            break;
        default:
            fputc(*s, f);
        }
    }
}

static void xmf_data_item(FILE *f, const cdem_h5_writer *w, const xmf_entry *e, size_t k) {
    const element_field *fd = &element_fields[k];
    fprintf(f,
            "        <DataItem Dimensions=\"%lld\" NumberType=\"%s\" Precision=\"%d\" "
            "Format=\"HDF\">",
            (long long)e->n, fd->xdmf, fd->type == EL_F64 ? 8 : 4);
    xml_escaped(f, w->h5_name);
    fprintf(f, ":/increments/%06d/%s</DataItem>\n", (int)e->number, fd->name);
}

/* Rewrites the sidecar from the list of increments: temp file, then rename. */
static cdem_status write_xmf(cdem_h5_writer *w, cdem_error *err) {
    FILE *f = fopen(w->xmf_tmp, "w");
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot create the XDMF sidecar: %s", w->xmf_tmp,
                         strerror(errno));
    fputs("<?xml version=\"1.0\" ?>\n"
          "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
          "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
          "  <Domain>\n"
          "    <Grid Name=\"increments\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
          f);
    for (size_t i = 0; i < w->n_entries; i++) {
        const xmf_entry *e = &w->entries[i];
        if (e->n == 0)
            continue; /* an empty grid has no geometry; viewers reject it */
        fprintf(f, "    <Grid Name=\"increment_%06d\" GridType=\"Uniform\">\n", (int)e->number);
        fprintf(f, "      <Time Value=\"%.17g\"/>\n", e->time);
        fprintf(f,
                "      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%lld\" "
                "NodesPerElement=\"1\"/>\n",
                (long long)e->n);
        fputs("      <Geometry GeometryType=\"X_Y\">\n", f);
        xmf_data_item(f, w, e, 1);
        xmf_data_item(f, w, e, 2);
        fputs("      </Geometry>\n", f);
        static const size_t attrs[] = {3, 4, 0, 5, 6, 7, 8, 9};
        for (size_t a = 0; a < sizeof attrs / sizeof attrs[0]; a++) {
            size_t k = attrs[a];
            if (element_fields[k].optional && !e->has_stress)
                continue;
            fprintf(f, "      <Attribute Name=\"%s\" AttributeType=\"Scalar\" Center=\"Node\">\n",
                    element_fields[k].name);
            xmf_data_item(f, w, e, k);
            fputs("      </Attribute>\n", f);
        }
        fputs("    </Grid>\n", f);
    }
    fputs("    </Grid>\n  </Domain>\n</Xdmf>\n", f);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        remove(w->xmf_tmp);
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot write the XDMF sidecar", w->xmf_tmp);
    }
    if (rename(w->xmf_tmp, w->xmf_path) != 0) {
        int e = errno;
        remove(w->xmf_tmp);
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot rename %s to it: %s", w->xmf_path,
                         w->xmf_tmp, strerror(e));
    }
    w->xmf_written = w->n_entries;
    return CDEM_OK;
}

/* Object creation property list with time stamps off (deterministic bytes). */
static hid_t untimed_plist(hid_t cls) {
    hid_t p = H5Pcreate(cls);
    if (p >= 0)
        H5Pset_obj_track_times(p, 0);
    return p;
}

/* /parameters: a compound table (name, value, unit as fixed-length strings, each as wide
 * as its longest entry) plus one string attribute per parameter. */
static cdem_status write_parameters(cdem_h5_writer *w, const cdem_params *p, cdem_error *err) {
    size_t count = 0;
    const cdem_param_def *table = cdem_params_table(&count);
    enum { NAME_MAX_ = 128, VALUE_MAX_ = 2 * CDEM_PATH_MAX + 64 };
    char *names = calloc(count ? count : 1, NAME_MAX_);
    char *values = calloc(count ? count : 1, VALUE_MAX_);
    size_t wn = 1, wv = 1, wu = 1;
    for (size_t i = 0; names && values && i < count; i++) {
        char *name = names + i * NAME_MAX_, *value = values + i * VALUE_MAX_;
        snprintf(name, NAME_MAX_, "%s.%s", table[i].section, table[i].key);
        cdem_params_format_value(p, &table[i], value, VALUE_MAX_);
        size_t lu = strlen(table[i].unit ? table[i].unit : "");
        wn = strlen(name) + 1 > wn ? strlen(name) + 1 : wn;
        wv = strlen(value) + 1 > wv ? strlen(value) + 1 : wv;
        wu = lu + 1 > wu ? lu + 1 : wu;
    }
    size_t row = wn + wv + wu;
    char *rows = names && values ? calloc(count ? count : 1, row) : NULL;
    if (!rows) {
        free(names);
        free(values);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory storing %zu parameters", count);
    }
    for (size_t i = 0; i < count; i++) {
        memcpy(rows + i * row, names + i * NAME_MAX_, strlen(names + i * NAME_MAX_));
        memcpy(rows + i * row + wn, values + i * VALUE_MAX_, strlen(values + i * VALUE_MAX_));
        if (table[i].unit)
            memcpy(rows + i * row + wn + wv, table[i].unit, strlen(table[i].unit));
    }
    cdem_status st = CDEM_OK;
    hid_t tn = fixed_string_type(wn - 1), tv = fixed_string_type(wv - 1);
    hid_t tu = fixed_string_type(wu - 1), ct = H5Tcreate(H5T_COMPOUND, row);
    H5Tinsert(ct, "name", 0, tn);
    H5Tinsert(ct, "value", wn, tv);
    H5Tinsert(ct, "unit", wn + wv, tu);
    hsize_t dim = count;
    hid_t sp = H5Screate_simple(1, &dim, NULL), dcpl = untimed_plist(H5P_DATASET_CREATE);
    hid_t ds = H5Dcreate2(w->file, "parameters", ct, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (ds < 0 || (count && H5Dwrite(ds, ct, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) < 0))
        st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot write the /parameters table", w->path);
    for (size_t i = 0; st == CDEM_OK && i < count; i++)
        if (put_str_attr(ds, names + i * NAME_MAX_, values + i * VALUE_MAX_) < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot write attribute /parameters %s = %s", w->path,
                        names + i * NAME_MAX_, values + i * VALUE_MAX_);
    if (ds >= 0)
        H5Dclose(ds);
    H5Pclose(dcpl);
    H5Sclose(sp);
    H5Tclose(ct);
    H5Tclose(tn);
    H5Tclose(tv);
    H5Tclose(tu);
    free(rows);
    free(names);
    free(values);
    return st;
}

static cdem_status create_series(cdem_h5_writer *w, cdem_error *err) {
    hid_t gcpl = untimed_plist(H5P_GROUP_CREATE);
    hid_t g = H5Gcreate2(w->file, "series", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    H5Pclose(gcpl);
    if (g < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot create group /series", w->path);
    /* Unfiltered on purpose: a fixed-size chunk is rewritten in place when samples are
     * appended, so the chunk the last flushed index points to stays valid. A compressed
     * chunk would move at every append and its old place could be reused before the next
     * flush. The series is small (about 0.1 MB for the default run), so this costs little. */
    hsize_t zero = 0, unlimited = H5S_UNLIMITED, chunk = SERIES_CHUNK;
    hid_t sp = H5Screate_simple(1, &zero, &unlimited);
    hid_t dcpl = untimed_plist(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, 1, &chunk);
    cdem_status st = CDEM_OK;
    for (size_t c = 0; c < N_SERIES; c++) {
        hid_t ft = series_columns[c].type == COL_I64 ? H5T_STD_I64LE : H5T_IEEE_F64LE;
        w->series[c] =
            H5Dcreate2(g, series_columns[c].name, ft, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
        if (w->series[c] < 0) {
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create dataset /series/%s", w->path,
                        series_columns[c].name);
            break;
        }
    }
    H5Pclose(dcpl);
    H5Sclose(sp);
    H5Gclose(g);
    return st;
}

static void writer_release(cdem_h5_writer *w) {
    for (size_t c = 0; c < N_SERIES; c++)
        if (w->series[c] >= 0)
            H5Dclose(w->series[c]);
    if (w->increments >= 0)
        H5Gclose(w->increments);
    if (w->file >= 0)
        H5Fclose(w->file);
    free(w->path);
    free(w->xmf_path);
    free(w->xmf_tmp);
    free(w->buf);
    free(w->column);
    free(w->entries);
    free(w);
}

static cdem_status writer_setup(cdem_h5_writer *w, const cdem_run_meta *meta, cdem_error *err) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_libver_bounds(fapl, H5F_LIBVER_V110, H5F_LIBVER_V110);
    /* Crash consistency between flushes (see the head comment): with evictions off,
     * metadata reaches the disk only at a flush, never half-way through an increment. */
    H5AC_cache_config_t mdc;
    memset(&mdc, 0, sizeof mdc);
    mdc.version = H5AC__CURR_CACHE_CONFIG_VERSION;
    if (H5Pget_mdc_config(fapl, &mdc) >= 0) {
        mdc.evictions_enabled = 0;
        mdc.incr_mode = H5C_incr__off;
        mdc.flash_incr_mode = H5C_flash_incr__off;
        mdc.decr_mode = H5C_decr__off;
        H5Pset_mdc_config(fapl, &mdc);
    }
    hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
    w->file = H5Fcreate(w->path, H5F_ACC_TRUNC, fcpl, fapl);
    hid_t es = keep_errors(w->file < 0);
    H5Pclose(fapl);
    H5Pclose(fcpl);
    restore_errors(es);
    if (w->file < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot create the output file", w->path);

    char created[32] = "";
    time_t now = time(NULL);
    struct tm tmv;
    if (gmtime_r(&now, &tmv))
        strftime(created, sizeof created, "%Y-%m-%dT%H:%M:%SZ", &tmv);
    hid_t root = w->file;
    if (put_str_attr(root, "format", CDEM_FORMAT_NAME) < 0 ||
        put_i32_attr(root, "format_version", CDEM_FORMAT_VERSION) < 0 ||
        put_str_attr(root, "program_version", meta->program_version) < 0 ||
        put_i64_attr(root, "seed", (int64_t)meta->params->seed) < 0 ||
        put_str_attr(root, "created", created) < 0 ||
        put_str_attr(root, "source", meta->source) < 0 ||
        put_str_attr(root, "summary", meta->summary) < 0 ||
        put_str_attr(root, "params_text", meta->params_text) < 0 ||
        put_str_attr(root, "stop_reason", "running") < 0 ||
        put_str_attr(root, "stop_detail", "") < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot write the root attributes", w->path);
    CDEM_TRY(write_parameters(w, meta->params, err));
    CDEM_TRY(create_series(w, err));
    /* Links stay in the group's object header (compact), which only grows by new
     * continuation blocks; dense storage (fractal heap + B-tree) moves and frees blocks
     * as it grows, and freed space may be reused before the next flush. */
    hid_t gcpl = untimed_plist(H5P_GROUP_CREATE);
    H5Pset_link_phase_change(gcpl, 65535, 65534);
    w->increments = H5Gcreate2(w->file, "increments", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    H5Pclose(gcpl);
    if (w->increments < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot create group /increments", w->path);
    CDEM_TRY(write_xmf(w, err));
    return flush_file(w, err);
}

cdem_status cdem_h5_writer_create(const char *path, const cdem_run_meta *meta, cdem_h5_writer **out,
                                  cdem_error *err) {
    if (out)
        *out = NULL;
    if (!path || !*path || !meta || !meta->params || !out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_h5_writer_create: path, meta, meta->params and out are required");
    quiet_hdf5();
    cdem_h5_writer *w = calloc(1, sizeof *w);
    if (!w)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory creating a writer for %s", path);
    w->file = w->increments = -1;
    for (size_t c = 0; c < N_SERIES; c++)
        w->series[c] = -1;
    w->path = dup_str(path);
    w->xmf_path = xmf_path_for(path);
    w->xmf_tmp = w->xmf_path ? malloc(strlen(w->xmf_path) + 5) : NULL;
    w->buf = malloc(SERIES_BUFFER * sizeof *w->buf);
    w->column = malloc(SERIES_BUFFER * 8);
    if (!w->path || !w->xmf_path || !w->xmf_tmp || !w->buf || !w->column) {
        writer_release(w);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory creating a writer for %s", path);
    }
    snprintf(w->xmf_tmp, strlen(w->xmf_path) + 5, "%s.tmp", w->xmf_path);
    const char *slash = strrchr(w->path, '/');
    w->h5_name = slash ? slash + 1 : w->path;
    cdem_status st = writer_setup(w, meta, err);
    if (st != CDEM_OK) {
        writer_release(w);
        return st;
    }
    *out = w;
    return CDEM_OK;
}

static cdem_status write_element_dataset(cdem_h5_writer *w, hid_t g, const char *gname, size_t k,
                                         const cdem_state *s, cdem_error *err) {
    const element_field *fd = &element_fields[k];
    hsize_t n = s->n;
    hid_t sp = H5Screate_simple(1, &n, NULL);
    hid_t dcpl = untimed_plist(H5P_DATASET_CREATE);
    H5Pset_dset_no_attrs_hint(dcpl, 1);
    H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER);
    if (n > 0) {
        hsize_t chunk = n < CHUNK_ELEMS ? n : CHUNK_ELEMS;
        H5Pset_chunk(dcpl, 1, &chunk);
        H5Pset_shuffle(dcpl);
        H5Pset_deflate(dcpl, DEFLATE_LEVEL);
        H5Pset_fletcher32(dcpl);
    }
    hid_t ds = H5Dcreate2(g, fd->name, el_file_type(fd->type), sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    int ok = ds >= 0 && (n == 0 || H5Dwrite(ds, el_mem_type(fd->type), H5S_ALL, H5S_ALL,
                                            H5P_DEFAULT, element_array(s, k)) >= 0);
    hid_t es = keep_errors(!ok);
    if (ds >= 0)
        H5Dclose(ds);
    H5Pclose(dcpl);
    H5Sclose(sp);
    restore_errors(es);
    if (!ok)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot write dataset /increments/%s/%s (%llu values)",
                      w->path, gname, fd->name, (unsigned long long)n);
    return CDEM_OK;
}

cdem_status cdem_h5_writer_write_increment(cdem_h5_writer *w, const cdem_increment_info *info,
                                           const cdem_state *s, cdem_error *err) {
    if (!w || !info || !s)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_h5_writer_write_increment: writer, info and state are required");
    if (info->number < 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "%s: increment number %d is negative", w->path,
                         (int)info->number);
    if (s->n > 0 && (!s->id || !s->x || !s->y || !s->radius || !s->layer || !s->flags || !s->born ||
                     (s->has_stress && (!s->sxx || !s->syy || !s->sxy))))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "%s: increment %d: the state has %zu elements but missing arrays", w->path,
                         (int)info->number, s->n);
    char gname[32];
    snprintf(gname, sizeof gname, "%06d", (int)info->number);
    if (H5Lexists(w->increments, gname, H5P_DEFAULT) > 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "%s: increment %d was already written", w->path,
                         (int)info->number);
    if (w->n_entries == w->cap_entries) {
        size_t cap = w->cap_entries ? 2 * w->cap_entries : 64;
        xmf_entry *e = realloc(w->entries, cap * sizeof *e);
        if (!e)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory listing %zu increments", cap);
        w->entries = e;
        w->cap_entries = cap;
    }
    CDEM_TRY(flush_series(w, err));

    /* Keep the 9 attributes and 10 links in the group's object header: past 8 attributes
     * HDF5 would otherwise move them to a fractal heap + B-tree (+1.8 KB per increment). */
    hid_t gcpl = untimed_plist(H5P_GROUP_CREATE);
    H5Pset_attr_phase_change(gcpl, 32, 24);
    H5Pset_est_link_info(gcpl, (unsigned)N_ELEMENT_FIELDS, 6);
    hid_t g = H5Gcreate2(w->increments, gname, H5P_DEFAULT, gcpl, H5P_DEFAULT);
    H5Pclose(gcpl);
    if (g < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot create group /increments/%s", w->path, gname);
    cdem_status st = CDEM_OK;
    if (put_i32_attr(g, "number", info->number) < 0 || put_i64_attr(g, "step", info->step) < 0 ||
        put_f64_attr(g, "time", info->time) < 0 || put_i32_attr(g, "phase", info->phase) < 0 ||
        put_f64_attr(g, "net_displacement", info->net_displacement) < 0 ||
        put_f64_attr(g, "axial_strain", info->axial_strain) < 0 ||
        put_f64_attr(g, "differential_stress", info->differential_stress) < 0 ||
        put_f64_attr(g, "sea_level", info->sea_level) < 0 ||
        put_i64_attr(g, "n", (int64_t)s->n) < 0)
        st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot write the attributes of /increments/%s", w->path,
                    gname);
    for (size_t k = 0; st == CDEM_OK && k < N_ELEMENT_FIELDS; k++)
        if (!element_fields[k].optional || s->has_stress)
            st = write_element_dataset(w, g, gname, k, s, err);
    H5Gclose(g);
    if (st != CDEM_OK)
        return st;
    w->entries[w->n_entries++] =
        (xmf_entry){info->number, info->time, (int64_t)s->n, s->has_stress ? 1 : 0};
    CDEM_TRY(flush_file(w, err));
    /* Rewriting the whole sidecar costs O(increments); past XMF_EVERY_LIMIT increments it is
     * rewritten only when 5 % more have accumulated (and at close), so a run's total
     * sidecar I/O stays linear in its length. */
    if (w->n_entries <= XMF_EVERY_LIMIT || w->n_entries - w->xmf_written >= w->n_entries / 20)
        return write_xmf(w, err);
    return CDEM_OK;
}

cdem_status cdem_h5_writer_append_series(cdem_h5_writer *w, const cdem_series_sample *sample,
                                         cdem_error *err) {
    if (!w || !sample)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_h5_writer_append_series: writer and sample are required");
    if (w->nbuf == SERIES_BUFFER)
        CDEM_TRY(flush_series(w, err));
    w->buf[w->nbuf++] = *sample;
    return CDEM_OK;
}

cdem_status cdem_h5_writer_set_stop_reason(cdem_h5_writer *w, const char *reason,
                                           const char *detail, cdem_error *err) {
    if (!w)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_writer_set_stop_reason: no writer");
    if (put_str_attr(w->file, "stop_reason", reason) < 0 ||
        put_str_attr(w->file, "stop_detail", detail) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot write the stop reason '%s'", w->path,
                      reason ? reason : "");
    return flush_file(w, err);
}

cdem_status cdem_h5_writer_close(cdem_h5_writer *w, cdem_error *err) {
    if (!w)
        return CDEM_OK;
    cdem_status st = flush_series(w, err);
    if (st == CDEM_OK && w->xmf_written != w->n_entries)
        st = write_xmf(w, err);
    for (size_t c = 0; c < N_SERIES; c++) {
        if (w->series[c] >= 0 && H5Dclose(w->series[c]) < 0 && st == CDEM_OK)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot close /series/%s", w->path,
                        series_columns[c].name);
        w->series[c] = -1;
    }
    if (w->increments >= 0)
        H5Gclose(w->increments);
    w->increments = -1;
    if (w->file >= 0 && H5Fclose(w->file) < 0 && st == CDEM_OK)
        st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot close the file", w->path);
    w->file = -1;
    writer_release(w);
    return st;
}

/* ------------------------------------------------------------------ reader */

typedef struct {
    cdem_increment_info info; /* attributes of the group */
    char name[32];            /* group name under /increments */
} incr_entry;

struct cdem_h5_reader {
    hid_t file; /* open HDF5 file */
    char *path; /* as given */
    /* Root text attributes, malloc'd, "" when absent. */
    char *summary;         /* model summary */
    char *params_text;     /* original parameter-file text */
    char *stop_reason;     /* "running", "completed", "interrupted", ... */
    char *stop_detail;     /* free-text diagnosis */
    char *program_version; /* version of the writing program */
    char *source;          /* "cdem-run" or "cdem2d-import:<folder>" */
    char *created;         /* ISO 8601 UTC creation time */
    long seed;             /* root attribute seed */
    int unclosed;          /* 1: the writer did not close the file (status flag set) */
    size_t n_skipped;      /* unclosed file: increments left out as incompletely flushed */
    incr_entry *incr;      /* increments sorted by number */
    size_t n_incr;         /* entries in incr */
    size_t cap_incr;       /* allocated entries */
};

void cdem_h5_reader_close(cdem_h5_reader *r) {
    if (!r)
        return;
    if (r->file >= 0)
        H5Fclose(r->file);
    free(r->path);
    free(r->summary);
    free(r->params_text);
    free(r->stop_reason);
    free(r->stop_detail);
    free(r->program_version);
    free(r->source);
    free(r->created);
    free(r->incr);
    free(r);
}

static uint64_t le_u64(const unsigned char *b, int size) {
    uint64_t v = 0;
    for (int i = size - 1; i >= 0; i--)
        v = (v << 8) | b[i];
    return v;
}

/* Looks at the superblock before HDF5 does. Fails on truncation (stored end-of-file beyond
 * the real size); sets *unclosed when a v3 superblock says a writer still has it open. */
static cdem_status precheck_superblock(const char *path, int *unclosed, cdem_error *err) {
    *unclosed = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0) {
        fclose(f);
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
    }
    uint64_t size = (uint64_t)sb.st_size;
    static const unsigned char sig[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    unsigned char b[64];
    cdem_status st = CDEM_OK;
    for (uint64_t at = 0; at + 8 <= size; at = at ? 2 * at : 512) {
        if (fseek(f, (long)at, SEEK_SET) != 0)
            break;
        size_t got = fread(b, 1, sizeof b, f);
        if (got < 8 || memcmp(b, sig, 8) != 0)
            continue;
        if (got < 12)
            break;
        int version = b[8];
        if (version < 2 || version > 3)
            break; /* older superblocks: leave the checks to HDF5 */
        int so = b[9];
        if (so != 2 && so != 4 && so != 8) {
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: corrupt HDF5 superblock (size of offsets %d; allowed 2, 4, 8)",
                           path, so);
            break;
        }
        if (got < (size_t)(12 + 4 * so)) {
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: truncated file: %llu bytes end inside the HDF5 superblock", path,
                           (unsigned long long)size);
            break;
        }
        uint64_t base = le_u64(b + 12, so), eof = le_u64(b + 12 + 2 * so, so);
        if (base + eof > size) {
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: truncated file: it has %llu bytes but its HDF5 superblock says "
                           "%llu (copy interrupted or disk full?)",
                           path, (unsigned long long)size, (unsigned long long)(base + eof));
            break;
        }
        if (version == 3 && (b[11] & 0x05))
            *unclosed = 1;
        break;
    }
    fclose(f);
    return st;
}

static int cmp_incr(const void *a, const void *b) {
    int32_t x = ((const incr_entry *)a)->info.number, y = ((const incr_entry *)b)->info.number;
    return (x > y) - (x < y);
}

typedef struct {
    cdem_h5_reader *r;  /* reader being filled */
    cdem_error *err;    /* where a failure goes */
    cdem_status status; /* first failure */
} scan_ctx;

/* Reads the info attributes of one increment group. */
static cdem_status read_incr_info(cdem_h5_reader *r, hid_t g, const char *name,
                                  cdem_increment_info *info, cdem_error *err) {
    memset(info, 0, sizeof *info);
    info->sea_level = NAN;
    int64_t n = -1;
    struct {
        const char *key; /* attribute name */
        hid_t type;      /* memory type to read as */
        void *dst;       /* destination field of info */
    } fields[] = {
        {"number", H5T_NATIVE_INT32, &info->number},
        {"step", H5T_NATIVE_INT64, &info->step},
        {"time", H5T_NATIVE_DOUBLE, &info->time},
        {"phase", H5T_NATIVE_INT32, &info->phase},
        {"net_displacement", H5T_NATIVE_DOUBLE, &info->net_displacement},
        {"axial_strain", H5T_NATIVE_DOUBLE, &info->axial_strain},
        {"differential_stress", H5T_NATIVE_DOUBLE, &info->differential_stress},
        {"sea_level", H5T_NATIVE_DOUBLE, &info->sea_level},
        {"n", H5T_NATIVE_INT64, &n},
    };
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++) {
        int rc = get_num_attr(g, fields[i].key, fields[i].type, fields[i].dst);
        if (rc != 0)
            return H5FAIL(err, CDEM_ERR_FORMAT,
                          "%s: /increments/%s: attribute '%s' is %s (a numeric scalar is "
                          "required)",
                          r->path, name, fields[i].key, rc > 0 ? "missing" : "unreadable");
    }
    if (n < 0 || (hsize_t)n > MAX_ELEMENTS)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: /increments/%s: attribute n = %lld (allowed 0..%d)", r->path, name,
                         (long long)n, INT32_MAX);
    info->n_elements = n;
    htri_t hs = H5Lexists(g, "sxx", H5P_DEFAULT);
    if (hs < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: /increments/%s: cannot look for sxx", r->path,
                      name);
    info->has_stress = hs > 0;
    return CDEM_OK;
}

static herr_t scan_increment(hid_t group, const char *name, const H5L_info_t *li, void *data) {
    (void)li;
    scan_ctx *c = data;
    cdem_h5_reader *r = c->r;
    if (r->n_incr == r->cap_incr) {
        size_t cap = r->cap_incr ? 2 * r->cap_incr : 64;
        incr_entry *e = realloc(r->incr, cap * sizeof *e);
        if (!e) {
            c->status = CDEM_FAIL(c->err, CDEM_ERR_NOMEM, "out of memory listing increments");
            return -1;
        }
        r->incr = e;
        r->cap_incr = cap;
    }
    if (strlen(name) >= sizeof r->incr[0].name) {
        c->status =
            CDEM_FAIL(c->err, CDEM_ERR_FORMAT,
                      "%s: /increments/%.40s...: name too long for an increment", r->path, name);
        return -1;
    }
    hid_t g = H5Gopen2(group, name, H5P_DEFAULT);
    incr_entry *e = &r->incr[r->n_incr];
    snprintf(e->name, sizeof e->name, "%s", name);
    if (g < 0)
        c->status =
            H5FAIL(c->err, CDEM_ERR_FORMAT, "%s: cannot open group /increments/%s", r->path, name);
    else
        c->status = read_incr_info(r, g, name, &e->info, c->err);
    if (g >= 0)
        H5Gclose(g);
    if (c->status != CDEM_OK && r->unclosed) {
        /* The writer died while flushing this increment: leave it out. */
        r->n_skipped++;
        c->status = CDEM_OK;
        cdem_error_clear(c->err);
        return 0;
    }
    if (c->status != CDEM_OK)
        return -1;
    r->n_incr++;
    return 0;
}

static cdem_status read_root_text(cdem_h5_reader *r, const char *name, char **out,
                                  cdem_error *err) {
    int rc = get_str_attr(r->file, name, out);
    if (rc < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: root attribute '%s' is not a readable string",
                      r->path, name);
    if (rc > 0 && !(*out = dup_str("")))
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    return CDEM_OK;
}

static cdem_status reader_setup(cdem_h5_reader *r, cdem_error *err) {
    const char *path = r->path;
    struct stat sb;
    if (stat(path, &sb) != 0)
        return CDEM_FAIL(err, errno == ENOENT ? CDEM_ERR_NOTFOUND : CDEM_ERR_IO,
                         "%s: cannot open: %s", path, strerror(errno));
    if (!S_ISREG(sb.st_mode))
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: not a regular file", path);
    htri_t is = H5Fis_hdf5(path);
    if (is <= 0)
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: not an HDF5 file (no HDF5 signature), so not a cdem file", path);
    CDEM_TRY(precheck_superblock(path, &r->unclosed, err));
    /* A writer that died (or still runs) left the v3 superblock marked "open for write";
     * HDF5 then refuses a plain open. "clear_status_flags" is the file-access property
     * h5clear uses; on a read-only open it only skips the check (the file is not changed).
     * File locking is off for the same case so that a live writer's lock does not block. */
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (r->unclosed) {
        hbool_t clear = 1;
        H5Pset(fapl, "clear_status_flags", &clear);
        H5Pset_file_locking(fapl, 0, 1);
    }
    r->file = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    if (r->file < 0 && r->unclosed) {
        /* The writer may be this very process (HDF5 then shares its open file, and the
         * access properties must match the writer's). */
        H5Eclear2(H5E_DEFAULT);
        r->file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    }
    if (r->file < 0) {
        cdem_status st = H5FAIL(err, CDEM_ERR_FORMAT,
                                "%s: cannot open as HDF5 (truncated or corrupt file?)", path);
        H5Pclose(fapl);
        return st;
    }
    H5Pclose(fapl);

    char *fmt = NULL;
    int rc = get_str_attr(r->file, "format", &fmt);
    if (rc != 0 || strcmp(fmt, CDEM_FORMAT_NAME) != 0) {
        cdem_status st = H5FAIL(err, CDEM_ERR_FORMAT,
                                "%s: an HDF5 file but not a cdem file: root attribute 'format' "
                                "is %s%s%s (expected \"%s\")",
                                path,
                                rc > 0   ? "missing"
                                : rc < 0 ? "unreadable"
                                         : "\"",
                                rc == 0 ? fmt : "", rc == 0 ? "\"" : "", CDEM_FORMAT_NAME);
        free(fmt);
        return st;
    }
    free(fmt);
    int32_t version = 0;
    rc = get_num_attr(r->file, "format_version", H5T_NATIVE_INT32, &version);
    if (rc != 0)
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: root attribute 'format_version' is %s (an integer is required)", path,
                      rc > 0 ? "missing" : "unreadable");
    if (version != CDEM_FORMAT_VERSION)
        return CDEM_FAIL(err, CDEM_ERR_VERSION,
                         "%s: cdem format version %d; this program reads version %d%s", path,
                         (int)version, CDEM_FORMAT_VERSION,
                         version > CDEM_FORMAT_VERSION ? " (written by a newer cdem-c)" : "");
    int64_t seed = 0;
    if (get_num_attr(r->file, "seed", H5T_NATIVE_INT64, &seed) < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: root attribute 'seed' is unreadable", path);
    r->seed = (long)seed;
    CDEM_TRY(read_root_text(r, "summary", &r->summary, err));
    CDEM_TRY(read_root_text(r, "params_text", &r->params_text, err));
    CDEM_TRY(read_root_text(r, "stop_reason", &r->stop_reason, err));
    CDEM_TRY(read_root_text(r, "stop_detail", &r->stop_detail, err));
    CDEM_TRY(read_root_text(r, "program_version", &r->program_version, err));
    CDEM_TRY(read_root_text(r, "source", &r->source, err));
    CDEM_TRY(read_root_text(r, "created", &r->created, err));

    htri_t ex = H5Lexists(r->file, "increments", H5P_DEFAULT);
    if (ex <= 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: group /increments is missing", path);
    scan_ctx c = {r, err, CDEM_OK};
    hsize_t idx = 0;
    if (H5Literate_by_name(r->file, "increments", H5_INDEX_NAME, H5_ITER_INC, &idx, scan_increment,
                           &c, H5P_DEFAULT) < 0) {
        if (c.status != CDEM_OK)
            return c.status;
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot list group /increments", path);
    }
    if (r->n_incr > 1)
        qsort(r->incr, r->n_incr, sizeof *r->incr, cmp_incr);
    return CDEM_OK;
}

cdem_status cdem_h5_reader_open(const char *path, cdem_h5_reader **out, cdem_error *err) {
    if (out)
        *out = NULL;
    if (!path || !out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_open: path and out are required");
    quiet_hdf5();
    cdem_h5_reader *r = calloc(1, sizeof *r);
    if (!r || !(r->path = dup_str(path))) {
        free(r);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory opening %s", path);
    }
    r->file = -1;
    cdem_status st = reader_setup(r, err);
    if (st != CDEM_OK) {
        cdem_h5_reader_close(r);
        return st;
    }
    *out = r;
    return CDEM_OK;
}

size_t cdem_h5_reader_increment_count(const cdem_h5_reader *r) {
    return r ? r->n_incr : 0;
}

cdem_status cdem_h5_reader_increment_info(const cdem_h5_reader *r, size_t index,
                                          cdem_increment_info *info, cdem_error *err) {
    if (!r || !info)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_increment_info: no reader");
    if (index >= r->n_incr)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s: increment index %zu (the file has %zu)",
                         r->path, index, r->n_incr);
    *info = r->incr[index].info;
    return CDEM_OK;
}

cdem_status cdem_h5_reader_find_increment(const cdem_h5_reader *r, const char *spec, size_t *index,
                                          cdem_error *err) {
    if (!r || !spec || !index)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_find_increment: bad arguments");
    if (r->n_incr == 0)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s: increment '%s': the file has no increments",
                         r->path, spec);
    int32_t lo = r->incr[0].info.number, hi = r->incr[r->n_incr - 1].info.number;
    if (!strcmp(spec, "first")) {
        *index = 0;
        return CDEM_OK;
    }
    if (!strcmp(spec, "last")) {
        *index = r->n_incr - 1;
        return CDEM_OK;
    }
    if (!strcmp(spec, "equil")) {
        for (size_t i = r->n_incr; i-- > 0;)
            if (r->incr[i].info.phase == CDEM_PHASE_EQUILIBRATION) {
                *index = i;
                return CDEM_OK;
            }
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "%s: increment 'equil': no increment is in the equilibration phase",
                         r->path);
    }
    const char *p = spec;
    while (isspace((unsigned char)*p))
        p++;
    char *end = NULL;
    errno = 0;
    long k = strtol(p, &end, 10);
    if (end == p || *end != '\0' || errno != 0 || !isdigit((unsigned char)*p))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "increment '%s': expected a number (%d..%d), first, last or equil", spec,
                         (int)lo, (int)hi);
    for (size_t i = 0; i < r->n_incr; i++)
        if (r->incr[i].info.number == k) {
            *index = i;
            return CDEM_OK;
        }
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                     "%s: increment %ld does not exist (the file has %zu increments, %d..%d)",
                     r->path, k, r->n_incr, (int)lo, (int)hi);
}

/* Opens /increments/<g>/<name>, checks class and length, reads it into dst. */
static cdem_status read_element_dataset(cdem_h5_reader *r, hid_t g, const char *gname, size_t k,
                                        hsize_t n, void *dst, cdem_error *err) {
    const element_field *fd = &element_fields[k];
    hid_t ds = H5Dopen2(g, fd->name, H5P_DEFAULT);
    if (ds < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /increments/%s/%s is missing or corrupt",
                      r->path, gname, fd->name);
    cdem_status st = CDEM_OK;
    hid_t t = H5Dget_type(ds), sp = H5Dget_space(ds);
    H5T_class_t cls = t >= 0 ? H5Tget_class(t) : H5T_NO_CLASS;
    H5T_class_t want = fd->type == EL_F64 ? H5T_FLOAT : H5T_INTEGER;
    hsize_t dims[2] = {0, 0};
    int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
    if (rank >= 0 && rank <= 2)
        H5Sget_simple_extent_dims(sp, dims, NULL);
    if (cls != want)
        st = H5FAIL(err, CDEM_ERR_FORMAT,
                    "%s: dataset /increments/%s/%s has type class %d (expected %s)", r->path, gname,
                    fd->name, (int)cls, want == H5T_FLOAT ? "float" : "integer");
    else if (rank != 1 || dims[0] != n)
        st = H5FAIL(err, CDEM_ERR_FORMAT,
                    "%s: dataset /increments/%s/%s has rank %d and length %llu (expected a 1-D "
                    "dataset of %llu values, the element count)",
                    r->path, gname, fd->name, rank, (unsigned long long)dims[0],
                    (unsigned long long)n);
    else if (n > 0 && H5Dread(ds, el_mem_type(fd->type), H5S_ALL, H5S_ALL, H5P_DEFAULT, dst) < 0)
        st = H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot read dataset /increments/%s/%s (corrupt?)",
                    r->path, gname, fd->name);
    if (t >= 0)
        H5Tclose(t);
    if (sp >= 0)
        H5Sclose(sp);
    H5Dclose(ds);
    return st;
}

static cdem_status load_into(cdem_h5_reader *r, hid_t g, const incr_entry *e, cdem_state *s,
                             cdem_error *err) {
    hsize_t n = (hsize_t)e->info.n_elements;
    int nstress = 0;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        if (!element_fields[k].optional)
            continue;
        htri_t ex = H5Lexists(g, element_fields[k].name, H5P_DEFAULT);
        if (ex < 0)
            return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot look up /increments/%s/%s", r->path,
                          e->name, element_fields[k].name);
        nstress += ex > 0;
    }
    if (nstress != 0 && nstress != 3)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: /increments/%s has %d of the 3 stress datasets sxx, syy, sxy (all "
                         "or none allowed)",
                         r->path, e->name, nstress);
    /* Check the length before allocating for it: n comes from an attribute. */
    hid_t ids = H5Dopen2(g, "id", H5P_DEFAULT);
    hid_t sp = ids >= 0 ? H5Dget_space(ids) : -1;
    hssize_t len = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    /* A dataspace can claim any length while its storage was never written (HDF5 then
     * returns fill values): an 89 kB file claiming 2e9 elements made the reader allocate
     * ~100 GB (fuzz_h5). A written dataset has storage. */
    hsize_t stored = ids >= 0 && len > 0 ? H5Dget_storage_size(ids) : 0;
    if (sp >= 0)
        H5Sclose(sp);
    if (ids >= 0)
        H5Dclose(ids);
    if (len < 0 || (hsize_t)len != n)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: dataset /increments/%s/id is %s (attribute n = %llu)", r->path,
                         e->name, len < 0 ? "missing or unreadable" : "of another length",
                         (unsigned long long)n);
    if (n > READER_MAX_ELEMENTS)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: /increments/%s claims %llu elements; this reader refuses more than "
                         "%llu (corrupt file?)",
                         r->path, e->name, (unsigned long long)n,
                         (unsigned long long)READER_MAX_ELEMENTS);
    if (n > 0 && stored == 0)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: dataset /increments/%s/id claims %llu elements but none was ever "
                         "written (truncated or corrupt file)",
                         r->path, e->name, (unsigned long long)n);
    cdem_state_free(s);
    CDEM_TRY(cdem_state_init(s, (size_t)n, nstress == 3, err));
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        if (element_fields[k].optional && nstress == 0)
            continue;
        CDEM_TRY(read_element_dataset(r, g, e->name, k, n, element_array(s, k), err));
    }
    s->n = (size_t)n;
    int32_t next = 0;
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] >= next)
            next = s->id[i] == INT32_MAX ? INT32_MAX : s->id[i] + 1;
    s->next_id = next;
    return CDEM_OK;
}

cdem_status cdem_h5_reader_load_increment(cdem_h5_reader *r, size_t index, cdem_state *s,
                                          cdem_increment_info *info, cdem_error *err) {
    if (!r || !s)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_load_increment: bad arguments");
    if (index >= r->n_incr)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s: increment index %zu (the file has %zu)",
                         r->path, index, r->n_incr);
    const incr_entry *e = &r->incr[index];
    char gpath[64];
    snprintf(gpath, sizeof gpath, "increments/%s", e->name);
    hid_t g = H5Gopen2(r->file, gpath, H5P_DEFAULT);
    if (g < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot open group /%s", r->path, gpath);
    cdem_status st = load_into(r, g, e, s, err);
    H5Gclose(g);
    if (st != CDEM_OK) {
        cdem_state_free(s);
        return st;
    }
    if (info)
        *info = e->info;
    return CDEM_OK;
}

/* Reads `len` leading values of a 1-D numeric dataset, converted to mtype. */
static int read_prefix(hid_t ds, hid_t mtype, hsize_t len, void *dst) {
    if (len == 0)
        return 0;
    hsize_t start = 0;
    hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(1, &len, NULL);
    int ok = fs >= 0 && ms >= 0 &&
             H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &len, NULL) >= 0 &&
             H5Dread(ds, mtype, ms, fs, H5P_DEFAULT, dst) >= 0;
    hid_t es = keep_errors(!ok);
    if (fs >= 0)
        H5Sclose(fs);
    if (ms >= 0)
        H5Sclose(ms);
    restore_errors(es);
    return ok ? 0 : -1;
}

cdem_status cdem_h5_reader_read_series(cdem_h5_reader *r, cdem_series_sample **samples,
                                       size_t *count, cdem_error *err) {
    if (!r || !samples || !count)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_read_series: bad arguments");
    *samples = NULL;
    *count = 0;
    hid_t ds[N_SERIES];
    hsize_t dims[N_SERIES];
    cdem_status st = CDEM_OK;
    size_t opened = 0;
    /* Pass 1: every column exists, is 1-D numeric; find the common length. */
    for (; opened < N_SERIES; opened++) {
        char name[64];
        snprintf(name, sizeof name, "series/%s", series_columns[opened].name);
        ds[opened] = H5Dopen2(r->file, name, H5P_DEFAULT);
        if (ds[opened] < 0) {
            st = H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /%s is missing or corrupt", r->path,
                        name);
            break;
        }
        hid_t sp = H5Dget_space(ds[opened]), t = H5Dget_type(ds[opened]);
        int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
        dims[opened] = 0;
        if (rank == 1)
            H5Sget_simple_extent_dims(sp, &dims[opened], NULL);
        H5T_class_t cls = t >= 0 ? H5Tget_class(t) : H5T_NO_CLASS;
        if (t >= 0)
            H5Tclose(t);
        if (sp >= 0)
            H5Sclose(sp);
        if (rank != 1 || (cls != H5T_INTEGER && cls != H5T_FLOAT)) {
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: dataset /%s is not a 1-D numeric dataset (rank %d, class %d)",
                           r->path, name, rank, (int)cls);
            opened++;
            break;
        }
    }
    hsize_t len = 0;
    if (st == CDEM_OK) {
        len = dims[0];
        for (size_t c = 1; c < N_SERIES; c++) {
            if (dims[c] == len)
                continue;
            /* A writer killed inside a flush may leave columns of different lengths: keep
             * the common part. A closed file must be consistent. */
            if (!r->unclosed) {
                st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                               "%s: dataset /series/%s has %llu samples but /series/%s has %llu",
                               r->path, series_columns[c].name, (unsigned long long)dims[c],
                               series_columns[0].name, (unsigned long long)len);
                break;
            }
            if (dims[c] < len)
                len = dims[c];
        }
    }
    cdem_series_sample *out = NULL;
    void *col = NULL;
    if (st == CDEM_OK && len > ((hsize_t)1 << 32))
        st = CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: /series claims %llu samples", r->path,
                       (unsigned long long)len);
    else if (st == CDEM_OK && len > 0 &&
             (!(out = calloc((size_t)len, sizeof *out)) || !(col = malloc((size_t)len * 8))))
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading %llu series samples",
                       (unsigned long long)len);
    /* Pass 2: read the columns into the samples. */
    for (size_t c = 0; st == CDEM_OK && c < N_SERIES && len > 0; c++) {
        const series_column *sc = &series_columns[c];
        hid_t mt = sc->type == COL_I64 ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE;
        if (read_prefix(ds[c], mt, len, col) < 0) {
            st = H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot read dataset /series/%s (corrupt?)",
                        r->path, sc->name);
            break;
        }
        for (hsize_t i = 0; i < len; i++)
            memcpy((char *)&out[i] + sc->offset, (char *)col + i * 8, 8);
    }
    for (size_t c = 0; c < opened && c < N_SERIES; c++)
        if (ds[c] >= 0)
            H5Dclose(ds[c]);
    free(col);
    if (st != CDEM_OK) {
        free(out);
        return st;
    }
    *samples = out;
    *count = (size_t)len;
    return CDEM_OK;
}

const char *cdem_h5_reader_summary(const cdem_h5_reader *r) {
    return r ? r->summary : "";
}
const char *cdem_h5_reader_params_text(const cdem_h5_reader *r) {
    return r ? r->params_text : "";
}
const char *cdem_h5_reader_stop_reason(const cdem_h5_reader *r) {
    return r ? r->stop_reason : "";
}
const char *cdem_h5_reader_stop_detail(const cdem_h5_reader *r) {
    return r ? r->stop_detail : "";
}
const char *cdem_h5_reader_program_version(const cdem_h5_reader *r) {
    return r ? r->program_version : "";
}
const char *cdem_h5_reader_source(const cdem_h5_reader *r) {
    return r ? r->source : "";
}
const char *cdem_h5_reader_created(const cdem_h5_reader *r) {
    return r ? r->created : "";
}
long cdem_h5_reader_seed(const cdem_h5_reader *r) {
    return r ? r->seed : 0;
}
int cdem_h5_reader_unclosed(const cdem_h5_reader *r) {
    return r ? r->unclosed : 0;
}

cdem_status cdem_h5_reader_params(const cdem_h5_reader *r, cdem_params *p, cdem_error *err) {
    if (!r || !p)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_params: bad arguments");
    cdem_params_defaults(p);
    hid_t ds = H5Dopen2(r->file, "parameters", H5P_DEFAULT);
    if (ds < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /parameters is missing or corrupt",
                      r->path);
    size_t count = 0;
    const cdem_param_def *table = cdem_params_table(&count);
    cdem_status st = CDEM_OK;
    for (size_t i = 0; i < count && st == CDEM_OK; i++) {
        char key[128];
        snprintf(key, sizeof key, "%s.%s", table[i].section, table[i].key);
        char *value = NULL;
        int rc = get_str_attr(ds, key, &value);
        if (rc < 0) {
            st = H5FAIL(err, CDEM_ERR_FORMAT,
                        "%s: attribute /parameters %s is not a readable string", r->path, key);
        } else if (rc == 0) {
            size_t len = strlen(key) + strlen(value) + 2;
            char *assign = malloc(len);
            if (!assign) {
                st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
            } else {
                snprintf(assign, len, "%s=%s", key, value);
                st = cdem_params_override(p, assign, err);
                if (st != CDEM_OK)
                    cdem_error_prefix(err, "%s: stored parameter /parameters %s", r->path, key);
                free(assign);
            }
        }
        free(value);
    }
    H5Dclose(ds);
    return st;
}
