/* h5_reader_series: the time series of a version-2 file (docs/format.md, "/series"): every
 * column checked for its shape and class, the common length kept, values checked against
 * their bounds; in a file whose writer did not close it the series ends before samples the
 * writer had not finished (a torn newest chunk, zeros). */
#include "h5_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
                           r->path, name, rank, h5i_class_name(cls),
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
        int bad = h5i_read_rows_retrying(r->swmr, ds[c], mt, len, col) < 0;
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
