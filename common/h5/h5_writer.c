/* h5_writer: appending to a run file that h5_create.c made (or h5_resume.c re-opened):
 * increments, time-series samples, the stop reason, and the close.
 * The commit protocol (docs/reliability.md, "Power cuts"): an increment's data is written,
 * flushed and synced (fdatasync), and only then its row of /increments/index, flushed and
 * synced again: the index row is the commit record, so a writer killed at any moment (or a
 * power cut) leaves every committed increment readable and never a row pointing at data
 * that is not there. All objects exist before SWMR writing starts (HDF5 1.10 forbids
 * creating objects in SWMR-write mode); from then on the file is only appended to.
 * append_series is called from the time-step loop: it never allocates (fixed buffer).
 * After a failed write (disk full) the writer refuses further writes and close leaves the
 * file as a killed writer would (closing would rewrite the superblock with an end-of-file
 * the disk cannot hold).
 * An increment's rows are written in ascending id order, whatever order the state holds
 * them in (the solver's is spatial and changes at every re-sort): row k of one increment
 * and row k of the next are the same element unless elements were removed or added before
 * it, the stored file does not depend on the solver's memory order, and the id column (a
 * run of increasing numbers) deflates to almost nothing (docs/format.md, "Size"). */
#include "h5_internal.h"
#include "outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static cdem_status flush_series(cdem_h5_writer *w, cdem_error *err) {
    if (w->nbuf == 0)
        return CDEM_OK;
    for (size_t c = 0; c < N_SERIES; c++) {
        const series_column *col = &h5i_series_columns[c];
        if (w->series[c] < 0 && col->optional)
            continue; /* a resumed file from before the column existed: it stays without */
        for (size_t i = 0; i < w->nbuf; i++) {
            const char *src = (const char *)&w->buf[i] + col->offset;
            memcpy((char *)w->column + i * 8, src, 8);
        }
        if (h5i_write_rows(w->series[c],
                           col->type == COL_I64 ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE,
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

/* The state's rows by ascending id into w->row_order (w->row_buf is grown to n rows of 8
 * bytes for put_rows). Sets *sorted = 1 when they already are in that order. A stable LSD
 * radix sort of (id, row) keys, three passes of 11 bits over the id: linear in n. */
static cdem_status order_rows_by_id(cdem_h5_writer *w, const cdem_state *s, int *sorted,
                                    cdem_error *err) {
    const size_t n = s->n;
    *sorted = 1;
    for (size_t i = 1; i < n && *sorted; i++)
        *sorted = s->id[i - 1] < s->id[i];
    if (*sorted)
        return CDEM_OK;
    if (n > UINT32_MAX)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "%s: %zu elements in one increment (at most %lu)",
                         w->path, n, (unsigned long)UINT32_MAX);
    if (w->row_cap < n) {
        const size_t c = n + n / 4 + 64;
        size_t *o = realloc(w->row_order, c * sizeof *o);
        if (o)
            w->row_order = o;
        void *b = o ? realloc(w->row_buf, c * 2 * sizeof(uint64_t)) : NULL;
        if (!b)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM,
                             "%s: out of memory ordering the %zu rows of an increment by id",
                             w->path, n);
        w->row_buf = b;
        w->row_cap = c;
    }
    /* keys: the id with its sign bit flipped (so that unsigned order is the ids' order) in
     * the high half, the row in the low half; sorted through row_buf's two halves */
    uint64_t *a = w->row_buf, *b = a + w->row_cap;
    for (size_t i = 0; i < n; i++)
        a[i] = ((uint64_t)((uint32_t)s->id[i] ^ 0x80000000u) << 32) | (uint64_t)i;
    enum { BITS = 11, DIGITS = 1 << BITS };
    for (int shift = 32; shift < 64; shift += BITS) {
        size_t count[DIGITS + 1] = {0};
        for (size_t i = 0; i < n; i++)
            count[((a[i] >> shift) & (DIGITS - 1)) + 1]++;
        for (size_t d = 0; d < DIGITS; d++)
            count[d + 1] += count[d];
        for (size_t i = 0; i < n; i++)
            b[count[(a[i] >> shift) & (DIGITS - 1)]++] = a[i];
        uint64_t *t = a;
        a = b;
        b = t;
    }
    for (size_t i = 0; i < n; i++) {
        w->row_order[i] = (size_t)(a[i] & 0xffffffffu);
        if (i && a[i] >> 32 == a[i - 1] >> 32) /* the reader refuses an id twice */
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "%s: an increment is not written: element id %d is in rows %zu and "
                             "%zu of the state (ids must be unique)",
                             w->path, (int)s->id[w->row_order[i]], w->row_order[i - 1],
                             w->row_order[i]);
    }
    return CDEM_OK;
}

/* The values of field k of the state in w->row_order's order, in w->row_buf. */
static const void *put_rows(cdem_h5_writer *w, const cdem_state *s, size_t k) {
    const size_t n = s->n, *restrict order = w->row_order;
    const void *src = h5i_element_array(s, k);
    if (h5i_element_fields[k].type == CDEM_FIELD_F64) {
        const double *restrict v = src;
        double *restrict out = w->row_buf;
        for (size_t i = 0; i < n; i++)
            out[i] = v[order[i]];
    } else { /* int32, uint32: 4 bytes */
        const uint32_t *restrict v = src;
        uint32_t *restrict out = w->row_buf;
        for (size_t i = 0; i < n; i++)
            out[i] = v[order[i]];
    }
    return w->row_buf;
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
        missing |= (!h5i_element_fields[k].optional || s->has_stress) && !h5i_element_array(s, k);
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
    /* what the reader refuses is never written (h5_layout.c): the row's values, then every
     * element's (a run that has blown up: run.c records "numerical-failure") */
    const index_row values = {.number = info->number,
                              .phase = info->phase,
                              .step = info->step,
                              .time = info->time,
                              .net_displacement = info->net_displacement,
                              .axial_strain = info->axial_strain,
                              .differential_stress = info->differential_stress,
                              .sea_level = info->sea_level,
                              .n = (int64_t)s->n,
                              .has_stress = s->has_stress && s->n > 0};
    char why[300];
    if (h5i_bad_index_values(&values, w->last_number >= 0 ? &w->last_row : NULL, why, sizeof why))
        return CDEM_FAIL(err,
                         values.phase < 0 || values.phase > 2 || values.step < w->last_row.step ||
                                 values.time < w->last_row.time
                             ? CDEM_ERR_INVALID
                             : CDEM_ERR_NUMERIC,
                         "%s: increment %d is not written: %s (a run file holds only values "
                         "within the physical bounds of docs/format.md)",
                         w->path, (int)info->number, why);
    for (size_t i = 0; i < s->n; i++) {
        const char *field = NULL;
        if (h5i_bad_element(s, i, &field, why, sizeof why))
            return CDEM_FAIL(err, CDEM_ERR_NUMERIC,
                             "%s: increment %d is not written: element id %d: %s (a run file "
                             "holds only values within the physical bounds of docs/format.md)",
                             w->path, (int)info->number, (int)s->id[i], why);
    }
    if (w->commit >= 0 && w->index_len >= w->commit_capacity)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "%s: increment %d is not written: the file was made for at most %llu "
                         "increments (the rows of its commit record, /increments/commit; "
                         "cdem_run_meta.max_increments)",
                         w->path, (int)info->number, (unsigned long long)w->commit_capacity);
    CDEM_TRY(h5i_grow_entries(w, err));
    CDEM_TRY(flush_series(w, err));
    /* The data first, then (after a flush) the index row: the index is the commit record. */
    const hsize_t n = s->n;
    const int stress = s->has_stress && n > 0;
    int sorted = 1;
    CDEM_TRY(order_rows_by_id(w, s, &sorted, err));
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        const element_field *fd = &h5i_element_fields[k];
        if (fd->optional && !stress)
            continue;
        hsize_t start = fd->optional ? w->stress_len : w->data_len;
        const void *rows = sorted ? h5i_element_array(s, k) : put_rows(w, s, k);
        if (h5i_write_rows(w->data[k], h5i_el_mem_type(fd->type), start, n, rows) < 0) {
            w->failed = 1;
            return H5FAIL(err, CDEM_ERR_IO,
                          "%s: cannot write increment %d to /increments/%s (%llu values; disk "
                          "full?); the file keeps the %llu increments before",
                          w->path, (int)info->number, fd->name, (unsigned long long)n,
                          (unsigned long long)w->index_len);
        }
    }
    CDEM_TRY(h5i_commit_flush(w, err)); /* the data is on disk before the record points to it */
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
    /* The commit record's row first (contiguous: it reaches the file as it is written),
     * then the same row appended to /increments/index for HDF5 tools, one flush for both. */
    if ((w->commit >= 0 && h5i_commit_write(w->commit, w->commit_mtype, w->index_len, &row) < 0) ||
        h5i_write_rows(w->index, w->index_mtype, w->index_len, 1, &row) < 0) {
        w->failed = 1;
        return H5FAIL(err, CDEM_ERR_IO,
                      "%s: cannot write the commit record of increment %d (disk full?); the file "
                      "keeps the %llu increments before",
                      w->path, (int)info->number, (unsigned long long)w->index_len);
    }
    CDEM_TRY(h5i_commit_flush(w, err));
    w->index_len++;
    if (n) {
        w->data_ext = w->data_len + n;
        w->data_len = h5i_chunk_end(w->data_ext, w->chunk_rows);
    }
    if (stress) {
        w->stress_ext = w->stress_len + n;
        w->stress_len = h5i_chunk_end(w->stress_ext, w->chunk_rows);
    }
    w->last_number = info->number;
    w->last_step = info->step;
    w->last_row = row;
    w->entries[w->n_entries++] =
        (xmf_entry){info->number, info->time, (int64_t)n, stress, row.offset, row.stress_offset};
    /* Rewriting the whole sidecar costs O(increments); past XMF_EVERY_LIMIT increments it is
     * rewritten only when 5 % more have accumulated (and at close), so a run's total
     * sidecar I/O stays linear in its length. */
    if (w->n_entries <= XMF_EVERY_LIMIT || w->n_entries - w->xmf_written >= w->n_entries / 20)
        return h5i_write_xmf(w, err);
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
    /* what the reader refuses is never written (h5_layout.c): a sample out of order, or one
     * whose values are not finite or beyond the physical bounds (a run that has blown up;
     * run.c then records "numerical-failure") */
    if (sample->step < 0 || sample->step <= w->last_sample_step ||
        !(sample->time >= 0.0 && sample->time <= CDEM_FILE_MAX_TIME) ||
        sample->time < w->last_sample_time)
        return CDEM_FAIL(err,
                         sample->step > w->last_sample_step ? CDEM_ERR_NUMERIC : CDEM_ERR_INVALID,
                         "%s: the series sample of step %lld, time %.17g s is not written: steps "
                         "must increase and times be finite, in 0..1e9 s and not decrease (the "
                         "last sample written is of step %lld, time %.17g s)",
                         w->path, (long long)sample->step, sample->time,
                         (long long)w->last_sample_step, w->last_sample_time);
    unsigned absent = 0;
    for (size_t c = 0; c < N_SERIES; c++)
        absent |= (unsigned)(w->series[c] < 0) << c;
    const char *column = NULL;
    char why[160];
    if (h5i_bad_sample(sample, 0, absent, &column, why, sizeof why))
        return CDEM_FAIL(err, CDEM_ERR_NUMERIC,
                         "%s: the series sample of step %lld is not written: %s (a run file holds "
                         "only values within the physical bounds of docs/format.md)",
                         w->path, (long long)sample->step, why);
    w->buf[w->nbuf++] = *sample;
    w->last_sample_step = sample->step;
    w->last_sample_time = sample->time;
    return CDEM_OK;
}

const char *cdem_h5_writer_kept_aside(const cdem_h5_writer *w) {
    return w ? w->kept_aside : NULL;
}

cdem_status cdem_h5_writer_set_stop_reason(cdem_h5_writer *w, const char *reason,
                                           const char *detail, cdem_error *err) {
    if (!w)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_writer_set_stop_reason: no writer");
    if (reason && !h5i_known_stop_reason(reason))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "%s: stop reason '%.80s' is not one a run file records (running, "
                         "completed, interrupted, stopped-early, numerical-failure, "
                         "write-failure, error)",
                         w->path, reason);
    /* Preallocated datasets: overwriting them needs no new file space (works on a full
     * disk). The detail is cut to STOP_DETAIL_LEN - 1 bytes. */
    if (h5i_write_fixed_string(w->stop_detail, STOP_DETAIL_LEN, detail) < 0 ||
        h5i_write_fixed_string(w->stop_reason, STOP_REASON_LEN, reason) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot write the stop reason '%s'", w->path,
                      reason ? reason : "");
    if (H5Dflush(w->stop_detail) < 0 || H5Dflush(w->stop_reason) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot flush the stop reason '%s'", w->path,
                      reason ? reason : "");
    w->completed = reason && strcmp(reason, "completed") == 0;
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
    return cdem_h5_writer_close_report(w, NULL, err);
}

cdem_status cdem_h5_writer_close_report(cdem_h5_writer *w, cdem_h5_close_report *rep,
                                        cdem_error *err) {
    cdem_h5_close_report scratch;
    if (!rep)
        rep = &scratch;
    memset(rep, 0, sizeof *rep);
    if (!w)
        return CDEM_OK;
    cdem_status st = w->failed ? CDEM_OK : flush_series(w, err);
    if (st == CDEM_OK && w->xmf_written != w->n_entries)
        st = h5i_write_xmf(w, err);
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
        w->index = w->commit = w->stop_reason = w->stop_detail = w->ckpt_index = -1;
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
        /* a completed run's checkpoints are dropped below, when there are any */
        const int has_checkpoints = (w->ckpt_data[0] >= 0 && h5i_extent_of(w->ckpt_data[0]) > 0) ||
                                    (w->ckpt_data[1] >= 0 && h5i_extent_of(w->ckpt_data[1]) > 0);
        /* and a paged file (h5_create.c) is rewritten without the pages' slack */
        int paged = 0;
        hid_t fcpl = H5Fget_create_plist(file);
        H5F_fspace_strategy_t strategy;
        hbool_t persist;
        hsize_t threshold;
        if (fcpl >= 0 && H5Pget_file_space_strategy(fcpl, &strategy, &persist, &threshold) >= 0)
            paged = strategy == H5F_FSPACE_STRATEGY_PAGE;
        if (fcpl >= 0)
            H5Pclose(fcpl);
        H5Eclear2(H5E_DEFAULT);
        hid_t *rest[] = {&w->index,        &w->commit,       &w->stop_reason, &w->stop_detail,
                         &w->ckpt_data[0], &w->ckpt_data[1], &w->ckpt_index};
        for (size_t i = 0; i < sizeof rest / sizeof rest[0]; i++) {
            if (*rest[i] >= 0)
                H5Dclose(*rest[i]);
            *rest[i] = -1;
        }
        if (H5Fclose(file) < 0 && st == CDEM_OK)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot close the file (disk full?)", w->path);
        es = h5i_keep_errors(st != CDEM_OK);
        /* closed cleanly: compact under the lock, which h5i_writer_release gives up */
        if (st == CDEM_OK && w->completed && (has_checkpoints || paged) && w->placed)
            h5i_compact_completed(w->path, w->sync, has_checkpoints, rep);
        /* the run it replaced (--force) is no longer needed once this one completed */
        if (st == CDEM_OK && w->completed && w->placed)
            rep->dropped_replaced = h5i_drop_replaced(w->path);
    }
    h5i_writer_release(w);
    h5i_restore_errors(es);
    return st;
}
