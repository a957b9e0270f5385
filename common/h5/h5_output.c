/* h5_output: the checks made before a run starts, so that a run is refused at once rather
 * than after hours: may the output path be written (no live writer holds it; an existing
 * file may be replaced under the policy: cdem_h5_replace), is there space for the run
 * (estimates measured on the default run, docs/format.md "Size"). The writer repeats the
 * replace check under its lock (h5i_check_replace). */
#include "h5_internal.h"
#include "outfile.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

double cdem_h5_estimate_file_size(double n_elements, double n_increments, int with_stress) {
    /* Measured on the default run (docs/format.md): 13.2 bytes per element and increment
     * without stress, 34.2 with, since the rows are stored by id (14.2 and 35.1 before, 16.1
     * and 40.5 with the 8192-row chunks before that), rounded up; plus 64 KiB of metadata
     * and 0.5 KB per increment. */
    double per = with_stress ? 34.5 : 13.5;
    return 65536.0 + n_increments * (512.0 + n_elements * per);
}

/* Checkpoint and sidecar sizes for cdem_h5_estimate_run_space, measured on cdem-run files
 * (docs/format.md, "Size"): a checkpoint holds about CKPT_BYTES_PER_ELEMENT bytes per
 * element (state, neighbour list, contact histories) plus the parameter text and the
 * summary, before compression: a bound (the default run's is 191 bytes per element before
 * and 101 after compression, h5_ckpt_codec.c; denser packings have more pairs); a
 * sidecar increment is about XMF_BYTES_PER_INCREMENT bytes of XML. */
#define CKPT_BYTES_FIXED        65536.0
#define CKPT_BYTES_PER_ELEMENT  400.0
#define XMF_BYTES_PER_INCREMENT 3400.0
#define XMF_BYTES_STRESS        1300.0

double cdem_h5_estimate_run_space(double n_elements, double n_increments, int with_stress,
                                  int with_checkpoints) {
    double total = cdem_h5_estimate_file_size(n_elements, n_increments, with_stress);
    if (with_checkpoints) {
        /* a slot is a whole number of chunks, allocated in full; two slots */
        double blob = CKPT_BYTES_FIXED + n_elements * CKPT_BYTES_PER_ELEMENT;
        total += 2.0 * ceil(blob / CKPT_CHUNK) * CKPT_CHUNK;
    }
    /* the sidecar, and its temporary copy while it is rewritten */
    total += 2.0 * n_increments * (XMF_BYTES_PER_INCREMENT + (with_stress ? XMF_BYTES_STRESS : 0));
    return total;
}

cdem_status cdem_h5_check_free_space(const char *path, double bytes_needed, cdem_error *err) {
    if (!path || !*path)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_check_free_space: no path");
    char dir[4096];
    cdem_outfile_folder_of(path, dir, sizeof dir);
    struct statvfs sv;
    if (statvfs(dir, &sv) != 0) {
        int e = errno;
        if (e == ENOENT)
            return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "cannot write %s: folder %s does not exist",
                             path, dir);
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "cannot write %s: cannot reach folder %s: %s",
                         path, dir, strerror(e));
    }
    /* A folder a run cannot write to is named as such, not as short of space: a read-only
     * file system reports little or no free space, and the caller's advice for too little
     * space ("free some space ... or --ignore-free-space") would not help (issue 35, item
     * 10). So neither is CDEM_ERR_IO, which the caller keeps for too little space. A folder
     * of mode 0555 is writable for root, and access() says so. */
    if (sv.f_flag & ST_RDONLY)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "cannot write %s: folder %s is on a read-only file system; write the "
                         "run elsewhere (-o)",
                         path, dir);
    if (access(dir, W_OK | X_OK) != 0) {
        const int e = errno;
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "cannot write %s: folder %s is not writable (%s); write the run "
                         "elsewhere (-o) or make the folder writable",
                         path, dir, strerror(e));
    }
    double avail = (double)sv.f_bavail * (double)sv.f_frsize;
    if (avail < bytes_needed)
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: the output needs about %.1f MB but %s has %.1f MB free", path,
                         bytes_needed / 1e6, dir, avail / 1e6);
    return CDEM_OK;
}

/* What is at path, for the messages of h5i_check_replace: *is_cdem becomes 1 for a file the
 * reader opens as a cdem file; desc receives e.g. 'a cdem run file (stop reason
 * "completed", 41 increments)' or 'not an HDF5 file'. */
static void describe_existing(const char *path, int *is_cdem, int *resumable, int *completed,
                              char *desc, size_t cap) {
    *is_cdem = *resumable = *completed = 0;
    cdem_error e;
    cdem_error_clear(&e);
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(path, &r, &e) != CDEM_OK) {
        const char *why = e.msg;
        size_t n = strlen(path);
        if (strncmp(why, path, n) == 0 && why[n] == ':') /* the message starts with the path */
            why += n + 2;
        snprintf(desc, cap, "%s%.300s", e.code == CDEM_ERR_FORMAT ? "" : "unreadable: ", why);
        return;
    }
    *is_cdem = 1;
    const char *stop = cdem_h5_reader_stop_reason(r);
    *completed = strcmp(stop, "completed") == 0;
    *resumable = strcmp(cdem_h5_reader_source(r), "cdem-run") == 0 && !*completed &&
                 cdem_h5_reader_format_version(r) >= 2;
    /* a file still saying "running" that no writer holds was interrupted (killed) */
    const int killed = !strcmp(stop, "running") && cdem_h5_reader_writer_alive(r) == 0;
    snprintf(desc, cap, "a cdem run file written by %.60s: stop reason \"%.40s\"%s, %zu increments",
             cdem_h5_reader_source(r), stop,
             killed ? " but no writer holds it (interrupted: killed or crashed)" : "",
             cdem_h5_reader_increment_count(r));
    cdem_h5_reader_close(r);
}

/* The policy for a file already at path; *replace becomes 1 when it may be replaced by a
 * rename, 0 when there is nothing there (the writer's rename then refuses to replace).
 * *completed (may be NULL) becomes 1 when what is there is a cdem run that completed. */
cdem_status h5i_check_replace(const char *path, cdem_h5_replace policy, int *replace,
                              int *completed, cdem_error *err) {
    *replace = 0;
    if (completed)
        *completed = 0;
    struct stat sb;
    if (lstat(path, &sb) != 0) {
        if (errno == ENOENT)
            return CDEM_OK;
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot examine the output path: %s", path,
                         strerror(errno));
    }
    if (S_ISDIR(sb.st_mode))
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT, "%s: the output path is a folder", path);
    if (policy == CDEM_H5_REPLACE_ANY) {
        *replace = 1;
        return CDEM_OK;
    }
    if (!S_ISREG(sb.st_mode))
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "%s already exists and is not a regular file (a link, a device, a "
                         "pipe?); a run never replaces it: choose another output file",
                         path);
    int is_cdem = 0, resumable = 0, done = 0;
    char desc[600];
    describe_existing(path, &is_cdem, &resumable, &done, desc, sizeof desc);
    if (!is_cdem)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "%s already exists and is not a cdem run file (%s); it is never "
                         "replaced by a run file, not even with --force: choose another output "
                         "file",
                         path, desc);
    if (policy == CDEM_H5_REPLACE_NEVER)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "%s already exists (%s); it was left as it is: choose another output "
                         "file (-o), remove it, or replace it on purpose with --force%s%s",
                         path, desc,
                         resumable ? "; to continue that run instead: cdem-run "
                                     "--resume "
                                   : "",
                         resumable ? path : "");
    *replace = 1;
    if (completed)
        *completed = done;
    return CDEM_OK;
}

char *h5i_replaced_path(const char *path) {
    const size_t n = strlen(path) + sizeof ".replaced";
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%s.replaced", path);
    return p;
}

int h5i_drop_replaced(const char *path) {
    char *aside = h5i_replaced_path(path);
    int dropped = 0;
    struct stat sb;
    if (aside && lstat(aside, &sb) == 0 && S_ISREG(sb.st_mode)) {
        int is_cdem = 0, resumable = 0, completed = 0;
        char desc[600];
        describe_existing(aside, &is_cdem, &resumable, &completed, desc, sizeof desc);
        dropped = is_cdem && unlink(aside) == 0;
    }
    free(aside);
    return dropped;
}

cdem_status cdem_h5_output_check(const char *path, cdem_h5_replace replace, cdem_error *err) {
    if (!path || !*path)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_output_check: no path");
    CDEM_TRY(cdem_runlock_check(path, err));
    int dummy = 0;
    return h5i_check_replace(path, replace, &dummy, NULL, err);
}
