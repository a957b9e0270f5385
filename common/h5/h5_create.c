/* h5_create: a new run file. The file is built as PATH.creating: root attributes, the
 * /parameters table, then every dataset of the layout (HDF5 1.10 forbids creating objects in
 * SWMR-write mode), then SWMR writing starts and the file is renamed to PATH, replacing a file
 * there only as the cdem_h5_replace policy allows (checked under the path's lock, runlock.h,
 * which the writer holds until close). Whatever is found at PATH therefore opens.
 * Files are V110 (superblock v3, object header v2): every piece of metadata carries a
 * checksum, so flipped bytes fail a checksum instead of being parsed. */
/* renameat2 (RENAME_NOREPLACE): never replace a file that appeared meanwhile */
#define _GNU_SOURCE
#include "h5_internal.h"
#include "xdmf.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* /parameters: a compound table (name, value, unit as fixed-length strings, each as wide
 * as its longest entry) plus one string attribute per parameter. */
static cdem_status write_parameters(cdem_h5_writer *w, const cdem_params *p, cdem_error *err) {
    size_t all = 0, count = 0;
    const cdem_param_def *every = cdem_params_table(&all);
    /* the rows of the record: a key recorded only when set is left out at its default */
    const cdem_param_def **rowdef = calloc(all ? all : 1, sizeof *rowdef);
    if (!rowdef)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory storing %zu parameters", all);
    for (size_t i = 0; i < all; i++)
        if (cdem_params_recorded(p, &every[i]))
            rowdef[count++] = &every[i];
    enum { NAME_MAX_ = 128, VALUE_MAX_ = 2 * CDEM_PATH_MAX + 64 };
    char *names = calloc(count ? count : 1, NAME_MAX_);
    char *values = calloc(count ? count : 1, VALUE_MAX_);
    size_t wn = 1, wv = 1, wu = 1;
    for (size_t i = 0; names && values && i < count; i++) {
        char *name = names + i * NAME_MAX_, *value = values + i * VALUE_MAX_;
        snprintf(name, NAME_MAX_, "%s.%s", rowdef[i]->section, rowdef[i]->key);
        cdem_params_format_value(p, rowdef[i], value, VALUE_MAX_);
        size_t lu = strlen(rowdef[i]->unit ? rowdef[i]->unit : "");
        wn = strlen(name) + 1 > wn ? strlen(name) + 1 : wn;
        wv = strlen(value) + 1 > wv ? strlen(value) + 1 : wv;
        wu = lu + 1 > wu ? lu + 1 : wu;
    }
    size_t row = wn + wv + wu;
    char *rows = names && values ? calloc(count ? count : 1, row) : NULL;
    if (!rows) {
        free(names);
        free(values);
        free(rowdef);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory storing %zu parameters", count);
    }
    for (size_t i = 0; i < count; i++) {
        memcpy(rows + i * row, names + i * NAME_MAX_, strlen(names + i * NAME_MAX_));
        memcpy(rows + i * row + wn, values + i * VALUE_MAX_, strlen(values + i * VALUE_MAX_));
        if (rowdef[i]->unit)
            memcpy(rows + i * row + wn + wv, rowdef[i]->unit, strlen(rowdef[i]->unit));
    }
    cdem_status st = CDEM_OK;
    hid_t tn = h5i_fixed_string_type(wn - 1), tv = h5i_fixed_string_type(wv - 1);
    hid_t tu = h5i_fixed_string_type(wu - 1), ct = H5Tcreate(H5T_COMPOUND, row);
    H5Tinsert(ct, "name", 0, tn);
    H5Tinsert(ct, "value", wn, tv);
    H5Tinsert(ct, "unit", wn + wv, tu);
    hsize_t dim = count;
    hid_t sp = H5Screate_simple(1, &dim, NULL), dcpl = h5i_untimed_plist(H5P_DATASET_CREATE);
    hid_t ds = H5Dcreate2(w->file, "parameters", ct, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (ds < 0 || (count && H5Dwrite(ds, ct, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) < 0))
        st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot write the /parameters table", w->path);
    for (size_t i = 0; st == CDEM_OK && i < count; i++)
        if (h5i_put_str_attr(ds, names + i * NAME_MAX_, values + i * VALUE_MAX_) < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot write attribute /parameters %s = %s", w->path,
                        names + i * NAME_MAX_, values + i * VALUE_MAX_);
    /* the boundary actors after the first: one attribute "boundary.N" each, its section's
     * "key = value" lines (cdem_params_set_actor_keys reads them back) */
    for (int j = 1; st == CDEM_OK && j < cdem_params_actor_count(p); j++) {
        char name[32];
        snprintf(name, sizeof name, "boundary.%d", j + 1);
        if (h5i_put_str_attr(ds, name, p->actor_keys[j - 1]) < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot write attribute /parameters %s", w->path,
                        name);
    }
    if (ds >= 0)
        H5Dclose(ds);
    H5Pclose(dcpl);
    H5Sclose(sp);
    H5Tclose(ct);
    H5Tclose(tn);
    H5Tclose(tv);
    H5Tclose(tu);
    free(rows);
    free(names);
    free(values);
    free(rowdef);
    return st;
}

static cdem_status create_layout(cdem_h5_writer *w, cdem_error *err) {
    hid_t gcpl = h5i_untimed_plist(H5P_GROUP_CREATE);
    hid_t gs = H5Gcreate2(w->file, "series", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    hid_t gi = H5Gcreate2(w->file, "increments", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    hid_t gc = H5Gcreate2(w->file, "checkpoint", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    H5Pclose(gcpl);
    cdem_status st = CDEM_OK;
    if (gs < 0 || gi < 0 || gc < 0)
        st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create the groups", w->path);
    for (size_t c = 0; st == CDEM_OK && c < N_SERIES; c++) {
        hid_t ft = h5i_series_columns[c].type == COL_I64 ? H5T_STD_I64LE : H5T_IEEE_F64LE;
        w->series[c] = h5i_create_extendible(gs, h5i_series_columns[c].name, ft, SERIES_CHUNK,
                                             FILTER_CHECKSUM);
        if (w->series[c] < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create dataset /series/%s", w->path,
                        h5i_series_columns[c].name);
    }
    for (size_t k = 0; st == CDEM_OK && k < N_ELEMENT_FIELDS; k++) {
        const element_field *fd = &h5i_element_fields[k];
        w->data[k] = h5i_create_extendible(gi, fd->name, h5i_el_file_type(fd->type), CHUNK_ELEMS,
                                           FILTER_COMPRESS);
        if (w->data[k] < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create dataset /increments/%s", w->path,
                        fd->name);
    }
    if (st == CDEM_OK) { /* for the XDMF 3 sidecar; no storage (xdmf.h) */
        hid_t xy = cdem_xdmf_create_xy_view(gi, "/increments/x", "/increments/y", "xy", 1);
        if (xy < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create the view /increments/xy", w->path);
        else
            H5Dclose(xy);
        w->has_xy = xy >= 0;
    }
    if (st == CDEM_OK && (w->commit = h5i_commit_create(gi, w->commit_capacity)) < 0)
        st = H5FAIL(err, CDEM_ERR_IO,
                    "%s: cannot create the commit record /increments/commit (%llu rows)", w->path,
                    (unsigned long long)w->commit_capacity);
    hid_t ft = -1;
    if (st == CDEM_OK) {
        ft = h5i_make_compound(h5i_index_members, N_INDEX_MEMBERS, sizeof(index_row), 1);
        w->index =
            ft >= 0 ? h5i_create_extendible(gi, "index", ft, INDEX_CHUNK, FILTER_CHECKSUM) : -1;
        if (w->index < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create dataset /increments/index", w->path);
        if (ft >= 0)
            H5Tclose(ft);
    }
    if (st == CDEM_OK) {
        ft = h5i_make_compound(h5i_ckpt_members, N_CKPT_MEMBERS, sizeof(ckpt_row), 1);
        w->ckpt_index = ft >= 0 ? h5i_create_fixed(gc, "index", ft, 2) : -1;
        w->ckpt_data[0] = h5i_create_extendible(gc, "slot0", H5T_STD_U8LE, CKPT_CHUNK, FILTER_NONE);
        w->ckpt_data[1] = h5i_create_extendible(gc, "slot1", H5T_STD_U8LE, CKPT_CHUNK, FILTER_NONE);
        if (w->ckpt_index < 0 || w->ckpt_data[0] < 0 || w->ckpt_data[1] < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create the /checkpoint datasets", w->path);
        if (ft >= 0)
            H5Tclose(ft);
    }
    if (st == CDEM_OK) {
        hid_t tr = h5i_fixed_string_type(STOP_REASON_LEN - 1),
              td = h5i_fixed_string_type(STOP_DETAIL_LEN - 1);
        w->stop_reason = h5i_create_fixed(w->file, "stop_reason", tr, 0);
        w->stop_detail = h5i_create_fixed(w->file, "stop_detail", td, 0);
        H5Tclose(tr);
        H5Tclose(td);
        if (w->stop_reason < 0 || w->stop_detail < 0 ||
            h5i_write_fixed_string(w->stop_reason, STOP_REASON_LEN, "running") < 0 ||
            h5i_write_fixed_string(w->stop_detail, STOP_DETAIL_LEN, "") < 0)
            st = H5FAIL(err, CDEM_ERR_IO, "%s: cannot create /stop_reason and /stop_detail",
                        w->path);
    }
    if (gs >= 0)
        H5Gclose(gs);
    if (gi >= 0)
        H5Gclose(gi);
    if (gc >= 0)
        H5Gclose(gc);
    return st;
}

/* Puts tmp at path: rename when an existing file may be replaced (replace = 1), otherwise
 * a rename that fails instead of replacing a file that appeared after the checks. */
static int put_in_place(const char *tmp, const char *path, int replace) {
    if (replace)
        return rename(tmp, path);
    if (renameat2(AT_FDCWD, tmp, AT_FDCWD, path, RENAME_NOREPLACE) == 0)
        return 0;
    if (errno != EINVAL && errno != ENOSYS)
        return -1;
    /* a filesystem without RENAME_NOREPLACE: a hard link fails on an existing name too */
    if (link(tmp, path) != 0)
        return -1;
    return unlink(tmp) == 0 || errno == ENOENT ? 0 : -1;
}

/* A completed run that this one replaces (--force) is not lost when this one is killed:
 * it is kept as PATH.replaced (a second name for the same file, or a rename where the file
 * system has no hard links) until this run completes (cdem_h5_writer_close). An older
 * PATH.replaced is given up only for a newer completed run. 0 or -1 (errno). */
static int keep_aside(cdem_h5_writer *w) {
    char *aside = h5i_replaced_path(w->path);
    if (!aside)
        return -1;
    if ((unlink(aside) != 0 && errno != ENOENT) ||
        (link(w->path, aside) != 0 && rename(w->path, aside) != 0)) {
        free(aside);
        return -1;
    }
    if (w->sync)
        h5i_sync_folder_of(w->path);
    w->kept_aside = aside;
    return 0;
}

/* The file is built under a temporary name (tmp) and renamed to w->path once its layout
 * is complete and SWMR writing has started: whatever is found at w->path opens.
 * replace: 1 when a file at w->path may be replaced (it was checked under the lock);
 * aside: 1 when that file is a completed run to keep aside until this one completes. */
static cdem_status writer_setup(cdem_h5_writer *w, const cdem_run_meta *meta, const char *tmp,
                                int replace, int aside, cdem_error *err) {
    hid_t fapl = h5i_writer_fapl();
    hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
    /* Paged file space (FILE_SPACE_PAGE): nothing the writer rewrites in place (object
     * headers, chunk indexes, the index's and the series' chunks) crosses a page boundary, so
     * a kill cannot tear it (docs/format.md, "HDF5 settings"; 10 % more file while the run
     * goes on, nothing once it completes: the compacted copy is not paged). */
    H5Pset_file_space_strategy(fcpl, H5F_FSPACE_STRATEGY_PAGE, 0, 1);
    H5Pset_file_space_page_size(fcpl, FILE_SPACE_PAGE);
    /* EXCL: the stale tmp of a killed run was removed under the lock; anything there now is
     * not ours to truncate */
    w->file = H5Fcreate(tmp, H5F_ACC_EXCL, fcpl, fapl);
    hid_t es = h5i_keep_errors(w->file < 0);
    H5Pclose(fapl);
    H5Pclose(fcpl);
    h5i_restore_errors(es);
    if (w->file < 0)
        return H5FAIL(err, CDEM_ERR_IO,
                      "%s: cannot create the run file (as the temporary %s); nothing was written",
                      w->path, tmp);

    char created[32] = "";
    time_t now = time(NULL);
    struct tm tmv;
    if (gmtime_r(&now, &tmv))
        strftime(created, sizeof created, "%Y-%m-%dT%H:%M:%SZ", &tmv);
    hid_t root = w->file;
    if (h5i_put_str_attr(root, "format", CDEM_FORMAT_NAME) < 0 ||
        h5i_put_i32_attr(root, "format_version", CDEM_FORMAT_VERSION) < 0 ||
        h5i_put_str_attr(root, "program_version", meta->program_version) < 0 ||
        h5i_put_i64_attr(root, "seed", (int64_t)meta->params->seed) < 0 ||
        h5i_put_str_attr(root, "created", created) < 0 ||
        h5i_put_str_attr(root, "source", meta->source) < 0 ||
        h5i_put_str_attr(root, "summary", meta->summary) < 0 ||
        h5i_put_str_attr(root, "params_text", meta->params_text) < 0)
        return H5FAIL(err, CDEM_ERR_IO, "%s: cannot write the root attributes", w->path);
    CDEM_TRY(write_parameters(w, meta->params, err));
    CDEM_TRY(create_layout(w, err));
    CDEM_TRY(h5i_flush_file(w, err));
    CDEM_TRY(h5i_start_swmr(w, err));
    CDEM_TRY(h5i_commit_flush(w, err));
    if (aside && keep_aside(w) != 0)
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: cannot keep the completed run it holds as %s.replaced while the "
                         "new run is written: %s; nothing was replaced",
                         w->path, w->path, strerror(errno));
    if (put_in_place(tmp, w->path, replace) != 0) {
        int e = errno;
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: cannot put the new run file in place (rename from %s): %s%s; "
                         "nothing was replaced",
                         w->path, tmp, strerror(e),
                         e == EEXIST ? " (a file appeared there while the run was set up)" : "");
    }
    w->placed = 1;
    if (w->sync)
        h5i_sync_folder_of(w->path);
    return h5i_write_xmf(w, err);
}

cdem_status cdem_h5_writer_create(const char *path, const cdem_run_meta *meta, cdem_h5_writer **out,
                                  cdem_error *err) {
    return cdem_h5_writer_create_checked(path, meta, CDEM_H5_REPLACE_ANY, out, err);
}

cdem_status cdem_h5_writer_create_checked(const char *path, const cdem_run_meta *meta,
                                          cdem_h5_replace replace_policy, cdem_h5_writer **out,
                                          cdem_error *err) {
    if (out)
        *out = NULL;
    if (!path || !*path || !meta || !meta->params || !out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_h5_writer_create: path, meta, meta->params and out are required");
    if (meta->max_increments < 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_h5_writer_create: max_increments = %ld must be >= 0 (0: %d)",
                         meta->max_increments, COMMIT_DEFAULT_CAPACITY);
    h5i_writer_hdf5_init();
    cdem_h5_writer *w = NULL;
    CDEM_TRY(h5i_writer_alloc(path, &w, err));
    if (meta->max_increments > 0)
        w->commit_capacity = (hsize_t)meta->max_increments;
    size_t n = strlen(path) + 10;
    char *tmp = malloc(n);
    if (!tmp) {
        h5i_writer_release(w);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory creating a writer for %s", path);
    }
    snprintf(tmp, n, "%s.creating", path);
    /* One writer per path for the writer's whole life: a second run of the same output would
     * otherwise remove this one's temporary file and rename its own over this one's. */
    int locked = 0, replace = 0, completed = 0;
    cdem_status st = cdem_runlock_acquire(path, meta->source, &w->lock, err);
    if (st == CDEM_OK) {
        locked = 1;
        st = h5i_check_replace(path, replace_policy, &replace, &completed, err);
    }
    /* a killed run's leftover (we hold the lock, so no live writer owns it) */
    if (st == CDEM_OK && unlink(tmp) != 0 && errno != ENOENT)
        st = CDEM_FAIL(err, CDEM_ERR_IO,
                       "%s: cannot remove %s, left by an earlier run that was killed: %s", path,
                       tmp, strerror(errno));
    /* and a crashed compaction's copy (h5_compact.c): the file at path is the complete one */
    if (st == CDEM_OK) {
        char *compacting = malloc(strlen(path) + 12);
        if (compacting) {
            snprintf(compacting, strlen(path) + 12, "%s.compacting", path);
            (void)unlink(compacting);
            free(compacting);
        }
    }
    if (st == CDEM_OK)
        st = writer_setup(w, meta, tmp, replace,
                          replace && completed && replace_policy == CDEM_H5_REPLACE_CDEM, err);
    if (st != CDEM_OK) {
        if (locked)
            remove(tmp); /* ours: removed while the lock is still held */
        h5i_writer_release(w);
        free(tmp);
        return st;
    }
    free(tmp);
    *out = w;
    return CDEM_OK;
}
