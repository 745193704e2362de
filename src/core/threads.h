/* The number of worker threads the kernels use (OpenMP when built with it, else 1), and the
 * tuner that keeps the default count from being slower than one thread on a shared machine. */
#ifndef GRAINLAB_CORE_THREADS_H
#define GRAINLAB_CORE_THREADS_H

/* The count the kernels use now (in auto mode: all processors, or inside a tuned run loop the
 * tuner's current choice). */
int threads_get(void);

/* Fixes the count at n >= 1 (values above the number of processors are allowed:
 * oversubscription); the tuner stays off until threads_set_auto. */
void threads_set(int n);

/* Auto mode (the default unless OMP_NUM_THREADS is set): all processors, and the tuner may run
 * the engines' steps on one thread while that is faster. */
void threads_set_auto(void);

/* 1 in auto mode, 0 when the count was fixed. */
int threads_auto(void);

/* The count outside the tuner's choices: in auto mode all processors (what the tuner compares
 * one thread with), else the fixed count. A decomposition that must give the same bits whatever
 * count the tuner picks is made for this many parts (the MPM noslip transfers' chunks). */
int threads_max(void);

/* Processors available to this process. */
int threads_available(void);

/* The tuner (auto mode only). On a machine where another process keeps a core busy, a step on
 * two threads can take several times as long as on one: at each of the step's barriers one
 * thread waits (spinning, so the scheduler sees both cores busy and never moves the other
 * process away) for the thread that shares its core. The engines' run loops time their steps in
 * windows of about 0.1 s. On all threads, when our threads waited on a run queue for more than
 * 10 % of their time in a window (Linux's per-thread schedstat: another process competes for the
 * cores), one window runs on one thread; on one thread, a window runs on all now and then. The
 * faster count is kept, and probed again after an interval that doubles (1 s to 8 s; the first
 * probe 0.1 s into the first tuned run) while the choice holds, or at once when a window is 1.5
 * times slower than the best at that count. On a quiet machine nothing is probed.
 * Results do not depend on it: a loop takes part only when its step gives the same bits on any
 * thread count (eligible = 0 otherwise, and for steps too small to run threaded).
 *   threads_tune_begin(scene, eligible) before a run's steps (it sets the count the steps use:
 *   the tuner's choice, or all processors for a loop that does not take part); then
 *   threads_tune_step() after each step: it returns 1 when the count changed (the loop re-reads
 *   threads_get()); threads_tune_end() after the last, on every path out (the count is all
 *   processors again, so that what runs between runs never depends on the timings). */
void threads_tune_begin(const void *owner, int eligible);
int threads_tune_step(void);
void threads_tune_end(void);

typedef struct threads_tune_stats {
    long probes;    /* windows run at the other count */
    long switches;  /* times the probe was faster and became the choice */
    long steps_one; /* steps run on one thread by the tuner's choice (auto, > 1 processor) */
    long steps_all; /* steps run on all threads */
} threads_tune_stats;
void threads_tune_get_stats(threads_tune_stats *out);

/* For tests of the tuner: auto mode on `processors` (> 0; else the machine's), with the clock
 * and the run-queue waiting (seconds, < 0: unknown) read from the given functions (NULL: the
 * real ones); the statistics restart. */
void threads_tune_fake(int processors, double (*wall)(void), double (*waiting)(void));

#endif
