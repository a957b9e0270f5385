/* h5_internal: what the files of common/h5/ share, and nothing outside them includes. The run
 * file's public interface is common/h5format.h; docs/format.md is the authority on the layout.
 * One concept per file, and no two of them call each other in a loop: h5_util.c (HDF5 calls:
 * errors, attributes, rows, dataset creation), h5_layout.c (the tables of datasets and index
 * members, the checks of a row and of a value), h5_commit.c (the commit record, and the
 * recovery of a torn index chunk in older files), h5_file.c (the writer's file: allocation
 * and release, access properties, SWMR, flush and sync), h5_create.c (a new file: layout,
 * then SWMR, then the rename into place), h5_writer.c (appending increments and series, the
 * stop reason, the close), h5_resume.c (re-opening a file for --resume), h5_checkpoint.c (the
 * two checkpoint slots), h5_compact.c (a completed run's file rewritten without its
 * checkpoints), h5_ckpt_codec.c (a snapshot as bytes), h5_superblock.c (the superblock read
 * before HDF5 does), h5_reader.c (open, texts, an increment's elements), h5_reader_list.c
 * (the list of increments), h5_reader_series.c (the time series), h5_reader_v1.c (the
 * version-1 layout), h5_sidecar.c (the XDMF grids; the XML itself is common/xdmf.c)
 * and h5_output.c (before a run: may the path be written, is there space; the kept-aside
 * run of --force).
 * Names are h5i_*: internal, global only because the concept spans several files.
 * Ownership, threads, units: as h5format.h (one handle per thread; SI units). */
#ifndef CDEM_H5_INTERNAL_H
#define CDEM_H5_INTERNAL_H

#include "cdem_error.h"
#include "h5format.h"
#include "runlock.h"
#include "snapshot.h"
#include "state.h"

#include <hdf5.h>

#include <stddef.h>
#include <stdint.h>

/* Compression, chunk and buffer sizes: each chosen by measuring the default run's file and
 * its writing time (the measurements are in docs/format.md, "Size", and
 * docs/performance.md). An increment of the element datasets starts at a chunk boundary and
 * is one chunk up to CHUNK_ELEMS elements, so a compressed chunk is written once; small
 * chunks keep the partly empty last chunk of the series, the index and the checkpoint slots
 * small. The index chunk (48 rows of 84 bytes) fits one file-space page. */
#define DEFLATE_LEVEL      4
#define CKPT_DEFLATE_LEVEL 6
#define CHUNK_ELEMS        4096
#define SERIES_CHUNK       128
#define SERIES_BUFFER      256
#define XMF_EVERY_LIMIT    1000
#define INDEX_CHUNK        48 /* rows of /increments/index per chunk (84 bytes each) */
/* Rows of /increments/commit (the commit record, h5_commit.c) a writer reserves when its
 * caller does not say how many increments the run will write (cdem_run_meta). */
#define COMMIT_DEFAULT_CAPACITY 1024
/* The file-space page (docs/format.md, "HDF5 settings"): every piece of metadata and every
 * raw chunk smaller than a page lies inside one page, so no write that rewrites something
 * in place crosses a page boundary, the only place where a killed writer's write can stop
 * (the kernel copies a write into the page cache page by page). */
#define FILE_SPACE_PAGE 4096
#define CKPT_CHUNK      (1 << 12) /* bytes of a checkpoint slot per chunk (h5_checkpoint.c) */
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

#define STOP_REASON_LEN 64   /* bytes of /stop_reason (with the NUL) */
#define STOP_DETAIL_LEN 2048 /* bytes of /stop_detail (with the NUL) */

/* ------------------------------------------------------------------ h5_util.c */

/* Records code with a message "<what> (HDF5: <innermost descriptions>)" and clears the
 * HDF5 error stack. Use through H5FAIL. */
cdem_status h5i_fail_at(cdem_error *err, cdem_status code, const char *file, int line,
                        const char *fmt, ...) __attribute__((format(printf, 5, 6)));
#define H5FAIL(err, code, ...) h5i_fail_at((err), (code), __FILE__, __LINE__, __VA_ARGS__)

/* Cleanup calls after a failure would clear HDF5's error stack (every API call resets it):
 * set it aside first (keep_errors) and put it back after (restore_errors). */
hid_t h5i_keep_errors(int failed);
void h5i_restore_errors(hid_t saved);
void h5i_quiet_hdf5(void);
void h5i_writer_hdf5_init(void);
char *h5i_dup_str(const char *s);

hid_t h5i_fixed_string_type(size_t len);
int h5i_put_str_attr(hid_t obj, const char *name, const char *value);
int h5i_put_i32_attr(hid_t o, const char *n, int32_t v);
int h5i_put_i64_attr(hid_t o, const char *n, int64_t v);
int h5i_get_num_attr(hid_t obj, const char *name, hid_t mtype, void *value);
int h5i_get_str_attr(hid_t obj, const char *name, char **out);

int h5i_write_rows(hid_t ds, hid_t mtype, hsize_t start, hsize_t count, const void *src);
int h5i_read_rows(hid_t ds, hid_t mtype, hsize_t start, hsize_t count, void *dst);
int h5i_read_all_rows(hid_t ds, hid_t mt, hsize_t n, void *dst);
hsize_t h5i_extent_of(hid_t ds);
/* h5i_read_all_rows of rows [0, n) of a checksummed dataset; with swmr (a live writer, which
 * rewrites the last chunk of the index and of the series in place) a read whose checksum
 * fails is tried again for about 0.6 s. 0 or -1. */
int h5i_read_rows_retrying(int swmr, hid_t ds, hid_t mt, hsize_t n, void *dst);
/* "integer", "float", ... for messages. */
const char *h5i_class_name(H5T_class_t c);

/* Filters of an extendible dataset. */
typedef enum {
    FILTER_NONE,     /* raw chunks (checkpoint slots: the blob carries its own checksum) */
    FILTER_COMPRESS, /* byte shuffle + deflate + Fletcher-32 (element data) */
    FILTER_CHECKSUM, /* Fletcher-32 only (index, series): a flipped bit is a read error, not
                        a time of 461 s in a 220 s run; the filtered chunk keeps its size
                        (data + 4 bytes), so HDF5 still rewrites it in place on append */
} dataset_filter;

hid_t h5i_untimed_plist(hid_t cls);
hid_t h5i_create_extendible(hid_t loc, const char *name, hid_t ftype, hsize_t chunk,
                            dataset_filter filter);
hid_t h5i_create_fixed(hid_t loc, const char *name, hid_t ftype, hsize_t n);
int h5i_write_fixed_string(hid_t ds, size_t width, const char *text);

/* ------------------------------------------------------------------ h5_layout.c */

typedef enum { COL_I64, COL_F64 } col_type;

typedef struct {
    const char *name; /* dataset name under /series */
    col_type type;    /* int64 or float64 */
    size_t offset;    /* offsetof(cdem_series_sample, field) */
    int optional;     /* 1: added after format version 2 first shipped; a file without it
                         reads as NaN (its writer did not measure it) */
    /* a process's column (common/processes/<id>.h, CDEM_PROCESS_SERIES): NaN (its process is
     * off) or within lo..hi (range: the bounds as declared, for messages), in unit */
    int process;
    double lo, hi;
    const char *range, *unit;
} series_column;

/* the columns of every run, the lateral walls' four, then the processes' */
#define N_SERIES (18 + CDEM_PROCESS_SERIES_COUNT)
extern const series_column h5i_series_columns[N_SERIES];

/* Per-element datasets of an increment: the rows of CDEM_STATE_FIELDS (state.h) marked
 * in_increments, in table order (velocities, forces and masses live only in checkpoints). */
typedef struct {
    const char *name;     /* dataset name in the increment group */
    const char *path;     /* "/increments/<name>" */
    cdem_field_type type; /* stored and memory type */
    int optional;         /* 1: stress, present only with has_stress */
    size_t offset;        /* of the array pointer in cdem_state */
} element_field;

#define H5I_COUNT_FIELD(name, ctype, ftype, in_increments, stress) +in_increments
enum { H5I_N_ELEMENT_FIELDS = 0 CDEM_STATE_FIELDS(H5I_COUNT_FIELD) };
#undef H5I_COUNT_FIELD
#define N_ELEMENT_FIELDS ((size_t)H5I_N_ELEMENT_FIELDS)
extern const element_field h5i_element_fields[H5I_N_ELEMENT_FIELDS];

void *h5i_element_array(const cdem_state *s, size_t k);
size_t h5i_first_stress_field(void);
hid_t h5i_el_file_type(cdem_field_type t);
hid_t h5i_el_mem_type(cdem_field_type t);

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

#define N_INDEX_MEMBERS 12
extern const index_member h5i_index_members[N_INDEX_MEMBERS];

/* One row of /increments/commit, the commit record (h5_commit.c): an index row and the
 * FNV-1a 64 checksum of its packed little-endian members and of its position. */
typedef struct {
    index_row row;     /* the increment, as in /increments/index */
    uint64_t checksum; /* h5i_commit_checksum(&row, position); 0 in a row never written */
} commit_row;

/* The memory (native, padded) or file (little-endian, packed: the index members, then the
 * checksum as uint64) compound type of commit_row. */
hid_t h5i_commit_type(int file);

/* One row of /checkpoint/index (one per slot). */
typedef struct {
    int64_t sequence;  /* 0: slot never written; larger = newer */
    int32_t increment; /* increment the checkpoint belongs to */
    int64_t step;      /* time step of that increment */
    int64_t length;    /* bytes of the blob in the slot */
    uint64_t checksum; /* FNV-1a 64 of those bytes */
} ckpt_row;

#define N_CKPT_MEMBERS 5
extern const index_member h5i_ckpt_members[N_CKPT_MEMBERS];

/* Builds the memory (native, padded) or file (little-endian, packed) compound type. */
hid_t h5i_make_compound(const index_member *m, size_t nm, size_t mem_size, int file);

/* The checks of the values a run file holds against the physical bounds (CDEM_FILE_MAX_*,
 * h5format.h; docs/format.md, "Physical bounds"), shared by the writer (it refuses to write
 * what fails) and the reader (it refuses to read it). Each returns NULL when the value is
 * sensible, else what is wrong with the value in it (written into buf). */
/* An index row's own values and their order after prev (NULL for the first row). */
const char *h5i_bad_index_values(const index_row *row, const index_row *prev, char *buf,
                                 size_t cap);
/* The same, and its rows within the extents of the element and stress datasets. */
const char *h5i_bad_index_row(const index_row *row, const index_row *prev, hsize_t data_ext,
                              hsize_t stress_ext, char *buf, size_t cap);
/* Element i of s (*field: the dataset of the value refused). */
const char *h5i_bad_element(const cdem_state *s, size_t i, const char **field, char *buf,
                            size_t cap);
/* A series sample, except its step and time (their order is the reader's check). Bit c of
 * absent: column c is not in the file (read as NaN). blown_up: the file's stop reason is
 * "numerical-failure", whose last samples may hold Inf or NaN. *column: the column refused. */
const char *h5i_bad_sample(const cdem_series_sample *q, int blown_up, unsigned absent,
                           const char **column, char *buf, size_t cap);
/* 1 when two of the n ids are equal (*first < *second: their positions), 0 when none is, -1
 * when out of memory. Linear for ascending ids (every file written since 2026-11-27). */
int h5i_find_duplicate_id(const int32_t *id, size_t n, size_t *first, size_t *second);
/* 1 when reason is one of cdem_stop_reasons or "" (none recorded). */
int h5i_known_stop_reason(const char *reason);
/* text with every byte that is not part of printable UTF-8 (nor a newline or tab) written as
 * \xNN: a stop detail or summary is printed to a terminal. malloc'd, NULL when out of memory. */
char *h5i_printable(const char *text);
hsize_t h5i_chunk_end(hsize_t rows, hsize_t chunk_rows);
hsize_t h5i_chunk_rows_of(hid_t ds);

/* ------------------------------------------------------------------ h5_commit.c */

uint64_t h5i_commit_checksum(const index_row *row, uint64_t position);
/* 1 when the row's checksum matches its members and its position. */
int h5i_commit_row_valid(const commit_row *c, uint64_t position);
/* 1 when every member and the checksum are 0 (a row never written, or blanked). */
int h5i_commit_row_blank(const commit_row *c);
/* The record of a new file: capacity rows of zeros, contiguous, allocated now. */
hid_t h5i_commit_create(hid_t group, hsize_t capacity);
/* Writes row at position (mtype: memory type of commit_row); 0 or -1. */
int h5i_commit_write(hid_t ds, hid_t mtype, hsize_t position, const index_row *row);
/* Blanks the rows from keep on that are not blank (rows: the record as read), the last first,
 * one write each; 0 or -1. */
int h5i_commit_blank_from(hid_t ds, hid_t mtype, hsize_t keep, const commit_row *rows,
                          hsize_t capacity);
/* What a row of the commit record is (h5i_commit_scan). */
enum {
    COMMIT_VALID,         /* its checksum matches: a committed increment */
    COMMIT_BLANK,         /* all zero: never written, or blanked by --resume */
    COMMIT_TORN,          /* the row a killed writer was writing: not committed, not damage */
    COMMIT_DAMAGED,       /* a row that held an increment: its checksum fails, or it is blank */
    COMMIT_SPARE_DAMAGED, /* a spare row (never written) that is not blank: no increment lost */
};
#define H5I_ROWS_UNKNOWN ((hsize_t)-1)
typedef struct {
    int unclosed;       /* 1: the writer did not close the file (a torn row is allowed) */
    int live;           /* 1: a writer holds it now (any row after the valid ones may be torn) */
    hsize_t index_rows; /* extent of /increments/index, or H5I_ROWS_UNKNOWN */
    uint64_t record_at; /* file offset of row 0, or H5I_ROWS_UNKNOWN (every row tearable) */
    size_t row_bytes;   /* bytes of a row in the file (92) */
} commit_scan_in;
typedef struct {
    hsize_t valid;                 /* valid rows: the committed increments */
    hsize_t written;               /* rows 0..written-1 held increments (valid or damaged) */
    hsize_t torn;                  /* 1: row `written` is torn (left out, no damage) */
    hsize_t damaged;               /* damaged rows, written or spare */
    hsize_t first_damaged;         /* the first of them (capacity: none) */
    hsize_t damaged_written;       /* damaged rows that held an increment */
    hsize_t first_damaged_written; /* the first of them (capacity: none) */
} commit_scan_out;
/* The rows of a record read whole, each classified into kind[i] (capacity entries). NULL, or
 * what is wrong with the record as a whole (a closed file whose rows below the index's extent
 * are all blank, or with a valid row beyond it): then nothing of it can be trusted. */
const char *h5i_commit_scan(const commit_row *rows, hsize_t capacity, const commit_scan_in *in,
                            unsigned char *kind, commit_scan_out *out);
/* What is wrong with a damaged row (kind COMMIT_DAMAGED or COMMIT_SPARE_DAMAGED). */
const char *h5i_commit_damage_text(const commit_row *row, unsigned char kind);
/* A file without the record: recovers rows [0, rows) of /increments/index into out when only
 * its last chunk fails its Fletcher-32 because a kill tore its rewrite (the stored checksum
 * is that of a shorter prefix of the rows). Returns the rows recovered (0: none). */
hsize_t h5i_index_recover_torn_chunk(hid_t index, hsize_t rows, index_row *out);

/* ------------------------------------------------------------------ the writer */

typedef struct {
    int32_t number;        /* increment number */
    double time;           /* s */
    int64_t n;             /* element count */
    int has_stress;        /* 1: sxx, syy, sxy stored */
    int64_t offset;        /* first row in the element datasets */
    int64_t stress_offset; /* first row in sxx, syy, sxy */
} xmf_entry;

struct cdem_h5_writer {
    hid_t file;                     /* open HDF5 file (SWMR write mode once set up) */
    hid_t data[N_ELEMENT_FIELDS];   /* /increments/<field> */
    hid_t index;                    /* /increments/index */
    hid_t index_mtype;              /* memory type of index_row */
    hid_t commit;                   /* /increments/commit, the commit record (-1: a file
                                       written before it, resumed: the index alone) */
    hid_t commit_mtype;             /* memory type of commit_row */
    hsize_t commit_capacity;        /* rows of /increments/commit */
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
    hsize_t chunk_rows;             /* rows per chunk of the element datasets: CHUNK_ELEMS,
                                       or what a resumed file has (8192 before) */
    hsize_t index_len;              /* rows in /increments/index */
    int32_t last_number;            /* number of the last increment written (-1: none) */
    int64_t last_step;              /* its step */
    index_row last_row;             /* its row (the next one is checked against it) */
    int64_t last_sample_step;       /* step of the last series sample (-1: none) */
    double last_sample_time;        /* its time, s (0: none) */
    ckpt_row ckpt[2];               /* the checkpoint index as on disk */
    unsigned char *ckpt_buf;        /* serialised snapshot, grown as needed */
    size_t ckpt_cap;                /* bytes allocated in ckpt_buf */
    unsigned char *ckpt_zbuf;       /* the same compressed (what a slot holds), grown */
    size_t ckpt_zcap;               /* bytes allocated in ckpt_zbuf */
    int failed;                     /* 1 after a failed write: the file keeps what it had */
    xmf_entry *entries;             /* one per written increment, in write order */
    size_t n_entries, cap_entries;  /* used / allocated entries */
    size_t xmf_written;             /* entries in the sidecar on disk */
    int has_xy;                     /* 1: /increments/xy exists (XDMF 3 sidecar) */
    cdem_runlock *lock;             /* the path's lock (PATH.lock), held until close */
    int sync;                       /* 1: sync (fdatasync) every commit (_set_sync) */
    int placed;                     /* 1 once the file is at path (before: PATH.creating) */
    int completed;                  /* 1: the last stop reason recorded is "completed" */
    char *kept_aside;               /* PATH.replaced when this writer's file replaced a
                                       completed run that waits there (else NULL) */
    size_t *row_order;              /* an increment's rows by ascending id (write_increment) */
    void *row_buf;                  /* one field's values in that order, 8 bytes a row */
    size_t row_cap;                 /* rows allocated in row_order and row_buf */
};

/* h5_file.c */
cdem_status h5i_writer_alloc(const char *path, cdem_h5_writer **out, cdem_error *err);
hid_t h5i_writer_fapl(void);
cdem_status h5i_start_swmr(cdem_h5_writer *w, cdem_error *err);

cdem_status h5i_flush_file(cdem_h5_writer *w, cdem_error *err);
cdem_status h5i_commit_flush(cdem_h5_writer *w, cdem_error *err);
void h5i_sync_folder_of(const char *path);
void h5i_writer_release(cdem_h5_writer *w);
cdem_status h5i_grow_entries(cdem_h5_writer *w, cdem_error *err);

/* h5_compact.c: replaces the closed file at path by a copy without checkpoints and without
 * the paged file space of a file being written (the caller holds the path's lock); never
 * fails the run: rep says what happened (has_checkpoints: how its note words it). */
void h5i_compact_completed(const char *path, int sync, int has_checkpoints,
                           cdem_h5_close_report *rep);

/* h5_sidecar.c: rewrites the writer's sidecar from its list of increments. */
cdem_status h5i_write_xmf(cdem_h5_writer *w, cdem_error *err);

/* h5_output.c: the policy for a file already at path (*replace: 1 = replace by a rename;
 * *completed: 1 = what is there is a completed cdem run; may be NULL). */
cdem_status h5i_check_replace(const char *path, cdem_h5_replace policy, int *replace,
                              int *completed, cdem_error *err);
/* PATH.replaced: where a completed run replaced with --force waits until the run replacing
 * it completes (h5_create.c); malloc'd, NULL when out of memory. */
char *h5i_replaced_path(const char *path);
/* Removes PATH.replaced when it is there and a cdem run file (the run at path completed);
 * 1 when it was removed. */
int h5i_drop_replaced(const char *path);

/* ------------------------------------------------------------------ the reader */

typedef struct {
    cdem_increment_info info; /* version 1: attributes of the group; 2: the index row */
    char name[32];            /* version 1: group name under /increments */
    int64_t offset;           /* version 2: first row in the element datasets */
    int64_t stress_offset;    /* version 2: first row in sxx, syy, sxy (-1 without stress) */
} incr_entry;

/* A damaged row of a file's commit record (h5_reader_list.c). */
typedef struct {
    hsize_t row;      /* row of /increments/commit */
    int32_t number;   /* the increment it held (-1: unknown, or a spare row) */
    int spare;        /* 1: a spare row (never written): no increment was lost */
    const char *what; /* what is wrong with it (static text) */
} damaged_row;

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
    int swmr;                     /* 1: opened in SWMR-read mode (a writer holds the lock) */
    int writer;                   /* a writer held the lock at open: 1 yes, 0 no, -1 cannot
                                     tell (cdem_runlock_probe; 0 for a closed file) */
    hid_t data[N_ELEMENT_FIELDS]; /* version 2: /increments/<field>, -1 when not open */
    hid_t index;                  /* version 2: /increments/index, -1 when not open */
    size_t n_skipped;             /* unclosed file: increments left out as incompletely flushed */
    incr_entry *incr;             /* increments sorted by number */
    size_t n_incr;                /* entries in incr */
    size_t cap_incr;              /* allocated entries */
    damaged_row *damaged;         /* the damaged rows of the commit record (issue 46) */
    size_t n_damaged;             /* entries in damaged */
    int32_t damaged_through;      /* the last increment listed before the first damaged row
                                     that held one (-1: none; INT32_MAX: no such row) */
    int last_damaged;             /* 1: the last row written is damaged (so is "last") */
    char damage[1024];            /* the warning naming them ("" when none) */
};

/* h5_reader.c: cdem_h5_reader_open without the damage warning on stderr (--resume's check of
 * what it keeps: cdem-run opened the file, and warned, before). */
cdem_status h5i_reader_open_quiet(const char *path, cdem_h5_reader **out, cdem_error *err);

/* h5_reader_list.c: the list of increments into r->incr (r->n_incr, r->n_skipped), the
 * stop texts already read. */
cdem_status h5i_reader_scan(cdem_h5_reader *r, cdem_error *err);
/* A run that completed, or was stopped and wrote its final increment, holds increments: a
 * file of such a run that lists none is refused, saying why (either version). */
cdem_status h5i_reader_check_not_empty(cdem_h5_reader *r, cdem_error *err);

/* h5_superblock.c */
cdem_status h5i_precheck_superblock(const char *path, int *status, cdem_error *err);
uint64_t h5i_superblock_eoa(const char *path);

/* h5_reader_v1.c: the increment groups of a version-1 file, listed into r->incr (sorted),
 * and one of them loaded into s. */
cdem_status h5i_v1_list_increments(cdem_h5_reader *r, cdem_error *err);
cdem_status h5i_v1_load(cdem_h5_reader *r, const incr_entry *e, cdem_state *s, cdem_error *err);

/* ------------------------------------------------------------------ checkpoints */

/* h5_ckpt_codec.c: a snapshot as one self-describing blob (docs/format.md, "Checkpoints"). */
#define SNAP_HEADER    24
#define SNAP_MAX_BYTES ((uint64_t)1 << 36)
int h5i_host_little_endian(void);
uint64_t h5i_fnv1a64(const unsigned char *p, size_t n);
/* Serialises snap into *buf (grown, *cap its size); *len receives the blob length. path
 * names the file in messages. */
cdem_status h5i_snap_encode(const cdem_snapshot *snap, unsigned char **buf, size_t *cap,
                            size_t *len, const char *path, cdem_error *err);
/* Parses a blob into snap (cleared first). what names the blob in messages. */
cdem_status h5i_snap_decode(const unsigned char *p, size_t len, cdem_snapshot *snap,
                            const char *what, cdem_error *err);
/* What a checkpoint slot holds: the blob compressed (deflate, some arrays byte-transposed
 * first), behind its own header. Packs the blob blob[0, blob_len) into *buf (grown, *cap its
 * size; *len the packed length). The blob is used as scratch: its arrays are left
 * transposed (the writer encodes a new one for every checkpoint). */
cdem_status h5i_snap_pack(unsigned char *blob, size_t blob_len, unsigned char **buf, size_t *cap,
                          size_t *len, const char *path, cdem_error *err);
/* The blob of a slot's bytes p[0, len): *raw points into p for an uncompressed blob (files
 * written before compression) or to a malloc'd copy (*owned = 1, the caller frees it) for a
 * packed one. CDEM_ERR_FORMAT naming what when the bytes are neither. */
cdem_status h5i_snap_unpack(const unsigned char *p, size_t len, const unsigned char **raw,
                            size_t *raw_len, int *owned, const char *what, cdem_error *err);

#endif
