/* h5format: the element-state file (one HDF5 file per simulation), written by cdem-run and
 * read by cdem-strain, h5py and ParaView (.xmf sidecar). docs/format.md is the authority on
 * the layout (version 2; version 1 files are still read); this header is its C interface.
 * Layout: root attributes (format, version, seed, texts); /stop_reason, /stop_detail;
 * /parameters; /increments/index (one row per increment, written after its data: the commit
 * record) and ragged extendible element datasets /increments/{id,x,y,...}; /series/<column>;
 * /checkpoint/{index,slot0,slot1} (double-buffered, checksummed snapshot blobs; empty in a
 * completed run's file, whose close drops them).
 * Every object is created with the file; the writer then runs in HDF5 SWMR-write mode, so a
 * writer killed at any moment leaves every completed increment readable and a reader can
 * follow a running simulation (cdem_h5_reader_refresh). A writer holds the path's lock
 * (runlock.h) from creation to close: one writer per path, and a reader knows whether the
 * writer is alive (a dead writer's file is read as a complete file).
 * Ownership: writer and reader are opaque handles; _close releases them (NULL allowed).
 * Thread safety: one handle per thread; HDF5 itself is not called concurrently.
 * Units: SI (m, s, N/m) as documented per field. */
#ifndef CDEM_H5FORMAT_H
#define CDEM_H5FORMAT_H

#include "cdem_error.h"
#include "file_bounds.h"
#include "params.h"
#include "snapshot.h"
#include "state.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#define CDEM_FORMAT_NAME    "cdem-c"
#define CDEM_FORMAT_VERSION 2

/* Physical bounds of what a run file holds (docs/format.md, "Physical bounds"):
 * CDEM_FILE_MAX_*, file_bounds.h. */

/* The stop reasons a file may record (/stop_reason; "" = none recorded): the reader refuses
 * any other text. NULL-terminated. */
extern const char *const cdem_stop_reasons[];

typedef enum {
    CDEM_PHASE_EQUILIBRATION = 0, /* walls still, assembly settling */
    CDEM_PHASE_DEFORMATION = 1,   /* boundaries moving */
    CDEM_PHASE_SETTLING = 2,      /* boundaries still while new sediment settles */
} cdem_phase;

/* What is known about one display increment. */
typedef struct {
    int32_t number;             /* increment number, 0 = start of equilibration */
    int64_t step;               /* time step at which it was written */
    double time;                /* model time, s */
    int32_t phase;              /* cdem_phase */
    double net_displacement;    /* m, displacement of the moving boundary (net under inversion) */
    double axial_strain;        /* biaxial test: platen shortening / initial height; else 0 */
    double differential_stress; /* biaxial test: sigma1 - sigma3 in N/m; else 0 */
    double sea_level;           /* m; NaN when there is no sedimentation */
    int64_t n_elements;         /* element count of the increment (filled by the reader) */
    int32_t has_stress;         /* 1 when sxx, syy, sxy are stored (filled by the reader) */
} cdem_increment_info;

/* One time-series sample. Columns with no meaning for the mode are 0. A process adds its
 * own columns in its file common/processes/<id>.h (CDEM_PROCESS_SERIES(name, unit, lo, hi,
 * label): a float64 member here, a column of /series after the others, its bounds lo..hi
 * checked by the reader and the writer, NaN allowed: its process was off; the analysis's
 * label), without a line here or in common/h5/. */
typedef struct {
    int64_t step;               /* time step */
    double time;                /* s */
    double kinetic_energy;      /* J per metre, sum of 1/2 m v^2 over free elements */
    int64_t contacts;           /* touching pairs */
    int64_t bonds;              /* intact bonds (bonded model) or cohesive contacts (granular) */
    int64_t n_elements;         /* elements present */
    double net_displacement;    /* m */
    double boundary_force_x;    /* N, total contact force on the moving boundary elements */
    double boundary_force_y;    /* N */
    double base_force_x;        /* N, total contact force on the fixed base elements */
    double base_force_y;        /* N */
    double left_wall_force_x;   /* N, total contact force on the left lateral wall's elements
                                   (wall elements off the base row, left of the model's
                                   middle; fixed or moving); NaN when read from a file
                                   written before the column existed */
    double left_wall_force_y;   /* N */
    double right_wall_force_x;  /* N, the same for the right lateral wall */
    double right_wall_force_y;  /* N */
    double axial_strain;        /* biaxial */
    double differential_stress; /* biaxial, N/m */
    double sea_level;           /* m, NaN when none */
    /* the processes' own columns (common/processes/<id>.h, CDEM_PROCESS_SERIES), in registry
     * order; NaN while their process is off (cdem_series_processes_absent) */
#define CDEM_PROCESS_SERIES(name, unit, lo, hi, label) double name;
#include "processes.def"
#undef CDEM_PROCESS_SERIES
} cdem_series_sample;

/* The number of the processes' own series columns. */
enum {
    CDEM_PROCESS_SERIES_COUNT = 0
#define CDEM_PROCESS_SERIES(name, unit, lo, hi, label) +1
#include "processes.def"
#undef CDEM_PROCESS_SERIES
};

/* Sets every process's columns of q to NaN (not measured: the process is off); a process
 * that runs fills its own (solver/process/process.h, its sample hook). */
static inline void cdem_series_processes_absent(cdem_series_sample *q) {
#define CDEM_PROCESS_SERIES(name, unit, lo, hi, label) q->name = NAN;
#include "processes.def"
#undef CDEM_PROCESS_SERIES
    (void)q;
}

/* What the writer may do with a file already at the output path.
 * Whatever the policy, the old file stays untouched until the new one is complete enough to
 * open (it replaces the old one by a rename). */
typedef enum {
    CDEM_H5_REPLACE_ANY = 0, /* replace whatever is there (the library's first behaviour) */
    CDEM_H5_REPLACE_NEVER,   /* refuse any existing file (cdem-run without --force) */
    CDEM_H5_REPLACE_CDEM,    /* replace only a cdem file (cdem-run --force, import-cdem2d);
                                never a parameter file, notes or a damaged file */
} cdem_h5_replace;

/* Everything stored once per file. Strings may be NULL (stored empty). */
typedef struct {
    const cdem_params *params;   /* the full parameter record (required) */
    const char *params_text;     /* the original parameter-file text, or NULL */
    const char *summary;         /* the model summary text */
    const char *program_version; /* e.g. CDEM_VERSION */
    const char *source;          /* "cdem-run" or "cdem2d-import:<folder>" */
    long max_increments;         /* the most increments the file will hold at any time (the
                                    capacity of its commit record, /increments/commit); 0:
                                    1024. Writing more fails (CDEM_ERR_RANGE). */
} cdem_run_meta;

/* ---------------------------------------------------------------- writer */
typedef struct cdem_h5_writer cdem_h5_writer;

/* Creates path, writes the metadata and the .xmf sidecar placeholder, and flushes. The
 * writer holds the path's lock (runlock.h, PATH.lock) from here until _close, so a second
 * writer of the same path fails at once (CDEM_ERR_CONFLICT naming the first) and readers
 * know the file is being written. The file is built as PATH.creating and renamed to path
 * once its layout is complete; a file already at path is replaced then. Fails with
 * CDEM_ERR_IO naming the path if it cannot be created. */
cdem_status cdem_h5_writer_create(const char *path, const cdem_run_meta *meta, cdem_h5_writer **out,
                                  cdem_error *err);

/* The same, with a policy for a file already at path (CDEM_ERR_CONFLICT, saying what is
 * there and what to do, when it may not be replaced; checked under the lock). */
cdem_status cdem_h5_writer_create_checked(const char *path, const cdem_run_meta *meta,
                                          cdem_h5_replace replace, cdem_h5_writer **out,
                                          cdem_error *err);

/* Appends one increment (all s->n elements; stress when s->has_stress), updates the .xmf
 * sidecar and flushes the file. */
cdem_status cdem_h5_writer_write_increment(cdem_h5_writer *w, const cdem_increment_info *info,
                                           const cdem_state *s, cdem_error *err);

/* Appends one time-series sample (buffered; written at the next increment or close). */
cdem_status cdem_h5_writer_append_series(cdem_h5_writer *w, const cdem_series_sample *sample,
                                         cdem_error *err);

/* Records how the run ended: "completed", "interrupted", "numerical-failure", ... and a
 * free-text diagnosis. */
cdem_status cdem_h5_writer_set_stop_reason(cdem_h5_writer *w, const char *reason,
                                           const char *detail, cdem_error *err);

/* Flushes everything and closes; w may be NULL. Returns the first error met.
 * A run whose stop reason is "completed" is never resumed, so when its file holds checkpoints
 * close drops them: it writes a copy without them next to the file (PATH.compacting), syncs it
 * and renames it over PATH (docs/format.md, "Completed runs"); /checkpoint stays, empty. Any
 * other stop reason keeps the checkpoints for cdem-run --resume. A crash while compacting
 * leaves the complete original; a compaction that cannot be done (no space for the copy)
 * leaves the file with its checkpoints and is not an error (cdem_h5_writer_close_report says
 * why). The environment variable CDEM_KEEP_CHECKPOINTS=1 turns compaction off (tests). */
cdem_status cdem_h5_writer_close(cdem_h5_writer *w, cdem_error *err);

/* What close did with a completed run's checkpoints. */
typedef struct {
    int compacted;         /* 1: the checkpoints were dropped and the file compacted */
    uint64_t bytes_before; /* file size before compacting (0: not tried) */
    uint64_t bytes_after;  /* file size after (= before when not compacted) */
    char note[640];        /* why a completed run's file kept its checkpoints, else "" */
    int dropped_replaced;  /* 1: PATH.replaced, the completed run this one replaced, was
                              removed (cdem_h5_writer_kept_aside) */
} cdem_h5_close_report;

/* A run that replaces a completed run (CDEM_H5_REPLACE_CDEM: cdem-run --force) keeps that
 * run as PATH.replaced until it completes itself: close then removes PATH.replaced (also in
 * a resumed run's close); a run killed, interrupted or failed before leaves it, so a result
 * is never lost to a replacement that did not finish. Returns that path (owned by the
 * writer) when this writer kept one aside, else NULL. */
const char *cdem_h5_writer_kept_aside(const cdem_h5_writer *w);

/* cdem_h5_writer_close, also reporting the compaction (rep may be NULL). */
cdem_status cdem_h5_writer_close_report(cdem_h5_writer *w, cdem_h5_close_report *rep,
                                        cdem_error *err);

/* Durability (on by default): every commit (an increment's index row, a checkpoint's index
 * row, the stop reason) is flushed to stable storage with fsync before the writer goes on,
 * and the data it commits is flushed before it, so a power cut keeps every committed
 * increment. sync = 0 leaves that to the operating system (a killed process still keeps
 * everything; a power cut may not): cdem-run --no-fsync, for throwaway runs. */
void cdem_h5_writer_set_sync(cdem_h5_writer *w, int sync);

/* Checks, before a run is set up, that a writer could create path under the policy
 * replace: no live writer holds the path (CDEM_ERR_CONFLICT naming it), and an existing
 * file is allowed to be replaced (CDEM_ERR_CONFLICT saying what it is and what to do).
 * The writer repeats these checks under its lock; this one only makes refusals immediate. */
cdem_status cdem_h5_output_check(const char *path, cdem_h5_replace replace, cdem_error *err);

/* ------------------------------------------------------------ checkpoints */
/* Stores snap as the file's checkpoint, belonging to the increment written last (a resumed
 * run continues after it). The previous checkpoint stays readable until the new one is
 * complete, so a kill at any moment leaves one valid checkpoint. */
cdem_status cdem_h5_writer_write_checkpoint(cdem_h5_writer *w, const cdem_snapshot *snap,
                                            cdem_error *err);

/* Re-opens an existing run file to go on writing it (cdem-run --resume): increments numbered
 * above keep_through_increment and series samples with step > keep_through_step are
 * dropped, so the resumed run writes them again. */
cdem_status cdem_h5_writer_reopen(const char *path, int32_t keep_through_increment,
                                  int64_t keep_through_step, cdem_h5_writer **out, cdem_error *err);

/* ---------------------------------------------------------------- reader */
typedef struct cdem_h5_reader cdem_h5_reader;

/* Opens a cdem file read-only. Non-HDF5, non-cdem, wrong-version, truncated or corrupt
 * files fail with a message naming the path and the problem, never a crash. */
cdem_status cdem_h5_reader_open(const char *path, cdem_h5_reader **out, cdem_error *err);
void cdem_h5_reader_close(cdem_h5_reader *r);

/* Increments present, in ascending number order. */
size_t cdem_h5_reader_increment_count(const cdem_h5_reader *r);
cdem_status cdem_h5_reader_increment_info(const cdem_h5_reader *r, size_t index,
                                          cdem_increment_info *info, cdem_error *err);

/* Resolves "K" (an increment number), "last", "first" or "equil" (the end of equilibration,
 * cdem_h5_reader_equil_end) to an index. */
cdem_status cdem_h5_reader_find_increment(const cdem_h5_reader *r, const char *spec, size_t *index,
                                          cdem_error *err);

/* Added with issue 35: the end of equilibration, the last increment of the equilibration
 * phase, into *index; known only when an increment of a later phase follows it, or the run
 * completed. CDEM_ERR_NOTFOUND, saying why, when the file has no increment of that phase or
 * the run has not left it (stopped, killed or still running in equilibration: its last
 * increment is then not the end, which lies later; it is never guessed). */
cdem_status cdem_h5_reader_equil_end(const cdem_h5_reader *r, size_t *index, cdem_error *err);

/* Loads increment `index` into s (re-initialised; velocities and forces zero, masses zero).
 * s must be zeroed ({0}) or initialised; on failure it is left empty. */
cdem_status cdem_h5_reader_load_increment(cdem_h5_reader *r, size_t index, cdem_state *s,
                                          cdem_increment_info *info, cdem_error *err);

/* Reads the whole time series (malloc'd array, caller frees). */
cdem_status cdem_h5_reader_read_series(cdem_h5_reader *r, cdem_series_sample **samples,
                                       size_t *count, cdem_error *err);

/* Stored texts ("" when absent); valid until close. */
const char *cdem_h5_reader_summary(const cdem_h5_reader *r);
const char *cdem_h5_reader_params_text(const cdem_h5_reader *r);
const char *cdem_h5_reader_stop_reason(const cdem_h5_reader *r);
const char *cdem_h5_reader_program_version(const cdem_h5_reader *r);
long cdem_h5_reader_seed(const cdem_h5_reader *r);
/* Added after the first interface: the stop diagnosis, the source ("cdem-run", ...), the
 * creation time (ISO 8601 UTC) and whether the writer never closed the file (it died or
 * is still running; see docs/format.md, "A writer that dies"). */
const char *cdem_h5_reader_stop_detail(const cdem_h5_reader *r);
const char *cdem_h5_reader_source(const cdem_h5_reader *r);
const char *cdem_h5_reader_created(const cdem_h5_reader *r);
int cdem_h5_reader_unclosed(const cdem_h5_reader *r);
/* Added with issue 35: whether a writer held the file's lock (runlock.h) when it was opened:
 * 1 yes (the run is being written), 0 no, -1 cannot tell (a filesystem without locks). A
 * file its writer did not close (_unclosed) and that no writer holds was left by a killed or
 * crashed writer: its stop reason still says "running", but the run was interrupted. */
int cdem_h5_reader_writer_alive(const cdem_h5_reader *r);

/* Added with format version 2: re-reads the increment list and the stop reason of a file
 * that is being written (SWMR-read mode); *changed (may be NULL) becomes 1 when the list or
 * the stop reason changed. For a closed file or a version-1 file it changes nothing.
 * Increment indices of earlier increments stay valid (increments are only appended). */
cdem_status cdem_h5_reader_refresh(cdem_h5_reader *r, int *changed, cdem_error *err);

/* Added with issue 46: damaged rows of the commit record (docs/format.md,
 * "/increments/commit"). A row that fails its checksum costs its own increment, no other:
 * the file opens, lists every valid increment (before and after it), refuses the damaged
 * rows' increments by number (and "last" when the last row is damaged) with CDEM_ERR_FORMAT
 * naming the row, and _open writes one warning naming the file and each row to stderr.
 * _damage: that warning's text ("" when the record is sound; a torn last row of a killed
 * writer is no damage). _damaged_increments: 1 when a row that held an increment is
 * damaged, *last_before (may be NULL) then the number of the last increment listed before
 * the first such row (-1: none); 0 when none is (a damaged spare row costs nothing). */
const char *cdem_h5_reader_damage(const cdem_h5_reader *r);
int cdem_h5_reader_damaged_increments(const cdem_h5_reader *r, int32_t *last_before);

/* The file format version of the open file (1 or CDEM_FORMAT_VERSION). */
int cdem_h5_reader_format_version(const cdem_h5_reader *r);

/* Added with the XDMF 3 sidecar: writes the sidecar of the run file h5_path to xmf_path
 * (NULL: next to it, run.h5 -> run.xmf), referring to the file by name when both are in one
 * folder, else by its absolute path. flavour 3 (ParaView's default Xdmf3 readers) or 2
 * (legacy XDMF readers, VisIt); docs/format.md, "XDMF sidecar". A file without the view
 * /increments/xy (written before it existed), or whose name holds ':' or '|', gets flavour
 * 2; *written (may be NULL) is the flavour written. Version-1 files are refused. */
cdem_status cdem_h5_write_xdmf(const char *h5_path, const char *xmf_path, int flavour, int *written,
                               cdem_error *err);

/* Estimated size in bytes of a run file with n_elements elements in each of n_increments
 * increments (stress stored when with_stress), from the measured compression of the
 * default run (docs/format.md, "Size"). Element data, index and series only. */
double cdem_h5_estimate_file_size(double n_elements, double n_increments, int with_stress);

/* Estimated disk space a whole run needs (for the free-space check before it): the file as
 * above, its two checkpoint slots when with_checkpoints (each a whole number of 16 KiB
 * chunks holding one checkpoint of n_elements elements) and the .xmf sidecar, counted twice
 * because it is rewritten through a temporary copy. */
double cdem_h5_estimate_run_space(double n_elements, double n_increments, int with_stress,
                                  int with_checkpoints);

/* Checks, before a run starts, that the directory of path has at least bytes_needed bytes
 * free for an unprivileged user (statvfs). Fails with CDEM_ERR_IO naming the directory, the
 * estimate and the free space when it has not (and only then: callers advise freeing space);
 * with CDEM_ERR_NOTFOUND, naming it, when the directory cannot be reached (missing, not a
 * folder, no permission) or written (a read-only file system, no write permission). */
cdem_status cdem_h5_check_free_space(const char *path, double bytes_needed, cdem_error *err);

/* The parameter record rebuilt into a cdem_params (defaults for keys the file lacks). */
/* Loads the newest complete checkpoint into snap (cleared first) and the number of the
 * increment it belongs to. CDEM_ERR_NOTFOUND, naming the path, when the file has none. */
cdem_status cdem_h5_reader_read_checkpoint(cdem_h5_reader *r, cdem_snapshot *snap,
                                           int32_t *increment_number, cdem_error *err);
/* Added with issue 46: the same, the newest complete checkpoint of an increment numbered at
 * most through (a resume must not build on a damaged row); CDEM_ERR_NOTFOUND naming the
 * limit when none is. */
cdem_status cdem_h5_reader_read_checkpoint_through(cdem_h5_reader *r, cdem_snapshot *snap,
                                                   int32_t through, int32_t *increment_number,
                                                   cdem_error *err);

cdem_status cdem_h5_reader_params(const cdem_h5_reader *r, cdem_params *p, cdem_error *err);

#endif
