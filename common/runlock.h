/* runlock: the exclusive lock a writer holds on a run file for its whole life, so that two
 * processes never write the same output (docs/reliability.md, "One writer per file").
 *
 * Design: the lock is an open-file-description write lock (fcntl F_OFD_SETLK) on a small
 * companion file PATH.lock, which holds one line naming the holder ("cdem-run pid 1234,
 * started 2026-11-25T16:40:00Z on host"). Why so:
 *  - a lock file, not the HDF5 file: the run file does not exist yet when the lock is
 *    needed (it is built as PATH.creating and renamed), and the refused process must be able
 *    to name the holder, which an OFD lock does not report (F_OFD_GETLK gives no pid);
 *  - OFD locks, not POSIX record locks: a POSIX lock is dropped when the process closes any
 *    descriptor of the file, which any open-and-close of it elsewhere in the process would
 *    do; an OFD lock lives as long as its own descriptor. They do not interact with the
 *    flock() that HDF5 takes on the HDF5 file itself;
 *  - the kernel releases the lock when its holder dies, so a killed run never leaves a stale
 *    lock, only a stale PATH.lock file that the next holder reuses (and that readers ignore:
 *    a lock file that nobody holds means "no live writer").
 * A reader asks cdem_runlock_probe whether a writer is alive (common/h5/h5_reader.c opens a file
 * whose writer is alive in SWMR-read mode, a finished or abandoned one as a complete file).
 * Filesystems without lock support (ENOLCK, EINVAL: some network mounts) give a handle that
 * locks nothing (cdem_runlock_effective returns 0) rather than refusing to run.
 * Ownership: cdem_runlock_release removes the lock file and frees the handle (NULL allowed).
 * Thread safety: one handle per thread; no shared state. */
#ifndef CDEM_RUNLOCK_H
#define CDEM_RUNLOCK_H

#include "cdem_error.h"

#include <stddef.h>

typedef struct cdem_runlock cdem_runlock;

/* How long a refused writer waits for the holder's line before it refuses without naming the
 * holder, in milliseconds. The holder writes the line right after it takes the lock, but a
 * virtual machine's vCPU can stall it: 200 ms was once not enough (tests/test_run_output,
 * 2026-11-27). */
#define CDEM_RUNLOCK_NAME_WAIT_MS 2000

/* Takes the lock of the run file path (the lock file is path + ".lock"), recording program,
 * this process's id, the time and the host in it. Fails without waiting for the lock, with
 * CDEM_ERR_CONFLICT when another process (or another handle of this one) holds it, the
 * message naming path and the holder (when the holder has not yet written its line, it waits
 * for the line, up to CDEM_RUNLOCK_NAME_WAIT_MS); with CDEM_ERR_IO when the lock file cannot be
 * made (its folder missing or not writable: the message says which). */
cdem_status cdem_runlock_acquire(const char *path, const char *program, cdem_runlock **out,
                                 cdem_error *err);

/* Releases the lock and removes the lock file; l may be NULL. */
void cdem_runlock_release(cdem_runlock *l);

/* 1 when the lock really protects the file, 0 when the filesystem offers no locks. */
int cdem_runlock_effective(const cdem_runlock *l);

/* Is a writer of path alive? 1: the lock is held (holder, when not NULL, receives the
 * holder's line, e.g. "cdem-run pid 1234, started ... on host"); 0: no lock file or nobody
 * holds it; -1: cannot tell (the lock file cannot be opened or the filesystem has no
 * locks). */
int cdem_runlock_probe(const char *path, char *holder, size_t holder_cap);

/* CDEM_ERR_CONFLICT, with the message cdem_runlock_acquire would give, when a writer of path
 * is alive; CDEM_OK otherwise (also when it cannot tell). Takes no lock: for refusing early,
 * before the lock is taken for real. */
cdem_status cdem_runlock_check(const char *path, cdem_error *err);

/* The lock file's path for path (path + ".lock") into buf; 0, or -1 when it does not fit. */
int cdem_runlock_path(const char *path, char *buf, size_t cap);

#endif
