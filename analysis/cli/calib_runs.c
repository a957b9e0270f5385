/* calib_runs: see calib_runs.h. */
#include "calib_runs.h"

#include "h5format.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* A run that fails this often (a resume, then a fresh start) fails the calibration. */
#define CALIB_MAX_ATTEMPTS 2
/* How often a file another writer holds is looked at again (seconds). */
#define CALIB_WAIT_SECONDS 2

static int executable(const char *path) {
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode) && access(path, X_OK) == 0;
}

void cdem_calib_self(char *path, size_t cap) {
    ssize_t n = readlink("/proc/self/exe", path, cap - 1);
    if (n <= 0) {
        snprintf(path, cap, "cdem-strain");
        return;
    }
    path[n] = '\0';
}

cdem_status cdem_calib_find_cdem_run(const char *given, char *path, size_t cap, cdem_error *err) {
    if (given) {
        if (!executable(given))
            return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                             "--cdem-run %s: not an executable file (give the cdem-run program)",
                             given);
        snprintf(path, cap, "%s", given);
        return CDEM_OK;
    }
    char self[CDEM_CALIB_PATH_MAX];
    cdem_calib_self(self, sizeof self);
    char *slash = strrchr(self, '/');
    if (slash) {
        snprintf(path, cap, "%.*s/cdem-run", (int)(slash - self), self);
        if (executable(path))
            return CDEM_OK;
    }
    const char *env = getenv("PATH");
    for (const char *p = env; p && *p;) {
        const char *e = strchr(p, ':');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        snprintf(path, cap, "%.*s/cdem-run", (int)len, len ? p : ".");
        if (executable(path))
            return CDEM_OK;
        p = e ? e + 1 : p + len;
    }
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                     "cdem-run not found: neither next to this program (%s) nor on PATH; give "
                     "it with --cdem-run PATH",
                     self);
}

void cdem_calib_file_state(const char *path, char *reason, size_t cap, int *alive) {
    reason[0] = '\0';
    *alive = 0;
    cdem_h5_reader *r = NULL;
    cdem_error err;
    if (access(path, F_OK) != 0 || cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        return;
    snprintf(reason, cap, "%s", cdem_h5_reader_stop_reason(r));
    if (!reason[0])
        snprintf(reason, cap, "running");
    *alive = cdem_h5_reader_writer_alive(r);
    cdem_h5_reader_close(r);
}

/* What a run needs. */
typedef enum { NEED_NOTHING, NEED_FRESH, NEED_RESUME, NEED_WAIT, NEED_FAILED } calib_need;

static calib_need need_of(const cdem_calib_run *run, int attempts, char *reason, size_t cap) {
    int alive;
    cdem_calib_file_state(run->path, reason, cap, &alive);
    if (!strcmp(reason, "completed"))
        return NEED_NOTHING;
    if (attempts >= CALIB_MAX_ATTEMPTS)
        return NEED_FAILED;
    if (!reason[0])
        return NEED_FRESH; /* not written yet, or killed before its first write */
    if (!strcmp(reason, "running") && alive == 1)
        return NEED_WAIT;
    if (!strcmp(reason, "interrupted") || !strcmp(reason, "running"))
        return attempts == 0 ? NEED_RESUME : NEED_FRESH;
    return NEED_FAILED; /* numerical-failure, write-failure, error, stopped-early */
}

/* The last line of a run's log, for messages ("" when none). */
static void log_tail(const char *dir, const char *name, char *out, size_t cap) {
    char path[CDEM_CALIB_PATH_MAX + 300];
    snprintf(path, sizeof path, "%s/%s.log", dir, name);
    out[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    char line[512];
    while (fgets(line, sizeof line, f))
        if (line[0] != '\n')
            snprintf(out, cap, "%s", line);
    fclose(f);
    out[strcspn(out, "\n")] = '\0';
}

/* Starts one cdem-run: a fresh run (--force: a file left by a killed writer is replaced) or
 * a resume. Returns the child's pid, or -1 with err set. */
static pid_t start_local(const cdem_calib_runner *r, const cdem_calib_run *run, int resume,
                         cdem_error *err) {
    char logpath[CDEM_CALIB_PATH_MAX + 300];
    snprintf(logpath, sizeof logpath, "%s/%s.log", r->dir, run->name);
    const char *argv[8 + 2 * (4 + CDEM_CALIB_MAX_SETS)];
    int a = 0;
    argv[a++] = r->cdem_run;
    argv[a++] = "-q";
    if (resume) {
        argv[a++] = "--resume";
        argv[a++] = run->path;
    } else {
        argv[a++] = "--force";
        argv[a++] = r->model;
        for (int k = 0; k < run->n_sets; k++) {
            argv[a++] = "-s";
            argv[a++] = run->sets[k];
        }
        for (size_t k = 0; k < r->n_sets && k < CDEM_CALIB_MAX_SETS; k++) {
            argv[a++] = "-s";
            argv[a++] = r->sets[k];
        }
        argv[a++] = "-o";
        argv[a++] = run->path;
    }
    argv[a] = NULL;
    if (!resume) {
        /* a file left unreadable (killed before its first write) is ours to replace:
         * cdem-run --force replaces only a cdem file */
        unlink(run->path);
    }
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        CDEM_FAIL(err, CDEM_ERR_IO, "cannot start %s for %s: %s", r->cdem_run, run->path,
                  strerror(errno));
        return -1;
    }
    if (pid == 0) {
        /* the child: SIGTERM when calibrate dies (the run then stops cleanly, resumable) */
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        int fd = open(logpath, O_WRONLY | O_CREAT | O_APPEND, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
            close(fd);
        }
        if (r->nice > 0 && nice(r->nice) == -1 && errno)
            _exit(126);
        if (!getenv("OMP_NUM_THREADS")) {
            long cores = sysconf(_SC_NPROCESSORS_ONLN);
            char t[24];
            snprintf(t, sizeof t, "%ld", cores / r->jobs > 1 ? cores / r->jobs : 1);
            setenv("OMP_NUM_THREADS", t, 1);
        }
        setenv("OMP_WAIT_POLICY", "passive", 0);
        execv(r->cdem_run, (char *const *)argv);
        fprintf(stderr, "cannot run %s: %s\n", r->cdem_run, strerror(errno));
        _exit(127);
    }
    return pid;
}

/* Runs the to-do list locally, at most r->jobs at a time. */
static cdem_status run_local(const cdem_calib_runner *r, cdem_calib_run *runs, const size_t *todo,
                             const int *resume, size_t m, cdem_error *err) {
    size_t next = 0, active = 0;
    cdem_status st = CDEM_OK;
    while (next < m || active > 0) {
        while (st == CDEM_OK && next < m && active < (size_t)r->jobs) {
            cdem_calib_run *run = &runs[todo[next]];
            if (r->progress)
                fprintf(r->progress, "  %s %s\n", resume[next] ? "resuming" : "running", run->name);
            if (start_local(r, run, resume[next], err) < 0)
                st = CDEM_ERR_IO;
            else
                active++;
            next++;
        }
        if (active == 0)
            break;
        int status;
        pid_t w = wait(&status);
        if (w < 0) {
            if (errno == EINTR)
                continue;
            break;
        }
        active--;
    }
    return st;
}

/* Runs the to-do list as one Slurm job array through the sweep script. */
static cdem_status run_slurm(const cdem_calib_runner *r, cdem_calib_run *runs, const size_t *todo,
                             size_t m, int round, cdem_error *err) {
    char params[CDEM_CALIB_PATH_MAX + 64];
    snprintf(params, sizeof params, "%s/slurm-params-%d.txt", r->dir, round);
    FILE *f = fopen(params, "w");
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s: %s", params, strerror(errno));
    fprintf(f, "# runs of cdem-strain calibrate for %s (one line per array task)\n",
            r->slurm_script);
    for (size_t i = 0; i < m; i++) {
        cdem_calib_run *run = &runs[todo[i]];
        fprintf(f, "%s", run->name);
        for (int k = 0; k < run->n_sets; k++)
            fprintf(f, " -s %s", run->sets[k]);
        fprintf(f, "\n");
    }
    if (fclose(f) != 0)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s", params);
    char args[CDEM_CALIB_MAX_SETS * 100] = "";
    for (size_t k = 0; k < r->n_sets; k++) {
        size_t len = strlen(args);
        snprintf(args + len, sizeof args - len, "%s-s %s", len ? " " : "", r->sets[k]);
    }
    char array[64];
    snprintf(array, sizeof array, "--array=0-%zu", m - 1);
    if (r->progress)
        fprintf(r->progress, "  sbatch --wait %s %s (%zu runs, %s)\n", array, r->slurm_script, m,
                params);
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot start sbatch: %s", strerror(errno));
    if (pid == 0) {
        setenv("MODEL", r->model, 1);
        setenv("PARAMS", params, 1);
        setenv("OUT", r->dir, 1);
        setenv("ARGS", args, 1);
        setenv("CDEM_RUN", r->cdem_run, 1);
        setenv("CDEM_STRAIN", r->cdem_strain, 1);
        char out[CDEM_CALIB_PATH_MAX + 64];
        snprintf(out, sizeof out, "--output=%s/slurm-%%A_%%a.out", r->dir);
        execlp("sbatch", "sbatch", "--wait", array, out, r->slurm_script, (char *)NULL);
        fprintf(stderr, "cannot run sbatch: %s\n", strerror(errno));
        _exit(127);
    }
    int status;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "--slurm %s: sbatch not found on PATH (Slurm's client must be "
                         "installed where calibrate runs)",
                         r->slurm_script);
    return CDEM_OK; /* a failed task shows in its file's stop reason */
}

cdem_status cdem_calib_complete(const cdem_calib_runner *r, cdem_calib_run *runs, size_t n,
                                size_t *n_ran, cdem_error *err) {
    int *attempts = calloc(n ? n : 1, sizeof *attempts);
    size_t *todo = malloc((n ? n : 1) * sizeof *todo);
    int *resume = malloc((n ? n : 1) * sizeof *resume);
    if (!attempts || !todo || !resume) {
        free(attempts);
        free(todo);
        free(resume);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "no memory for %zu runs", n);
    }
    cdem_status st = CDEM_OK;
    *n_ran = 0;
    for (int round = 0; st == CDEM_OK; round++) {
        size_t m = 0, waiting = 0;
        for (size_t i = 0; i < n && st == CDEM_OK; i++) {
            char reason[64];
            calib_need need = need_of(&runs[i], attempts[i], reason, sizeof reason);
            if (need == NEED_FAILED) {
                char tail[512];
                log_tail(r->dir, runs[i].name, tail, sizeof tail);
                st = CDEM_FAIL(err, CDEM_ERR_NUMERIC,
                               "%s did not complete (stop reason: %s)%s%s; see %s/%s.log",
                               runs[i].path, reason[0] ? reason : "no file written",
                               tail[0] ? ": " : "", tail, r->dir, runs[i].name);
            } else if (need == NEED_WAIT) {
                waiting++;
            } else if (need != NEED_NOTHING) {
                todo[m] = i;
                resume[m] = need == NEED_RESUME && !r->slurm_script;
                attempts[i]++;
                m++;
            }
        }
        if (st != CDEM_OK)
            break;
        if (m == 0 && waiting == 0)
            break;
        if (m == 0) {
            if (round == 0 && r->progress)
                fprintf(r->progress, "  waiting for %zu runs another process is writing\n",
                        waiting);
            struct timespec ts = {CALIB_WAIT_SECONDS, 0};
            nanosleep(&ts, NULL);
            continue;
        }
        st = r->slurm_script ? run_slurm(r, runs, todo, m, round, err)
                             : run_local(r, runs, todo, resume, m, err);
    }
    /* each run once, however many rounds it took (a run killed and resumed was counted
     * twice: "2 runs, 3 run now", issue 46, item 13d) */
    for (size_t i = 0; i < n; i++)
        *n_ran += attempts[i] > 0;
    free(attempts);
    free(todo);
    free(resume);
    return st;
}

void cdem_calib_count_text(size_t n_runs, size_t n_ran, char *buf, size_t cap) {
    if (n_ran > n_runs)
        n_ran = n_runs;
    const char *runs = n_runs == 1 ? "run" : "runs";
    if (n_ran == 0)
        snprintf(buf, cap, "%zu %s, none run now", n_runs, runs);
    else if (n_ran == n_runs)
        snprintf(buf, cap, "%zu %s, %s run now", n_runs, runs, n_runs == 1 ? "it was" : "all");
    else
        snprintf(buf, cap, "%zu %s, %zu of them run now", n_runs, runs, n_ran);
}
