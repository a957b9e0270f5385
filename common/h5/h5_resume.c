/* h5_resume: re-opens a run file to go on writing it (cdem-run --resume). Under the path's
 * lock, in this order:
 *  - every increment to keep (up to the checkpoint's) and the series are read back through
 *    the reader, data and checksums: a resume never continues a file that holds an increment
 *    nobody can read (issue 35, item 4); such a file is refused, naming the increment, before
 *    anything is written, so it stays byte for byte as it was;
 *  - a file a size limit cut short (its superblock records more bytes than it has, and its
 *    writer did not close it) is extended with zeros to the recorded size: the bytes past
 *    the cut were never written, so nothing committed was there (item 3); if the file then
 *    still does not open, it is cut back to its size and refused;
 *  - the file is opened for writing with its status flags cleared (what h5clear -s does) and
 *    its end of file put after everything it holds;
 *  - the increments after the checkpoint's are dropped: first their rows of the commit record
 *    (blanked from the last to the first, h5_commit.c), then the datasets are shrunk to what
 *    is kept (the resumed run writes them again, bit for bit), and /increments/index is
 *    rewritten from the record when a kill tore it; checkpoints of dropped increments are
 *    invalidated, the stop reason is set back to "running", and SWMR writing starts again. */
#include "h5_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Before anything is written: every increment a resume would keep (numbers up to keep_inc)
 * and the series read back, through the reader, as a killed run's file.
 * The file is only read, so a refusal leaves it byte for byte as it was (a writer's open
 * would already mark it closed). */
static cdem_status verify_kept(const char *path, int32_t keep_inc, cdem_error *err) {
    cdem_h5_reader *r = NULL;
    cdem_status st = h5i_reader_open_quiet(path, &r, err);
    if (st != CDEM_OK) {
        cdem_error_prefix(err, "%s: cannot be resumed, it was not changed", path);
        return st;
    }
    const size_t n = cdem_h5_reader_increment_count(r);
    cdem_state s;
    memset(&s, 0, sizeof s);
    int32_t first = -1, last_good = -1;
    for (size_t i = 0; i < n && st == CDEM_OK; i++) {
        cdem_increment_info in;
        if (cdem_h5_reader_increment_info(r, i, &in, err) != CDEM_OK || in.number > keep_inc)
            break;
        cdem_error e;
        cdem_error_clear(&e);
        if (cdem_h5_reader_load_increment(r, i, &s, NULL, &e) != CDEM_OK)
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: cannot be resumed: increment %d does not read back and a resumed "
                           "run would keep it; it was not changed; increments %d..%d read back "
                           "(%.500s)",
                           path, (int)in.number, (int)first, (int)last_good, e.msg);
        first = first < 0 ? in.number : first;
        last_good = in.number;
    }
    cdem_state_free(&s);
    cdem_series_sample *q = NULL;
    size_t nq = 0;
    cdem_error e;
    cdem_error_clear(&e);
    if (st == CDEM_OK && cdem_h5_reader_read_series(r, &q, &nq, &e) != CDEM_OK)
        st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                       "%s: cannot be resumed: its series does not read back; it was not "
                       "changed (%.500s)",
                       path, e.msg);
    free(q);
    cdem_h5_reader_close(r);
    return st;
}

/* The increments a resume can keep, into *out (malloc'd, *rows of them; NULL when none): the
 * valid rows of the commit record up to its first row that is not (a resume keeps a prefix
 * and never builds on a damaged row: *damaged_row is then that row, and *damaged_why what is
 * wrong with it; else *damaged_row is the record's capacity), or, in a file written before
 * the record, the rows of its index. */
static cdem_status read_rows_to_keep(cdem_h5_writer *w, int unclosed, index_row **out,
                                     hsize_t *rows, hsize_t *damaged_row, const char **damaged_why,
                                     cdem_error *err) {
    *out = NULL;
    *rows = 0;
    *damaged_row = w->commit_capacity;
    *damaged_why = NULL;
    if (w->commit >= 0) {
        const hsize_t cap = w->commit_capacity;
        commit_row *c = calloc(cap ? cap : 1, sizeof *c);
        index_row *ix = malloc((cap ? cap : 1) * sizeof *ix);
        unsigned char *kind = malloc(cap ? cap : 1);
        cdem_status st = CDEM_OK;
        if (!c || !ix || !kind)
            st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the commit record of %s",
                           w->path);
        else if (h5i_read_all_rows(w->commit, w->commit_mtype, cap, c) < 0)
            st = H5FAIL(err, CDEM_ERR_FORMAT,
                        "%s: cannot be resumed: its commit record /increments/commit is "
                        "unreadable; it was not changed",
                        w->path);
        commit_scan_out scan;
        memset(&scan, 0, sizeof scan);
        if (st == CDEM_OK) {
            const haddr_t base = H5Dget_offset(w->commit);
            hid_t ft = H5Dget_type(w->commit);
            H5Eclear2(H5E_DEFAULT);
            const commit_scan_in in = {
                .unclosed = unclosed,
                .live = 0, /* this writer holds the lock */
                .index_rows = h5i_extent_of(w->index),
                .record_at = base == HADDR_UNDEF ? H5I_ROWS_UNKNOWN : (uint64_t)base,
                .row_bytes = ft >= 0 ? H5Tget_size(ft) : 0,
            };
            if (ft >= 0)
                H5Tclose(ft);
            if (h5i_commit_scan(c, cap, &in, kind, &scan))
                st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                               "%s: cannot be resumed: its commit record /increments/commit "
                               "holds %llu committed rows but /increments/index %llu (the writer "
                               "writes every row to both): damaged file; it was not changed",
                               w->path, (unsigned long long)scan.valid,
                               (unsigned long long)in.index_rows);
        }
        hsize_t committed = 0;
        while (st == CDEM_OK && committed < cap && kind[committed] == COMMIT_VALID)
            committed++;
        if (st == CDEM_OK && scan.damaged_written) {
            *damaged_row = scan.first_damaged_written;
            *damaged_why = h5i_commit_damage_text(&c[*damaged_row], kind[*damaged_row]);
        }
        for (hsize_t i = 0; st == CDEM_OK && i < committed; i++)
            ix[i] = c[i].row;
        free(kind);
        free(c);
        if (st != CDEM_OK) {
            free(ix);
            return st;
        }
        *out = ix;
        *rows = committed;
        return CDEM_OK;
    }
    hsize_t n = h5i_extent_of(w->index);
    index_row *ix = n ? malloc(n * sizeof *ix) : NULL;
    if (n && !ix)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the index of %s", w->path);
    if (n && h5i_read_all_rows(w->index, w->index_mtype, n, ix) < 0) {
        hsize_t got = unclosed ? h5i_index_recover_torn_chunk(w->index, n, ix) : 0;
        if (got == 0) {
            free(ix);
            return H5FAIL(err, CDEM_ERR_FORMAT,
                          "%s: cannot be resumed: /increments/index is unreadable; it was not "
                          "changed",
                          w->path);
        }
        n = got;
    }
    *out = ix;
    *rows = n;
    return CDEM_OK;
}

/* /increments/index must hold exactly rows[0, keep) and be appendable: a chunk a kill tore
 * (or a row the commit record does not have) makes HDF5 refuse the next append, so the
 * dataset is then made anew from the kept rows (before SWMR writing: objects can still be
 * created). */
static cdem_status repair_index(cdem_h5_writer *w, const index_row *rows, hsize_t keep,
                                cdem_error *err) {
    const hsize_t ext = h5i_extent_of(w->index);
    index_row *have = ext ? malloc(ext * sizeof *have) : NULL;
    int sound = !ext || (have && h5i_read_all_rows(w->index, w->index_mtype, ext, have) == 0);
    H5Eclear2(H5E_DEFAULT);
    for (hsize_t i = 0; sound && i < keep; i++)
        sound = i < ext && memcmp(&have[i], &rows[i], sizeof rows[i]) == 0;
    free(have);
    if (sound)
        return CDEM_OK;
    H5Dclose(w->index);
    w->index = -1;
    hid_t ft = h5i_make_compound(h5i_index_members, N_INDEX_MEMBERS, sizeof(index_row), 1);
    int ok = ft >= 0 && H5Ldelete(w->file, "increments/index", H5P_DEFAULT) >= 0;
    hid_t g = ok ? H5Gopen2(w->file, "increments", H5P_DEFAULT) : -1;
    if (g >= 0)
        w->index = h5i_create_extendible(g, "index", ft, INDEX_CHUNK, FILTER_CHECKSUM);
    ok = w->index >= 0 && h5i_write_rows(w->index, w->index_mtype, 0, keep, rows) == 0;
    hid_t es = h5i_keep_errors(!ok);
    if (g >= 0)
        H5Gclose(g);
    if (ft >= 0)
        H5Tclose(ft);
    h5i_restore_errors(es);
    if (!ok)
        return H5FAIL(err, CDEM_ERR_IO,
                      "%s: cannot rewrite /increments/index from the commit record", w->path);
    return CDEM_OK;
}

static cdem_status reopen_setup(cdem_h5_writer *w, int32_t keep_inc, int64_t keep_step,
                                off_t *extended_from, cdem_error *err) {
    w->placed = 1;
    int flags = 0;
    CDEM_TRY(h5i_precheck_superblock(w->path, &flags, err));
    /* A writer stopped by a file size limit (or a full disk) leaves the superblock's end of
     * the file past the bytes it could write: those were never written, so zeros stand in
     * for them. Only in a file its writer did not close; cut back if the resume fails. */
    struct stat sb;
    const uint64_t eoa = h5i_superblock_eoa(w->path);
    if (flags != 0 && stat(w->path, &sb) == 0 && eoa > (uint64_t)sb.st_size) {
        if (truncate(w->path, (off_t)eoa) != 0)
            return CDEM_FAIL(err, CDEM_ERR_IO,
                             "%s: cannot be resumed: the file has %llu bytes, its HDF5 superblock "
                             "says %llu (cut short by a size limit or a full disk), and it cannot "
                             "be extended to that size: %s; it was not changed",
                             w->path, (unsigned long long)sb.st_size, (unsigned long long)eoa,
                             strerror(errno));
        *extended_from = sb.st_size;
    }
    hid_t fapl = h5i_writer_fapl();
    hbool_t clear = 1;
    H5Pset(fapl, "clear_status_flags", &clear); /* what h5clear -s does */
    w->file = H5Fopen(w->path, H5F_ACC_RDWR, fapl);
    hid_t es = h5i_keep_errors(w->file < 0);
    H5Pclose(fapl);
    h5i_restore_errors(es);
    if (w->file < 0) {
        /* The writer holds the file's lock, so no other writer is running: the file itself is
         * the problem. A killed run's file can be cut short (full disk, interrupted copy),
         * and HDF5 opens such a file for writing no more. */
        if (stat(w->path, &sb) == 0 && eoa > (uint64_t)sb.st_size) {
            H5Eclear2(H5E_DEFAULT);
            return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                             "%s: cannot be resumed: the file is truncated (it has %llu bytes, "
                             "its HDF5 superblock says %llu; cut short by an interrupted copy?); "
                             "it was not changed, and the increments that survived the cut can "
                             "still be read (cdem-strain info)",
                             w->path, (unsigned long long)sb.st_size, (unsigned long long)eoa);
        }
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: cannot be resumed: HDF5 cannot open it for writing (damaged file?); "
                      "it was not changed%s",
                      w->path,
                      *extended_from >= 0 ? " (it had been cut short by a size limit; zeros in "
                                            "place of the missing bytes did not make it whole)"
                                          : "");
    }
    /* A writer killed inside a flush can have written metadata past the end of the file
     * its superblock records (the superblock is written last): new space must begin after
     * everything in the file, or the resumed writer would allocate over it. */
    if (H5Fincrement_filesize(w->file, 0) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot be resumed: its end of file cannot be set",
                      w->path);
    char *fmt = NULL;
    int32_t version = 0;
    int rc = h5i_get_str_attr(w->file, "format", &fmt);
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
    if (h5i_get_num_attr(w->file, "format_version", H5T_NATIVE_INT32, &version) != 0 ||
        version != CDEM_FORMAT_VERSION)
        return CDEM_FAIL(err, version == 1 ? CDEM_ERR_UNSUPPORTED : CDEM_ERR_VERSION,
                         "%s: cdem format version %d cannot be resumed (only version %d files "
                         "hold checkpoints)",
                         w->path, (int)version, CDEM_FORMAT_VERSION);
    char name[64];
    for (size_t c = 0; c < N_SERIES; c++) {
        snprintf(name, sizeof name, "series/%s", h5i_series_columns[c].name);
        if (h5i_series_columns[c].optional && H5Lexists(w->file, name, H5P_DEFAULT) <= 0) {
            w->series[c] = -1; /* written before the column existed: it stays without it */
            continue;
        }
        if ((w->series[c] = H5Dopen2(w->file, name, H5P_DEFAULT)) < 0)
            return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /%s is missing", w->path, name);
    }
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        snprintf(name, sizeof name, "increments/%s", h5i_element_fields[k].name);
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
    /* files written before the commit record have the index alone (and keep it so) */
    if (H5Lexists(w->file, "increments/commit", H5P_DEFAULT) > 0) {
        if ((w->commit = H5Dopen2(w->file, "increments/commit", H5P_DEFAULT)) < 0)
            return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /increments/commit is corrupt",
                          w->path);
        w->commit_capacity = h5i_extent_of(w->commit);
    }
    w->has_xy = H5Lexists(w->file, "/increments/xy", H5P_DEFAULT) > 0; /* older files lack it */
    /* appending continues at the file's own chunk boundaries (8192 rows before 4096), so no
     * compressed chunk is rewritten */
    w->chunk_rows = h5i_chunk_rows_of(w->data[0]);
    if (w->chunk_rows == 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: /increments/%s is not chunked", w->path,
                      h5i_element_fields[0].name);

    /* Increments to keep: the valid prefix of the record up to keep_inc. */
    hsize_t data_ext = h5i_extent_of(w->data[0]),
            stress_ext = h5i_extent_of(w->data[h5i_first_stress_field()]);
    for (size_t k = 1; k < N_ELEMENT_FIELDS; k++) {
        hsize_t e = h5i_extent_of(w->data[k]);
        if (h5i_element_fields[k].optional)
            stress_ext = e < stress_ext ? e : stress_ext;
        else
            data_ext = e < data_ext ? e : data_ext;
    }
    index_row *ix = NULL;
    hsize_t rows = 0, damaged = 0;
    const char *damaged_why = NULL;
    CDEM_TRY(read_rows_to_keep(w, flags != 0, &ix, &rows, &damaged, &damaged_why, err));
    hsize_t keep = 0;
    char why[300];
    while (keep < rows && ix[keep].number <= keep_inc &&
           !h5i_bad_index_row(&ix[keep], keep ? &ix[keep - 1] : NULL, data_ext, stress_ext, why,
                              sizeof why))
        keep++;
    /* The kept rows end before the first damaged row: the checkpoint's increment must be
     * among them, or the resumed run would build on the damaged row (issue 46). */
    if (damaged_why && damaged == keep && !(keep > 0 && ix[keep - 1].number == keep_inc)) {
        free(ix);
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: cannot be resumed from increment %d: /increments/commit row %llu, "
                         "at or before that increment's row, is damaged (%s): a resumed run "
                         "would build on it; it was not changed",
                         w->path, (int)keep_inc, (unsigned long long)damaged, damaged_why);
    }
    /* Series samples to keep: the leading ones with step <= keep_step. */
    hsize_t slen = h5i_extent_of(w->series[0]);
    for (size_t c = 1; c < N_SERIES; c++) {
        if (w->series[c] < 0)
            continue;
        hsize_t e = h5i_extent_of(w->series[c]);
        slen = e < slen ? e : slen;
    }
    int64_t *steps = slen ? malloc(slen * sizeof *steps) : NULL;
    cdem_status st = CDEM_OK;
    if (slen && !steps)
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the series of %s", w->path);
    else if (slen && h5i_read_rows(w->series[0], H5T_NATIVE_INT64, 0, slen, steps) < 0)
        st = H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot read /series/step", w->path);
    hsize_t skeep = 0;
    while (st == CDEM_OK && skeep < slen && steps[skeep] <= keep_step)
        skeep++;
    if (st == CDEM_OK && skeep > 0) { /* the next sample is checked against the last kept */
        w->last_sample_step = steps[skeep - 1];
        if (h5i_read_rows(w->series[1], H5T_NATIVE_DOUBLE, skeep - 1, 1, &w->last_sample_time) < 0)
            st = H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot read /series/time", w->path);
    }
    free(steps);
    /* From here on the file is changed. */
    if (st == CDEM_OK && w->commit >= 0) {
        commit_row *c = calloc(w->commit_capacity ? w->commit_capacity : 1, sizeof *c);
        if (!c)
            st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
        else if (h5i_read_all_rows(w->commit, w->commit_mtype, w->commit_capacity, c) < 0 ||
                 h5i_commit_blank_from(w->commit, w->commit_mtype, keep, c, w->commit_capacity) < 0)
            st = H5FAIL(err, CDEM_ERR_IO,
                        "%s: cannot drop the increments after %d from the "
                        "commit record",
                        w->path, (int)keep_inc);
        free(c);
        if (st == CDEM_OK)
            st = h5i_commit_flush(w, err); /* dropped before anything they point to shrinks */
        if (st == CDEM_OK)
            st = repair_index(w, ix, keep, err);
    } else if (st == CDEM_OK) {
        st = repair_index(w, ix, keep, err); /* an old file whose torn chunk was recovered */
    }
    w->data_len = w->stress_len = 0;
    for (hsize_t i = 0; i < keep && st == CDEM_OK; i++) {
        w->data_len = (hsize_t)(ix[i].offset + ix[i].n);
        if (ix[i].has_stress)
            w->stress_len = (hsize_t)(ix[i].stress_offset + ix[i].n);
        st = h5i_grow_entries(w, err);
        if (st == CDEM_OK)
            w->entries[w->n_entries++] =
                (xmf_entry){ix[i].number,     ix[i].time,   ix[i].n,
                            ix[i].has_stress, ix[i].offset, ix[i].stress_offset};
    }
    w->index_len = keep;
    w->last_number = keep ? ix[keep - 1].number : -1;
    w->last_step = keep ? ix[keep - 1].step : 0;
    if (keep)
        w->last_row = ix[keep - 1];
    free(ix);
    CDEM_TRY(st);
    w->series_len = skeep;
    /* Shrink everything to what is kept. */
    int ok = 1;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        ok = ok && H5Dset_extent(w->data[k], h5i_element_fields[k].optional ? &w->stress_len
                                                                            : &w->data_len) >= 0;
    for (size_t c = 0; c < N_SERIES; c++)
        ok = ok && (w->series[c] < 0 || H5Dset_extent(w->series[c], &w->series_len) >= 0);
    ok = ok && H5Dset_extent(w->index, &w->index_len) >= 0;
    if (!ok)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot truncate the datasets to increment %d", w->path,
                      (int)keep_inc);
    w->data_ext = w->data_len;
    w->stress_ext = w->stress_len;
    w->data_len = h5i_chunk_end(w->data_len, w->chunk_rows);
    w->stress_len = h5i_chunk_end(w->stress_len, w->chunk_rows);
    /* Checkpoints of dropped increments are invalidated. */
    if (h5i_read_all_rows(w->ckpt_index, w->ckpt_mtype, 2, w->ckpt) < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot read /checkpoint/index", w->path);
    for (int s = 0; s < 2; s++)
        if (w->ckpt[s].sequence > 0 && w->ckpt[s].increment > w->last_number) {
            int64_t seq = w->ckpt[s].sequence;
            memset(&w->ckpt[s], 0, sizeof w->ckpt[s]);
            w->ckpt[s].sequence = -seq; /* keeps sequence numbers increasing */
        }
    if (h5i_write_rows(w->ckpt_index, w->ckpt_mtype, 0, 2, w->ckpt) < 0 ||
        h5i_write_fixed_string(w->stop_reason, STOP_REASON_LEN, "running") < 0 ||
        h5i_write_fixed_string(w->stop_detail, STOP_DETAIL_LEN, "") < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot reset the checkpoint index and stop reason",
                      w->path);
    for (int s = 0; s < 2; s++)
        if (w->ckpt[s].sequence < 0)
            w->ckpt[s].sequence = 0;
    CDEM_TRY(h5i_commit_flush(w, err));
    CDEM_TRY(h5i_start_swmr(w, err));
    CDEM_TRY(h5i_write_xmf(w, err));
    return CDEM_OK;
}

cdem_status cdem_h5_writer_reopen(const char *path, int32_t keep_through_increment,
                                  int64_t keep_through_step, cdem_h5_writer **out,
                                  cdem_error *err) {
    if (out)
        *out = NULL;
    if (!path || !*path || !out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_writer_reopen: path and out are required");
    h5i_writer_hdf5_init();
    cdem_h5_writer *w = NULL;
    CDEM_TRY(h5i_writer_alloc(path, &w, err));
    cdem_status st = cdem_runlock_acquire(path, "cdem-run --resume", &w->lock, err);
    off_t extended_from = -1; /* the size before zeros were added (item 3), -1: none */
    if (st == CDEM_OK)
        st = verify_kept(path, keep_through_increment, err);
    if (st == CDEM_OK)
        st = reopen_setup(w, keep_through_increment, keep_through_step, &extended_from, err);
    if (st != CDEM_OK) {
        /* the file closed before its zeros are cut off again, still under the lock */
        cdem_runlock *lock = w->lock;
        w->lock = NULL;
        h5i_writer_release(w);
        if (extended_from >= 0 && truncate(path, extended_from) != 0)
            errno = 0; /* the zeros stay: the file reads as before (readers skip the end) */
        struct stat sb;
        const uint64_t eoa = h5i_superblock_eoa(path);
        if (err && stat(path, &sb) == 0 && eoa > (uint64_t)sb.st_size &&
            !strstr(err->msg, "is truncated")) {
            const size_t len = strlen(err->msg);
            snprintf(err->msg + len, sizeof err->msg - len,
                     " (the file is truncated: it has %lld bytes, its HDF5 superblock says %llu; "
                     "cut short by a size limit, a full disk or an interrupted copy)",
                     (long long)sb.st_size, (unsigned long long)eoa);
        }
        cdem_runlock_release(lock);
        return st;
    }
    *out = w;
    return CDEM_OK;
}
