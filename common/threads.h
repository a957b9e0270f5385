/* threads: how cdem-c's programs wait for their OpenMP threads, and how many they use.
 *
 * libgomp's default wait policy keeps an idle thread spinning for 300,000 iterations
 * (tenths of a millisecond) before it sleeps. On an idle machine that makes a barrier cost
 * well under a microsecond. But when another process keeps a core busy, the thread our
 * barrier waits for is descheduled, and its partner spins away the time slice it could
 * have given it: on 2 cores with one competitor, a 2-thread cdem-run took 4.2x the 1-thread
 * time (docs/performance.md, "Threads on a busy machine"). OMP_WAIT_POLICY=passive (sleep
 * at once) fixes that but costs a futex wake-up (~40 us on a VM) at every parallel region,
 * which takes away the idle machine's speed-up.
 *
 * cdem_threads_settle_wait_policy gives the programs a short spin instead: GOMP_SPINCOUNT
 * = CDEM_SPIN_COUNT (a few tens of microseconds of spinning, then sleep). It covers the
 * load imbalance of a step on an idle machine and gives the core away soon on a busy one.
 * libgomp reads its environment before main runs, so the only way to change it is to set
 * the variable and execute the program again (once: the new process finds it set). A user's
 * own OMP_WAIT_POLICY or GOMP_SPINCOUNT is always honoured, and so is CDEM_NO_REEXEC=1
 * (for tools that follow a process, such as valgrind without --trace-children). Results do
 * not depend on any of this: the solver is bit-identical for every thread count.
 *
 * cdem_threads_parse reads the --threads N option's value (1..CDEM_THREADS_MAX); the
 * caller then calls omp_set_num_threads. Without --threads, OMP_NUM_THREADS applies.
 * Ownership: no state; the environment is the process's. Thread safety: call from main
 * before any thread starts. */
#ifndef CDEM_THREADS_H
#define CDEM_THREADS_H

/* Spin iterations before an idle libgomp thread sleeps (libgomp's default: 300,000). */
#define CDEM_SPIN_COUNT  "10000"
#define CDEM_THREADS_MAX 1024 /* the --threads messages say 1024 */

/* When neither OMP_WAIT_POLICY, GOMP_SPINCOUNT nor CDEM_NO_REEXEC is set: sets
 * GOMP_SPINCOUNT = CDEM_SPIN_COUNT and re-executes the program (/proc/self/exe) with argv.
 * Returns only when nothing was to be done or the re-execution failed (the program then
 * runs with libgomp's defaults). */
void cdem_threads_settle_wait_policy(char **argv);

/* Parses text as a thread count 1..CDEM_THREADS_MAX into *n; 0 on success, -1 when it is
 * not one. */
int cdem_threads_parse(const char *text, int *n);

#endif
