/* h5_resume: re-opens a run file to go on writing it (cdem-run --resume). Under the path's
 * lock the file's status flags are cleared (what h5clear -s does), increments after the
 * checkpoint's and series samples after its step are dropped (the datasets shrunk to what is
 * kept: the resumed run writes them again, bit for bit), checkpoints of dropped increments
 * are invalidated, the stop reason is set back to "running", and SWMR writing starts again.
 * A truncated or damaged file is refused unchanged. */
#include "h5_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static cdem_status reopen_setup(cdem_h5_writer *w, int32_t keep_inc, int64_t keep_step,
                                cdem_error *err) {
    w->placed = 1;
    int flags = 0;
    CDEM_TRY(h5i_precheck_superblock(w->path, &flags, err));
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
        struct stat sb;
        uint64_t eoa = h5i_superblock_eoa(w->path);
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
    w->has_xy = H5Lexists(w->file, "/increments/xy", H5P_DEFAULT) > 0; /* older files lack it */
    /* appending continues at the file's own chunk boundaries (8192 rows before 4096), so no
     * compressed chunk is rewritten */
    w->chunk_rows = h5i_chunk_rows_of(w->data[0]);
    if (w->chunk_rows == 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: /increments/%s is not chunked", w->path,
                      h5i_element_fields[0].name);

    /* Increments to keep: the valid prefix of the index up to keep_inc. */
    hsize_t rows = h5i_extent_of(w->index), data_ext = h5i_extent_of(w->data[0]),
            stress_ext = h5i_extent_of(w->data[h5i_first_stress_field()]);
    for (size_t k = 1; k < N_ELEMENT_FIELDS; k++) {
        hsize_t e = h5i_extent_of(w->data[k]);
        if (h5i_element_fields[k].optional)
            stress_ext = e < stress_ext ? e : stress_ext;
        else
            data_ext = e < data_ext ? e : data_ext;
    }
    index_row *ix = rows ? malloc(rows * sizeof *ix) : NULL;
    if (rows && !ix)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the index of %s", w->path);
    if (rows && h5i_read_all_rows(w->index, w->index_mtype, rows, ix) < 0) {
        free(ix);
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot read /increments/index", w->path);
    }
    hsize_t keep = 0;
    while (keep < rows && ix[keep].number <= keep_inc &&
           !h5i_bad_index_row(&ix[keep], keep ? &ix[keep - 1] : NULL, data_ext, stress_ext))
        keep++;
    cdem_status st = CDEM_OK;
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
    free(ix);
    CDEM_TRY(st);
    /* Series samples to keep: the leading ones with step <= keep_step. */
    hsize_t slen = h5i_extent_of(w->series[0]);
    for (size_t c = 1; c < N_SERIES; c++) {
        hsize_t e = h5i_extent_of(w->series[c]);
        slen = e < slen ? e : slen;
    }
    int64_t *steps = slen ? malloc(slen * sizeof *steps) : NULL;
    if (slen && !steps)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading the series of %s", w->path);
    if (slen && h5i_read_rows(w->series[0], H5T_NATIVE_INT64, 0, slen, steps) < 0) {
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
        ok = ok && H5Dset_extent(w->data[k], h5i_element_fields[k].optional ? &w->stress_len
                                                                            : &w->data_len) >= 0;
    for (size_t c = 0; c < N_SERIES; c++)
        ok = ok && H5Dset_extent(w->series[c], &w->series_len) >= 0;
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
    if (st == CDEM_OK)
        st = reopen_setup(w, keep_through_increment, keep_through_step, err);
    if (st != CDEM_OK) {
        h5i_writer_release(w);
        return st;
    }
    *out = w;
    return CDEM_OK;
}
