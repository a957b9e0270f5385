/* runlock: see runlock.h. */
#define _GNU_SOURCE /* F_OFD_SETLK, F_OFD_GETLK (Linux open-file-description locks) */
#include "runlock.h"

#include "outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

struct cdem_runlock {
    int fd;     /* open lock file, holding the OFD write lock */
    int locked; /* 1: the lock is held; 0: the filesystem has no locks */
    char *path; /* the lock file's path */
};

int cdem_runlock_path(const char *path, char *buf, size_t cap) {
    int n = snprintf(buf, cap, "%s.lock", path ? path : "");
    return n < 0 || (size_t)n >= cap ? -1 : 0;
}

/* Reads the holder's line from fd into buf (empty when the file is empty). */
static void read_holder(int fd, char *buf, size_t cap) {
    if (cap == 0)
        return;
    ssize_t got = pread(fd, buf, cap - 1, 0);
    buf[got > 0 ? (size_t)got : 0] = '\0';
    buf[strcspn(buf, "\r\n")] = '\0';
}

/* The refusal, the same whether found by acquire or by check. */
static cdem_status held_by_other(const char *path, const char *lock_path, const char *holder,
                                 cdem_error *err) {
    return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                     "%s is being written by another process (%s; lock file %s): two writers "
                     "would destroy each other's results; wait until it has finished, stop it, "
                     "or write to another file",
                     path, holder && holder[0] ? holder : "it has not yet recorded its name",
                     lock_path);
}

static int whole_file_lock(int fd, int cmd, short type, struct flock *fl) {
    memset(fl, 0, sizeof *fl);
    fl->l_type = type;
    fl->l_whence = SEEK_SET;
    fl->l_start = 0;
    fl->l_len = 0; /* to the end of the file, however long */
    return fcntl(fd, cmd, fl);
}

/* The lock file may be removed by its previous holder between our open() and our lock: the
 * lock would then be on an unlinked file that the next process cannot see. So after locking,
 * the descriptor must still be the file at the path. */
static int still_at_path(int fd, const char *lock_path) {
    struct stat a, b;
    return fstat(fd, &a) == 0 && stat(lock_path, &b) == 0 && a.st_dev == b.st_dev &&
           a.st_ino == b.st_ino;
}

static cdem_status open_failure(const char *path, const char *lock_path, int e, cdem_error *err) {
    char dir[4096];
    cdem_outfile_folder_of(path, dir, sizeof dir);
    if (e == ENOENT)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s: folder %s does not exist", path, dir);
    if (e == ENOTDIR)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s: %s is not a folder", path, dir);
    if (e == EACCES || e == EROFS || e == EPERM)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s: folder %s is not writable (%s)", path,
                         dir, strerror(e));
    if (e == EISDIR)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s: %s is a folder", path, lock_path);
    return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s: cannot create its lock file %s: %s", path,
                     lock_path, strerror(e));
}

cdem_status cdem_runlock_acquire(const char *path, const char *program, cdem_runlock **out,
                                 cdem_error *err) {
    if (out)
        *out = NULL;
    if (!path || !*path || !out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_runlock_acquire: path and out are required");
    cdem_runlock *l = calloc(1, sizeof *l);
    size_t n = strlen(path) + 6;
    if (!l || !(l->path = malloc(n))) {
        free(l);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory locking %s", path);
    }
    cdem_runlock_path(path, l->path, n);
    l->fd = -1;
    for (int attempt = 0; attempt < 50; attempt++) {
        l->fd = open(l->path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (l->fd < 0) {
            int e = errno;
            cdem_status st = open_failure(path, l->path, e, err);
            free(l->path);
            free(l);
            return st;
        }
        struct flock fl;
        if (whole_file_lock(l->fd, F_OFD_SETLK, F_WRLCK, &fl) == 0) {
            if (still_at_path(l->fd, l->path)) {
                l->locked = 1;
                break;
            }
            close(l->fd); /* the previous holder removed it meanwhile: lock the new one */
            l->fd = -1;
            continue;
        }
        int e = errno;
        if (e == ENOLCK || e == EINVAL || e == EOPNOTSUPP) {
            l->locked = 0; /* no locks on this filesystem: run unprotected */
            break;
        }
        /* Held by another writer. It writes its line right after locking: give it a moment
         * (runlock.h, CDEM_RUNLOCK_NAME_WAIT_MS), in 10 ms looks that end with the line. */
        char holder[512] = "";
        for (int k = 0; k < CDEM_RUNLOCK_NAME_WAIT_MS / 10 && !holder[0]; k++) {
            read_holder(l->fd, holder, sizeof holder);
            if (!holder[0]) {
                struct timespec ts = {0, 10 * 1000 * 1000};
                nanosleep(&ts, NULL);
            }
        }
        close(l->fd);
        cdem_status st = held_by_other(path, l->path, holder, err);
        free(l->path);
        free(l);
        return st;
    }
    if (l->fd < 0) {
        free(l->path);
        free(l);
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "cannot lock %s: its lock file kept being replaced by other processes",
                         path);
    }
    char when[32] = "?", host[256] = "?";
    time_t now = time(NULL);
    struct tm tmv;
    if (gmtime_r(&now, &tmv))
        strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tmv);
    if (gethostname(host, sizeof host) != 0)
        snprintf(host, sizeof host, "?");
    host[sizeof host - 1] = '\0';
    char line[512];
    int len = snprintf(line, sizeof line, "%s pid %ld, started %s on %s\n",
                       program && *program ? program : "a cdem writer", (long)getpid(), when, host);
    if (len < 0 || (size_t)len >= sizeof line)
        len = (int)strlen(line);
    /* The line is only for messages; failing to write it does not weaken the lock. */
    if (ftruncate(l->fd, 0) != 0 || pwrite(l->fd, line, (size_t)len, 0) != len)
        errno = 0;
    *out = l;
    return CDEM_OK;
}

void cdem_runlock_release(cdem_runlock *l) {
    if (!l)
        return;
    if (l->fd >= 0) {
        /* Remove the file only while it is still ours (see still_at_path), then unlock by
         * closing: a process that opened the old file meanwhile notices and starts over. */
        if (still_at_path(l->fd, l->path))
            unlink(l->path);
        close(l->fd);
    }
    free(l->path);
    free(l);
}

int cdem_runlock_effective(const cdem_runlock *l) {
    return l ? l->locked : 0;
}

int cdem_runlock_probe(const char *path, char *holder, size_t holder_cap) {
    if (holder && holder_cap)
        holder[0] = '\0';
    char lock_path[4200];
    if (!path || cdem_runlock_path(path, lock_path, sizeof lock_path) != 0)
        return -1;
    int fd = open(lock_path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return errno == ENOENT ? 0 : -1;
    struct flock fl;
    int rc;
    if (whole_file_lock(fd, F_OFD_GETLK, F_WRLCK, &fl) != 0)
        rc = -1;
    else
        rc = fl.l_type != F_UNLCK;
    if (rc == 1 && holder && holder_cap)
        read_holder(fd, holder, holder_cap);
    close(fd);
    return rc;
}

cdem_status cdem_runlock_check(const char *path, cdem_error *err) {
    char holder[512];
    if (cdem_runlock_probe(path, holder, sizeof holder) != 1)
        return CDEM_OK;
    char lock_path[4200];
    cdem_runlock_path(path, lock_path, sizeof lock_path);
    return held_by_other(path, lock_path, holder, err);
}
