/* outfile: an output file that appears complete or not at all. A writer writes to
 * "<path>.tmp" (cdem_outfile_begin gives that name), then cdem_outfile_end renames it over
 * <path> on success (after fsync) or removes it on failure, so an error, a full disk or a
 * kill never leaves a truncated file under the name the user asked for.
 * cdem_outfile_begin also checks up front that <path> is not a folder and that its folder
 * exists and is writable, so an unwritable destination is reported before any work.
 * Ownership: a cdem_outfile is a plain value holding the two paths; no heap memory.
 * Thread safety: one handle per writer; no shared state. Units: none. */
#ifndef CDEM_OUTFILE_H
#define CDEM_OUTFILE_H

#include "cdem_error.h"

#include <stdio.h>

#define CDEM_OUTFILE_PATH_MAX 4096

typedef struct {
    char path[CDEM_OUTFILE_PATH_MAX];    /* final path as given by the caller */
    char tmp[CDEM_OUTFILE_PATH_MAX + 8]; /* path + ".tmp": where the writer writes */
    int active;                          /* 1 between begin and end/discard */
} cdem_outfile;

/* Prepares writing path through o->tmp. Fails with CDEM_ERR_INVALID (empty or too long
 * path) or CDEM_ERR_IO (path is a folder; its folder is missing or not writable), the
 * message naming path. Removes a stale o->tmp left by an earlier crash. */
cdem_status cdem_outfile_begin(cdem_outfile *o, const char *path, cdem_error *err);

/* Ends the write: when st is CDEM_OK, flushes o->tmp to disk and renames it over o->path
 * (CDEM_ERR_IO naming both paths if that fails, o->tmp then removed); otherwise removes
 * o->tmp and returns st unchanged (err keeps the writer's message). */
cdem_status cdem_outfile_end(cdem_outfile *o, cdem_status st, cdem_error *err);

/* Creates the folder dir and any missing parents (mkdir -p), for outputs that are a folder
 * of files (SSPX export, picture albums). An existing folder is fine; an existing file of
 * that name, or a parent that cannot be created, fails with CDEM_ERR_IO naming it. */
cdem_status cdem_outfile_make_dirs(const char *dir, cdem_error *err);

/* The folder part of path into buf: everything before the last '/', "/" for a file at the
 * root, "." when path has no '/'. The one definition for every module that checks, syncs or
 * measures the folder an output goes to. */
void cdem_outfile_folder_of(const char *path, char *buf, size_t cap);

/* A text output through o: cdem_outfile_begin, then o->tmp opened for writing into *f.
 * On failure (the message names o->tmp) nothing is left behind and *f is NULL. */
cdem_status cdem_outfile_open_text(cdem_outfile *o, const char *path, FILE **f, cdem_error *err);

/* Closes f (from cdem_outfile_open_text) and ends the write as cdem_outfile_end does; a
 * write error (ferror or fclose) turns CDEM_OK into CDEM_ERR_IO naming o->tmp. */
cdem_status cdem_outfile_close_text(cdem_outfile *o, FILE *f, cdem_status st, cdem_error *err);

/* Removes o->tmp if the write is still active; o may be NULL. */
void cdem_outfile_discard(cdem_outfile *o);

#endif
