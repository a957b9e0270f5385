/* h5_util: the HDF5 calls every part of the run file makes, each wrapped once: error
 * reporting (HDF5's error stack becomes part of the cdem_error message; HDF5's own printing
 * is off), scalar attributes, rows of 1-D datasets, compound types from member tables, and
 * dataset creation with the project's filters.
 * Design choices a maintainer may question (docs/format.md has the measurements):
 *  - Strings are fixed-length: variable-length ones live in the global heap, which has no
 *    checksum, and HDF5 1.10 crashes on a corrupt one (only reading one is supported here).
 *  - Object time stamps are off (h5i_untimed_plist): same input, same bytes except the
 *    attribute "created".
 *  - Raw chunks carry Fletcher-32 (the element data also compressed, the index and the
 *    series not): a flipped bit is a read error, not a wrong value. */
#include "h5_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ------------------------------------------------------------------ errors */

typedef struct {
    char text[400]; /* collected HDF5 error descriptions */
    int count;      /* descriptions collected so far */
} h5_err_text;

/* HDF5 describes a failed read or write of the file as "file write failed: time = ...,
 * filename = 'run.h5.creating', file descriptor = 3, errno = 28, error message = 'No space
 * left on device', buf = 0x..., ..., bytes actually written = 18446744073709551615, ...":
 * the temporary name, pointers and a -1 printed unsigned. Only "file write failed: No space
 * left on device" says something to a user (our message names the file and what it kept).
 * Returns desc shortened that way into buf, or desc itself when it is not such a line. */
static const char *plain_h5_desc(const char *desc, char *buf, size_t cap) {
    const char *msg = strstr(desc, "error message = '");
    const char *colon = strchr(desc, ':');
    if (!msg || !colon || colon > msg)
        return desc;
    msg += strlen("error message = '");
    const char *end = strchr(msg, '\'');
    snprintf(buf, cap, "%.*s: %.*s", (int)(colon - desc), desc,
             (int)(end ? (size_t)(end - msg) : strlen(msg)), msg);
    return buf;
}

static herr_t collect_h5_error(unsigned n, const H5E_error2_t *e, void *data) {
    (void)n;
    h5_err_text *t = data;
    if (t->count >= 3 || !e->desc || !e->desc[0])
        return 0;
    size_t len = strlen(t->text);
    char plain[256];
    snprintf(t->text + len, sizeof t->text - len, "%s%s", t->count ? "; " : "",
             plain_h5_desc(e->desc, plain, sizeof plain));
    for (char *c = t->text + len; *c; c++)
        if (*c == '\n' || *c == '\r')
            *c = ' '; /* one-line messages */
    t->count++;
    return 0;
}

/* Records code with a message "<what> (HDF5: <innermost descriptions>)" and clears the
 * HDF5 error stack. Use through H5FAIL. */
cdem_status h5i_fail_at(cdem_error *err, cdem_status code, const char *file, int line,
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

/* Cleanup calls after a failure would clear HDF5's error stack (every API call resets it):
 * set it aside first (h5i_keep_errors) and put it back after (h5i_restore_errors), so H5FAIL can
 * still report it. */
hid_t h5i_keep_errors(int failed) {
    return failed ? H5Eget_current_stack() : -1;
}

void h5i_restore_errors(hid_t saved) {
    if (saved >= 0)
        H5Eset_current_stack(saved);
}

void h5i_quiet_hdf5(void) {
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

/* Called by the writer before its first HDF5 call: HDF5 1.10.8 crashes (SIGSEGV in
 * H5F__close_cb) in its atexit clean-up when a file whose H5Fclose failed (disk full,
 * file size limit) is still registered. The writer closes every file it opens itself, so
 * the clean-up is not needed; this has an effect only when HDF5 is not yet initialised. */
void h5i_writer_hdf5_init(void) {
    if (H5dont_atexit() < 0)
        H5Eclear2(H5E_DEFAULT);
    h5i_quiet_hdf5();
}

char *h5i_dup_str(const char *s) {
    size_t n = strlen(s ? s : "") + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s ? s : "", n);
    return d;
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
    hid_t es = h5i_keep_errors(!ok);
    if (a >= 0)
        H5Aclose(a);
    H5Sclose(space);
    h5i_restore_errors(es);
    return ok ? 0 : -1;
}

/* Strings are fixed-length (size strlen + 1, null-terminated, UTF-8): they live in the
 * checksummed object header. Variable-length strings would live in the global heap, which
 * has no checksum, and HDF5 1.10 crashes on a corrupt global heap. */
hid_t h5i_fixed_string_type(size_t len) {
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t < 0)
        return t;
    H5Tset_size(t, len + 1);
    H5Tset_strpad(t, H5T_STR_NULLTERM);
    H5Tset_cset(t, H5T_CSET_UTF8);
    return t;
}

int h5i_put_str_attr(hid_t obj, const char *name, const char *value) {
    const char *v = value ? value : "";
    hid_t t = h5i_fixed_string_type(strlen(v));
    int rc = t < 0 ? -1 : put_attr(obj, name, t, t, v);
    if (t >= 0)
        H5Tclose(t);
    return rc;
}

int h5i_put_i32_attr(hid_t o, const char *n, int32_t v) {
    return put_attr(o, n, H5T_STD_I32LE, H5T_NATIVE_INT32, &v);
}

int h5i_put_i64_attr(hid_t o, const char *n, int64_t v) {
    return put_attr(o, n, H5T_STD_I64LE, H5T_NATIVE_INT64, &v);
}

/* Reads a scalar numeric attribute converted to mtype. Returns 0, 1 when missing, -1 on a
 * bad type or read failure. */
int h5i_get_num_attr(hid_t obj, const char *name, hid_t mtype, void *value) {
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
    hid_t es = h5i_keep_errors(!ok);
    if (t >= 0)
        H5Tclose(t);
    if (sp >= 0)
        H5Sclose(sp);
    H5Aclose(a);
    h5i_restore_errors(es);
    return ok ? 0 : -1;
}

/* Reads a scalar string attribute (variable or fixed length) into a malloc'd string.
 * Returns 0, 1 when missing (*out = NULL), -1 on a bad type or read failure. */
int h5i_get_str_attr(hid_t obj, const char *name, char **out) {
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
            *out = h5i_dup_str(v);
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
    hid_t es = h5i_keep_errors(rc < 0);
    if (mt >= 0)
        H5Tclose(mt);
    if (t >= 0)
        H5Tclose(t);
    if (sp >= 0)
        H5Sclose(sp);
    H5Aclose(a);
    h5i_restore_errors(es);
    return rc;
}

/* Builds the memory (native, padded) or file (little-endian, packed) compound type. */
hid_t h5i_make_compound(const index_member *m, size_t nm, size_t mem_size, int file) {
    size_t size = mem_size;
    if (file) {
        size = 0;
        for (size_t i = 0; i < nm; i++)
            size += m[i].kind == IX_I32 ? 4 : 8;
    }
    hid_t t = H5Tcreate(H5T_COMPOUND, size);
    if (t < 0)
        return t;
    size_t at = 0;
    for (size_t i = 0; i < nm; i++) {
        hid_t mt;
        if (m[i].kind == IX_I32)
            mt = file ? H5T_STD_I32LE : H5T_NATIVE_INT32;
        else if (m[i].kind == IX_I64)
            mt = file ? H5T_STD_I64LE : H5T_NATIVE_INT64;
        else
            mt = file ? H5T_IEEE_F64LE : H5T_NATIVE_DOUBLE;
        if (H5Tinsert(t, m[i].name, file ? at : m[i].offset, mt) < 0) {
            H5Tclose(t);
            return -1;
        }
        at += m[i].kind == IX_I32 ? 4 : 8;
    }
    return t;
}

/* Writes count values at rows [start, start + count) of the 1-D dataset ds, extending it
 * to at least start + count. Returns 0 or -1 (HDF5 error stack kept). */
int h5i_write_rows(hid_t ds, hid_t mtype, hsize_t start, hsize_t count, const void *src) {
    if (count == 0)
        return 0;
    hsize_t total = start + count, cur = 0;
    hid_t fs = H5Dget_space(ds);
    if (fs < 0)
        return -1;
    H5Sget_simple_extent_dims(fs, &cur, NULL);
    H5Sclose(fs);
    if (cur < total && H5Dset_extent(ds, &total) < 0)
        return -1;
    hid_t ms = -1;
    fs = H5Dget_space(ds);
    int ok = fs >= 0 && H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &count, NULL) >= 0 &&
             (ms = H5Screate_simple(1, &count, NULL)) >= 0 &&
             H5Dwrite(ds, mtype, ms, fs, H5P_DEFAULT, src) >= 0;
    hid_t es = h5i_keep_errors(!ok);
    if (fs >= 0)
        H5Sclose(fs);
    if (ms >= 0)
        H5Sclose(ms);
    h5i_restore_errors(es);
    return ok ? 0 : -1;
}

/* Reads count values at rows [start, start + count) of the 1-D dataset ds. */
int h5i_read_rows(hid_t ds, hid_t mtype, hsize_t start, hsize_t count, void *dst) {
    if (count == 0)
        return 0;
    hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(1, &count, NULL);
    int ok = fs >= 0 && ms >= 0 &&
             H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &count, NULL) >= 0 &&
             H5Dread(ds, mtype, ms, fs, H5P_DEFAULT, dst) >= 0;
    hid_t es = h5i_keep_errors(!ok);
    if (fs >= 0)
        H5Sclose(fs);
    if (ms >= 0)
        H5Sclose(ms);
    h5i_restore_errors(es);
    return ok ? 0 : -1;
}

/* Reads rows [0, n) of a compound dataset with memory type mt; 0 or -1. */
int h5i_read_all_rows(hid_t ds, hid_t mt, hsize_t n, void *dst) {
    return h5i_read_rows(ds, mt, 0, n, dst);
}

/* The length of the 1-D dataset ds (0 when it is not 1-D or cannot be read). */
hsize_t h5i_extent_of(hid_t ds) {
    hsize_t n = 0;
    hid_t sp = H5Dget_space(ds);
    if (sp >= 0) {
        if (H5Sget_simple_extent_ndims(sp) == 1)
            H5Sget_simple_extent_dims(sp, &n, NULL);
        H5Sclose(sp);
    }
    return n;
}

/* Object creation property list with time stamps off (deterministic bytes). */
hid_t h5i_untimed_plist(hid_t cls) {
    hid_t p = H5Pcreate(cls);
    if (p >= 0)
        H5Pset_obj_track_times(p, 0);
    return p;
}

/* Creates an empty extendible 1-D dataset loc/name with the given filters. */
hid_t h5i_create_extendible(hid_t loc, const char *name, hid_t ftype, hsize_t chunk,
                            dataset_filter filter) {
    hsize_t zero = 0, unlimited = H5S_UNLIMITED;
    hid_t sp = H5Screate_simple(1, &zero, &unlimited);
    hid_t dcpl = h5i_untimed_plist(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, 1, &chunk);
    H5Pset_dset_no_attrs_hint(dcpl, 1);
    H5Pset_fill_time(dcpl, filter != FILTER_NONE ? H5D_FILL_TIME_ALLOC : H5D_FILL_TIME_NEVER);
    if (filter == FILTER_COMPRESS) {
        H5Pset_shuffle(dcpl);
        H5Pset_deflate(dcpl, DEFLATE_LEVEL);
    }
    if (filter != FILTER_NONE)
        H5Pset_fletcher32(dcpl);
    hid_t ds = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    hid_t es = h5i_keep_errors(ds < 0);
    H5Pclose(dcpl);
    H5Sclose(sp);
    h5i_restore_errors(es);
    return ds;
}

/* A fixed-size contiguous dataset allocated at creation (overwriting it never grows the
 * file, so it can be written even when the disk is full). */
hid_t h5i_create_fixed(hid_t loc, const char *name, hid_t ftype, hsize_t n) {
    hid_t sp = n ? H5Screate_simple(1, &n, NULL) : H5Screate(H5S_SCALAR);
    hid_t dcpl = h5i_untimed_plist(H5P_DATASET_CREATE);
    H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY);
    H5Pset_fill_time(dcpl, H5D_FILL_TIME_ALLOC);
    hid_t ds = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    hid_t es = h5i_keep_errors(ds < 0);
    H5Pclose(dcpl);
    H5Sclose(sp);
    h5i_restore_errors(es);
    return ds;
}

int h5i_write_fixed_string(hid_t ds, size_t width, const char *text) {
    char buf[STOP_DETAIL_LEN];
    memset(buf, 0, sizeof buf);
    snprintf(buf, width < sizeof buf ? width : sizeof buf, "%s", text ? text : "");
    hid_t t = h5i_fixed_string_type(width - 1);
    int rc = t >= 0 && H5Dwrite(ds, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0 ? 0 : -1;
    hid_t es = h5i_keep_errors(rc < 0);
    if (t >= 0)
        H5Tclose(t);
    h5i_restore_errors(es);
    return rc;
}

/* Length of the valid UTF-8 sequence of one printable character at p (0 when there is
 * none): no overlong forms, no surrogates, nothing above U+10FFFF, no control characters
 * (C0, DEL, C1). */
static size_t printable_utf8(const unsigned char *p) {
    if (p[0] >= 0x20 && p[0] < 0x7f)
        return 1;
    size_t len = p[0] >= 0xc2 && p[0] <= 0xdf   ? 2
                 : p[0] >= 0xe0 && p[0] <= 0xef ? 3
                 : p[0] >= 0xf0 && p[0] <= 0xf4 ? 4
                                                : 0;
    if (!len)
        return 0;
    uint32_t cp = p[0] & (0x7f >> len);
    for (size_t k = 1; k < len; k++) {
        if ((p[k] & 0xc0) != 0x80)
            return 0; /* also stops at the terminating NUL */
        cp = cp << 6 | (p[k] & 0x3f);
    }
    static const uint32_t least[5] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < least[len] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff) || cp < 0xa0)
        return 0;
    return len;
}

char *h5i_printable(const char *text) {
    const unsigned char *p = (const unsigned char *)text;
    char *out = malloc(4 * strlen(text) + 1), *o = out;
    if (!out)
        return NULL;
    while (*p) {
        size_t len = *p == '\n' || *p == '\t' ? 1 : printable_utf8(p);
        if (len) {
            memcpy(o, p, len);
            o += len;
            p += len;
        } else {
            o += sprintf(o, "\\x%02X", *p++);
        }
    }
    *o = '\0';
    return out;
}

/* "integer", "float", ... for messages. */
const char *h5i_class_name(H5T_class_t c) {
    return c == H5T_INTEGER    ? "integer"
           : c == H5T_FLOAT    ? "float"
           : c == H5T_STRING   ? "string"
           : c == H5T_COMPOUND ? "compound"
           : c == H5T_ARRAY    ? "array"
                               : "other";
}

/* Reads rows [0, n) of a checksummed dataset. A live writer rewrites the last chunk of the
 * index and of the series in place at every append, so a SWMR reader can catch a chunk
 * half-written, and its Fletcher-32 check then fails: such a read is tried again a few times
 * (about 0.6 s in all); a file without a live writer is read once. 0 or -1. */
int h5i_read_rows_retrying(int swmr, hid_t ds, hid_t mt, hsize_t n, void *dst) {
    for (int attempt = 0;; attempt++) {
        if (h5i_read_all_rows(ds, mt, n, dst) == 0)
            return 0;
        if (!swmr || attempt >= 6)
            return -1;
        H5Eclear2(H5E_DEFAULT);
        struct timespec ts = {0, (long)(10 * 1000 * 1000) << attempt}; /* 10 .. 320 ms */
        nanosleep(&ts, NULL);
    }
}
