/* h5_reader_list: the list of increments of a version-2 file (docs/format.md,
 * "/increments/commit"): from the commit record when the file has one, else from
 * /increments/index (with the recovery of a torn last chunk, h5_commit.c); every row
 * checked against the one before, the element datasets' extents and the physical bounds;
 * a follower's view of a running writer (SWMR) handled where it may lag. h5_reader.c reads
 * the stop texts and calls h5i_reader_scan on open and on every refresh. */
#include "h5_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The extent of /increments/index (H5I_ROWS_UNKNOWN when it cannot be opened or is not 1-D):
 * in a closed file the number of rows its writer wrote. Its chunks are not read (damage
 * there costs no increment); an index that cannot be opened is left to HDF5 tools. */
static hsize_t index_extent(cdem_h5_reader *r) {
    if (r->index < 0 && (r->index = H5Dopen2(r->file, "increments/index", H5P_DEFAULT)) < 0) {
        H5Eclear2(H5E_DEFAULT);
        return H5I_ROWS_UNKNOWN;
    }
    hid_t sp = H5Dget_space(r->index);
    hsize_t rows = 0;
    const int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
    if (rank == 1)
        H5Sget_simple_extent_dims(sp, &rows, NULL);
    if (sp >= 0)
        H5Sclose(sp);
    H5Eclear2(H5E_DEFAULT);
    return rank == 1 ? rows : H5I_ROWS_UNKNOWN;
}

/* The increment damaged row j held, from the valid rows around it (kind: the record's
 * classification, c its rows): the number of the valid row before it plus the rows between,
 * when the valid row after it (if any) agrees; from the row after it when none is before;
 * j itself (cdem-run numbers its increments by row) when no row is valid. -1: unknown. */
static int32_t damaged_number(const commit_row *c, const unsigned char *kind, hsize_t capacity,
                              hsize_t j) {
    hsize_t i = j, m = j + 1;
    while (i > 0 && kind[i - 1] != COMMIT_VALID)
        i--;
    while (m < capacity && kind[m] != COMMIT_VALID)
        m++;
    const int have_prev = i > 0, have_next = m < capacity;
    if (have_prev) {
        const int64_t guess = (int64_t)c[i - 1].row.number + (int64_t)(j - (i - 1));
        if (have_next && (int64_t)c[m].row.number != guess + (int64_t)(m - j))
            return -1;
        return guess <= INT32_MAX ? (int32_t)guess : -1;
    }
    if (have_next) {
        const int64_t guess = (int64_t)c[m].row.number - (int64_t)(m - j);
        return guess >= 0 ? (int32_t)guess : -1;
    }
    return j <= INT32_MAX ? (int32_t)j : -1;
}

/* The damaged rows of the record into r (r->damaged, r->damage: the one warning that names
 * them, the file, what is wrong with each and what it costs). */
static cdem_status note_damage(cdem_h5_reader *r, const commit_row *c, const unsigned char *kind,
                               hsize_t capacity, const commit_scan_out *scan, cdem_error *err) {
    free(r->damaged);
    r->damaged = NULL;
    r->n_damaged = 0;
    r->damage[0] = '\0';
    r->damaged_through = INT32_MAX;
    r->last_damaged = 0;
    if (scan->damaged == 0)
        return CDEM_OK;
    if (!(r->damaged = calloc((size_t)scan->damaged, sizeof *r->damaged)))
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory listing the damaged rows of %s",
                         r->path);
    char *t = r->damage;
    const size_t cap = sizeof r->damage;
    size_t at = (size_t)snprintf(t, cap, "%s: damaged file: /increments/commit ", r->path);
    size_t named = 0, lost = 0;
    char lost_list[200] = "";
    for (hsize_t j = 0; j < capacity; j++) {
        if (kind[j] != COMMIT_DAMAGED && kind[j] != COMMIT_SPARE_DAMAGED)
            continue;
        damaged_row *d = &r->damaged[r->n_damaged++];
        d->row = j;
        d->spare = kind[j] == COMMIT_SPARE_DAMAGED;
        d->number = d->spare ? -1 : damaged_number(c, kind, capacity, j);
        d->what = h5i_commit_damage_text(&c[j], kind[j]);
        if (!d->spare) {
            if (r->damaged_through == INT32_MAX) { /* the last valid increment before it */
                hsize_t i = j;
                while (i > 0 && kind[i - 1] != COMMIT_VALID)
                    i--;
                r->damaged_through = i > 0 ? c[i - 1].row.number : -1;
            }
            r->last_damaged = j + 1 == scan->written;
            const size_t len = strlen(lost_list);
            if (lost < 6 && d->number >= 0)
                snprintf(lost_list + len, sizeof lost_list - len, "%s%d", lost ? ", " : "",
                         (int)d->number);
            else if (lost < 6)
                snprintf(lost_list + len, sizeof lost_list - len, "%sthat of row %llu",
                         lost ? ", " : "", (unsigned long long)j);
            else if (lost == 6)
                snprintf(lost_list + len, sizeof lost_list - len, ", ...");
            lost++;
        }
        if (named < 4 && at < cap) {
            char num[48];
            if (d->spare)
                snprintf(num, sizeof num, "a spare row");
            else if (d->number >= 0)
                snprintf(num, sizeof num, "increment %d", (int)d->number);
            else
                snprintf(num, sizeof num, "increment unknown");
            at += (size_t)snprintf(t + at, cap - at, "%srow %llu (%s): %s", named ? "; " : "",
                                   (unsigned long long)j, num,
                                   d->spare ? "not blank, yet never written" : d->what);
        } else if (named == 4 && at < cap) {
            at += (size_t)snprintf(t + at, cap - at, "; and %llu more damaged rows",
                                   (unsigned long long)(scan->damaged - 4));
        }
        named++;
    }
    if (at < cap) {
        if (lost)
            snprintf(t + at, cap - at,
                     "; increment%s %s cannot be read, the other %llu increments can "
                     "(docs/format.md, \"/increments/commit\")",
                     lost > 1 ? "s" : "", lost_list, (unsigned long long)scan->valid);
        else
            snprintf(t + at, cap - at,
                     "; no increment is lost: the %llu increments can be read (docs/format.md, "
                     "\"/increments/commit\")",
                     (unsigned long long)scan->valid);
    }
    return CDEM_OK;
}

/* Version 2, a file with the commit record (h5_commit.c): its valid rows into *out and their
 * positions into *pos (malloc'd, *rows of them), its damaged rows into r (note_damage). The
 * dataset is opened for this read alone, so a reader that follows a running writer reads the
 * rows from the file every time, never from a buffer. */
static cdem_status read_commit_record(cdem_h5_reader *r, index_row **out, hsize_t **pos,
                                      hsize_t *rows, cdem_error *err) {
    *out = NULL;
    *pos = NULL;
    *rows = 0;
    hid_t ds = H5Dopen2(r->file, "increments/commit", H5P_DEFAULT);
    if (ds < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /increments/commit is missing or corrupt",
                      r->path);
    const hsize_t capacity = h5i_extent_of(ds);
    hid_t ft = H5Dget_type(ds), mt = h5i_commit_type(0), want = h5i_commit_type(1);
    const int type_ok = ft >= 0 && want >= 0 && H5Tequal(ft, want) > 0;
    const int sized = capacity && capacity <= MAX_ELEMENTS;
    commit_row *c = sized ? calloc(capacity, sizeof *c) : NULL;
    index_row *ix = sized ? malloc(capacity * sizeof *ix) : NULL;
    hsize_t *at = sized ? malloc(capacity * sizeof *at) : NULL;
    unsigned char *kind = sized ? malloc(capacity) : NULL;
    cdem_status st = CDEM_OK;
    if (!type_ok)
        st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                       "%s: dataset /increments/commit does not have the commit record's type "
                       "(docs/format.md)",
                       r->path);
    else if (!sized)
        st = CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: /increments/commit claims %llu rows", r->path,
                       (unsigned long long)capacity);
    else if (!c || !ix || !at || !kind || mt < 0)
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the commit record of %s",
                       r->path);
    else if (h5i_read_all_rows(ds, mt, capacity, c) < 0)
        st = H5FAIL(err, CDEM_ERR_FORMAT,
                    "%s: /increments/commit (the commit record) is unreadable", r->path);
    commit_scan_out scan;
    memset(&scan, 0, sizeof scan);
    if (st == CDEM_OK) {
        const haddr_t base = H5Dget_offset(ds);
        H5Eclear2(H5E_DEFAULT);
        commit_scan_in in = {
            .unclosed = r->unclosed,
            .live = r->swmr,
            /* a live writer's index is not read: it grows after the record */
            .index_rows = r->swmr ? H5I_ROWS_UNKNOWN : index_extent(r),
            .record_at = base == HADDR_UNDEF ? H5I_ROWS_UNKNOWN : (uint64_t)base,
            .row_bytes = H5Tget_size(ft),
        };
        if (h5i_commit_scan(c, capacity, &in, kind, &scan))
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: the commit record /increments/commit holds %llu committed rows "
                           "but /increments/index %llu, in a file its writer closed (it writes "
                           "every row to both): damaged file",
                           r->path, (unsigned long long)scan.valid,
                           (unsigned long long)in.index_rows);
    }
    if (st == CDEM_OK)
        st = note_damage(r, c, kind, capacity, &scan, err);
    if (st == CDEM_OK) {
        hsize_t n = 0;
        for (hsize_t i = 0; i < capacity; i++)
            if (kind[i] == COMMIT_VALID) {
                ix[n] = c[i].row;
                at[n++] = i;
            }
        *out = ix;
        *pos = at;
        *rows = n;
        r->n_skipped = (size_t)scan.torn;
        ix = NULL;
        at = NULL;
    }
    free(kind);
    free(at);
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
                     r->path, rank, h5i_class_name(cls));
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
    } else if (h5i_read_rows_retrying(r->swmr, r->index, mt, n, ix) < 0) {
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
cdem_status h5i_reader_check_not_empty(cdem_h5_reader *r, cdem_error *err) {
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
cdem_status h5i_reader_scan(cdem_h5_reader *r, cdem_error *err) {
    r->n_skipped = 0;
    const htri_t has_commit = H5Lexists(r->file, "increments/commit", H5P_DEFAULT);
    if (has_commit < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: the group /increments is missing or corrupt",
                      r->path);
    index_row *ix = NULL;
    hsize_t rows = 0, *pos = NULL; /* pos: each listed row's place in the record (NULL: i) */
    CDEM_TRY(has_commit ? read_commit_record(r, &ix, &pos, &rows, err)
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
                           (unsigned long long)(pos ? pos[i] : i), (int)ix[i].number, why);
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
    free(pos);
    return st == CDEM_OK ? h5i_reader_check_not_empty(r, err) : st;
}
