/* outfile: see outfile.h. */
#include "outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

cdem_status cdem_outfile_begin(cdem_outfile *o, const char *path, cdem_error *err) {
    if (!o)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_outfile_begin: no handle");
    o->active = 0;
    o->path[0] = o->tmp[0] = '\0';
    if (!path || !path[0])
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "output path is empty");
    size_t len = strlen(path);
    if (len >= sizeof o->path)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "output path %.60s... is %zu characters long; at most %zu allowed", path,
                         len, sizeof o->path - 1);
    memcpy(o->path, path, len + 1);
    snprintf(o->tmp, sizeof o->tmp, "%s.tmp", path);
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot create %s: it is a folder", path);
    char dir[CDEM_OUTFILE_PATH_MAX];
    cdem_outfile_folder_of(path, dir, sizeof dir);
    if (stat(dir, &sb) != 0)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot create %s: folder %s: %s", path, dir,
                         strerror(errno));
    if (!S_ISDIR(sb.st_mode))
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot create %s: %s is not a folder", path, dir);
    if (access(dir, W_OK | X_OK) != 0)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot create %s: folder %s is not writable: %s", path,
                         dir, strerror(errno));
    if (unlink(o->tmp) != 0 && errno != ENOENT)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot create %s: cannot remove the stale %s: %s", path,
                         o->tmp, strerror(errno));
    o->active = 1;
    return CDEM_OK;
}

cdem_status cdem_outfile_make_dirs(const char *dir, cdem_error *err) {
    char buf[CDEM_OUTFILE_PATH_MAX];
    if (!dir || !dir[0])
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "output folder name is empty");
    if (strlen(dir) >= sizeof buf)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "output folder %.60s... is too long", dir);
    snprintf(buf, sizeof buf, "%s", dir);
    /* each prefix ending before a '/', then the whole path */
    for (char *p = buf + 1;; p++) {
        if (*p != '/' && *p != '\0')
            continue;
        const char c = *p;
        *p = '\0';
        struct stat sb;
        if (mkdir(buf, 0777) != 0 && errno != EEXIST)
            return CDEM_FAIL(err, CDEM_ERR_IO, "cannot create the folder %s: %s", buf,
                             strerror(errno));
        if (stat(buf, &sb) != 0 || !S_ISDIR(sb.st_mode))
            return CDEM_FAIL(err, CDEM_ERR_IO, "cannot create the folder %s: %s is not a folder",
                             dir, buf);
        *p = c;
        if (c == '\0')
            break;
    }
    return CDEM_OK;
}

void cdem_outfile_discard(cdem_outfile *o) {
    if (!o || !o->active)
        return;
    unlink(o->tmp);
    o->active = 0;
}

cdem_status cdem_outfile_end(cdem_outfile *o, cdem_status st, cdem_error *err) {
    if (!o || !o->active)
        return st != CDEM_OK ? st : CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_outfile_end: not begun");
    if (st != CDEM_OK) {
        cdem_outfile_discard(o);
        return st;
    }
    /* the data must be on disk before the name points at it */
    int fd = open(o->tmp, O_RDONLY);
    if (fd < 0) {
        int e = errno;
        cdem_outfile_discard(o);
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s: %s vanished: %s", o->path, o->tmp,
                         strerror(e));
    }
    int bad = fsync(fd) != 0 && errno != EINVAL && errno != EROFS;
    int e = errno;
    close(fd);
    if (bad) {
        cdem_outfile_discard(o);
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s: flushing %s: %s", o->path, o->tmp,
                         strerror(e));
    }
    if (rename(o->tmp, o->path) != 0) {
        e = errno;
        cdem_outfile_discard(o);
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s: renaming %s to it: %s", o->path,
                         o->tmp, strerror(e));
    }
    o->active = 0;
    return CDEM_OK;
}

cdem_status cdem_outfile_open_text(cdem_outfile *o, const char *path, FILE **f, cdem_error *err) {
    *f = NULL;
    CDEM_TRY(cdem_outfile_begin(o, path, err));
    if (!(*f = fopen(o->tmp, "w")))
        return cdem_outfile_end(
            o, CDEM_FAIL(err, CDEM_ERR_IO, "cannot create %s: %s", o->tmp, strerror(errno)), err);
    return CDEM_OK;
}

cdem_status cdem_outfile_close_text(cdem_outfile *o, FILE *f, cdem_status st, cdem_error *err) {
    const int bad = ferror(f);
    if ((fclose(f) != 0 || bad) && st == CDEM_OK)
        st = CDEM_FAIL(err, CDEM_ERR_IO, "error writing %s", o->tmp);
    return cdem_outfile_end(o, st, err);
}

void cdem_outfile_folder_of(const char *path, char *buf, size_t cap) {
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(buf, cap, ".");
    else if (slash == path)
        snprintf(buf, cap, "/");
    else
        snprintf(buf, cap, "%.*s", (int)(slash - path), path);
}
