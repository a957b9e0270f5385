/* h5_checkpoint: the run file's checkpoint, what cdem-run --resume continues from
 * (docs/format.md, "Checkpoints"). A snapshot (snapshot.h; encoded by h5_ckpt_codec.c) goes
 * into one of two slots, /checkpoint/slot0 and slot1: double buffering. The slot that does
 * not hold the newest checkpoint is overwritten, the file flushed (and synced), and only then
 * is that slot's row of /checkpoint/index written (sequence = previous + 1, length, FNV-1a
 * checksum): a kill at any moment leaves one valid checkpoint. The reader tries the newest
 * sequence first and falls back to the other slot when a checksum or the blob fails.
 * A slot holds the blob compressed (h5i_snap_pack); length and checksum in the index are
 * those of the bytes in the slot, so a torn slot is found before anything is inflated. The
 * slots are unfiltered and chunked in CKPT_CHUNK (4 KiB) pieces: a rewrite stays in place
 * (docs/format.md, "Size"), and a slot holds less than 4 KiB more than its checkpoint. */
#include "h5_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

cdem_status cdem_h5_writer_write_checkpoint(cdem_h5_writer *w, const cdem_snapshot *snap,
                                            cdem_error *err) {
    if (!w || !snap)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_h5_writer_write_checkpoint: writer and snapshot are required");
    if (!h5i_host_little_endian())
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "%s: checkpoints are stored only on little-endian hosts", w->path);
    if (w->last_number < 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "%s: a checkpoint belongs to the last increment written, and none is",
                         w->path);
    if (w->failed)
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: an earlier write failed; no checkpoint written",
                         w->path);
    size_t raw = 0, len = 0;
    CDEM_TRY(h5i_snap_encode(snap, &w->ckpt_buf, &w->ckpt_cap, &raw, w->path, err));
    CDEM_TRY(h5i_snap_pack(w->ckpt_buf, raw, &w->ckpt_zbuf, &w->ckpt_zcap, &len, w->path, err));
    /* Double buffering: overwrite the slot that does not hold the newest checkpoint, flush,
     * and only then point the index at it. */
    int slot = w->ckpt[0].sequence > w->ckpt[1].sequence ? 1 : 0;
    int64_t seq =
        (w->ckpt[0].sequence > w->ckpt[1].sequence ? w->ckpt[0].sequence : w->ckpt[1].sequence) + 1;
    if (h5i_write_rows(w->ckpt_data[slot], H5T_NATIVE_UINT8, 0, len, w->ckpt_zbuf) < 0) {
        w->failed = 1;
        return H5FAIL(err, CDEM_ERR_IO,
                      "%s: cannot write a checkpoint of %zu bytes to /checkpoint/slot%d (disk "
                      "full?); the previous checkpoint stays valid",
                      w->path, len, slot);
    }
    CDEM_TRY(h5i_commit_flush(w, err));
    ckpt_row row = {seq, w->last_number, w->last_step, (int64_t)len,
                    h5i_fnv1a64(w->ckpt_zbuf, len)};
    hsize_t start = (hsize_t)slot, one = 1;
    hid_t fs = H5Dget_space(w->ckpt_index), ms = H5Screate_simple(1, &one, NULL);
    int ok = fs >= 0 && ms >= 0 &&
             H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &one, NULL) >= 0 &&
             H5Dwrite(w->ckpt_index, w->ckpt_mtype, ms, fs, H5P_DEFAULT, &row) >= 0;
    hid_t es = h5i_keep_errors(!ok);
    if (fs >= 0)
        H5Sclose(fs);
    if (ms >= 0)
        H5Sclose(ms);
    h5i_restore_errors(es);
    if (!ok) {
        w->failed = 1;
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot write /checkpoint/index", w->path);
    }
    CDEM_TRY(h5i_commit_flush(w, err));
    w->ckpt[slot] = row;
    return CDEM_OK;
}

cdem_status cdem_h5_reader_read_checkpoint(cdem_h5_reader *r, cdem_snapshot *snap,
                                           int32_t *increment_number, cdem_error *err) {
    return cdem_h5_reader_read_checkpoint_through(r, snap, INT32_MAX, increment_number, err);
}

cdem_status cdem_h5_reader_read_checkpoint_through(cdem_h5_reader *r, cdem_snapshot *snap,
                                                   int32_t through, int32_t *increment_number,
                                                   cdem_error *err) {
    if (!r || !snap || !increment_number)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_read_checkpoint: bad arguments");
    *increment_number = -1;
    cdem_snapshot_clear(snap);
    if (r->version < 2)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "%s: the file holds no checkpoint (format version %d has none)", r->path,
                         r->version);
    if (!h5i_host_little_endian())
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "%s: checkpoints are read only on little-endian hosts", r->path);
    hid_t ix = H5Dopen2(r->file, "checkpoint/index", H5P_DEFAULT);
    hid_t slot[2] = {H5Dopen2(r->file, "checkpoint/slot0", H5P_DEFAULT),
                     H5Dopen2(r->file, "checkpoint/slot1", H5P_DEFAULT)};
    hid_t mt = h5i_make_compound(h5i_ckpt_members, N_CKPT_MEMBERS, sizeof(ckpt_row), 0);
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
    if (st == CDEM_OK && (h5i_extent_of(ix) != 2 || h5i_read_all_rows(ix, mt, 2, rows) < 0))
        st = H5FAIL(err, CDEM_ERR_FORMAT, "%s: /checkpoint/index is unreadable (2 rows expected)",
                    r->path);
    char why[2][CDEM_ERROR_MSG_MAX / 2];
    why[0][0] = why[1][0] = '\0';
    int tried = 0, found = 0, later = 0;
    int order[2] = {rows[0].sequence >= rows[1].sequence ? 0 : 1,
                    rows[0].sequence >= rows[1].sequence ? 1 : 0};
    for (int o = 0; st == CDEM_OK && o < 2 && !found; o++) {
        int s = order[o];
        if (rows[s].sequence <= 0)
            continue;
        tried++;
        if (rows[s].increment > through) {
            snprintf(why[o], sizeof why[o], "slot%d belongs to increment %d, after %d", s,
                     (int)rows[s].increment, (int)through);
            later++;
            continue;
        }
        hsize_t ext = h5i_extent_of(slot[s]);
        if (rows[s].length < 16 || (uint64_t)rows[s].length > SNAP_MAX_BYTES ||
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
        if (h5i_read_rows(slot[s], H5T_NATIVE_UINT8, 0, len, buf) < 0) {
            H5Eclear2(H5E_DEFAULT);
            snprintf(why[o], sizeof why[o], "slot%d: unreadable", s);
        } else if (h5i_fnv1a64(buf, len) != rows[s].checksum) {
            snprintf(why[o], sizeof why[o], "slot%d (sequence %lld): checksum mismatch", s,
                     (long long)rows[s].sequence);
        } else {
            char what[1200];
            snprintf(what, sizeof what, "%s: /checkpoint/slot%d", r->path, s);
            cdem_error e2;
            cdem_error_clear(&e2);
            const unsigned char *raw = NULL;
            size_t raw_len = 0;
            int owned = 0;
            if (h5i_snap_unpack(buf, len, &raw, &raw_len, &owned, what, &e2) == CDEM_OK &&
                h5i_snap_decode(raw, raw_len, snap, what, &e2) == CDEM_OK) {
                found = 1;
                *increment_number = rows[s].increment;
            } else {
                snprintf(why[o], sizeof why[o], "%.400s", e2.msg);
            }
            if (owned)
                free((void *)raw);
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
    if (tried == 0) {
        /* a completed run's file, compacted without them (h5_compact.c) */
        htri_t dropped = H5Aexists_by_name(r->file, "checkpoint", "dropped", H5P_DEFAULT);
        H5Eclear2(H5E_DEFAULT);
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s: the file holds no checkpoint%s", r->path,
                         dropped > 0 ? " (the run completed and its checkpoints were dropped)"
                                     : "");
    }
    if (later > 0)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "%s: no valid checkpoint of increment %d or before (%s%s%s)", r->path,
                         (int)through, why[0], why[0][0] && why[1][0] ? "; " : "", why[1]);
    return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: no valid checkpoint (%s%s%s)", r->path, why[0],
                     why[0][0] && why[1][0] ? "; " : "", why[1]);
}
