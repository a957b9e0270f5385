/* h5_compact: a completed run's file without its checkpoints (docs/format.md, "Completed
 * runs"). A completed run is never resumed (cdem-run --resume refuses it), so its two
 * checkpoint slots (0.52 MB of the default run's 10.4 MB) are dead weight. HDF5 never gives
 * freed file space back, so shrinking the slots in place would save nothing: the writer
 * closes the file, copies it object by object into PATH.compacting next to it (H5Ocopy
 * copies chunked datasets with their chunking and filters and their chunks as stored, without
 * decompressing them), with an empty /checkpoint in place of the old one, syncs the copy and
 * renames it over PATH. The original stays untouched until that rename, so a crash or a
 * failure at any moment leaves a complete, closed run file (with its checkpoints) at PATH;
 * a failure is not an error of the run, the caller gets a note saying why the file kept its
 * checkpoints. Runs under the writer's lock (runlock.h), which close releases only after. */
#include "h5_internal.h"
#include "outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

/* Test hook (tests/test_format.c): CDEM_TEST_COMPACT_CRASH=copy kills the process with
 * SIGKILL once the copy is written but not closed, =rename once it is closed and synced but
 * not yet renamed: the two moments at which a crash leaves a PATH.compacting behind. */
static void crash_point(const char *where) {
    const char *want = getenv("CDEM_TEST_COMPACT_CRASH");
    if (want && strcmp(want, where) == 0)
        raise(SIGKILL);
}

/* Copies the root attributes of src to dst, in the order they are stored. */
typedef struct {
    hid_t dst;     /* destination object */
    int failed;    /* 1 once a copy failed */
    char name[64]; /* the attribute that failed */
} attr_copy;

static herr_t copy_attr(hid_t loc, const char *name, const H5A_info_t *info, void *data) {
    (void)info;
    attr_copy *c = data;
    hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
    hid_t t = a >= 0 ? H5Aget_type(a) : -1, sp = a >= 0 ? H5Aget_space(a) : -1;
    hssize_t n = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    size_t size = t >= 0 ? H5Tget_size(t) : 0;
    /* variable-length data would need its heap copied too; the writer stores none */
    int ok = n >= 0 && size > 0 && t >= 0 && H5Tis_variable_str(t) == 0 &&
             H5Tdetect_class(t, H5T_VLEN) == 0;
    void *buf = ok ? calloc((size_t)(n ? n : 1), size) : NULL;
    hid_t b = -1;
    ok = buf && H5Aread(a, t, buf) >= 0 &&
         (b = H5Acreate2(c->dst, name, t, sp, H5P_DEFAULT, H5P_DEFAULT)) >= 0 &&
         H5Awrite(b, t, buf) >= 0;
    free(buf);
    if (b >= 0)
        H5Aclose(b);
    if (sp >= 0)
        H5Sclose(sp);
    if (t >= 0)
        H5Tclose(t);
    if (a >= 0)
        H5Aclose(a);
    if (!ok) {
        c->failed = 1;
        snprintf(c->name, sizeof c->name, "%s", name);
        return -1;
    }
    return 0;
}

/* An empty /checkpoint in dst, as a new file has it (index rows of sequence 0, empty slots),
 * and the attribute "dropped" saying why it is empty. */
static int empty_checkpoint_group(hid_t dst) {
    hid_t gcpl = h5i_untimed_plist(H5P_GROUP_CREATE);
    hid_t g = H5Gcreate2(dst, "checkpoint", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    H5Pclose(gcpl);
    if (g < 0)
        return -1;
    hid_t ft = h5i_make_compound(h5i_ckpt_members, N_CKPT_MEMBERS, sizeof(ckpt_row), 1);
    hid_t ix = ft >= 0 ? h5i_create_fixed(g, "index", ft, 2) : -1;
    hid_t s0 = h5i_create_extendible(g, "slot0", H5T_STD_U8LE, CKPT_CHUNK, FILTER_NONE);
    hid_t s1 = h5i_create_extendible(g, "slot1", H5T_STD_U8LE, CKPT_CHUNK, FILTER_NONE);
    int rc = ix >= 0 && s0 >= 0 && s1 >= 0 &&
                     h5i_put_str_attr(g, "dropped",
                                      "the run completed: its checkpoints were dropped and the "
                                      "file compacted (a completed run is not resumed)") >= 0
                 ? 0
                 : -1;
    hid_t hs[] = {ix, s0, s1};
    for (size_t i = 0; i < 3; i++)
        if (hs[i] >= 0)
            H5Dclose(hs[i]);
    if (ft >= 0)
        H5Tclose(ft);
    H5Gclose(g);
    return rc;
}

typedef struct {
    hid_t dst;     /* destination file */
    hid_t ocpypl;  /* object copy properties */
    char what[96]; /* the object that failed */
} link_copy;

/* Every object of the root, in stored order; /checkpoint is replaced by an empty one. */
static herr_t copy_link(hid_t root, const char *name, const H5L_info_t *info, void *data) {
    (void)info;
    link_copy *c = data;
    int rc = strcmp(name, "checkpoint") == 0
                 ? empty_checkpoint_group(c->dst)
                 : (H5Ocopy(root, name, c->dst, name, c->ocpypl, H5P_DEFAULT) < 0 ? -1 : 0);
    if (rc < 0)
        snprintf(c->what, sizeof c->what, "/%s", name);
    return rc;
}

/* Writes the compacted copy of the closed file src_path to tmp; 0 on success, else -1 with
 * why (HDF5's words appended through err). */
static int write_compacted(const char *src_path, const char *tmp, int sync, cdem_error *err) {
    hid_t src = H5Fopen(src_path, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t fapl = h5i_writer_fapl();
    hid_t dst = src >= 0 ? H5Fcreate(tmp, H5F_ACC_EXCL, H5P_DEFAULT, fapl) : -1;
    H5Pclose(fapl);
    if (src < 0 || dst < 0) {
        H5FAIL(err, CDEM_ERR_IO, "cannot %s",
               src < 0 ? "open the closed file again" : "create the compacted copy");
        if (src >= 0)
            H5Fclose(src);
        return -1;
    }
    int rc = 0;
    attr_copy ac = {.dst = dst, .failed = 0, .name = ""};
    hsize_t at = 0;
    if (H5Aiterate2(src, H5_INDEX_NAME, H5_ITER_NATIVE, &at, copy_attr, &ac) < 0 || ac.failed) {
        H5FAIL(err, CDEM_ERR_IO, "cannot copy the root attribute '%s'", ac.name);
        rc = -1;
    }
    link_copy lc = {.dst = dst, .ocpypl = H5Pcreate(H5P_OBJECT_COPY), .what = ""};
    hsize_t li = 0;
    if (rc == 0 && H5Literate(src, H5_INDEX_NAME, H5_ITER_NATIVE, &li, copy_link, &lc) < 0) {
        H5FAIL(err, CDEM_ERR_IO, "cannot copy %s", lc.what[0] ? lc.what : "the root's objects");
        rc = -1;
    }
    H5Pclose(lc.ocpypl);
    if (rc == 0)
        crash_point("copy");
    if (H5Fclose(dst) < 0 && rc == 0) {
        H5FAIL(err, CDEM_ERR_IO, "cannot close the compacted copy (disk full?)");
        rc = -1;
    }
    H5Fclose(src);
    if (rc == 0 && sync) {
        int fd = open(tmp, O_RDONLY | O_CLOEXEC);
        if (fd < 0 || fsync(fd) != 0) {
            CDEM_FAIL(err, CDEM_ERR_IO, "cannot flush the compacted copy to disk: %s",
                      strerror(errno));
            rc = -1;
        }
        if (fd >= 0)
            close(fd);
    }
    return rc;
}

void h5i_compact_completed(const char *path, int sync, int has_checkpoints,
                           cdem_h5_close_report *rep) {
    /* what the note says stays as it was when the file is not compacted */
    const char *kept = has_checkpoints ? "keeps its checkpoints" : "is not compacted";
    rep->compacted = 0;
    rep->note[0] = '\0';
    const char *keep = getenv("CDEM_KEEP_CHECKPOINTS");
    if (keep && *keep && strcmp(keep, "0") != 0) {
        snprintf(rep->note, sizeof rep->note, "%s %s: CDEM_KEEP_CHECKPOINTS is set", path, kept);
        return;
    }
    struct stat sb;
    if (stat(path, &sb) != 0) {
        snprintf(rep->note, sizeof rep->note, "%s: cannot compact it: %s", path, strerror(errno));
        return;
    }
    rep->bytes_before = rep->bytes_after = (uint64_t)sb.st_size;
    size_t n = strlen(path) + 12;
    char *tmp = malloc(n);
    if (!tmp) {
        snprintf(rep->note, sizeof rep->note, "%s %s: out of memory", path, kept);
        return;
    }
    snprintf(tmp, n, "%s.compacting", path);
    /* a crashed compaction's leftover (under the lock nobody else owns it) */
    if (unlink(tmp) != 0 && errno != ENOENT) {
        snprintf(rep->note, sizeof rep->note, "%s %s: cannot remove the leftover %s: %s", path,
                 kept, tmp, strerror(errno));
        free(tmp);
        return;
    }
    /* the copy needs about the file's size; without it the file stays as it is */
    char dir[4096];
    cdem_outfile_folder_of(path, dir, sizeof dir);
    struct statvfs vs;
    if (statvfs(dir, &vs) == 0 && (uint64_t)vs.f_bavail * vs.f_frsize < (uint64_t)sb.st_size) {
        snprintf(rep->note, sizeof rep->note,
                 "%s %s: too little free space for a compacted copy (%.1f MB free, %.1f MB "
                 "needed)",
                 path, kept, (double)vs.f_bavail * vs.f_frsize / 1e6, (double)sb.st_size / 1e6);
        free(tmp);
        return;
    }
    cdem_error e;
    cdem_error_clear(&e);
    if (write_compacted(path, tmp, sync, &e) != 0) {
        remove(tmp);
        snprintf(rep->note, sizeof rep->note, "%s %s: compacting it failed: %.400s", path, kept,
                 e.msg);
        free(tmp);
        return;
    }
    crash_point("rename");
    if (rename(tmp, path) != 0) {
        int en = errno;
        remove(tmp);
        snprintf(rep->note, sizeof rep->note, "%s %s: cannot rename the compacted copy over it: %s",
                 path, kept, strerror(en));
        free(tmp);
        return;
    }
    free(tmp);
    if (sync)
        h5i_sync_folder_of(path);
    rep->compacted = 1;
    if (stat(path, &sb) == 0)
        rep->bytes_after = (uint64_t)sb.st_size;
}
