/* h5_reader: opens a run file read-only and reads it: root texts and stop texts, an
 * increment's elements (checked against their physical bounds), the parameters, and the
 * increment a name such as "last" or "equil" means. The list of increments is read by
 * h5_reader_list.c, the time series by h5_reader_series.c, version-1 files (one group per
 * increment) by h5_reader_v1.c. Non-HDF5, non-cdem, wrong-version, truncated or corrupt
 * files fail with a message naming the path and the problem, never a crash.
 * How a file is opened (the reasons are at reader_setup): SWMR-read, with bounded metadata
 * retries, while a writer holds the path's lock; otherwise the file is complete and opened as
 * one ("clear_status_flags" and "skip_eof_check", read-only, what h5clear uses). */
#include "h5_internal.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

void cdem_h5_reader_close(cdem_h5_reader *r) {
    if (!r)
        return;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        if (r->data[k] >= 0)
            H5Dclose(r->data[k]);
    if (r->index >= 0)
        H5Dclose(r->index);
    if (r->file >= 0)
        H5Fclose(r->file);
    free(r->path);
    free(r->summary);
    free(r->params_text);
    free(r->stop_reason);
    free(r->stop_detail);
    free(r->program_version);
    free(r->source);
    free(r->created);
    free(r->incr);
    free(r->damaged);
    free(r);
}

/* *text replaced by its printable form (h5i_printable): the texts of a file are printed to
 * terminals and into JSON, and a damaged or forged one may hold any bytes (a stop reason of
 * 0xFF 0xFE was printed raw). */
static int make_printable(char **text) {
    char *p = h5i_printable(*text);
    if (!p)
        return -1;
    free(*text);
    *text = p;
    return 0;
}

/* A root text attribute into *out (malloc'd, "" when absent); printable when shown (every
 * text but the parameter file, which is parsed, never printed by the reader). */
static cdem_status read_root_text(cdem_h5_reader *r, const char *name, char **out, int shown,
                                  cdem_error *err) {
    int rc = h5i_get_str_attr(r->file, name, out);
    if (rc < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: root attribute '%s' is not a readable string",
                      r->path, name);
    if (rc > 0 && !(*out = h5i_dup_str("")))
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    if (shown && make_printable(out) != 0)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    return CDEM_OK;
}

/* The stop reason must be one the writer records (h5format.h, cdem_stop_reasons); the detail
 * is made printable. Called once the texts are read (either version). */
static cdem_status check_stop_texts(cdem_h5_reader *r, const char *where, cdem_error *err) {
    if (!h5i_known_stop_reason(r->stop_reason)) {
        char *shown = h5i_printable(r->stop_reason);
        cdem_status st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                                   "%s: %s is \"%.80s\", not a stop reason (running, completed, "
                                   "interrupted, stopped-early, numerical-failure, "
                                   "write-failure, error): damaged file",
                                   r->path, where, shown ? shown : "?");
        free(shown);
        return st;
    }
    if (make_printable(&r->stop_detail) != 0)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    return CDEM_OK;
}

/* Version 2: reads a scalar fixed-length string dataset (/stop_reason, /stop_detail) into a
 * malloc'd string (replacing *out). */
static cdem_status read_text_dataset(cdem_h5_reader *r, const char *name, char **out,
                                     cdem_error *err) {
    hid_t ds = H5Dopen2(r->file, name, H5P_DEFAULT);
    if (ds < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /%s is missing or corrupt", r->path, name);
    if (r->swmr)
        H5Drefresh(ds);
    hid_t t = H5Dget_type(ds), sp = H5Dget_space(ds), mt = -1;
    size_t size =
        t >= 0 && H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) == 0 ? H5Tget_size(t) : 0;
    char *buf = NULL;
    int ok = size > 0 && size <= 65536 && sp >= 0 && H5Sget_simple_extent_npoints(sp) == 1 &&
             (buf = calloc(size + 1, 1)) != NULL && (mt = H5Tcopy(H5T_C_S1)) >= 0 &&
             H5Tset_size(mt, size + 1) >= 0 && H5Tset_cset(mt, H5Tget_cset(t)) >= 0 &&
             H5Dread(ds, mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0;
    hid_t es = h5i_keep_errors(!ok);
    if (mt >= 0)
        H5Tclose(mt);
    if (t >= 0)
        H5Tclose(t);
    if (sp >= 0)
        H5Sclose(sp);
    H5Dclose(ds);
    h5i_restore_errors(es);
    if (!ok) {
        free(buf);
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: dataset /%s is not a readable fixed-length string scalar", r->path,
                      name);
    }
    free(*out);
    *out = buf;
    return CDEM_OK;
}

/* Version 2: the stop texts, then the list of increments (h5_reader_list.c). */
static cdem_status scan_v2(cdem_h5_reader *r, cdem_error *err) {
    CDEM_TRY(read_text_dataset(r, "stop_reason", &r->stop_reason, err));
    CDEM_TRY(read_text_dataset(r, "stop_detail", &r->stop_detail, err));
    CDEM_TRY(check_stop_texts(r, "dataset /stop_reason", err));
    return h5i_reader_scan(r, err);
}

cdem_status cdem_h5_reader_refresh(cdem_h5_reader *r, int *changed, cdem_error *err) {
    if (!r)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_refresh: no reader");
    if (changed)
        *changed = 0;
    if (!r->swmr)
        return CDEM_OK; /* a closed file (or version 1) does not change */
    size_t before = r->n_incr;
    int32_t last = before ? r->incr[before - 1].info.number : -1;
    char *reason = h5i_dup_str(r->stop_reason);
    if (!reason)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
    char damage[sizeof r->damage];
    memcpy(damage, r->damage, sizeof damage);
    cdem_status st = scan_v2(r, err);
    if (st == CDEM_OK && r->damage[0] && strcmp(damage, r->damage) != 0)
        fprintf(stderr, "warning: %s\n", r->damage); /* new damage while following */
    if (changed && st == CDEM_OK)
        *changed = r->n_incr != before ||
                   (r->n_incr && r->incr[r->n_incr - 1].info.number != last) ||
                   strcmp(reason, r->stop_reason) != 0;
    free(reason);
    return st;
}

/* 1 when the folder holds a modelresults_N.txt file, as a cdem2D simulation folder does
 * (analysis/input/cdem2d.c reads one; here it is only recognised, to say what to do). */
static int looks_like_cdem2d(const char *dir) {
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    static const char pre[] = "modelresults_";
    int found = 0;
    const struct dirent *e;
    while (!found && (e = readdir(d)) != NULL) {
        const char *name = e->d_name;
        const size_t len = strlen(name);
        found = len > strlen(pre) + 4 && strncmp(name, pre, strlen(pre)) == 0 &&
                isdigit((unsigned char)name[strlen(pre)]) && !strcmp(name + len - 4, ".txt");
    }
    closedir(d);
    return found;
}

static cdem_status reader_setup(cdem_h5_reader *r, cdem_error *err) {
    const char *path = r->path;
    struct stat sb;
    if (stat(path, &sb) != 0)
        return CDEM_FAIL(err, errno == ENOENT ? CDEM_ERR_NOTFOUND : CDEM_ERR_IO,
                         "%s: cannot open: %s", path, strerror(errno));
    if (S_ISDIR(sb.st_mode) && looks_like_cdem2d(path))
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: is a folder, not a cdem run file; it holds modelresults_N.txt "
                         "files, so it looks like a cdem2D simulation folder: import it with "
                         "`cdem-strain import-cdem2d %s -o run.h5` and read run.h5",
                         path, path);
    if (S_ISDIR(sb.st_mode))
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: is a folder, not a cdem run file (the HDF5 file cdem-run writes)",
                         path);
    if (!S_ISREG(sb.st_mode))
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: not a regular file (a device, pipe or socket), so not a cdem run "
                         "file",
                         path);
    htri_t is = H5Fis_hdf5(path);
    if (is <= 0)
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: not an HDF5 file (no HDF5 signature), so not a cdem file", path);
    int status = 0;
    CDEM_TRY(h5i_precheck_superblock(path, &status, err));
    r->unclosed = status != 0;
    /* A writer that still runs or died leaves the v3 superblock's status flags set; HDF5
     * then refuses a plain open. Whether the writer still runs is what its lock says
     * (runlock.h; a symbolic link is followed to the file the writer named):
     *  - alive (or cannot tell): SWMR-read, which sees the file grow (H5Drefresh). HDF5
     *    retries a metadata read whose checksum fails, because the writer may be rewriting
     *    that piece; between attempts it sleeps 1, 2, 4, ... ns, 100 attempts by default:
     *    2^100 ns, i.e. for ever on a damaged file (a reader sat in H5C_protect ->
     *    H5_nanosleep for more than 300 s). SWMR_READ_ATTEMPTS bounds the total wait;
     *  - dead (killed, or a copy of its file): the file is complete, so it is opened as one,
     *    without SWMR and its retries: "clear_status_flags" (the file-access property h5clear
     *    uses; on a read-only open it only skips the check, the file is not changed) and
     *    "skip_eof_check" (a killed writer may have reserved space it never wrote).
     * A version-1 writer (flags 0x01) never ran in SWMR mode: also the second way.
     * File locking (HDF5's own) is off either way so that a live writer does not block the
     * reader, and a process may open the same file twice (render --follow; HDF5 refuses a
     * second open whose locking setting differs). */
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_file_locking(fapl, 0, 1);
    r->writer = 0;
    if (r->unclosed) {
        char *real = realpath(path, NULL);
        r->writer = cdem_runlock_probe(real ? real : path, NULL, 0);
        free(real);
    }
    const int live = (status & 0x04) && r->writer != 0;
    if (live) {
        H5Pset_metadata_read_attempts(fapl, SWMR_READ_ATTEMPTS);
        r->file = H5Fopen(path, H5F_ACC_RDONLY | H5F_ACC_SWMR_READ, fapl);
        r->swmr = r->file >= 0;
        if (r->file < 0)
            H5Eclear2(H5E_DEFAULT);
        H5Pset_metadata_read_attempts(fapl, 1);
    }
    if (r->file < 0) {
        if (r->unclosed) {
            hbool_t yes = 1;
            H5Pset(fapl, "clear_status_flags", &yes);
            H5Pset(fapl, "skip_eof_check", &yes);
        }
        r->file = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    }
    if (r->file < 0) {
        /* The file may already be open in this process (its writer, or a caller's own
         * H5Fopen): HDF5 then shares it, and the access properties must match. */
        H5Eclear2(H5E_DEFAULT);
        r->file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    }
    if (r->file < 0) {
        cdem_status st = H5FAIL(err, CDEM_ERR_FORMAT,
                                "%s: cannot open as HDF5 (truncated or corrupt file?)", path);
        H5Pclose(fapl);
        return st;
    }
    H5Pclose(fapl);

    char *fmt = NULL;
    int rc = h5i_get_str_attr(r->file, "format", &fmt);
    if (rc < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: damaged file: HDF5 opens it but its root attribute 'format' cannot "
                      "be read (corrupt HDF5 metadata)",
                      path);
    if (rc != 0 || strcmp(fmt, CDEM_FORMAT_NAME) != 0) {
        cdem_status st = H5FAIL(err, CDEM_ERR_FORMAT,
                                "%s: an HDF5 file but not a cdem file: root attribute 'format' "
                                "is %s%s%s (expected \"%s\")",
                                path,
                                rc > 0   ? "missing"
                                : rc < 0 ? "unreadable"
                                         : "\"",
                                rc == 0 ? fmt : "", rc == 0 ? "\"" : "", CDEM_FORMAT_NAME);
        free(fmt);
        return st;
    }
    free(fmt);
    int32_t version = 0;
    rc = h5i_get_num_attr(r->file, "format_version", H5T_NATIVE_INT32, &version);
    if (rc != 0)
        return H5FAIL(err, CDEM_ERR_FORMAT,
                      "%s: root attribute 'format_version' is %s (an integer is required)", path,
                      rc > 0 ? "missing" : "unreadable");
    if (version != CDEM_FORMAT_VERSION && version != 1)
        return CDEM_FAIL(err, CDEM_ERR_VERSION,
                         "%s: cdem format version %d; this program reads versions 1 and %d%s", path,
                         (int)version, CDEM_FORMAT_VERSION,
                         version > CDEM_FORMAT_VERSION ? " (written by a newer cdem-c)" : "");
    r->version = (int)version;
    int64_t seed = 0;
    if (h5i_get_num_attr(r->file, "seed", H5T_NATIVE_INT64, &seed) < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: root attribute 'seed' is unreadable", path);
    r->seed = (long)seed;
    CDEM_TRY(read_root_text(r, "summary", &r->summary, 1, err));
    CDEM_TRY(read_root_text(r, "params_text", &r->params_text, 0, err));
    CDEM_TRY(read_root_text(r, "program_version", &r->program_version, 1, err));
    CDEM_TRY(read_root_text(r, "source", &r->source, 1, err));
    CDEM_TRY(read_root_text(r, "created", &r->created, 1, err));
    if (r->version >= 2)
        return scan_v2(r, err);
    CDEM_TRY(read_root_text(r, "stop_reason", &r->stop_reason, 0, err));
    CDEM_TRY(read_root_text(r, "stop_detail", &r->stop_detail, 0, err));
    CDEM_TRY(check_stop_texts(r, "root attribute stop_reason", err));
    CDEM_TRY(h5i_v1_list_increments(r, err));
    return h5i_reader_check_not_empty(r, err);
}

/* cdem_h5_reader_open; warn: 1 to write the damage warning to stderr. */
static cdem_status open_reader(const char *path, cdem_h5_reader **out, int warn, cdem_error *err) {
    if (out)
        *out = NULL;
    if (!path || !out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_open: path and out are required");
    h5i_quiet_hdf5();
    cdem_h5_reader *r = calloc(1, sizeof *r);
    if (!r || !(r->path = h5i_dup_str(path))) {
        free(r);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory opening %s", path);
    }
    r->file = r->index = -1;
    r->damaged_through = INT32_MAX;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++)
        r->data[k] = -1;
    cdem_status st = reader_setup(r, err);
    if (st != CDEM_OK) {
        cdem_h5_reader_close(r);
        return st;
    }
    /* damaged commit rows cost their increments only: the file opens, and says so once */
    if (warn && r->damage[0])
        fprintf(stderr, "warning: %s\n", r->damage);
    *out = r;
    return CDEM_OK;
}

cdem_status cdem_h5_reader_open(const char *path, cdem_h5_reader **out, cdem_error *err) {
    return open_reader(path, out, 1, err);
}

cdem_status h5i_reader_open_quiet(const char *path, cdem_h5_reader **out, cdem_error *err) {
    return open_reader(path, out, 0, err);
}

size_t cdem_h5_reader_increment_count(const cdem_h5_reader *r) {
    return r ? r->n_incr : 0;
}

cdem_status cdem_h5_reader_increment_info(const cdem_h5_reader *r, size_t index,
                                          cdem_increment_info *info, cdem_error *err) {
    if (!r || !info)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_increment_info: no reader");
    if (index >= r->n_incr)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s: increment index %zu (the file has %zu)",
                         r->path, index, r->n_incr);
    *info = r->incr[index].info;
    return CDEM_OK;
}

/* The rule of docs/format.md ("Counting"): the last increment of the equilibration phase is
 * its end only once an increment of a later phase follows it, or the run completed. A run
 * stopped, killed or still running in equilibration has not written its end yet (its last
 * increment was 42 where the end was 56): never guessed. */
static cdem_status equil_end(const cdem_h5_reader *r, size_t *index, const char *what,
                             cdem_error *err) {
    size_t last = SIZE_MAX;
    for (size_t i = r->n_incr; i-- > 0 && last == SIZE_MAX;)
        if (r->incr[i].info.phase == CDEM_PHASE_EQUILIBRATION)
            last = i;
    if (last == SIZE_MAX)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "%s: %sno increment is in the equilibration phase, so the file has no "
                         "end of equilibration",
                         r->path, what);
    if (last + 1 < r->n_incr || !strcmp(r->stop_reason, "completed")) {
        *index = last;
        return CDEM_OK;
    }
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                     "%s: %sthe end of equilibration is not reached: %s (its last increment, %d, "
                     "is of the equilibration phase; the end is known once an increment of the "
                     "deformation phase follows)",
                     r->path, what,
                     r->writer == 1 && !strcmp(r->stop_reason, "running")
                         ? "the run is still in equilibration"
                         : "the run stopped during equilibration",
                     (int)r->incr[last].info.number);
}

cdem_status cdem_h5_reader_equil_end(const cdem_h5_reader *r, size_t *index, cdem_error *err) {
    if (!r || !index)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_equil_end: bad arguments");
    return equil_end(r, index, "", err);
}

/* The last damaged row that held an increment (r->last_damaged: the last row written). */
static const damaged_row *last_damaged_row(const cdem_h5_reader *r) {
    const damaged_row *d = NULL;
    for (size_t i = 0; i < r->n_damaged; i++)
        if (!r->damaged[i].spare)
            d = &r->damaged[i];
    return d;
}

cdem_status cdem_h5_reader_find_increment(const cdem_h5_reader *r, const char *spec, size_t *index,
                                          cdem_error *err) {
    if (!r || !spec || !index)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_find_increment: bad arguments");
    if (r->n_incr == 0)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s: increment '%s': the file has no increments",
                         r->path, spec);
    int32_t lo = r->incr[0].info.number, hi = r->incr[r->n_incr - 1].info.number;
    if (!strcmp(spec, "first")) {
        *index = 0;
        return CDEM_OK;
    }
    if (!strcmp(spec, "last")) {
        if (r->last_damaged) { /* the run's last increment is the damaged row's, not this */
            const damaged_row *d = last_damaged_row(r);
            return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                             "%s: increment 'last': the run's last row, /increments/commit row "
                             "%llu (increment %d), is damaged (%s): that increment cannot be "
                             "read; the last that can is %d",
                             r->path, (unsigned long long)d->row, (int)d->number, d->what, (int)hi);
        }
        *index = r->n_incr - 1;
        return CDEM_OK;
    }
    if (!strcmp(spec, "equil")) {
        return equil_end(r, index, "increment 'equil': ", err);
    }
    const char *p = spec;
    while (isspace((unsigned char)*p))
        p++;
    char *end = NULL;
    errno = 0;
    long k = strtol(p, &end, 10);
    if (end == p || *end != '\0' || errno != 0 || !isdigit((unsigned char)*p))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "increment '%s': expected a number (%d..%d), first, last or equil", spec,
                         (int)lo, (int)hi);
    for (size_t i = 0; i < r->n_incr; i++)
        if (r->incr[i].info.number == k) {
            *index = i;
            return CDEM_OK;
        }
    for (size_t i = 0; i < r->n_damaged; i++)
        if (!r->damaged[i].spare && r->damaged[i].number == k)
            return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                             "%s: increment %ld cannot be read: its row of the commit record, "
                             "/increments/commit row %llu, is damaged (%s); the file's other "
                             "%zu increments can be read",
                             r->path, k, (unsigned long long)r->damaged[i].row, r->damaged[i].what,
                             r->n_incr);
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                     "%s: increment %ld does not exist (the file has %zu increments, %d..%d)",
                     r->path, k, r->n_incr, (int)lo, (int)hi);
}

static cdem_status load_v2(cdem_h5_reader *r, const incr_entry *e, cdem_state *s, cdem_error *err) {
    const hsize_t n = (hsize_t)e->info.n_elements;
    const int stress = e->info.has_stress != 0;
    /* n comes from the index, checked only against the datasets' extents; an extent can be
     * declared with no storage behind it (HDF5 then returns fill values), so a forged file
     * could make the reader allocate for 2^31 elements: the cap of version-1 files, before
     * allocating */
    if (n > READER_MAX_ELEMENTS)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: increment %d claims %llu elements; this reader refuses more than "
                         "%llu (corrupt file?)",
                         r->path, (int)e->info.number, (unsigned long long)n,
                         (unsigned long long)READER_MAX_ELEMENTS);
    cdem_state_free(s);
    CDEM_TRY(cdem_state_init(s, n ? (size_t)n : 1, stress, err));
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        const element_field *fd = &h5i_element_fields[k];
        if (fd->optional && !stress)
            continue;
        hsize_t off = (hsize_t)(fd->optional ? e->stress_offset : e->offset);
        if (h5i_read_rows(r->data[k], h5i_el_mem_type(fd->type), off, n, h5i_element_array(s, k)) <
            0)
            return H5FAIL(err, CDEM_ERR_FORMAT,
                          "%s: cannot read rows %llu..%llu of /increments/%s for increment %d "
                          "(corrupt?)",
                          r->path, (unsigned long long)off, (unsigned long long)(off + n), fd->name,
                          (int)e->info.number);
    }
    s->n = (size_t)n;
    int32_t next = 0;
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] >= next)
            next = s->id[i] == INT32_MAX ? INT32_MAX : s->id[i] + 1;
    s->next_id = next;
    return CDEM_OK;
}

/* The dataset and row of value i of field (an element dataset's name) of increment e, for
 * messages: "/increments/x row 8197" (version 2), "/increments/000003/x row 5" (version 1). */
static void row_name(const cdem_h5_reader *r, const incr_entry *e, const char *field, size_t i,
                     char *buf, size_t cap) {
    const int stress = field[0] == 's'; /* sxx, syy, sxy */
    if (r->version >= 2)
        snprintf(buf, cap, "/increments/%s row %llu", field,
                 (unsigned long long)(stress ? e->stress_offset : e->offset) +
                     (unsigned long long)i);
    else
        snprintf(buf, cap, "/increments/%s/%s row %zu", e->name, field, i);
}

/* A loaded increment's values against the physical bounds (h5i_bad_element) and its ids
 * unique: a checksum says the bytes are the writer's, not that they are a model's (radii of
 * 0 made compute print 1288 nan; a duplicated id failed deep inside the strain code, naming
 * neither file nor increment). */
static cdem_status check_loaded(const cdem_h5_reader *r, const incr_entry *e, const cdem_state *s,
                                cdem_error *err) {
    char why[200], where[160];
    for (size_t i = 0; i < s->n; i++) {
        const char *field = NULL;
        if (!h5i_bad_element(s, i, &field, why, sizeof why))
            continue;
        row_name(r, e, field, i, where, sizeof where);
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: increment %d, %s (element id %d): %s (docs/format.md, \"Physical "
                         "bounds\"): damaged file",
                         r->path, (int)e->info.number, where, (int)s->id[i], why);
    }
    size_t a = 0, b = 0;
    const int dup = h5i_find_duplicate_id(s->id, s->n, &a, &b);
    if (dup < 0)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory checking the ids of increment %d",
                         r->path, (int)e->info.number);
    if (dup) {
        row_name(r, e, "id", a, where, sizeof where);
        row_name(r, e, "id", b, why, sizeof why);
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: increment %d: element id %d appears twice, at %s and at %s (ids are "
                         "unique within an increment): damaged file",
                         r->path, (int)e->info.number, (int)s->id[a], where, strstr(why, "row"));
    }
    return CDEM_OK;
}

cdem_status cdem_h5_reader_load_increment(cdem_h5_reader *r, size_t index, cdem_state *s,
                                          cdem_increment_info *info, cdem_error *err) {
    if (!r || !s)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_load_increment: bad arguments");
    if (index >= r->n_incr)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s: increment index %zu (the file has %zu)",
                         r->path, index, r->n_incr);
    const incr_entry *e = &r->incr[index];
    cdem_status st = r->version >= 2 ? load_v2(r, e, s, err) : h5i_v1_load(r, e, s, err);
    if (st == CDEM_OK)
        st = check_loaded(r, e, s, err);
    if (st != CDEM_OK) {
        cdem_state_free(s);
        return st;
    }
    if (info)
        *info = e->info;
    return CDEM_OK;
}

const char *cdem_h5_reader_summary(const cdem_h5_reader *r) {
    return r ? r->summary : "";
}

const char *cdem_h5_reader_params_text(const cdem_h5_reader *r) {
    return r ? r->params_text : "";
}

const char *cdem_h5_reader_stop_reason(const cdem_h5_reader *r) {
    return r ? r->stop_reason : "";
}

const char *cdem_h5_reader_stop_detail(const cdem_h5_reader *r) {
    return r ? r->stop_detail : "";
}

const char *cdem_h5_reader_program_version(const cdem_h5_reader *r) {
    return r ? r->program_version : "";
}

const char *cdem_h5_reader_source(const cdem_h5_reader *r) {
    return r ? r->source : "";
}

const char *cdem_h5_reader_created(const cdem_h5_reader *r) {
    return r ? r->created : "";
}

long cdem_h5_reader_seed(const cdem_h5_reader *r) {
    return r ? r->seed : 0;
}

int cdem_h5_reader_unclosed(const cdem_h5_reader *r) {
    return r ? r->unclosed : 0;
}

int cdem_h5_reader_writer_alive(const cdem_h5_reader *r) {
    return r ? r->writer : 0;
}

const char *cdem_h5_reader_damage(const cdem_h5_reader *r) {
    return r ? r->damage : "";
}

int cdem_h5_reader_damaged_increments(const cdem_h5_reader *r, int32_t *last_before) {
    if (!r || r->damaged_through == INT32_MAX)
        return 0;
    if (last_before)
        *last_before = r->damaged_through;
    return 1;
}

int cdem_h5_reader_format_version(const cdem_h5_reader *r) {
    return r ? r->version : 0;
}

cdem_status cdem_h5_reader_params(const cdem_h5_reader *r, cdem_params *p, cdem_error *err) {
    if (!r || !p)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_h5_reader_params: bad arguments");
    cdem_params_defaults(p);
    hid_t ds = H5Dopen2(r->file, "parameters", H5P_DEFAULT);
    if (ds < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /parameters is missing or corrupt",
                      r->path);
    size_t count = 0;
    const cdem_param_def *table = cdem_params_table(&count);
    cdem_status st = CDEM_OK;
    for (size_t i = 0; i < count && st == CDEM_OK; i++) {
        char key[128];
        snprintf(key, sizeof key, "%s.%s", table[i].section, table[i].key);
        char *value = NULL;
        int rc = h5i_get_str_attr(ds, key, &value);
        if (rc < 0) {
            st = H5FAIL(err, CDEM_ERR_FORMAT,
                        "%s: attribute /parameters %s is not a readable string", r->path, key);
        } else if (rc == 0) {
            size_t len = strlen(key) + strlen(value) + 2;
            char *assign = malloc(len);
            if (!assign) {
                st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory");
            } else {
                snprintf(assign, len, "%s=%s", key, value);
                st = cdem_params_override(p, assign, err);
                if (st != CDEM_OK)
                    cdem_error_prefix(err, "%s: stored parameter /parameters %s", r->path, key);
                free(assign);
            }
        }
        free(value);
    }
    /* the boundary actors after the first (h5_create.c): boundary.2, boundary.3, ... */
    for (int n = 2; n <= CDEM_BOUNDARY_ACTORS && st == CDEM_OK; n++) {
        char key[32];
        snprintf(key, sizeof key, "boundary.%d", n);
        char *value = NULL;
        const int rc = h5i_get_str_attr(ds, key, &value);
        if (rc < 0)
            st = H5FAIL(err, CDEM_ERR_FORMAT,
                        "%s: attribute /parameters %s is not a readable string", r->path, key);
        else if (rc == 0) {
            char where[CDEM_PATH_MAX + 64];
            snprintf(where, sizeof where, "%s: stored parameters", r->path);
            st = cdem_params_set_actor_keys(p, n, value, where, err);
        }
        free(value);
        if (rc > 0)
            break;
    }
    H5Dclose(ds);
    return st;
}
