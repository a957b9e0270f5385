/* h5_reader: opens a run file read-only and reads it: root texts, the increment list
 * (/increments/index, checked row by row), an increment's elements, the time series, the
 * parameters. Non-HDF5, non-cdem, wrong-version, truncated or corrupt files fail with a
 * message naming the path and the problem, never a crash.
 * How a file is opened (the reasons are at reader_setup): SWMR-read, with bounded metadata
 * retries, while a writer holds the path's lock; otherwise the file is complete and opened as
 * one ("clear_status_flags" and "skip_eof_check", read-only, what h5clear uses). A file whose
 * writer did not close it ends before the first increment not backed by data.
 * Version-1 files (one group per increment) are read by h5_reader_v1.c. */
#include "h5_internal.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

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

/* *text replaced by its printable form (h5i_printable): the texts of a file are printed to
 * terminals and into JSON, and a damaged or forged one may hold any bytes (a stop reason of
 * 0xFF 0xFE was printed raw). */
static int make_printable(char **text) {
    char *p = h5i_printable(*text);
    if (!p)
        return -1;
    free(*text);
    *text = p;
    return 0;
}

/* A root text attribute into *out (malloc'd, "" when absent); printable when shown (every
 * text but the parameter file, which is parsed, never printed by the reader). */
static cdem_status read_root_text(cdem_h5_reader *r, const char *name, char **out, int shown,
                                  cdem_error *err) {
    int rc = h5i_get_str_attr(r->file, name, out);
    if (rc < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: root attribute '%s' is not a readable string",
                      r->path, name);
    if (rc > 0 && !(*out = h5i_dup_str("")))
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    if (shown && make_printable(out) != 0)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    return CDEM_OK;
}

/* The stop reason must be one the writer records (h5format.h, cdem_stop_reasons); the detail
 * is made printable. Called once the texts are read (either version). */
static cdem_status check_stop_texts(cdem_h5_reader *r, const char *where, cdem_error *err) {
    if (!h5i_known_stop_reason(r->stop_reason)) {
        char *shown = h5i_printable(r->stop_reason);
        cdem_status st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                                   "%s: %s is \"%.80s\", not a stop reason (running, completed, "
                                   "interrupted, stopped-early, numerical-failure, "
                                   "write-failure, error): damaged file",
                                   r->path, where, shown ? shown : "?");
        free(shown);
        return st;
    }
    if (make_printable(&r->stop_detail) != 0)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    return CDEM_OK;
}

/* "integer", "float", ... for messages. */
static const char *class_name(H5T_class_t c) {
    return c == H5T_INTEGER    ? "integer"
           : c == H5T_FLOAT    ? "float"
           : c == H5T_STRING   ? "string"
           : c == H5T_COMPOUND ? "compound"
           : c == H5T_ARRAY    ? "array"
                               : "other";
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
    hid_t es = h5i_keep_errors(!ok);
    if (mt >= 0)
        H5Tclose(mt);
    if (t >= 0)
        H5Tclose(t);
    if (sp >= 0)
        H5Sclose(sp);
    H5Dclose(ds);
    h5i_restore_errors(es);
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
        if (h5i_read_all_rows(ds, mt, n, dst) == 0)
            return 0;
        if (!r->swmr || attempt >= 6)
            return -1;
        H5Eclear2(H5E_DEFAULT);
        struct timespec ts = {0, (long)(10 * 1000 * 1000) << attempt}; /* 10 .. 320 ms */
        nanosleep(&ts, NULL);
    }
}

/* A closed file with the commit record: its writer wrote every row to both the record and
 * /increments/index, so their lengths agree; a record whose rows were blanked (all zero
 * passes as "never written") would otherwise read as a run of fewer increments, or none. The
 * index's chunks are not read (damage there costs no increment), only its extent; an index
 * that cannot be opened is left to HDF5 tools. */
static cdem_status check_index_agrees(cdem_h5_reader *r, hsize_t committed, cdem_error *err) {
    if (r->index < 0 && (r->index = H5Dopen2(r->file, "increments/index", H5P_DEFAULT)) < 0) {
        H5Eclear2(H5E_DEFAULT);
        return CDEM_OK;
    }
    hid_t sp = H5Dget_space(r->index);
    hsize_t rows = 0;
    const int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
    if (rank == 1)
        H5Sget_simple_extent_dims(sp, &rows, NULL);
    if (sp >= 0)
        H5Sclose(sp);
    H5Eclear2(H5E_DEFAULT);
    if (rank != 1 || rows == committed)
        return CDEM_OK;
    return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                     "%s: the commit record /increments/commit holds %llu committed rows but "
                     "/increments/index %llu, in a file its writer closed (it writes every row to "
                     "both): damaged file",
                     r->path, (unsigned long long)committed, (unsigned long long)rows);
}

/* Version 2, a file with the commit record (h5_commit.c): its committed rows into *out
 * (malloc'd, *rows of them). The dataset is opened for this read alone, so a reader that
 * follows a running writer reads the rows from the file every time, never from a buffer. */
static cdem_status read_commit_record(cdem_h5_reader *r, index_row **out, hsize_t *rows,
                                      cdem_error *err) {
    *out = NULL;
    *rows = 0;
    hid_t ds = H5Dopen2(r->file, "increments/commit", H5P_DEFAULT);
    if (ds < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /increments/commit is missing or corrupt",
                      r->path);
    const hsize_t capacity = h5i_extent_of(ds);
    hid_t ft = H5Dget_type(ds), mt = h5i_commit_type(0), want = h5i_commit_type(1);
    const int type_ok = ft >= 0 && want >= 0 && H5Tequal(ft, want) > 0;
    commit_row *c = capacity && capacity <= MAX_ELEMENTS ? calloc(capacity, sizeof *c) : NULL;
    index_row *ix = capacity && capacity <= MAX_ELEMENTS ? malloc(capacity * sizeof *ix) : NULL;
    cdem_status st = CDEM_OK;
    if (!type_ok)
        st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                       "%s: dataset /increments/commit does not have the commit record's type "
                       "(docs/format.md)",
                       r->path);
    else if (capacity == 0 || capacity > MAX_ELEMENTS)
        st = CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: /increments/commit claims %llu rows", r->path,
                       (unsigned long long)capacity);
    else if (!c || !ix || mt < 0)
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the commit record of %s",
                       r->path);
    else if (h5i_read_all_rows(ds, mt, capacity, c) < 0)
        st = H5FAIL(err, CDEM_ERR_FORMAT,
                    "%s: /increments/commit (the commit record) is unreadable", r->path);
    hsize_t committed = 0, torn = 0, bad = 0;
    const char *why =
        st == CDEM_OK ? h5i_commit_scan(c, capacity, r->unclosed, &committed, &torn, &bad) : NULL;
    if (why)
        st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                       "%s: /increments/commit row %llu: %s; rows 0..%lld are valid: damaged file",
                       r->path, (unsigned long long)bad, why, (long long)committed - 1);
    if (st == CDEM_OK && !r->unclosed)
        st = check_index_agrees(r, committed, err);
    if (st == CDEM_OK) {
        for (hsize_t i = 0; i < committed; i++)
            ix[i] = c[i].row;
        *out = ix;
        *rows = committed;
        r->n_skipped = (size_t)torn;
        ix = NULL;
    }
    free(ix);
    free(c);
    if (mt >= 0)
        H5Tclose(mt);
    if (want >= 0)
        H5Tclose(want);
    if (ft >= 0)
        H5Tclose(ft);
    H5Dclose(ds);
    return st;
}

/* Version 2, a file without the commit record: /increments/index must be a 1-D compound
 * dataset with every member of an index row, of its type class (an index replaced by a 5 x 5
 * float dataset read as a file of no increments beside a stop detail of 284). */
static cdem_status check_index_type(cdem_h5_reader *r, cdem_error *err) {
    hid_t t = H5Dget_type(r->index), sp = H5Dget_space(r->index);
    const H5T_class_t cls = t >= 0 ? H5Tget_class(t) : H5T_NO_CLASS;
    const int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
    const char *missing = NULL;
    for (size_t k = 0; k < N_INDEX_MEMBERS && cls == H5T_COMPOUND && !missing; k++) {
        const index_member *m = &h5i_index_members[k];
        const int at = H5Tget_member_index(t, m->name);
        const H5T_class_t mc = at >= 0 ? H5Tget_member_class(t, (unsigned)at) : H5T_NO_CLASS;
        if (mc != (m->kind == IX_F64 ? H5T_FLOAT : H5T_INTEGER))
            missing = m->name;
    }
    hid_t es = h5i_keep_errors(cls != H5T_COMPOUND || rank != 1 || missing);
    if (t >= 0)
        H5Tclose(t);
    if (sp >= 0)
        H5Sclose(sp);
    h5i_restore_errors(es);
    H5Eclear2(H5E_DEFAULT);
    if (cls == H5T_COMPOUND && rank == 1 && !missing)
        return CDEM_OK;
    if (missing)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: dataset /increments/index (the list of increments) lacks the "
                         "member '%s' of its documented type (docs/format.md): damaged file",
                         r->path, missing);
    return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                     "%s: dataset /increments/index (the list of increments) is a %d-D %s "
                     "dataset, not the 1-D compound dataset of index rows (number, step, time, "
                     "...; docs/format.md): damaged file",
                     r->path, rank, class_name(cls));
}

/* Version 2, a file without the commit record (written before it existed): the rows of
 * /increments/index into *out (malloc'd, *rows of them). In a file whose writer did not
 * close it, a last chunk whose checksum fails because a kill tore its rewrite gives back the
 * rows its stored checksum covers (h5i_index_recover_torn_chunk). */
static cdem_status read_old_index(cdem_h5_reader *r, index_row **out, hsize_t *rows,
                                  cdem_error *err) {
    *out = NULL;
    *rows = 0;
    if (r->index < 0 && (r->index = H5Dopen2(r->file, "increments/index", H5P_DEFAULT)) < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /increments/index is missing or corrupt",
                      r->path);
    if (r->swmr && H5Drefresh(r->index) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot refresh /increments/index", r->path);
    CDEM_TRY(check_index_type(r, err));
    hsize_t n = h5i_extent_of(r->index);
    if (n > MAX_ELEMENTS)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: /increments/index claims %llu rows", r->path,
                         (unsigned long long)n);
    if (n == 0)
        return CDEM_OK;
    index_row *ix = malloc(n * sizeof *ix);
    hid_t mt = h5i_make_compound(h5i_index_members, N_INDEX_MEMBERS, sizeof(index_row), 0);
    cdem_status st = CDEM_OK;
    if (!ix || mt < 0) {
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the index of %s", r->path);
    } else if (read_rows_retrying(r, r->index, mt, n, ix) < 0) {
        hsize_t got = r->unclosed ? h5i_index_recover_torn_chunk(r->index, n, ix) : 0;
        if (got == 0)
            st = H5FAIL(err, CDEM_ERR_FORMAT,
                        "%s: /increments/index (the list of increments) is damaged or unreadable: "
                        "no increment of this file can be trusted",
                        r->path);
        else
            H5Eclear2(H5E_DEFAULT);
        n = got;
    }
    if (mt >= 0)
        H5Tclose(mt);
    if (st != CDEM_OK) {
        free(ix);
        return st;
    }
    *out = ix;
    *rows = n;
    return CDEM_OK;
}

/* A follower's second look at the element datasets (all open): refreshed again, their
 * shortest extents into *data_ext and *stress_ext. */
static void refresh_extents(cdem_h5_reader *r, hsize_t *data_ext, hsize_t *stress_ext) {
    int first_data = 1, first_stress = 1;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        if (r->data[k] < 0 || H5Drefresh(r->data[k]) < 0)
            continue;
        const hsize_t e = h5i_extent_of(r->data[k]);
        hsize_t *ext = h5i_element_fields[k].optional ? stress_ext : data_ext;
        int *first = h5i_element_fields[k].optional ? &first_stress : &first_data;
        *ext = *first || e < *ext ? e : *ext;
        *first = 0;
    }
    H5Eclear2(H5E_DEFAULT);
}

static int all_zero(const void *p, size_t n) {
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++)
        if (b[i])
            return 0;
    return 1;
}

/* A run that completed, or was stopped and wrote its final increment, holds increments:
 * such a stop reason in a closed file of none is damage, not "increments: 0" (the audit of
 * issue 35 saw that beside "completed ... 284 increments"). */
static cdem_status check_not_empty(cdem_h5_reader *r, cdem_error *err) {
    const char *why = r->stop_reason;
    if (r->n_incr > 0 || r->unclosed ||
        (strcmp(why, "completed") && strcmp(why, "interrupted") && strcmp(why, "stopped-early")))
        return CDEM_OK;
    return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                     "%s: the run's stop reason is \"%s\" (\"%.200s\"), which it records after "
                     "writing increments, but the file lists none (%s holds no valid row): "
                     "damaged file",
                     r->path, why, r->stop_detail,
                     r->version < 2 ? "/increments has no group"
                     : H5Lexists(r->file, "increments/commit", H5P_DEFAULT) > 0
                         ? "the commit record /increments/commit"
                         : "/increments/index");
}

/* Version 2: (re)reads the list of increments and the stop reason. The list comes from the
 * commit record (/increments/commit) when the file has one, else from /increments/index;
 * in SWMR-read mode the element datasets are refreshed after it, so that they are at least
 * as long as the rows it lists (the writer writes them in the other order). Every row is
 * checked against the one before and the extents. In a file whose writer did not close it,
 * an old-layout list ends before a row not backed by data (a kill mid-append, or a follower
 * that sees the grown extent before the row) when only such rows follow; in a closed file
 * such a row is an error. */
static cdem_status scan_v2(cdem_h5_reader *r, cdem_error *err) {
    CDEM_TRY(read_text_dataset(r, "stop_reason", &r->stop_reason, err));
    CDEM_TRY(read_text_dataset(r, "stop_detail", &r->stop_detail, err));
    CDEM_TRY(check_stop_texts(r, "dataset /stop_reason", err));
    r->n_skipped = 0;
    const htri_t has_commit = H5Lexists(r->file, "increments/commit", H5P_DEFAULT);
    if (has_commit < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: the group /increments is missing or corrupt",
                      r->path);
    index_row *ix = NULL;
    hsize_t rows = 0;
    CDEM_TRY(has_commit ? read_commit_record(r, &ix, &rows, err)
                        : read_old_index(r, &ix, &rows, err));
    hsize_t data_ext = 0, stress_ext = 0;
    int first_data = 1, first_stress = 1;
    cdem_status st = CDEM_OK;
    for (size_t k = 0; k < N_ELEMENT_FIELDS && st == CDEM_OK; k++) {
        const element_field *fd = &h5i_element_fields[k];
        char name[64];
        snprintf(name, sizeof name, "increments/%s", fd->name);
        if (r->data[k] < 0) {
            if ((r->data[k] = H5Dopen2(r->file, name, H5P_DEFAULT)) < 0) {
                st = H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /%s is missing or corrupt", r->path,
                            name);
                break;
            }
            hid_t t = H5Dget_type(r->data[k]), sp = H5Dget_space(r->data[k]);
            H5T_class_t cls = t >= 0 ? H5Tget_class(t) : H5T_NO_CLASS;
            int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
            if (t >= 0)
                H5Tclose(t);
            if (sp >= 0)
                H5Sclose(sp);
            H5T_class_t want = fd->type == CDEM_FIELD_F64 ? H5T_FLOAT : H5T_INTEGER;
            if (cls != want || rank != 1) {
                st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                               "%s: dataset /%s has type class %d and rank %d (expected a 1-D "
                               "%s dataset)",
                               r->path, name, (int)cls, rank,
                               want == H5T_FLOAT ? "float" : "integer");
                break;
            }
        } else if (r->swmr && H5Drefresh(r->data[k]) < 0) {
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot refresh /%s", r->path, name);
            break;
        }
        hsize_t e = h5i_extent_of(r->data[k]);
        if (fd->optional) {
            stress_ext = first_stress || e < stress_ext ? e : stress_ext;
            first_stress = 0;
        } else {
            data_ext = first_data || e < data_ext ? e : data_ext;
            first_data = 0;
        }
    }
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
    for (hsize_t i = 0; st == CDEM_OK && i < rows; i++) {
        char buf[300];
        const char *why =
            h5i_bad_index_row(&ix[i], i ? &ix[i - 1] : NULL, data_ext, stress_ext, buf, sizeof buf);
        /* A follower can see a commit row before HDF5 shows it the extents the writer flushed
         * before that row (seen under load: a row "beyond the element datasets" that a later
         * refresh covers): it looks again for about 0.6 s, and lists no row it cannot see. */
        for (int attempt = 0; why && has_commit && r->swmr && attempt < 6; attempt++) {
            struct timespec ts = {0, (long)(10 * 1000 * 1000) << attempt}; /* 10 .. 320 ms */
            nanosleep(&ts, NULL);
            refresh_extents(r, &data_ext, &stress_ext);
            why = h5i_bad_index_row(&ix[i], i ? &ix[i - 1] : NULL, data_ext, stress_ext, buf,
                                    sizeof buf);
        }
        if (why && has_commit && r->swmr) {
            r->n_skipped = (size_t)(rows - i);
            break;
        }
        if (why) {
            /* An old-layout list: a writer that died (or is writing) can leave its last rows
             * unwritten (fill, all zero), never an earlier one: a bad row before a good one
             * is damage. A committed row of the commit record is never unwritten. */
            int only_unwritten_after = 1;
            for (hsize_t j = i + 1; j < rows && only_unwritten_after; j++)
                only_unwritten_after = all_zero(&ix[j], sizeof ix[j]);
            if (!has_commit && r->unclosed && only_unwritten_after) {
                r->n_skipped = (size_t)(rows - i);
                break;
            }
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: %s row %llu (increment %d): %s: damaged file",
                           r->path, has_commit ? "/increments/commit" : "/increments/index",
                           (unsigned long long)i, (int)ix[i].number, why);
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
    return st == CDEM_OK ? check_not_empty(r, err) : st;
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
    char *reason = h5i_dup_str(r->stop_reason);
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
    CDEM_TRY(h5i_precheck_superblock(path, &status, err));
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
    r->writer = 0;
    if (r->unclosed) {
        char *real = realpath(path, NULL);
        r->writer = cdem_runlock_probe(real ? real : path, NULL, 0);
        free(real);
    }
    const int live = (status & 0x04) && r->writer != 0;
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
    int rc = h5i_get_str_attr(r->file, "format", &fmt);
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
    rc = h5i_get_num_attr(r->file, "format_version", H5T_NATIVE_INT32, &version);
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
    if (h5i_get_num_attr(r->file, "seed", H5T_NATIVE_INT64, &seed) < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: root attribute 'seed' is unreadable", path);
    r->seed = (long)seed;
    CDEM_TRY(read_root_text(r, "summary", &r->summary, 1, err));
    CDEM_TRY(read_root_text(r, "params_text", &r->params_text, 0, err));
    CDEM_TRY(read_root_text(r, "program_version", &r->program_version, 1, err));
    CDEM_TRY(read_root_text(r, "source", &r->source, 1, err));
    CDEM_TRY(read_root_text(r, "created", &r->created, 1, err));
    if (r->version >= 2)
        return scan_v2(r, err);
    CDEM_TRY(read_root_text(r, "stop_reason", &r->stop_reason, 0, err));
    CDEM_TRY(read_root_text(r, "stop_detail", &r->stop_detail, 0, err));
    CDEM_TRY(check_stop_texts(r, "root attribute stop_reason", err));
    CDEM_TRY(h5i_v1_list_increments(r, err));
    return check_not_empty(r, err);
}

cdem_status cdem_h5_reader_open(const char *path, cdem_h5_reader **out, cdem_error *err) {
    if (out)
        *out = NULL;
    if (!path || !out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_open: path and out are required");
    h5i_quiet_hdf5();
    cdem_h5_reader *r = calloc(1, sizeof *r);
    if (!r || !(r->path = h5i_dup_str(path))) {
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

/* The rule of docs/format.md ("Counting"): the last increment of the equilibration phase is
 * its end only once an increment of a later phase follows it, or the run completed. A run
 * stopped, killed or still running in equilibration has not written its end yet (its last
 * increment was 42 where the end was 56): never guessed. */
static cdem_status equil_end(const cdem_h5_reader *r, size_t *index, const char *what,
                             cdem_error *err) {
    size_t last = SIZE_MAX;
    for (size_t i = r->n_incr; i-- > 0 && last == SIZE_MAX;)
        if (r->incr[i].info.phase == CDEM_PHASE_EQUILIBRATION)
            last = i;
    if (last == SIZE_MAX)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "%s: %sno increment is in the equilibration phase, so the file has no "
                         "end of equilibration",
                         r->path, what);
    if (last + 1 < r->n_incr || !strcmp(r->stop_reason, "completed")) {
        *index = last;
        return CDEM_OK;
    }
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                     "%s: %sthe end of equilibration is not reached: %s (its last increment, %d, "
                     "is of the equilibration phase; the end is known once an increment of the "
                     "deformation phase follows)",
                     r->path, what,
                     r->writer == 1 && !strcmp(r->stop_reason, "running")
                         ? "the run is still in equilibration"
                         : "the run stopped during equilibration",
                     (int)r->incr[last].info.number);
}

cdem_status cdem_h5_reader_equil_end(const cdem_h5_reader *r, size_t *index, cdem_error *err) {
    if (!r || !index)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_equil_end: bad arguments");
    return equil_end(r, index, "", err);
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
        return equil_end(r, index, "increment 'equil': ", err);
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

static cdem_status load_v2(cdem_h5_reader *r, const incr_entry *e, cdem_state *s, cdem_error *err) {
    const hsize_t n = (hsize_t)e->info.n_elements;
    const int stress = e->info.has_stress != 0;
    /* n comes from the index, checked only against the datasets' extents; an extent can be
     * declared with no storage behind it (HDF5 then returns fill values), so a forged file
     * could make the reader allocate for 2^31 elements: the cap of version-1 files, before
     * allocating */
    if (n > READER_MAX_ELEMENTS)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: increment %d claims %llu elements; this reader refuses more than "
                         "%llu (corrupt file?)",
                         r->path, (int)e->info.number, (unsigned long long)n,
                         (unsigned long long)READER_MAX_ELEMENTS);
    cdem_state_free(s);
    CDEM_TRY(cdem_state_init(s, n ? (size_t)n : 1, stress, err));
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        const element_field *fd = &h5i_element_fields[k];
        if (fd->optional && !stress)
            continue;
        hsize_t off = (hsize_t)(fd->optional ? e->stress_offset : e->offset);
        if (h5i_read_rows(r->data[k], h5i_el_mem_type(fd->type), off, n, h5i_element_array(s, k)) <
            0)
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

/* The dataset and row of value i of field (an element dataset's name) of increment e, for
 * messages: "/increments/x row 8197" (version 2), "/increments/000003/x row 5" (version 1). */
static void row_name(const cdem_h5_reader *r, const incr_entry *e, const char *field, size_t i,
                     char *buf, size_t cap) {
    const int stress = field[0] == 's'; /* sxx, syy, sxy */
    if (r->version >= 2)
        snprintf(buf, cap, "/increments/%s row %llu", field,
                 (unsigned long long)(stress ? e->stress_offset : e->offset) +
                     (unsigned long long)i);
    else
        snprintf(buf, cap, "/increments/%s/%s row %zu", e->name, field, i);
}

/* A loaded increment's values against the physical bounds (h5i_bad_element) and its ids
 * unique: a checksum says the bytes are the writer's, not that they are a model's (radii of
 * 0 made compute print 1288 nan; a duplicated id failed deep inside the strain code, naming
 * neither file nor increment). */
static cdem_status check_loaded(const cdem_h5_reader *r, const incr_entry *e, const cdem_state *s,
                                cdem_error *err) {
    char why[200], where[160];
    for (size_t i = 0; i < s->n; i++) {
        const char *field = NULL;
        if (!h5i_bad_element(s, i, &field, why, sizeof why))
            continue;
        row_name(r, e, field, i, where, sizeof where);
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: increment %d, %s (element id %d): %s (docs/format.md, \"Physical "
                         "bounds\"): damaged file",
                         r->path, (int)e->info.number, where, (int)s->id[i], why);
    }
    size_t a = 0, b = 0;
    const int dup = h5i_find_duplicate_id(s->id, s->n, &a, &b);
    if (dup < 0)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory checking the ids of increment %d",
                         r->path, (int)e->info.number);
    if (dup) {
        row_name(r, e, "id", a, where, sizeof where);
        row_name(r, e, "id", b, why, sizeof why);
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: increment %d: element id %d appears twice, at %s and at %s (ids are "
                         "unique within an increment): damaged file",
                         r->path, (int)e->info.number, (int)s->id[a], where, strstr(why, "row"));
    }
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
    cdem_status st = r->version >= 2 ? load_v2(r, e, s, err) : h5i_v1_load(r, e, s, err);
    if (st == CDEM_OK)
        st = check_loaded(r, e, s, err);
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
        snprintf(name, sizeof name, "series/%s", h5i_series_columns[opened].name);
        if (h5i_series_columns[opened].optional && H5Lexists(r->file, name, H5P_DEFAULT) <= 0) {
            ds[opened] = -1; /* a file from before the column existed: NaN below */
            dims[opened] = 0;
            continue;
        }
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
        /* each column of its documented class: a float step (or an integer time) is a
         * forgery, not a file any writer made */
        const H5T_class_t want =
            h5i_series_columns[opened].type == COL_I64 ? H5T_INTEGER : H5T_FLOAT;
        if (rank != 1 || cls != want) {
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: dataset /%s is a %d-D %s dataset; the column is a 1-D %s dataset "
                           "(docs/format.md, \"/series\"): damaged file",
                           r->path, name, rank, class_name(cls),
                           want == H5T_INTEGER ? "integer (int64)" : "float (float64)");
            opened++;
            break;
        }
    }
    hsize_t len = 0;
    if (st == CDEM_OK) {
        len = dims[0];
        for (size_t c = 1; c < N_SERIES; c++) {
            if (dims[c] == len || ds[c] < 0)
                continue;
            /* A writer killed inside a flush may leave columns of different lengths: keep
             * the common part. A closed file must be consistent. */
            if (!r->unclosed) {
                st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                               "%s: dataset /series/%s has %llu samples but /series/%s has %llu",
                               r->path, h5i_series_columns[c].name, (unsigned long long)dims[c],
                               h5i_series_columns[0].name, (unsigned long long)len);
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
    const hsize_t full = len;
    for (size_t c = 0; st == CDEM_OK && c < N_SERIES && len > 0; c++) {
        const series_column *sc = &h5i_series_columns[c];
        if (ds[c] < 0) { /* absent optional column (float64): not measured */
            const double nan = NAN;
            for (hsize_t i = 0; i < len; i++)
                memcpy((char *)&out[i] + sc->offset, &nan, 8);
            continue;
        }
        hid_t mt = sc->type == COL_I64 ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE;
        int bad = read_rows_retrying(r, ds[c], mt, len, col) < 0;
        /* A writer killed while it extended the series can leave the newest chunk of a
         * column unreadable (seen: its index entry pointing past the end of the file, after
         * a SIGKILL in test_format_writer_killed_mid_increment under load). In a file its
         * writer did not close, the series then ends before that chunk: the samples of every
         * committed increment lie in the chunks before it (a new chunk is begun only by
         * samples after the last commit). One chunk only: damage further back is an error. */
        const hsize_t chunk = bad && r->unclosed && len == full ? h5i_chunk_rows_of(ds[c]) : 0;
        if (chunk > 0) {
            H5Eclear2(H5E_DEFAULT);
            const hsize_t shorter = (len - 1) / chunk * chunk;
            if (shorter == 0 || h5i_read_all_rows(ds[c], mt, shorter, col) == 0) {
                len = shorter;
                bad = 0;
                if (len == 0)
                    break;
            }
        }
        if (bad) {
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
        if (q->step >= 0 && q->time >= 0.0 && q->time <= CDEM_FILE_MAX_TIME &&
            (!p || (q->step > p->step && q->time >= p->time)))
            continue;
        if (r->unclosed) {
            len = i;
            break;
        }
        st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                       "%s: /series sample %llu (step %lld, time %.17g s) is out of order (the "
                       "previous one is step %lld, time %.17g s; steps must increase and times "
                       "must be finite, in 0..1e9 s and not decrease): damaged file",
                       r->path, (unsigned long long)i, (long long)q->step, q->time,
                       p ? (long long)p->step : -1LL, p ? p->time : 0.0);
    }
    /* Every other value within the physical bounds (a run that blew up may end on samples of
     * Inf or NaN: its stop reason says so). */
    unsigned absent = 0;
    for (size_t c = 0; st == CDEM_OK && c < N_SERIES; c++)
        absent |= (unsigned)(ds[c] < 0) << c;
    const int blown_up = !strcmp(r->stop_reason, "numerical-failure");
    for (hsize_t i = 0; st == CDEM_OK && i < len; i++) {
        const char *column = NULL;
        char why[160];
        if (h5i_bad_sample(&out[i], blown_up, absent, &column, why, sizeof why))
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: /series/%s sample %llu (step %lld): %s (docs/format.md, "
                           "\"Physical bounds\"): damaged file",
                           r->path, column, (unsigned long long)i, (long long)out[i].step, why);
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

int cdem_h5_reader_writer_alive(const cdem_h5_reader *r) {
    return r ? r->writer : 0;
}

int cdem_h5_reader_format_version(const cdem_h5_reader *r) {
    return r ? r->version : 0;
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
        int rc = h5i_get_str_attr(ds, key, &value);
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
