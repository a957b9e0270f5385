/* h5_file: the writer's file, whatever it is doing: a writer with every handle unset
 * (h5i_writer_alloc) and its release, the file-access properties every writer opens with,
 * entering SWMR mode, flushing (and syncing to stable storage: the commit protocol's
 * barrier) and syncing a folder after a rename. h5_create.c, h5_resume.c, h5_writer.c,
 * h5_checkpoint.c and h5_compact.c build on these; this file calls none of them, so the
 * files of the writer call each other in no loop. */
#include "h5_internal.h"
#include "outfile.h"
#include "xdmf.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

hid_t h5i_writer_fapl(void) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_libver_bounds(fapl, H5F_LIBVER_V110, H5F_LIBVER_V110);
    /* No sieve buffer: a write to a contiguous dataset (the commit record) goes to the file
     * as it is made, alone; with one, --resume's row-by-row blanking of the record, last row
     * first, would reach the file as one write in ascending order (h5_commit.c). */
    H5Pset_sieve_buf_size(fapl, 0);
    return fapl;
}

cdem_status h5i_start_swmr(cdem_h5_writer *w, cdem_error *err) {
    if (H5Fstart_swmr_write(w->file) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot enter single-writer/multiple-reader mode",
                      w->path);
    return CDEM_OK;
}

/* Allocates a writer with every handle unset. */
cdem_status h5i_writer_alloc(const char *path, cdem_h5_writer **out, cdem_error *err) {
    cdem_h5_writer *w = calloc(1, sizeof *w);
    if (!w)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory creating a writer for %s", path);
    w->file = w->index = w->index_mtype = w->stop_reason = w->stop_detail = -1;
    w->commit = w->commit_mtype = -1;
    w->commit_capacity = COMMIT_DEFAULT_CAPACITY;
    w->ckpt_data[0] = w->ckpt_data[1] = w->ckpt_index = w->ckpt_mtype = -1;
    for (size_t c = 0; c < N_SERIES; c++)
        w->series[c] = -1;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        w->data[k] = -1;
    w->last_number = -1;
    w->last_sample_step = -1;
    w->chunk_rows = CHUNK_ELEMS;
    w->sync = 1;
    w->path = h5i_dup_str(path);
    w->xmf_path = cdem_xdmf_path_for(path);
    w->buf = malloc(SERIES_BUFFER * sizeof *w->buf);
    w->column = malloc(SERIES_BUFFER * 8);
    w->index_mtype = h5i_make_compound(h5i_index_members, N_INDEX_MEMBERS, sizeof(index_row), 0);
    w->ckpt_mtype = h5i_make_compound(h5i_ckpt_members, N_CKPT_MEMBERS, sizeof(ckpt_row), 0);
    w->commit_mtype = h5i_commit_type(0);
    if (!w->path || !w->xmf_path || !w->buf || !w->column || w->index_mtype < 0 ||
        w->ckpt_mtype < 0 || w->commit_mtype < 0) {
        h5i_writer_release(w);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory creating a writer for %s", path);
    }
    const char *slash = strrchr(w->path, '/');
    w->h5_name = slash ? slash + 1 : w->path;
    *out = w;
    return CDEM_OK;
}

cdem_status h5i_flush_file(cdem_h5_writer *w, cdem_error *err) {
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

/* h5i_flush_file, then to stable storage when durability is on. */
cdem_status h5i_commit_flush(cdem_h5_writer *w, cdem_error *err) {
    CDEM_TRY(h5i_flush_file(w, err));
    return sync_file(w, err);
}

/* After a rename, the directory entry is durable only once the folder is synced. */
void h5i_sync_folder_of(const char *path) {
    char dir[4096];
    cdem_outfile_folder_of(path, dir, sizeof dir);
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

void h5i_writer_release(cdem_h5_writer *w) {
    hid_t ds[N_SERIES + N_ELEMENT_FIELDS + 7];
    size_t n = 0;
    for (size_t c = 0; c < N_SERIES; c++)
        ds[n++] = w->series[c];
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        ds[n++] = w->data[k];
    ds[n++] = w->index;
    ds[n++] = w->commit;
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
    if (w->commit_mtype >= 0)
        H5Tclose(w->commit_mtype);
    if (w->file >= 0)
        H5Fclose(w->file);
    cdem_runlock_release(w->lock); /* last: nothing of ours is touched after this */
    free(w->path);
    free(w->xmf_path);
    free(w->buf);
    free(w->column);
    free(w->entries);
    free(w->ckpt_buf);
    free(w->ckpt_zbuf);
    free(w->row_order);
    free(w->row_buf);
    free(w->kept_aside);
    free(w);
}

cdem_status h5i_grow_entries(cdem_h5_writer *w, cdem_error *err) {
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
