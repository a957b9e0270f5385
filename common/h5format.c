/* h5format: see h5format.h; docs/format.md is the authority on the layout.
 *
 * Design notes a maintainer may question (docs/format.md has the measurements):
 *  - Files are V110 (superblock v3, object header v2): every piece of metadata carries a
 *    checksum, so flipped bytes fail a checksum instead of being parsed. Raw chunks carry
 *    Fletcher-32 (the element data also compressed, the index and the series not). Strings are
 *    fixed-length: variable-length ones live in the global heap, which has no checksum, and
 *    HDF5 1.10 crashes on a corrupt one.
 *  - Version 2 is SWMR: all objects are created first (HDF5 1.10 forbids creating objects in
 *    SWMR-write mode), then the file is only appended to. The index row of an increment is
 *    written, flushed and synced (fdatasync) after its data, itself flushed and synced: the
 *    commit record, which survives a power cut too.
 *  - A writer holds the path's lock (runlock.h) for its whole life: one writer per path,
 *    and readers can tell a running writer from a dead one.
 *  - Each increment starts at a chunk boundary, so compressed chunks are written once.
 *  - The reader reads the superblock's status flags itself: SWMR-read (with bounded metadata
 *    retries) while a writer holds the lock, otherwise the file is complete and opened as
 *    one ("clear_status_flags" and "skip_eof_check", read-only, what h5clear uses): HDF5's
 *    SWMR retries never end on a damaged file. It also compares the superblock's end-of-file
 *    with the real size, which catches truncation before HDF5 parses anything.
 *  - Object time stamps are off: same input, same bytes except the attribute "created".
 *  - HDF5's error printing is off; its error stack becomes part of cdem_error messages.
 *  - append_series is called from the time-step loop: it never allocates (fixed buffer). */
/* renameat2 (RENAME_NOREPLACE): never replace a file that appeared meanwhile */
#define _GNU_SOURCE
#include "h5format.h"
#include "xdmf.h"

#include "runlock.h"

#include <hdf5.h>

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

/* Compression settings, chosen by measurement (docs/format.md, "Size"): deflate level 4
 * after byte shuffle; levels 6 and 9 saved 0.2 % more for 20-30 % more CPU. Per-increment
 * datasets are one chunk up to CHUNK_ELEMS elements (8192 doubles = 64 KiB). */
#define DEFLATE_LEVEL   4
#define CHUNK_ELEMS     8192
#define SERIES_CHUNK    512
#define SERIES_BUFFER   256
#define XMF_EVERY_LIMIT 1000
#define INDEX_CHUNK     256       /* rows of /increments/index per chunk */
#define CKPT_CHUNK      (1 << 20) /* bytes of a checkpoint slot per chunk */
/* Largest element count a reader accepts (ids are int32). */
#define MAX_ELEMENTS ((hsize_t)INT32_MAX)
/* Largest element count an increment may have to be loaded (~2 GB of state; cdem-run's
 * largest model has ~10^5 elements): a corrupt count is refused before allocating. */
#define READER_MAX_ELEMENTS ((hsize_t)20000000)
/* Metadata read attempts of a SWMR reader (reader_setup): HDF5 sleeps 1, 2, 4, ... ns
 * between attempts, so n attempts wait about 2^n ns in all before a read fails: 28 wait
 * 0.27 s (measured: a damaged file fails after 0.3 s at 28, 1.1 s at 30, 4.3 s at 32), about
 * 10^5 times longer than a writer takes to write the piece of metadata a reader may have
 * caught half-written. */
#define SWMR_READ_ATTEMPTS 28

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

/* Called by the writer before its first HDF5 call: HDF5 1.10.8 crashes (SIGSEGV in
 * H5F__close_cb) in its atexit clean-up when a file whose H5Fclose failed (disk full,
 * file size limit) is still registered. The writer closes every file it opens itself, so
 * the clean-up is not needed; this has an effect only when HDF5 is not yet initialised. */
static void writer_hdf5_init(void) {
    if (H5dont_atexit() < 0)
        H5Eclear2(H5E_DEFAULT);
    quiet_hdf5();
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

/* Per-element datasets of an increment: the rows of CDEM_STATE_FIELDS (state.h) marked
 * in_increments, in table order (velocities, forces and masses live only in checkpoints).
 * The list is built by the preprocessor so that its length is a compile-time constant. */
typedef struct {
    const char *name;     /* dataset name in the increment group */
    const char *path;     /* "/increments/<name>" */
    cdem_field_type type; /* stored and memory type */
    int optional;         /* 1: stress, present only with has_stress */
    size_t offset;        /* of the array pointer in cdem_state */
} element_field;

#define IF_IN_INCREMENTS_0(...)
#define IF_IN_INCREMENTS_1(...) __VA_ARGS__
#define INCREMENT_FIELD(name, ctype, ftype, in_increments, stress)                                 \
    IF_IN_INCREMENTS_##in_increments(                                                              \
        {#name, "/increments/" #name, ftype, stress, offsetof(cdem_state, name)}, )
static const element_field element_fields[] = {CDEM_STATE_FIELDS(INCREMENT_FIELD)};
#undef INCREMENT_FIELD
#define N_ELEMENT_FIELDS (sizeof element_fields / sizeof element_fields[0])

/* The array of element field k in s. */
static void *element_array(const cdem_state *s, size_t k) {
    void *p;
    memcpy(&p, (const char *)s + element_fields[k].offset, sizeof p);
    return p;
}

/* Index of the first stress field (the stress datasets share one extent). */
static size_t first_stress_field(void) {
    size_t k = 0;
    while (k < N_ELEMENT_FIELDS && !element_fields[k].optional)
        k++;
    return k;
}

static const char *xdmf_number_type(cdem_field_type t) {
    return t == CDEM_FIELD_I32 ? "Int" : t == CDEM_FIELD_U32 ? "UInt" : "Float";
}

static hid_t el_file_type(cdem_field_type t) {
    return t == CDEM_FIELD_I32   ? H5T_STD_I32LE
           : t == CDEM_FIELD_U32 ? H5T_STD_U32LE
                                 : H5T_IEEE_F64LE;
}
static hid_t el_mem_type(cdem_field_type t) {
    return t == CDEM_FIELD_I32   ? H5T_NATIVE_INT32
           : t == CDEM_FIELD_U32 ? H5T_NATIVE_UINT32
                                 : H5T_NATIVE_DOUBLE;
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

/* ------------------------------------------------------------------ writer */

/* One row of /increments/index (memory layout; the file type is packed little-endian). */
typedef struct {
    int32_t number;             /* increment number */
    int32_t phase;              /* cdem_phase */
    int64_t step;               /* time step */
    double time;                /* s */
    double net_displacement;    /* m */
    double axial_strain;        /* - */
    double differential_stress; /* N/m */
    double sea_level;           /* m, NaN when none */
    int64_t offset;             /* first row of this increment in the element datasets */
    int64_t n;                  /* element count */
    int32_t has_stress;         /* 1: rows stress_offset.. of sxx, syy, sxy belong to it */
    int64_t stress_offset;      /* first row in sxx, syy, sxy (-1 without stress) */
} index_row;

typedef enum { IX_I32, IX_I64, IX_F64 } ix_kind;
typedef struct {
    const char *name; /* compound member name */
    size_t offset;    /* offsetof(index_row, field) */
    ix_kind kind;     /* member type */
} index_member;

#define IXM(field, kind)                                                                           \
    { #field, offsetof(index_row, field), kind }
static const index_member index_members[] = {
    IXM(number, IX_I32),
    IXM(step, IX_I64),
    IXM(time, IX_F64),
    IXM(phase, IX_I32),
    IXM(net_displacement, IX_F64),
    IXM(axial_strain, IX_F64),
    IXM(differential_stress, IX_F64),
    IXM(sea_level, IX_F64),
    IXM(offset, IX_I64),
    IXM(n, IX_I64),
    IXM(has_stress, IX_I32),
    IXM(stress_offset, IX_I64),
};
#undef IXM
#define N_INDEX_MEMBERS (sizeof index_members / sizeof index_members[0])

/* One row of /checkpoint/index (one per slot). */
typedef struct {
    int64_t sequence;  /* 0: slot never written; larger = newer */
    int32_t increment; /* increment the checkpoint belongs to */
    int64_t step;      /* time step of that increment */
    int64_t length;    /* bytes of the blob in the slot */
    uint64_t checksum; /* FNV-1a 64 of those bytes */
} ckpt_row;

#define CKM(field, kind)                                                                           \
    { #field, offsetof(ckpt_row, field), kind }
static const index_member ckpt_members[] = {
    CKM(sequence, IX_I64), CKM(increment, IX_I32), CKM(step, IX_I64),
    CKM(length, IX_I64),   CKM(checksum, IX_I64),
};
#undef CKM
#define N_CKPT_MEMBERS (sizeof ckpt_members / sizeof ckpt_members[0])

/* Builds the memory (native, padded) or file (little-endian, packed) compound type. */
static hid_t make_compound(const index_member *m, size_t nm, size_t mem_size, int file) {
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

/* FNV-1a, 64 bit: detects torn or corrupted checkpoint blobs. */
static uint64_t fnv1a64(const unsigned char *p, size_t n) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

typedef struct {
    int32_t number;        /* increment number */
    double time;           /* s */
    int64_t n;             /* element count */
    int has_stress;        /* 1: sxx, syy, sxy stored */
    int64_t offset;        /* first row in the element datasets */
    int64_t stress_offset; /* first row in sxx, syy, sxy */
} xmf_entry;

#define STOP_REASON_LEN 64   /* bytes of /stop_reason (with the NUL) */
#define STOP_DETAIL_LEN 2048 /* bytes of /stop_detail (with the NUL) */

struct cdem_h5_writer {
    hid_t file;                     /* open HDF5 file (SWMR write mode once set up) */
    hid_t data[N_ELEMENT_FIELDS];   /* /increments/<field> */
    hid_t index;                    /* /increments/index */
    hid_t index_mtype;              /* memory type of index_row */
    hid_t series[N_SERIES];         /* /series/<column> datasets */
    hid_t stop_reason, stop_detail; /* /stop_reason, /stop_detail */
    hid_t ckpt_data[2];             /* /checkpoint/slot0, slot1 */
    hid_t ckpt_index;               /* /checkpoint/index, 2 rows */
    hid_t ckpt_mtype;               /* memory type of ckpt_row */
    char *path;                     /* the .h5 path as given */
    char *xmf_path;                 /* sidecar path */
    const char *h5_name;            /* basename of path, referenced from the sidecar */
    cdem_series_sample *buf;        /* SERIES_BUFFER buffered samples */
    size_t nbuf;                    /* samples in buf */
    void *column;                   /* SERIES_BUFFER * 8 bytes: one column being written */
    hsize_t series_len;             /* samples already in the file */
    hsize_t data_len;               /* first row of the next increment in id..born (a chunk
                                       boundary) */
    hsize_t stress_len;             /* the same in sxx, syy, sxy */
    hsize_t data_ext, stress_ext;   /* current extents of id..born and of sxx, syy, sxy */
    hsize_t index_len;              /* rows in /increments/index */
    int32_t last_number;            /* number of the last increment written (-1: none) */
    int64_t last_step;              /* its step */
    ckpt_row ckpt[2];               /* the checkpoint index as on disk */
    unsigned char *ckpt_buf;        /* serialised snapshot, grown as needed */
    size_t ckpt_cap;                /* bytes allocated in ckpt_buf */
    int failed;                     /* 1 after a failed write: the file keeps what it had */
    xmf_entry *entries;             /* one per written increment, in write order */
    size_t n_entries, cap_entries;  /* used / allocated entries */
    size_t xmf_written;             /* entries in the sidecar on disk */
    int has_xy;                     /* 1: /increments/xy exists (XDMF 3 sidecar) */
    cdem_runlock *lock;             /* the path's lock (PATH.lock), held until close */
    int sync;                       /* 1: sync (fdatasync) every commit (_set_sync) */
    int placed;                     /* 1 once the file is at path (before: PATH.creating) */
};

static cdem_status flush_file(cdem_h5_writer *w, cdem_error *err) {
    if (H5Fflush(w->file, H5F_SCOPE_GLOBAL) < 0) {
        w->failed = 1;
        if (!w->placed)
            return H5FAIL(err, CDEM_ERR_IO,
                          "%s: cannot create the run file: writing it (as %s.creating) failed "
                          "(disk full?); that temporary file was removed and nothing was "
                          "replaced",
                          w->path, w->path);
        return H5FAIL(err, CDEM_ERR_IO,
                      "%s: cannot flush the file (disk full?); the file keeps the %llu "
                      "increments completed before",
                      w->path, (unsigned long long)w->index_len);
    }
    return CDEM_OK;
}

/* H5Fflush hands the bytes to the operating system, which may keep them in memory for
 * seconds: a killed process loses nothing, a power cut may lose the commit record or, worse,
 * keep the record and lose the data it points to (the kernel writes pages in any order).
 * A sync after the data and again after the record orders them on the disk. fdatasync, not
 * fsync: it writes the data and the metadata needed to read it back (the file's size), not
 * the time stamps, which saves a journal commit where nothing else changed. */
static cdem_status sync_file(cdem_h5_writer *w, cdem_error *err) {
    if (!w->sync)
        return CDEM_OK;
    void *handle = NULL;
    if (H5Fget_vfd_handle(w->file, H5P_DEFAULT, &handle) < 0 || !handle) {
        w->failed = 1;
        return H5FAIL(err, CDEM_ERR_IO,
                      "%s: cannot reach the file's descriptor to flush it to disk; the file keeps "
                      "the %llu increments completed before",
                      w->path, (unsigned long long)w->index_len);
    }
    int fd = *(int *)handle; /* the default (sec2) driver's handle is its descriptor */
    if (fdatasync(fd) != 0 && errno != EINVAL && errno != EROFS) {
        w->failed = 1;
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: cannot flush the file to disk: %s; the file keeps the %llu "
                         "increments committed before",
                         w->path, strerror(errno), (unsigned long long)w->index_len);
    }
    return CDEM_OK;
}

/* flush_file, then to stable storage when durability is on. */
static cdem_status commit_flush(cdem_h5_writer *w, cdem_error *err) {
    CDEM_TRY(flush_file(w, err));
    return sync_file(w, err);
}

/* After a rename, the directory entry is durable only once the folder is synced. */
static void sync_folder_of(const char *path) {
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        if (fsync(fd) != 0)
            errno = 0; /* best effort: some filesystems refuse fsync on folders */
        close(fd);
    }
}

void cdem_h5_writer_set_sync(cdem_h5_writer *w, int sync) {
    if (w)
        w->sync = sync ? 1 : 0;
}

/* Writes count values at rows [start, start + count) of the 1-D dataset ds, extending it
 * to at least start + count. Returns 0 or -1 (HDF5 error stack kept). */
static int write_rows(hid_t ds, hid_t mtype, hsize_t start, hsize_t count, const void *src) {
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
    hid_t es = keep_errors(!ok);
    if (fs >= 0)
        H5Sclose(fs);
    if (ms >= 0)
        H5Sclose(ms);
    restore_errors(es);
    return ok ? 0 : -1;
}

/* Reads count values at rows [start, start + count) of the 1-D dataset ds. */
static int read_rows(hid_t ds, hid_t mtype, hsize_t start, hsize_t count, void *dst) {
    if (count == 0)
        return 0;
    hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(1, &count, NULL);
    int ok = fs >= 0 && ms >= 0 &&
             H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &count, NULL) >= 0 &&
             H5Dread(ds, mtype, ms, fs, H5P_DEFAULT, dst) >= 0;
    hid_t es = keep_errors(!ok);
    if (fs >= 0)
        H5Sclose(fs);
    if (ms >= 0)
        H5Sclose(ms);
    restore_errors(es);
    return ok ? 0 : -1;
}

/* Reads rows [0, n) of a compound dataset with memory type mt; 0 or -1. */
static int read_all_rows(hid_t ds, hid_t mt, hsize_t n, void *dst) {
    return read_rows(ds, mt, 0, n, dst);
}

/* Checks one index row against the previous row (NULL for the first) and the extents of
 * the element datasets; NULL when it is valid, otherwise what is wrong. Files written
 * before the index carried a checksum (Fletcher-32) rely on these checks alone: a flipped
 * bit gave a time of 461 s in a 220 s run, or a net displacement of 5.7e78 m. */
static const char *bad_index_row(const index_row *row, const index_row *prev, hsize_t data_ext,
                                 hsize_t stress_ext) {
    if (row->number < 0 || (prev && row->number <= prev->number))
        return "increment numbers must be >= 0 and increasing";
    if (row->step < 0 || (prev && row->step < prev->step))
        return "its step is negative or smaller than the previous increment's";
    if (!isfinite(row->time) || row->time < 0.0 || (prev && row->time < prev->time))
        return "its time is not a finite number of seconds, >= 0 and >= the previous "
               "increment's";
    if (row->phase < CDEM_PHASE_EQUILIBRATION || row->phase > CDEM_PHASE_SETTLING)
        return "its phase is not 0, 1 or 2";
    if (!isfinite(row->net_displacement) || !isfinite(row->axial_strain) ||
        !isfinite(row->differential_stress) || isinf(row->sea_level))
        return "its net displacement, axial strain, differential stress or sea level is not a "
               "finite number";
    if (row->n < 0 || (hsize_t)row->n > MAX_ELEMENTS)
        return "element count n out of range";
    if (row->offset < 0 || (hsize_t)row->offset > data_ext ||
        (hsize_t)row->n > data_ext - (hsize_t)row->offset)
        return "rows offset..offset+n lie beyond the element datasets";
    if (row->has_stress != 0 && row->has_stress != 1)
        return "has_stress is neither 0 nor 1";
    if (row->has_stress && (row->stress_offset < 0 || (hsize_t)row->stress_offset > stress_ext ||
                            (hsize_t)row->n > stress_ext - (hsize_t)row->stress_offset))
        return "rows stress_offset..stress_offset+n lie beyond sxx, syy, sxy";
    return NULL;
}

static hsize_t extent_of(hid_t ds) {
    hsize_t n = 0;
    hid_t sp = H5Dget_space(ds);
    if (sp >= 0) {
        if (H5Sget_simple_extent_ndims(sp) == 1)
            H5Sget_simple_extent_dims(sp, &n, NULL);
        H5Sclose(sp);
    }
    return n;
}

/* Each increment starts at a chunk boundary of the element datasets, so every compressed
 * chunk is written once and never rewritten (rewriting a partly filled compressed chunk
 * at every append moves it and, in SWMR mode, leaves the old space unused: the file grew
 * 2.4-fold). The padding rows belong to no increment and compress to almost nothing. */
static hsize_t chunk_end(hsize_t rows) {
    return (rows + CHUNK_ELEMS - 1) / CHUNK_ELEMS * CHUNK_ELEMS;
}

/* Writes the buffered series samples (appending to every /series dataset). */
static cdem_status flush_series(cdem_h5_writer *w, cdem_error *err) {
    if (w->nbuf == 0)
        return CDEM_OK;
    for (size_t c = 0; c < N_SERIES; c++) {
        const series_column *col = &series_columns[c];
        for (size_t i = 0; i < w->nbuf; i++) {
            const char *src = (const char *)&w->buf[i] + col->offset;
            memcpy((char *)w->column + i * 8, src, 8);
        }
        if (write_rows(w->series[c], col->type == COL_I64 ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE,
                       w->series_len, w->nbuf, w->column) < 0) {
            w->failed = 1;
            return H5FAIL(err, CDEM_ERR_IO,
                          "%s: cannot append %zu samples to /series/%s (disk full?)", w->path,
                          w->nbuf, col->name);
        }
    }
    w->series_len += w->nbuf;
    w->nbuf = 0;
    return CDEM_OK;
}

/* ------------------------------------------------------------------ XDMF sidecar */
/* The attributes of a grid, in sidecar order (names of element_fields). */
static const char *const xmf_attributes[] = {"radius", "layer", "id",  "flags",
                                             "born",   "sxx",   "syy", "sxy"};

static const element_field *element_field_named(const char *name) {
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        if (!strcmp(element_fields[k].name, name))
            return &element_fields[k];
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
static cdem_status write_xmf(cdem_h5_writer *w, cdem_error *err) {
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

/* Filters of an extendible dataset. */
typedef enum {
    FILTER_NONE,     /* raw chunks (checkpoint slots: the blob carries its own checksum) */
    FILTER_COMPRESS, /* byte shuffle + deflate + Fletcher-32 (element data) */
    FILTER_CHECKSUM, /* Fletcher-32 only (index, series): a flipped bit is a read error, not
                        a time of 461 s in a 220 s run; the filtered chunk keeps its size
                        (data + 4 bytes), so HDF5 still rewrites it in place on append */
} dataset_filter;

/* Creates an empty extendible 1-D dataset loc/name with the given filters. */
static hid_t create_extendible(hid_t loc, const char *name, hid_t ftype, hsize_t chunk,
                               dataset_filter filter) {
    hsize_t zero = 0, unlimited = H5S_UNLIMITED;
    hid_t sp = H5Screate_simple(1, &zero, &unlimited);
    hid_t dcpl = untimed_plist(H5P_DATASET_CREATE);
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
    hid_t es = keep_errors(ds < 0);
    H5Pclose(dcpl);
    H5Sclose(sp);
    restore_errors(es);
    return ds;
}

/* A fixed-size contiguous dataset allocated at creation (overwriting it never grows the
 * file, so it can be written even when the disk is full). */
static hid_t create_fixed(hid_t loc, const char *name, hid_t ftype, hsize_t n) {
    hid_t sp = n ? H5Screate_simple(1, &n, NULL) : H5Screate(H5S_SCALAR);
    hid_t dcpl = untimed_plist(H5P_DATASET_CREATE);
    H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY);
    H5Pset_fill_time(dcpl, H5D_FILL_TIME_ALLOC);
    hid_t ds = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    hid_t es = keep_errors(ds < 0);
    H5Pclose(dcpl);
    H5Sclose(sp);
    restore_errors(es);
    return ds;
}

static int write_fixed_string(hid_t ds, size_t width, const char *text) {
    char buf[STOP_DETAIL_LEN];
    memset(buf, 0, sizeof buf);
    snprintf(buf, width < sizeof buf ? width : sizeof buf, "%s", text ? text : "");
    hid_t t = fixed_string_type(width - 1);
    int rc = t >= 0 && H5Dwrite(ds, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0 ? 0 : -1;
    hid_t es = keep_errors(rc < 0);
    if (t >= 0)
        H5Tclose(t);
    restore_errors(es);
    return rc;
}

static cdem_status create_layout(cdem_h5_writer *w, cdem_error *err) {
    hid_t gcpl = untimed_plist(H5P_GROUP_CREATE);
    hid_t gs = H5Gcreate2(w->file, "series", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    hid_t gi = H5Gcreate2(w->file, "increments", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    hid_t gc = H5Gcreate2(w->file, "checkpoint", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    H5Pclose(gcpl);
    cdem_status st = CDEM_OK;
    if (gs < 0 || gi < 0 || gc < 0)
        st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create the groups", w->path);
    for (size_t c = 0; st == CDEM_OK && c < N_SERIES; c++) {
        hid_t ft = series_columns[c].type == COL_I64 ? H5T_STD_I64LE : H5T_IEEE_F64LE;
        w->series[c] =
            create_extendible(gs, series_columns[c].name, ft, SERIES_CHUNK, FILTER_CHECKSUM);
        if (w->series[c] < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create dataset /series/%s", w->path,
                        series_columns[c].name);
    }
    for (size_t k = 0; st == CDEM_OK && k < N_ELEMENT_FIELDS; k++) {
        const element_field *fd = &element_fields[k];
        w->data[k] =
            create_extendible(gi, fd->name, el_file_type(fd->type), CHUNK_ELEMS, FILTER_COMPRESS);
        if (w->data[k] < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create dataset /increments/%s", w->path,
                        fd->name);
    }
    if (st == CDEM_OK) { /* for the XDMF 3 sidecar; no storage (xdmf.h) */
        hid_t xy = cdem_xdmf_create_xy_view(gi, "/increments/x", "/increments/y", "xy", 1);
        if (xy < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create the view /increments/xy", w->path);
        else
            H5Dclose(xy);
        w->has_xy = xy >= 0;
    }
    hid_t ft = -1;
    if (st == CDEM_OK) {
        ft = make_compound(index_members, N_INDEX_MEMBERS, sizeof(index_row), 1);
        w->index = ft >= 0 ? create_extendible(gi, "index", ft, INDEX_CHUNK, FILTER_CHECKSUM) : -1;
        if (w->index < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create dataset /increments/index", w->path);
        if (ft >= 0)
            H5Tclose(ft);
    }
    if (st == CDEM_OK) {
        ft = make_compound(ckpt_members, N_CKPT_MEMBERS, sizeof(ckpt_row), 1);
        w->ckpt_index = ft >= 0 ? create_fixed(gc, "index", ft, 2) : -1;
        w->ckpt_data[0] = create_extendible(gc, "slot0", H5T_STD_U8LE, CKPT_CHUNK, FILTER_NONE);
        w->ckpt_data[1] = create_extendible(gc, "slot1", H5T_STD_U8LE, CKPT_CHUNK, FILTER_NONE);
        if (w->ckpt_index < 0 || w->ckpt_data[0] < 0 || w->ckpt_data[1] < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create the /checkpoint datasets", w->path);
        if (ft >= 0)
            H5Tclose(ft);
    }
    if (st == CDEM_OK) {
        hid_t tr = fixed_string_type(STOP_REASON_LEN - 1),
              td = fixed_string_type(STOP_DETAIL_LEN - 1);
        w->stop_reason = create_fixed(w->file, "stop_reason", tr, 0);
        w->stop_detail = create_fixed(w->file, "stop_detail", td, 0);
        H5Tclose(tr);
        H5Tclose(td);
        if (w->stop_reason < 0 || w->stop_detail < 0 ||
            write_fixed_string(w->stop_reason, STOP_REASON_LEN, "running") < 0 ||
            write_fixed_string(w->stop_detail, STOP_DETAIL_LEN, "") < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create /stop_reason and /stop_detail",
                        w->path);
    }
    if (gs >= 0)
        H5Gclose(gs);
    if (gi >= 0)
        H5Gclose(gi);
    if (gc >= 0)
        H5Gclose(gc);
    return st;
}

static void writer_release(cdem_h5_writer *w) {
    hid_t ds[N_SERIES + N_ELEMENT_FIELDS + 6];
    size_t n = 0;
    for (size_t c = 0; c < N_SERIES; c++)
        ds[n++] = w->series[c];
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        ds[n++] = w->data[k];
    ds[n++] = w->index;
    ds[n++] = w->stop_reason;
    ds[n++] = w->stop_detail;
    ds[n++] = w->ckpt_data[0];
    ds[n++] = w->ckpt_data[1];
    ds[n++] = w->ckpt_index;
    for (size_t i = 0; i < n; i++)
        if (ds[i] >= 0)
            H5Dclose(ds[i]);
    if (w->index_mtype >= 0)
        H5Tclose(w->index_mtype);
    if (w->ckpt_mtype >= 0)
        H5Tclose(w->ckpt_mtype);
    if (w->file >= 0)
        H5Fclose(w->file);
    cdem_runlock_release(w->lock); /* last: nothing of ours is touched after this */
    free(w->path);
    free(w->xmf_path);
    free(w->buf);
    free(w->column);
    free(w->entries);
    free(w->ckpt_buf);
    free(w);
}

static hid_t writer_fapl(void) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_libver_bounds(fapl, H5F_LIBVER_V110, H5F_LIBVER_V110);
    return fapl;
}

static cdem_status start_swmr(cdem_h5_writer *w, cdem_error *err) {
    if (H5Fstart_swmr_write(w->file) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot enter single-writer/multiple-reader mode",
                      w->path);
    return CDEM_OK;
}

/* Puts tmp at path: rename when an existing file may be replaced (replace = 1), otherwise
 * a rename that fails instead of replacing a file that appeared after the checks. */
static int put_in_place(const char *tmp, const char *path, int replace) {
    if (replace)
        return rename(tmp, path);
    if (renameat2(AT_FDCWD, tmp, AT_FDCWD, path, RENAME_NOREPLACE) == 0)
        return 0;
    if (errno != EINVAL && errno != ENOSYS)
        return -1;
    /* a filesystem without RENAME_NOREPLACE: a hard link fails on an existing name too */
    if (link(tmp, path) != 0)
        return -1;
    return unlink(tmp) == 0 || errno == ENOENT ? 0 : -1;
}

/* The file is built under a temporary name (tmp) and renamed to w->path once its layout
 * is complete and SWMR writing has started: whatever is found at w->path opens.
 * replace: 1 when a file at w->path may be replaced (it was checked under the lock). */
static cdem_status writer_setup(cdem_h5_writer *w, const cdem_run_meta *meta, const char *tmp,
                                int replace, cdem_error *err) {
    hid_t fapl = writer_fapl();
    hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
    /* EXCL: the stale tmp of a killed run was removed under the lock; anything there now is
     * not ours to truncate */
    w->file = H5Fcreate(tmp, H5F_ACC_EXCL, fcpl, fapl);
    hid_t es = keep_errors(w->file < 0);
    H5Pclose(fapl);
    H5Pclose(fcpl);
    restore_errors(es);
    if (w->file < 0)
        return H5FAIL(err, CDEM_ERR_IO,
                      "%s: cannot create the run file (as the temporary %s); nothing was written",
                      w->path, tmp);

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
        put_str_attr(root, "params_text", meta->params_text) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot write the root attributes", w->path);
    CDEM_TRY(write_parameters(w, meta->params, err));
    CDEM_TRY(create_layout(w, err));
    CDEM_TRY(flush_file(w, err));
    CDEM_TRY(start_swmr(w, err));
    CDEM_TRY(commit_flush(w, err));
    if (put_in_place(tmp, w->path, replace) != 0) {
        int e = errno;
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: cannot put the new run file in place (rename from %s): %s%s; "
                         "nothing was replaced",
                         w->path, tmp, strerror(e),
                         e == EEXIST ? " (a file appeared there while the run was set up)" : "");
    }
    w->placed = 1;
    if (w->sync)
        sync_folder_of(w->path);
    return write_xmf(w, err);
}

static cdem_status check_replace(const char *path, cdem_h5_replace policy, int *replace,
                                 cdem_error *err);

/* Allocates a writer with every handle unset. */
static cdem_status writer_alloc(const char *path, cdem_h5_writer **out, cdem_error *err) {
    cdem_h5_writer *w = calloc(1, sizeof *w);
    if (!w)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory creating a writer for %s", path);
    w->file = w->index = w->index_mtype = w->stop_reason = w->stop_detail = -1;
    w->ckpt_data[0] = w->ckpt_data[1] = w->ckpt_index = w->ckpt_mtype = -1;
    for (size_t c = 0; c < N_SERIES; c++)
        w->series[c] = -1;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        w->data[k] = -1;
    w->last_number = -1;
    w->sync = 1;
    w->path = dup_str(path);
    w->xmf_path = cdem_xdmf_path_for(path);
    w->buf = malloc(SERIES_BUFFER * sizeof *w->buf);
    w->column = malloc(SERIES_BUFFER * 8);
    w->index_mtype = make_compound(index_members, N_INDEX_MEMBERS, sizeof(index_row), 0);
    w->ckpt_mtype = make_compound(ckpt_members, N_CKPT_MEMBERS, sizeof(ckpt_row), 0);
    if (!w->path || !w->xmf_path || !w->buf || !w->column || w->index_mtype < 0 ||
        w->ckpt_mtype < 0) {
        writer_release(w);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory creating a writer for %s", path);
    }
    const char *slash = strrchr(w->path, '/');
    w->h5_name = slash ? slash + 1 : w->path;
    *out = w;
    return CDEM_OK;
}

cdem_status cdem_h5_writer_create(const char *path, const cdem_run_meta *meta, cdem_h5_writer **out,
                                  cdem_error *err) {
    return cdem_h5_writer_create_checked(path, meta, CDEM_H5_REPLACE_ANY, out, err);
}

cdem_status cdem_h5_writer_create_checked(const char *path, const cdem_run_meta *meta,
                                          cdem_h5_replace replace_policy, cdem_h5_writer **out,
                                          cdem_error *err) {
    if (out)
        *out = NULL;
    if (!path || !*path || !meta || !meta->params || !out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_h5_writer_create: path, meta, meta->params and out are required");
    writer_hdf5_init();
    cdem_h5_writer *w = NULL;
    CDEM_TRY(writer_alloc(path, &w, err));
    size_t n = strlen(path) + 10;
    char *tmp = malloc(n);
    if (!tmp) {
        writer_release(w);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory creating a writer for %s", path);
    }
    snprintf(tmp, n, "%s.creating", path);
    /* One writer per path for the writer's whole life: a second run of the same output would
     * otherwise remove this one's temporary file and rename its own over this one's. */
    int locked = 0, replace = 0;
    cdem_status st = cdem_runlock_acquire(path, meta->source, &w->lock, err);
    if (st == CDEM_OK) {
        locked = 1;
        st = check_replace(path, replace_policy, &replace, err);
    }
    /* a killed run's leftover (we hold the lock, so no live writer owns it) */
    if (st == CDEM_OK && unlink(tmp) != 0 && errno != ENOENT)
        st = CDEM_FAIL(err, CDEM_ERR_IO,
                       "%s: cannot remove %s, left by an earlier run that was killed: %s", path,
                       tmp, strerror(errno));
    if (st == CDEM_OK)
        st = writer_setup(w, meta, tmp, replace, err);
    if (st != CDEM_OK) {
        if (locked)
            remove(tmp); /* ours: removed while the lock is still held */
        writer_release(w);
        free(tmp);
        return st;
    }
    free(tmp);
    *out = w;
    return CDEM_OK;
}

static cdem_status grow_entries(cdem_h5_writer *w, cdem_error *err) {
    if (w->n_entries < w->cap_entries)
        return CDEM_OK;
    size_t cap = w->cap_entries ? 2 * w->cap_entries : 64;
    xmf_entry *e = realloc(w->entries, cap * sizeof *e);
    if (!e)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory listing %zu increments", cap);
    w->entries = e;
    w->cap_entries = cap;
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
    int missing = 0;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        missing |= (!element_fields[k].optional || s->has_stress) && !element_array(s, k);
    if (s->n > 0 && missing)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "%s: increment %d: the state has %zu elements but missing arrays", w->path,
                         (int)info->number, s->n);
    if (info->number <= w->last_number)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "%s: increment %d was already written or is out of order (the last "
                         "written is %d; numbers must increase)",
                         w->path, (int)info->number, (int)w->last_number);
    if (w->failed)
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: an earlier write failed; increment %d is not written (the file "
                         "keeps the %llu increments before)",
                         w->path, (int)info->number, (unsigned long long)w->index_len);
    CDEM_TRY(grow_entries(w, err));
    CDEM_TRY(flush_series(w, err));
    /* The data first, then (after a flush) the index row: the index is the commit record. */
    const hsize_t n = s->n;
    const int stress = s->has_stress && n > 0;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        const element_field *fd = &element_fields[k];
        if (fd->optional && !stress)
            continue;
        hsize_t start = fd->optional ? w->stress_len : w->data_len;
        if (write_rows(w->data[k], el_mem_type(fd->type), start, n, element_array(s, k)) < 0) {
            w->failed = 1;
            return H5FAIL(err, CDEM_ERR_IO,
                          "%s: cannot write increment %d to /increments/%s (%llu values; disk "
                          "full?); the file keeps the %llu increments before",
                          w->path, (int)info->number, fd->name, (unsigned long long)n,
                          (unsigned long long)w->index_len);
        }
    }
    CDEM_TRY(commit_flush(w, err)); /* the data is on disk before the record points to it */
    index_row row = {
        .number = info->number,
        .phase = info->phase,
        .step = info->step,
        .time = info->time,
        .net_displacement = info->net_displacement,
        .axial_strain = info->axial_strain,
        .differential_stress = info->differential_stress,
        .sea_level = info->sea_level,
        .offset = n ? (int64_t)w->data_len : (int64_t)w->data_ext,
        .n = (int64_t)n,
        .has_stress = stress,
        .stress_offset = stress ? (int64_t)w->stress_len : -1,
    };
    if (write_rows(w->index, w->index_mtype, w->index_len, 1, &row) < 0) {
        w->failed = 1;
        return H5FAIL(err, CDEM_ERR_IO,
                      "%s: cannot write the index row of increment %d (disk full?); the file "
                      "keeps the %llu increments before",
                      w->path, (int)info->number, (unsigned long long)w->index_len);
    }
    CDEM_TRY(commit_flush(w, err));
    w->index_len++;
    if (n) {
        w->data_ext = w->data_len + n;
        w->data_len = chunk_end(w->data_ext);
    }
    if (stress) {
        w->stress_ext = w->stress_len + n;
        w->stress_len = chunk_end(w->stress_ext);
    }
    w->last_number = info->number;
    w->last_step = info->step;
    w->entries[w->n_entries++] =
        (xmf_entry){info->number, info->time, (int64_t)n, stress, row.offset, row.stress_offset};
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
    if (w->nbuf == SERIES_BUFFER) {
        if (w->failed)
            return CDEM_FAIL(err, CDEM_ERR_IO, "%s: an earlier write failed; no more samples",
                             w->path);
        CDEM_TRY(flush_series(w, err));
    }
    w->buf[w->nbuf++] = *sample;
    return CDEM_OK;
}

cdem_status cdem_h5_writer_set_stop_reason(cdem_h5_writer *w, const char *reason,
                                           const char *detail, cdem_error *err) {
    if (!w)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_writer_set_stop_reason: no writer");
    /* Preallocated datasets: overwriting them needs no new file space (works on a full
     * disk). The detail is cut to STOP_DETAIL_LEN - 1 bytes. */
    if (write_fixed_string(w->stop_detail, STOP_DETAIL_LEN, detail) < 0 ||
        write_fixed_string(w->stop_reason, STOP_REASON_LEN, reason) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot write the stop reason '%s'", w->path,
                      reason ? reason : "");
    if (H5Dflush(w->stop_detail) < 0 || H5Dflush(w->stop_reason) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot flush the stop reason '%s'", w->path,
                      reason ? reason : "");
    /* not sync_file: after a failed write it would mark nothing new, and w->failed must not
     * turn a recorded stop reason into an error */
    if (w->sync && !w->failed) {
        void *handle = NULL;
        if (H5Fget_vfd_handle(w->file, H5P_DEFAULT, &handle) >= 0 && handle &&
            fdatasync(*(int *)handle) != 0 && errno != EINVAL && errno != EROFS)
            return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot flush the stop reason '%s' to disk: %s",
                             w->path, reason ? reason : "", strerror(errno));
        H5Eclear2(H5E_DEFAULT);
    }
    return CDEM_OK;
}

cdem_status cdem_h5_writer_close(cdem_h5_writer *w, cdem_error *err) {
    if (!w)
        return CDEM_OK;
    cdem_status st = w->failed ? CDEM_OK : flush_series(w, err);
    if (st == CDEM_OK && w->xmf_written != w->n_entries)
        st = write_xmf(w, err);
    hid_t file = w->file;
    w->file = -1;
    hid_t es = -1;
    if (file >= 0 && w->failed) {
        /* After a failed write (disk full) the file is left as a killed writer leaves it:
         * closing would rewrite the superblock with an end-of-file the disk cannot hold
         * (the file then reads as truncated) and HDF5 1.10.8 crashes later on the
         * half-closed file. Its handles are abandoned (this process is about to stop);
         * every committed increment and the stop reason are already on disk. */
        for (size_t c = 0; c < N_SERIES; c++)
            w->series[c] = -1;
        for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
            w->data[k] = -1;
        w->index = w->stop_reason = w->stop_detail = w->ckpt_index = -1;
        w->ckpt_data[0] = w->ckpt_data[1] = -1;
        if (st == CDEM_OK)
            st = CDEM_FAIL(err, CDEM_ERR_IO,
                           "%s: left unfinished after a failed write; it keeps its %llu "
                           "complete increments (readable like the file of a killed run)",
                           w->path, (unsigned long long)w->index_len);
        file = -1;
    }
    if (file >= 0) {
        /* Close the datasets first so that H5Fclose really closes the file. */
        for (size_t c = 0; c < N_SERIES; c++) {
            if (w->series[c] >= 0)
                H5Dclose(w->series[c]);
            w->series[c] = -1;
        }
        for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
            if (w->data[k] >= 0)
                H5Dclose(w->data[k]);
            w->data[k] = -1;
        }
        hid_t *rest[] = {&w->index,        &w->stop_reason,  &w->stop_detail,
                         &w->ckpt_data[0], &w->ckpt_data[1], &w->ckpt_index};
        for (size_t i = 0; i < sizeof rest / sizeof rest[0]; i++) {
            if (*rest[i] >= 0)
                H5Dclose(*rest[i]);
            *rest[i] = -1;
        }
        if (H5Fclose(file) < 0 && st == CDEM_OK)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot close the file (disk full?)", w->path);
        es = keep_errors(st != CDEM_OK);
    }
    writer_release(w);
    restore_errors(es);
    return st;
}

/* ------------------------------------------------------------------ reader */

typedef struct {
    cdem_increment_info info; /* version 1: attributes of the group; 2: the index row */
    char name[32];            /* version 1: group name under /increments */
    int64_t offset;           /* version 2: first row in the element datasets */
    int64_t stress_offset;    /* version 2: first row in sxx, syy, sxy (-1 without stress) */
} incr_entry;

struct cdem_h5_reader {
    hid_t file; /* open HDF5 file */
    char *path; /* as given */
    /* Root text attributes, malloc'd, "" when absent. */
    char *summary;                /* model summary */
    char *params_text;            /* original parameter-file text */
    char *stop_reason;            /* "running", "completed", "interrupted", ... */
    char *stop_detail;            /* free-text diagnosis */
    char *program_version;        /* version of the writing program */
    char *source;                 /* "cdem-run" or "cdem2d-import:<folder>" */
    char *created;                /* ISO 8601 UTC creation time */
    long seed;                    /* root attribute seed */
    int unclosed;                 /* 1: the writer did not close the file (status flag set) */
    int version;                  /* format_version of the file: 1 or 2 */
    int swmr;                     /* 1: opened in SWMR-read mode (writer running or killed) */
    hid_t data[N_ELEMENT_FIELDS]; /* version 2: /increments/<field>, -1 when not open */
    hid_t index;                  /* version 2: /increments/index, -1 when not open */
    size_t n_skipped;             /* unclosed file: increments left out as incompletely flushed */
    incr_entry *incr;             /* increments sorted by number */
    size_t n_incr;                /* entries in incr */
    size_t cap_incr;              /* allocated entries */
};

void cdem_h5_reader_close(cdem_h5_reader *r) {
    if (!r)
        return;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        if (r->data[k] >= 0)
            H5Dclose(r->data[k]);
    if (r->index >= 0)
        H5Dclose(r->index);
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

/* Looks at the superblock before HDF5 does. *status receives the status flags of a v3
 * superblock (bit 0: open for write, bit 2: open for SWMR write; 0 when closed). Fails on
 * truncation (stored end-of-file beyond the real size), except for a file open for SWMR
 * write, whose writer may have moved the end-of-file ahead of the data it is writing. */
static cdem_status precheck_superblock(const char *path, int *status, cdem_error *err) {
    *status = 0;
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
        int swmr_writer = version == 3 && (b[11] & 0x04);
        if (base + eof > size && !swmr_writer) {
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: truncated file: it has %llu bytes but its HDF5 superblock says "
                           "%llu (copy interrupted or disk full?)",
                           path, (unsigned long long)size, (unsigned long long)(base + eof));
            break;
        }
        if (version == 3)
            *status = b[11] & 0x05;
        break;
    }
    fclose(f);
    return st;
}

/* The end of the file according to its v2/v3 superblock (base address + end-of-file
 * address), or 0 when it cannot be read. */
static uint64_t superblock_eoa(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    static const unsigned char sig[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    unsigned char b[64];
    uint64_t eoa = 0;
    for (uint64_t at = 0; at < ((uint64_t)1 << 40); at = at ? 2 * at : 512) {
        if (fseek(f, (long)at, SEEK_SET) != 0)
            break;
        size_t got = fread(b, 1, sizeof b, f);
        if (got < 12)
            break;
        if (memcmp(b, sig, 8) != 0)
            continue;
        int so = b[9];
        if ((b[8] == 2 || b[8] == 3) && (so == 2 || so == 4 || so == 8) &&
            got >= (size_t)(12 + 4 * so))
            eoa = le_u64(b + 12, so) + le_u64(b + 12 + 2 * so, so);
        break;
    }
    fclose(f);
    return eoa;
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

/* Version 2: reads a scalar fixed-length string dataset (/stop_reason, /stop_detail) into a
 * malloc'd string (replacing *out). */
static cdem_status read_text_dataset(cdem_h5_reader *r, const char *name, char **out,
                                     cdem_error *err) {
    hid_t ds = H5Dopen2(r->file, name, H5P_DEFAULT);
    if (ds < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /%s is missing or corrupt", r->path, name);
    if (r->swmr)
        H5Drefresh(ds);
    hid_t t = H5Dget_type(ds), sp = H5Dget_space(ds), mt = -1;
    size_t size =
        t >= 0 && H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) == 0 ? H5Tget_size(t) : 0;
    char *buf = NULL;
    int ok = size > 0 && size <= 65536 && sp >= 0 && H5Sget_simple_extent_npoints(sp) == 1 &&
             (buf = calloc(size + 1, 1)) != NULL && (mt = H5Tcopy(H5T_C_S1)) >= 0 &&
             H5Tset_size(mt, size + 1) >= 0 && H5Tset_cset(mt, H5Tget_cset(t)) >= 0 &&
             H5Dread(ds, mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0;
    hid_t es = keep_errors(!ok);
    if (mt >= 0)
        H5Tclose(mt);
    if (t >= 0)
        H5Tclose(t);
    if (sp >= 0)
        H5Sclose(sp);
    H5Dclose(ds);
    restore_errors(es);
    if (!ok) {
        free(buf);
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: dataset /%s is not a readable fixed-length string scalar", r->path,
                      name);
    }
    free(*out);
    *out = buf;
    return CDEM_OK;
}

/* Reads rows [0, n) of a checksummed dataset. A live writer rewrites the last chunk of the
 * index and of the series in place at every append, so a SWMR reader can catch a chunk
 * half-written, and its Fletcher-32 check then fails: such a read is tried again a few times
 * (about 0.6 s in all); a file without a live writer is read once. 0 or -1. */
static int read_rows_retrying(const cdem_h5_reader *r, hid_t ds, hid_t mt, hsize_t n, void *dst) {
    for (int attempt = 0;; attempt++) {
        if (read_all_rows(ds, mt, n, dst) == 0)
            return 0;
        if (!r->swmr || attempt >= 6)
            return -1;
        H5Eclear2(H5E_DEFAULT);
        struct timespec ts = {0, (long)(10 * 1000 * 1000) << attempt}; /* 10 .. 320 ms */
        nanosleep(&ts, NULL);
    }
}

/* Version 2: (re)reads the index and the stop reason. In SWMR-read mode every dataset is
 * refreshed first: the index before the element datasets, so that the element datasets are
 * at least as long as the rows the index lists (the writer writes them in the other order).
 * In a file whose writer did not close it, the list ends before the first row that is not
 * backed by data (a kill mid-append); in a closed file such a row is an error. */
static cdem_status scan_v2(cdem_h5_reader *r, cdem_error *err) {
    CDEM_TRY(read_text_dataset(r, "stop_reason", &r->stop_reason, err));
    CDEM_TRY(read_text_dataset(r, "stop_detail", &r->stop_detail, err));
    if (r->index < 0 && (r->index = H5Dopen2(r->file, "increments/index", H5P_DEFAULT)) < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /increments/index is missing or corrupt",
                      r->path);
    if (r->swmr && H5Drefresh(r->index) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot refresh /increments/index", r->path);
    hsize_t rows = extent_of(r->index);
    if (rows > MAX_ELEMENTS)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: /increments/index claims %llu rows", r->path,
                         (unsigned long long)rows);
    hsize_t data_ext = 0, stress_ext = 0;
    int first_data = 1, first_stress = 1;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        const element_field *fd = &element_fields[k];
        char name[64];
        snprintf(name, sizeof name, "increments/%s", fd->name);
        if (r->data[k] < 0) {
            if ((r->data[k] = H5Dopen2(r->file, name, H5P_DEFAULT)) < 0)
                return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /%s is missing or corrupt",
                              r->path, name);
            hid_t t = H5Dget_type(r->data[k]), sp = H5Dget_space(r->data[k]);
            H5T_class_t cls = t >= 0 ? H5Tget_class(t) : H5T_NO_CLASS;
            int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
            if (t >= 0)
                H5Tclose(t);
            if (sp >= 0)
                H5Sclose(sp);
            H5T_class_t want = fd->type == CDEM_FIELD_F64 ? H5T_FLOAT : H5T_INTEGER;
            if (cls != want || rank != 1)
                return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                                 "%s: dataset /%s has type class %d and rank %d (expected a 1-D "
                                 "%s dataset)",
                                 r->path, name, (int)cls, rank,
                                 want == H5T_FLOAT ? "float" : "integer");
        } else if (r->swmr && H5Drefresh(r->data[k]) < 0) {
            return H5FAIL(err, CDEM_ERR_IO, "%s: cannot refresh /%s", r->path, name);
        }
        hsize_t e = extent_of(r->data[k]);
        if (fd->optional) {
            stress_ext = first_stress || e < stress_ext ? e : stress_ext;
            first_stress = 0;
        } else {
            data_ext = first_data || e < data_ext ? e : data_ext;
            first_data = 0;
        }
    }
    index_row *ix = rows ? malloc(rows * sizeof *ix) : NULL;
    hid_t mt = make_compound(index_members, N_INDEX_MEMBERS, sizeof(index_row), 0);
    cdem_status st = CDEM_OK;
    if ((rows && !ix) || mt < 0)
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the index of %s", r->path);
    else if (rows && read_rows_retrying(r, r->index, mt, rows, ix) < 0)
        st = H5FAIL(err, CDEM_ERR_FORMAT,
                    "%s: /increments/index (the list of increments) is damaged or unreadable: "
                    "no increment of this file can be trusted",
                    r->path);
    if (mt >= 0)
        H5Tclose(mt);
    if (st == CDEM_OK && rows > r->cap_incr) {
        incr_entry *e = realloc(r->incr, rows * sizeof *e);
        if (!e)
            st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory listing %llu increments",
                           (unsigned long long)rows);
        else {
            r->incr = e;
            r->cap_incr = rows;
        }
    }
    r->n_incr = 0;
    r->n_skipped = 0;
    for (hsize_t i = 0; st == CDEM_OK && i < rows; i++) {
        const char *why = bad_index_row(&ix[i], i ? &ix[i - 1] : NULL, data_ext, stress_ext);
        if (why) {
            /* A writer that died (or is writing) can leave its last row unwritten, never an
             * earlier one: a bad row before a good one is damage. */
            if (r->unclosed && i == rows - 1) {
                r->n_skipped = 1;
                break;
            }
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: /increments/index row %llu (increment %d): %s (step %lld, time "
                           "%.17g s, net displacement %.17g m): damaged file",
                           r->path, (unsigned long long)i, (int)ix[i].number, why,
                           (long long)ix[i].step, ix[i].time, ix[i].net_displacement);
            break;
        }
        incr_entry *e = &r->incr[r->n_incr++];
        memset(e, 0, sizeof *e);
        e->info.number = ix[i].number;
        e->info.step = ix[i].step;
        e->info.time = ix[i].time;
        e->info.phase = ix[i].phase;
        e->info.net_displacement = ix[i].net_displacement;
        e->info.axial_strain = ix[i].axial_strain;
        e->info.differential_stress = ix[i].differential_stress;
        e->info.sea_level = ix[i].sea_level;
        e->info.n_elements = ix[i].n;
        e->info.has_stress = ix[i].has_stress;
        e->offset = ix[i].offset;
        e->stress_offset = ix[i].stress_offset;
        snprintf(e->name, sizeof e->name, "%06d", (int)ix[i].number);
    }
    free(ix);
    return st;
}

cdem_status cdem_h5_reader_refresh(cdem_h5_reader *r, int *changed, cdem_error *err) {
    if (!r)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_refresh: no reader");
    if (changed)
        *changed = 0;
    if (!r->swmr)
        return CDEM_OK; /* a closed file (or version 1) does not change */
    size_t before = r->n_incr;
    int32_t last = before ? r->incr[before - 1].info.number : -1;
    char *reason = dup_str(r->stop_reason);
    if (!reason)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    cdem_status st = scan_v2(r, err);
    if (changed && st == CDEM_OK)
        *changed = r->n_incr != before ||
                   (r->n_incr && r->incr[r->n_incr - 1].info.number != last) ||
                   strcmp(reason, r->stop_reason) != 0;
    free(reason);
    return st;
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
    int status = 0;
    CDEM_TRY(precheck_superblock(path, &status, err));
    r->unclosed = status != 0;
    /* A writer that still runs or died leaves the v3 superblock's status flags set; HDF5
     * then refuses a plain open. Whether the writer still runs is what its lock says
     * (runlock.h; a symbolic link is followed to the file the writer named):
     *  - alive (or cannot tell): SWMR-read, which sees the file grow (H5Drefresh). HDF5
     *    retries a metadata read whose checksum fails, because the writer may be rewriting
     *    that piece; between attempts it sleeps 1, 2, 4, ... ns, 100 attempts by default:
     *    2^100 ns, i.e. for ever on a damaged file (a reader sat in H5C_protect ->
     *    H5_nanosleep for more than 300 s). SWMR_READ_ATTEMPTS bounds the total wait;
     *  - dead (killed, or a copy of its file): the file is complete, so it is opened as one,
     *    without SWMR and its retries: "clear_status_flags" (the file-access property h5clear
     *    uses; on a read-only open it only skips the check, the file is not changed) and
     *    "skip_eof_check" (a killed writer may have reserved space it never wrote).
     * A version-1 writer (flags 0x01) never ran in SWMR mode: also the second way.
     * File locking (HDF5's own) is off either way so that a live writer does not block the
     * reader, and a process may open the same file twice (render --follow; HDF5 refuses a
     * second open whose locking setting differs). */
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_file_locking(fapl, 0, 1);
    int live = 0;
    if (status & 0x04) {
        char *real = realpath(path, NULL);
        live = cdem_runlock_probe(real ? real : path, NULL, 0) != 0;
        free(real);
    }
    if (live) {
        H5Pset_metadata_read_attempts(fapl, SWMR_READ_ATTEMPTS);
        r->file = H5Fopen(path, H5F_ACC_RDONLY | H5F_ACC_SWMR_READ, fapl);
        r->swmr = r->file >= 0;
        if (r->file < 0)
            H5Eclear2(H5E_DEFAULT);
        H5Pset_metadata_read_attempts(fapl, 1);
    }
    if (r->file < 0) {
        if (r->unclosed) {
            hbool_t yes = 1;
            H5Pset(fapl, "clear_status_flags", &yes);
            H5Pset(fapl, "skip_eof_check", &yes);
        }
        r->file = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    }
    if (r->file < 0) {
        /* The file may already be open in this process (its writer, or a caller's own
         * H5Fopen): HDF5 then shares it, and the access properties must match. */
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
    if (rc < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: damaged file: HDF5 opens it but its root attribute 'format' cannot "
                      "be read (corrupt HDF5 metadata)",
                      path);
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
    if (version != CDEM_FORMAT_VERSION && version != 1)
        return CDEM_FAIL(err, CDEM_ERR_VERSION,
                         "%s: cdem format version %d; this program reads versions 1 and %d%s", path,
                         (int)version, CDEM_FORMAT_VERSION,
                         version > CDEM_FORMAT_VERSION ? " (written by a newer cdem-c)" : "");
    r->version = (int)version;
    int64_t seed = 0;
    if (get_num_attr(r->file, "seed", H5T_NATIVE_INT64, &seed) < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: root attribute 'seed' is unreadable", path);
    r->seed = (long)seed;
    CDEM_TRY(read_root_text(r, "summary", &r->summary, err));
    CDEM_TRY(read_root_text(r, "params_text", &r->params_text, err));
    CDEM_TRY(read_root_text(r, "program_version", &r->program_version, err));
    CDEM_TRY(read_root_text(r, "source", &r->source, err));
    CDEM_TRY(read_root_text(r, "created", &r->created, err));
    if (r->version >= 2)
        return scan_v2(r, err);
    CDEM_TRY(read_root_text(r, "stop_reason", &r->stop_reason, err));
    CDEM_TRY(read_root_text(r, "stop_detail", &r->stop_detail, err));

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
    r->file = r->index = -1;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        r->data[k] = -1;
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
    H5T_class_t want = fd->type == CDEM_FIELD_F64 ? H5T_FLOAT : H5T_INTEGER;
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

/* Version 2: rows [offset, offset + n) of every element dataset. */
static cdem_status load_v2(cdem_h5_reader *r, const incr_entry *e, cdem_state *s, cdem_error *err) {
    const hsize_t n = (hsize_t)e->info.n_elements;
    const int stress = e->info.has_stress != 0;
    cdem_state_free(s);
    CDEM_TRY(cdem_state_init(s, n ? (size_t)n : 1, stress, err));
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        const element_field *fd = &element_fields[k];
        if (fd->optional && !stress)
            continue;
        hsize_t off = (hsize_t)(fd->optional ? e->stress_offset : e->offset);
        if (read_rows(r->data[k], el_mem_type(fd->type), off, n, element_array(s, k)) < 0)
            return H5FAIL(err, CDEM_ERR_FORMAT,
                          "%s: cannot read rows %llu..%llu of /increments/%s for increment %d "
                          "(corrupt?)",
                          r->path, (unsigned long long)off, (unsigned long long)(off + n), fd->name,
                          (int)e->info.number);
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
    if (r->version >= 2) {
        cdem_status st = load_v2(r, e, s, err);
        if (st != CDEM_OK) {
            cdem_state_free(s);
            return st;
        }
        if (info)
            *info = e->info;
        return CDEM_OK;
    }
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
        if (ds[opened] >= 0 && r->swmr)
            H5Drefresh(ds[opened]);
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
        if (read_rows_retrying(r, ds[c], mt, len, col) < 0) {
            st = H5FAIL(err, CDEM_ERR_FORMAT,
                        "%s: the time series column /series/%s is damaged or unreadable", r->path,
                        sc->name);
            break;
        }
        for (hsize_t i = 0; i < len; i++)
            memcpy((char *)&out[i] + sc->offset, (char *)col + i * 8, 8);
    }
    /* Samples come in time order. A writer that died (or is writing) may leave the last
     * samples unwritten (zeros): the series then ends before them. Anywhere else a sample out
     * of order is damage (files written before the series carried a checksum). */
    for (hsize_t i = 0; st == CDEM_OK && i < len; i++) {
        const cdem_series_sample *q = &out[i], *p = i ? &out[i - 1] : NULL;
        if (q->step >= 0 && isfinite(q->time) && q->time >= 0.0 &&
            (!p || (q->step > p->step && q->time >= p->time)))
            continue;
        if (r->unclosed) {
            len = i;
            break;
        }
        st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                       "%s: /series sample %llu (step %lld, time %.17g s) is out of order (the "
                       "previous one is step %lld, time %.17g s; steps must increase and times "
                       "must be finite, >= 0 and not decrease): damaged file",
                       r->path, (unsigned long long)i, (long long)q->step, q->time,
                       p ? (long long)p->step : -1LL, p ? p->time : 0.0);
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
int cdem_h5_reader_format_version(const cdem_h5_reader *r) {
    return r ? r->version : 0;
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
        reader_xmf_ctx c = {r, extent_of(r->data[1]), extent_of(r->data[7])};
        for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
            hsize_t e = extent_of(r->data[k]);
            hsize_t *m = element_fields[k].optional ? &c.stress_ext : &c.data_ext;
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

double cdem_h5_estimate_file_size(double n_elements, double n_increments, int with_stress) {
    /* Measured on the default run (docs/format.md): 16.1 bytes per element and increment
     * without stress, 40.5 with; plus 64 KiB of metadata and 0.5 KB per increment. */
    double per = with_stress ? 40.5 : 16.1;
    return 65536.0 + n_increments * (512.0 + n_elements * per);
}

/* Checkpoint and sidecar sizes for cdem_h5_estimate_run_space, measured on cdem-run files
 * (docs/format.md, "Size"): a checkpoint holds about CKPT_BYTES_PER_ELEMENT bytes per
 * element (state, neighbour list, contact histories) plus the parameter text and the
 * summary; a sidecar increment is about XMF_BYTES_PER_INCREMENT bytes of XML. */
#define CKPT_BYTES_FIXED        65536.0
#define CKPT_BYTES_PER_ELEMENT  400.0
#define XMF_BYTES_PER_INCREMENT 3400.0
#define XMF_BYTES_STRESS        1300.0

double cdem_h5_estimate_run_space(double n_elements, double n_increments, int with_stress,
                                  int with_checkpoints) {
    double total = cdem_h5_estimate_file_size(n_elements, n_increments, with_stress);
    if (with_checkpoints) {
        /* a slot is a whole number of chunks, allocated in full; two slots */
        double blob = CKPT_BYTES_FIXED + n_elements * CKPT_BYTES_PER_ELEMENT;
        total += 2.0 * ceil(blob / CKPT_CHUNK) * CKPT_CHUNK;
    }
    /* the sidecar, and its temporary copy while it is rewritten */
    total += 2.0 * n_increments * (XMF_BYTES_PER_INCREMENT + (with_stress ? XMF_BYTES_STRESS : 0));
    return total;
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

cdem_status cdem_h5_check_free_space(const char *path, double bytes_needed, cdem_error *err) {
    if (!path || !*path)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_check_free_space: no path");
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    struct statvfs sv;
    if (statvfs(dir, &sv) != 0) {
        int e = errno;
        if (e == ENOENT)
            return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "cannot write %s: folder %s does not exist",
                             path, dir);
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "cannot write %s: cannot reach folder %s: %s",
                         path, dir, strerror(e));
    }
    double avail = (double)sv.f_bavail * (double)sv.f_frsize;
    if (avail < bytes_needed)
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: the output needs about %.1f MB but %s has %.1f MB free", path,
                         bytes_needed / 1e6, dir, avail / 1e6);
    return CDEM_OK;
}

/* What is at path, for the messages of check_replace: *is_cdem becomes 1 for a file the
 * reader opens as a cdem file; desc receives e.g. 'a cdem run file (stop reason
 * "completed", 41 increments)' or 'not an HDF5 file'. */
static void describe_existing(const char *path, int *is_cdem, int *resumable, char *desc,
                              size_t cap) {
    *is_cdem = *resumable = 0;
    cdem_error e;
    cdem_error_clear(&e);
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(path, &r, &e) != CDEM_OK) {
        const char *why = e.msg;
        size_t n = strlen(path);
        if (strncmp(why, path, n) == 0 && why[n] == ':') /* the message starts with the path */
            why += n + 2;
        snprintf(desc, cap, "%s%.300s", e.code == CDEM_ERR_FORMAT ? "" : "unreadable: ", why);
        return;
    }
    *is_cdem = 1;
    const char *stop = cdem_h5_reader_stop_reason(r);
    *resumable = strcmp(cdem_h5_reader_source(r), "cdem-run") == 0 &&
                 strcmp(stop, "completed") != 0 && cdem_h5_reader_format_version(r) >= 2;
    snprintf(desc, cap, "a cdem run file written by %.60s: stop reason \"%.40s\", %zu increments",
             cdem_h5_reader_source(r), stop, cdem_h5_reader_increment_count(r));
    cdem_h5_reader_close(r);
}

/* The policy for a file already at path; *replace becomes 1 when it may be replaced by a
 * rename, 0 when there is nothing there (the writer's rename then refuses to replace). */
static cdem_status check_replace(const char *path, cdem_h5_replace policy, int *replace,
                                 cdem_error *err) {
    *replace = 0;
    struct stat sb;
    if (lstat(path, &sb) != 0) {
        if (errno == ENOENT)
            return CDEM_OK;
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot examine the output path: %s", path,
                         strerror(errno));
    }
    if (S_ISDIR(sb.st_mode))
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT, "%s: the output path is a folder", path);
    if (policy == CDEM_H5_REPLACE_ANY) {
        *replace = 1;
        return CDEM_OK;
    }
    if (!S_ISREG(sb.st_mode))
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "%s already exists and is not a regular file (a link, a device, a "
                         "pipe?); a run never replaces it: choose another output file",
                         path);
    int is_cdem = 0, resumable = 0;
    char desc[600];
    describe_existing(path, &is_cdem, &resumable, desc, sizeof desc);
    if (!is_cdem)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "%s already exists and is not a cdem run file (%s); it is never "
                         "replaced by a run file, not even with --force: choose another output "
                         "file",
                         path, desc);
    if (policy == CDEM_H5_REPLACE_NEVER)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "%s already exists (%s); it was left as it is: choose another output "
                         "file (-o), remove it, or replace it on purpose with --force%s%s",
                         path, desc,
                         resumable ? "; to continue that run instead: cdem-run "
                                     "--resume "
                                   : "",
                         resumable ? path : "");
    *replace = 1;
    return CDEM_OK;
}

cdem_status cdem_h5_output_check(const char *path, cdem_h5_replace replace, cdem_error *err) {
    if (!path || !*path)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_output_check: no path");
    CDEM_TRY(cdem_runlock_check(path, err));
    int dummy = 0;
    return check_replace(path, replace, &dummy, err);
}

/* ------------------------------------------------------------ checkpoints */
/* A snapshot is stored as one self-describing blob (docs/format.md, "Checkpoints"):
 *   "CDEMSNAP" | u32 version (1) | u32 array count | u64 blob length |
 *   per array: u16 name length | name | u8 type | u64 count | count values |
 *   u64 FNV-1a 64 of every byte before it.
 * All integers and values little-endian. */
#define SNAP_MAGIC      "CDEMSNAP"
#define SNAP_VERSION    1
#define SNAP_HEADER     24
#define SNAP_MAX_ARRAYS 100000
#define SNAP_MAX_BYTES  ((uint64_t)1 << 36)

static int host_little_endian(void) {
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static void put_le(unsigned char *p, uint64_t v, int bytes) {
    for (int i = 0; i < bytes; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

static uint64_t get_le(const unsigned char *p, int bytes) {
    uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; i--)
        v = (v << 8) | p[i];
    return v;
}

/* Serialises snap into w->ckpt_buf; *len receives the blob length. */
static cdem_status serialise_snapshot(cdem_h5_writer *w, const cdem_snapshot *snap, size_t *len,
                                      cdem_error *err) {
    size_t total = SNAP_HEADER + 8, count = cdem_snapshot_count(snap);
    for (size_t i = 0; i < count; i++) {
        const cdem_snapshot_array *a = cdem_snapshot_at(snap, i);
        size_t bytes = a->count * cdem_snapshot_type_size(a->type);
        total += 2 + strlen(a->name) + 1 + 8 + bytes;
    }
    if (total > w->ckpt_cap) {
        unsigned char *b = realloc(w->ckpt_buf, total);
        if (!b)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory for a checkpoint of %zu bytes",
                             w->path, total);
        w->ckpt_buf = b;
        w->ckpt_cap = total;
    }
    unsigned char *p = w->ckpt_buf;
    memcpy(p, SNAP_MAGIC, 8);
    put_le(p + 8, SNAP_VERSION, 4);
    put_le(p + 12, count, 4);
    put_le(p + 16, total, 8);
    size_t at = SNAP_HEADER;
    for (size_t i = 0; i < count; i++) {
        const cdem_snapshot_array *a = cdem_snapshot_at(snap, i);
        size_t nl = strlen(a->name), bytes = a->count * cdem_snapshot_type_size(a->type);
        put_le(p + at, nl, 2);
        memcpy(p + at + 2, a->name, nl);
        at += 2 + nl;
        p[at++] = (unsigned char)a->type;
        put_le(p + at, a->count, 8);
        at += 8;
        if (bytes)
            memcpy(p + at, a->data, bytes); /* little-endian host (checked by the caller) */
        at += bytes;
    }
    put_le(p + at, fnv1a64(p, at), 8);
    *len = at + 8;
    return CDEM_OK;
}

/* Parses a blob into snap (cleared first). what names the blob in messages. */
static cdem_status parse_snapshot(const unsigned char *p, size_t len, cdem_snapshot *snap,
                                  const char *what, cdem_error *err) {
    cdem_snapshot_clear(snap);
    if (len < SNAP_HEADER + 8 || memcmp(p, SNAP_MAGIC, 8) != 0)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: not a checkpoint blob (no %s header)", what,
                         SNAP_MAGIC);
    uint64_t version = get_le(p + 8, 4), count = get_le(p + 12, 4), total = get_le(p + 16, 8);
    if (version != SNAP_VERSION)
        return CDEM_FAIL(err, CDEM_ERR_VERSION,
                         "%s: checkpoint blob version %llu; this program reads version %d", what,
                         (unsigned long long)version, SNAP_VERSION);
    if (total != len)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: checkpoint blob says %llu bytes but has %zu",
                         what, (unsigned long long)total, len);
    if (get_le(p + len - 8, 8) != fnv1a64(p, len - 8))
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: checkpoint blob checksum mismatch (torn?)",
                         what);
    if (count > SNAP_MAX_ARRAYS)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: checkpoint blob claims %llu arrays", what,
                         (unsigned long long)count);
    size_t at = SNAP_HEADER, end = len - 8;
    for (uint64_t i = 0; i < count; i++) {
        char name[CDEM_SNAPSHOT_NAME_MAX];
        if (end - at < 2)
            goto short_blob;
        size_t nl = (size_t)get_le(p + at, 2);
        at += 2;
        if (nl == 0 || nl >= sizeof name || end - at < nl + 9)
            goto short_blob;
        memcpy(name, p + at, nl);
        name[nl] = '\0';
        at += nl;
        int type = p[at++];
        uint64_t n = get_le(p + at, 8);
        at += 8;
        size_t size = cdem_snapshot_type_size((cdem_snapshot_type)type);
        if (size == 0)
            return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: array \"%s\" has unknown type %d", what,
                             name, type);
        if (n > (end - at) / size)
            goto short_blob;
        cdem_status st = cdem_snapshot_put(snap, name, (cdem_snapshot_type)type, (size_t)n,
                                           n ? p + at : NULL, err);
        if (st != CDEM_OK) {
            cdem_snapshot_clear(snap);
            cdem_error_prefix(err, "%s", what);
            return st == CDEM_ERR_INVALID ? CDEM_ERR_FORMAT : st;
        }
        at += (size_t)n * size;
    }
    if (at != end)
        goto short_blob;
    return CDEM_OK;
short_blob:
    cdem_snapshot_clear(snap);
    return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                     "%s: checkpoint blob is inconsistent at byte %zu of %zu (array list does not "
                     "fit its length)",
                     what, at, len);
}

cdem_status cdem_h5_writer_write_checkpoint(cdem_h5_writer *w, const cdem_snapshot *snap,
                                            cdem_error *err) {
    if (!w || !snap)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_h5_writer_write_checkpoint: writer and snapshot are required");
    if (!host_little_endian())
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "%s: checkpoints are stored only on little-endian hosts", w->path);
    if (w->last_number < 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "%s: a checkpoint belongs to the last increment written, and none is",
                         w->path);
    if (w->failed)
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: an earlier write failed; no checkpoint written",
                         w->path);
    size_t len = 0;
    CDEM_TRY(serialise_snapshot(w, snap, &len, err));
    /* Double buffering: overwrite the slot that does not hold the newest checkpoint, flush,
     * and only then point the index at it. */
    int slot = w->ckpt[0].sequence > w->ckpt[1].sequence ? 1 : 0;
    int64_t seq =
        (w->ckpt[0].sequence > w->ckpt[1].sequence ? w->ckpt[0].sequence : w->ckpt[1].sequence) + 1;
    if (write_rows(w->ckpt_data[slot], H5T_NATIVE_UINT8, 0, len, w->ckpt_buf) < 0) {
        w->failed = 1;
        return H5FAIL(err, CDEM_ERR_IO,
                      "%s: cannot write a checkpoint of %zu bytes to /checkpoint/slot%d (disk "
                      "full?); the previous checkpoint stays valid",
                      w->path, len, slot);
    }
    CDEM_TRY(commit_flush(w, err));
    ckpt_row row = {seq, w->last_number, w->last_step, (int64_t)len, fnv1a64(w->ckpt_buf, len)};
    hsize_t start = (hsize_t)slot, one = 1;
    hid_t fs = H5Dget_space(w->ckpt_index), ms = H5Screate_simple(1, &one, NULL);
    int ok = fs >= 0 && ms >= 0 &&
             H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &one, NULL) >= 0 &&
             H5Dwrite(w->ckpt_index, w->ckpt_mtype, ms, fs, H5P_DEFAULT, &row) >= 0;
    hid_t es = keep_errors(!ok);
    if (fs >= 0)
        H5Sclose(fs);
    if (ms >= 0)
        H5Sclose(ms);
    restore_errors(es);
    if (!ok) {
        w->failed = 1;
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot write /checkpoint/index", w->path);
    }
    CDEM_TRY(commit_flush(w, err));
    w->ckpt[slot] = row;
    return CDEM_OK;
}

static cdem_status reopen_setup(cdem_h5_writer *w, int32_t keep_inc, int64_t keep_step,
                                cdem_error *err) {
    w->placed = 1;
    int flags = 0;
    CDEM_TRY(precheck_superblock(w->path, &flags, err));
    hid_t fapl = writer_fapl();
    hbool_t clear = 1;
    H5Pset(fapl, "clear_status_flags", &clear); /* what h5clear -s does */
    w->file = H5Fopen(w->path, H5F_ACC_RDWR, fapl);
    hid_t es = keep_errors(w->file < 0);
    H5Pclose(fapl);
    restore_errors(es);
    if (w->file < 0) {
        /* The writer holds the file's lock, so no other writer is running: the file itself is
         * the problem. A killed run's file can be cut short (full disk, interrupted copy),
         * and HDF5 opens such a file for writing no more. */
        struct stat sb;
        uint64_t eoa = superblock_eoa(w->path);
        if (stat(w->path, &sb) == 0 && eoa > (uint64_t)sb.st_size) {
            H5Eclear2(H5E_DEFAULT);
            return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                             "%s: cannot be resumed: the file is truncated (it has %llu bytes, "
                             "its HDF5 superblock says %llu; cut short by a full disk or an "
                             "interrupted copy?); it was not changed, and the increments that "
                             "survived the cut can still be read (cdem-strain info)",
                             w->path, (unsigned long long)sb.st_size, (unsigned long long)eoa);
        }
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: cannot be resumed: HDF5 cannot open it for writing (damaged file?); "
                      "it was not changed",
                      w->path);
    }
    char *fmt = NULL;
    int32_t version = 0;
    int rc = get_str_attr(w->file, "format", &fmt);
    int bad = rc != 0 || strcmp(fmt, CDEM_FORMAT_NAME) != 0;
    free(fmt);
    if (bad && rc < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: cannot be resumed: its root attribute 'format' is unreadable (corrupt "
                      "HDF5 metadata); it was not changed",
                      w->path);
    if (bad)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: not a cdem file (root attribute 'format')",
                      w->path);
    if (get_num_attr(w->file, "format_version", H5T_NATIVE_INT32, &version) != 0 ||
        version != CDEM_FORMAT_VERSION)
        return CDEM_FAIL(err, version == 1 ? CDEM_ERR_UNSUPPORTED : CDEM_ERR_VERSION,
                         "%s: cdem format version %d cannot be resumed (only version %d files "
                         "hold checkpoints)",
                         w->path, (int)version, CDEM_FORMAT_VERSION);
    char name[64];
    for (size_t c = 0; c < N_SERIES; c++) {
        snprintf(name, sizeof name, "series/%s", series_columns[c].name);
        if ((w->series[c] = H5Dopen2(w->file, name, H5P_DEFAULT)) < 0)
            return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /%s is missing", w->path, name);
    }
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        snprintf(name, sizeof name, "increments/%s", element_fields[k].name);
        if ((w->data[k] = H5Dopen2(w->file, name, H5P_DEFAULT)) < 0)
            return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /%s is missing", w->path, name);
    }
    if ((w->index = H5Dopen2(w->file, "increments/index", H5P_DEFAULT)) < 0 ||
        (w->stop_reason = H5Dopen2(w->file, "stop_reason", H5P_DEFAULT)) < 0 ||
        (w->stop_detail = H5Dopen2(w->file, "stop_detail", H5P_DEFAULT)) < 0 ||
        (w->ckpt_index = H5Dopen2(w->file, "checkpoint/index", H5P_DEFAULT)) < 0 ||
        (w->ckpt_data[0] = H5Dopen2(w->file, "checkpoint/slot0", H5P_DEFAULT)) < 0 ||
        (w->ckpt_data[1] = H5Dopen2(w->file, "checkpoint/slot1", H5P_DEFAULT)) < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: a version-2 dataset is missing", w->path);
    w->has_xy = H5Lexists(w->file, "/increments/xy", H5P_DEFAULT) > 0; /* older files lack it */

    /* Increments to keep: the valid prefix of the index up to keep_inc. */
    hsize_t rows = extent_of(w->index), data_ext = extent_of(w->data[0]),
            stress_ext = extent_of(w->data[first_stress_field()]);
    for (size_t k = 1; k < N_ELEMENT_FIELDS; k++) {
        hsize_t e = extent_of(w->data[k]);
        if (element_fields[k].optional)
            stress_ext = e < stress_ext ? e : stress_ext;
        else
            data_ext = e < data_ext ? e : data_ext;
    }
    index_row *ix = rows ? malloc(rows * sizeof *ix) : NULL;
    if (rows && !ix)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the index of %s", w->path);
    if (rows && read_all_rows(w->index, w->index_mtype, rows, ix) < 0) {
        free(ix);
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot read /increments/index", w->path);
    }
    hsize_t keep = 0;
    while (keep < rows && ix[keep].number <= keep_inc &&
           !bad_index_row(&ix[keep], keep ? &ix[keep - 1] : NULL, data_ext, stress_ext))
        keep++;
    cdem_status st = CDEM_OK;
    w->data_len = w->stress_len = 0;
    for (hsize_t i = 0; i < keep && st == CDEM_OK; i++) {
        w->data_len = (hsize_t)(ix[i].offset + ix[i].n);
        if (ix[i].has_stress)
            w->stress_len = (hsize_t)(ix[i].stress_offset + ix[i].n);
        st = grow_entries(w, err);
        if (st == CDEM_OK)
            w->entries[w->n_entries++] =
                (xmf_entry){ix[i].number,     ix[i].time,   ix[i].n,
                            ix[i].has_stress, ix[i].offset, ix[i].stress_offset};
    }
    w->index_len = keep;
    w->last_number = keep ? ix[keep - 1].number : -1;
    w->last_step = keep ? ix[keep - 1].step : 0;
    free(ix);
    CDEM_TRY(st);
    /* Series samples to keep: the leading ones with step <= keep_step. */
    hsize_t slen = extent_of(w->series[0]);
    for (size_t c = 1; c < N_SERIES; c++) {
        hsize_t e = extent_of(w->series[c]);
        slen = e < slen ? e : slen;
    }
    int64_t *steps = slen ? malloc(slen * sizeof *steps) : NULL;
    if (slen && !steps)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the series of %s", w->path);
    if (slen && read_rows(w->series[0], H5T_NATIVE_INT64, 0, slen, steps) < 0) {
        free(steps);
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot read /series/step", w->path);
    }
    hsize_t skeep = 0;
    while (skeep < slen && steps[skeep] <= keep_step)
        skeep++;
    free(steps);
    w->series_len = skeep;
    /* Shrink everything to what is kept. */
    int ok = 1;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        ok = ok && H5Dset_extent(w->data[k],
                                 element_fields[k].optional ? &w->stress_len : &w->data_len) >= 0;
    for (size_t c = 0; c < N_SERIES; c++)
        ok = ok && H5Dset_extent(w->series[c], &w->series_len) >= 0;
    ok = ok && H5Dset_extent(w->index, &w->index_len) >= 0;
    if (!ok)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot truncate the datasets to increment %d", w->path,
                      (int)keep_inc);
    w->data_ext = w->data_len;
    w->stress_ext = w->stress_len;
    w->data_len = chunk_end(w->data_len);
    w->stress_len = chunk_end(w->stress_len);
    /* Checkpoints of dropped increments are invalidated. */
    if (read_all_rows(w->ckpt_index, w->ckpt_mtype, 2, w->ckpt) < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot read /checkpoint/index", w->path);
    for (int s = 0; s < 2; s++)
        if (w->ckpt[s].sequence > 0 && w->ckpt[s].increment > w->last_number) {
            int64_t seq = w->ckpt[s].sequence;
            memset(&w->ckpt[s], 0, sizeof w->ckpt[s]);
            w->ckpt[s].sequence = -seq; /* keeps sequence numbers increasing */
        }
    if (write_rows(w->ckpt_index, w->ckpt_mtype, 0, 2, w->ckpt) < 0 ||
        write_fixed_string(w->stop_reason, STOP_REASON_LEN, "running") < 0 ||
        write_fixed_string(w->stop_detail, STOP_DETAIL_LEN, "") < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot reset the checkpoint index and stop reason",
                      w->path);
    for (int s = 0; s < 2; s++)
        if (w->ckpt[s].sequence < 0)
            w->ckpt[s].sequence = 0;
    CDEM_TRY(commit_flush(w, err));
    CDEM_TRY(start_swmr(w, err));
    CDEM_TRY(write_xmf(w, err));
    return CDEM_OK;
}

cdem_status cdem_h5_writer_reopen(const char *path, int32_t keep_through_increment,
                                  int64_t keep_through_step, cdem_h5_writer **out,
                                  cdem_error *err) {
    if (out)
        *out = NULL;
    if (!path || !*path || !out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_writer_reopen: path and out are required");
    writer_hdf5_init();
    cdem_h5_writer *w = NULL;
    CDEM_TRY(writer_alloc(path, &w, err));
    cdem_status st = cdem_runlock_acquire(path, "cdem-run --resume", &w->lock, err);
    if (st == CDEM_OK)
        st = reopen_setup(w, keep_through_increment, keep_through_step, err);
    if (st != CDEM_OK) {
        writer_release(w);
        return st;
    }
    *out = w;
    return CDEM_OK;
}

cdem_status cdem_h5_reader_read_checkpoint(cdem_h5_reader *r, cdem_snapshot *snap,
                                           int32_t *increment_number, cdem_error *err) {
    if (!r || !snap || !increment_number)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_read_checkpoint: bad arguments");
    *increment_number = -1;
    cdem_snapshot_clear(snap);
    if (r->version < 2)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "%s: the file holds no checkpoint (format version %d has none)", r->path,
                         r->version);
    if (!host_little_endian())
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "%s: checkpoints are read only on little-endian hosts", r->path);
    hid_t ix = H5Dopen2(r->file, "checkpoint/index", H5P_DEFAULT);
    hid_t slot[2] = {H5Dopen2(r->file, "checkpoint/slot0", H5P_DEFAULT),
                     H5Dopen2(r->file, "checkpoint/slot1", H5P_DEFAULT)};
    hid_t mt = make_compound(ckpt_members, N_CKPT_MEMBERS, sizeof(ckpt_row), 0);
    ckpt_row rows[2];
    memset(rows, 0, sizeof rows);
    cdem_status st = CDEM_OK;
    if (ix < 0 || slot[0] < 0 || slot[1] < 0 || mt < 0)
        st = H5FAIL(err, CDEM_ERR_FORMAT, "%s: the /checkpoint datasets are missing or corrupt",
                    r->path);
    if (st == CDEM_OK && r->swmr)
        for (int s = 0; s < 2; s++)
            H5Drefresh(slot[s]);
    if (st == CDEM_OK && r->swmr)
        H5Drefresh(ix);
    if (st == CDEM_OK && (extent_of(ix) != 2 || read_all_rows(ix, mt, 2, rows) < 0))
        st = H5FAIL(err, CDEM_ERR_FORMAT, "%s: /checkpoint/index is unreadable (2 rows expected)",
                    r->path);
    char why[2][CDEM_ERROR_MSG_MAX / 2];
    why[0][0] = why[1][0] = '\0';
    int tried = 0, found = 0;
    int order[2] = {rows[0].sequence >= rows[1].sequence ? 0 : 1,
                    rows[0].sequence >= rows[1].sequence ? 1 : 0};
    for (int o = 0; st == CDEM_OK && o < 2 && !found; o++) {
        int s = order[o];
        if (rows[s].sequence <= 0)
            continue;
        tried++;
        hsize_t ext = extent_of(slot[s]);
        if (rows[s].length < SNAP_HEADER + 8 || (uint64_t)rows[s].length > SNAP_MAX_BYTES ||
            (hsize_t)rows[s].length > ext) {
            snprintf(why[o], sizeof why[o], "slot%d: length %lld does not fit (slot has %llu)", s,
                     (long long)rows[s].length, (unsigned long long)ext);
            continue;
        }
        size_t len = (size_t)rows[s].length;
        unsigned char *buf = malloc(len);
        if (!buf) {
            st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading a checkpoint of %zu bytes",
                           len);
            break;
        }
        if (read_rows(slot[s], H5T_NATIVE_UINT8, 0, len, buf) < 0) {
            H5Eclear2(H5E_DEFAULT);
            snprintf(why[o], sizeof why[o], "slot%d: unreadable", s);
        } else if (fnv1a64(buf, len) != rows[s].checksum) {
            snprintf(why[o], sizeof why[o], "slot%d (sequence %lld): checksum mismatch", s,
                     (long long)rows[s].sequence);
        } else {
            char what[1200];
            snprintf(what, sizeof what, "%s: /checkpoint/slot%d", r->path, s);
            cdem_error e2;
            cdem_error_clear(&e2);
            if (parse_snapshot(buf, len, snap, what, &e2) == CDEM_OK) {
                found = 1;
                *increment_number = rows[s].increment;
            } else {
                snprintf(why[o], sizeof why[o], "%.400s", e2.msg);
            }
        }
        free(buf);
    }
    if (mt >= 0)
        H5Tclose(mt);
    for (int s = 0; s < 2; s++)
        if (slot[s] >= 0)
            H5Dclose(slot[s]);
    if (ix >= 0)
        H5Dclose(ix);
    if (st != CDEM_OK || found)
        return st;
    if (tried == 0)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s: the file holds no checkpoint", r->path);
    return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: no valid checkpoint (%s%s%s)", r->path, why[0],
                     why[0][0] && why[1][0] ? "; " : "", why[1]);
}
