/* threads: how cdem-c's programs wait for their OpenMP threads, and how many they use.
 *
 * libgomp's default wait policy keeps an idle thread spinning for 300,000 iterations
 * (tenths of a millisecond) before it sleeps. When another process keeps a core busy, the
 * thread a barrier waits for is descheduled, and its partner spins away the time slice it
 * could have given it: on this 2-core machine with one competitor, 2 threads took 2.2x the
 * 1-thread time (bench/contended.sh, docs/performance.md "Threads on a busy machine").
 *
 * cdem_threads_settle_wait_policy makes idle threads sleep at once (OMP_WAIT_POLICY =
 * passive). Measured with bench/contended.sh against libgomp's default and shorter spins
 * (GOMP_SPINCOUNT 1000, 3000, 10000): passive is the only one that keeps the busy-machine
 * slowdown within 1.15x (1.00-1.09x), and on an idle machine its 2-thread time equals the
 * default's within the noise at 8,300 and 16,700 elements (a step has few parallel regions,
 * so a thread's wake-up, tens of microseconds, is small beside it; smaller models run
 * serially, below CDEM_PAR_MIN). Short spins were worse on both counts (1.13-1.76x busy).
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

/* The wait policy the programs choose when the user has not: idle threads sleep at once. */
#define CDEM_WAIT_POLICY "passive"
#define CDEM_THREADS_MAX 1024 /* the --threads messages say 1024 */

/* When neither OMP_WAIT_POLICY, GOMP_SPINCOUNT nor CDEM_NO_REEXEC is set: sets
 * OMP_WAIT_POLICY = CDEM_WAIT_POLICY and re-executes the program (/proc/self/exe) with argv.
 * Returns only when nothing was to be done or the re-execution failed (the program then
 * runs with libgomp's defaults). */
void cdem_threads_settle_wait_policy(char **argv);

/* Parses text as a thread count 1..CDEM_THREADS_MAX into *n; 0 on success, -1 when it is
 * not one. */
int cdem_threads_parse(const char *text, int *n);

#endif
