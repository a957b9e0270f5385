/* threads: see threads.h. */
#include "threads.h"

#include <errno.h>
#include <stdlib.h>
#include <unistd.h>

void cdem_threads_settle_wait_policy(char **argv) {
    if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT") || getenv("CDEM_NO_REEXEC"))
        return;
    if (setenv("OMP_WAIT_POLICY", CDEM_WAIT_POLICY, 1) != 0)
        return;
    execv("/proc/self/exe", argv);
    /* not reached unless exec failed: go on with libgomp's defaults; the variable set above
     * is harmless (libgomp has read its environment already) */
}

int cdem_threads_parse(const char *text, int *n) {
    char *end = NULL;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno || text[0] == '+' || v < 1 || v > CDEM_THREADS_MAX)
        return -1;
    *n = (int)v;
    return 0;
}
