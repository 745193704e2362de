/* Thread count: a thin layer over OpenMP so kernels and bindings never include omp.h, and the
 * tuner of auto mode (threads.h says why it exists and what it promises). */
#define _DEFAULT_SOURCE /* dirent's d_name, for /proc/self/task */
#include "core/threads.h"

#include <dirent.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/clock.h"

#ifdef GRAINLAB_HAVE_OPENMP
#include <omp.h>
static int icv_get(void) { return omp_get_max_threads(); }
static void icv_set(int n) { omp_set_num_threads(n); }
int threads_available(void) { return omp_get_num_procs(); }
#else
static int icv_get(void) { return 1; }
static void icv_set(int n) { (void)n; }
int threads_available(void) { return 1; }
#endif

#define WINDOW_S 0.1      /* a window at the chosen count */
#define PROBE_S 0.05      /* a window at the other count */
#define FIRST_PROBE_S 0.1 /* into the first tuned loop */
#define MAX_EVERY_S 8.0   /* the longest interval between probes */
#define SLOWER 1.5        /* a window this much slower than the best: probe now */
#define MARGIN 0.9        /* the probe must be this much faster to become the choice */
/* Run-queue waiting, as a fraction of the threads' time in a window, that shows another
 * process competing for our cores (a quiet machine: up to ~5 %; one busy process on one of two
 * cores: 20-50 %). */
#define WAITED 0.10

static struct {
    int ready, fixed;
    int max;      /* auto: the processors; the count probing compares with one */
    int choice;   /* auto: the count the steps use (max or 1) */
    double next;  /* wall time of the next probe (0: none scheduled yet) */
    double every; /* the interval after the next probe that confirms the choice */
    /* the current window (one loop at a time: runs are not re-entrant) */
    const void *owner;
    int on, probing;
    long steps;
    double acc, last; /* seconds of steps in the window; wall time after the last step */
    double run_s, best_s;
    double wait0; /* run-queue wait of our threads at the window's start (s), -1: unknown */
    threads_tune_stats st;
} g;

/* The tuner's clock and waiting meter (a test substitutes its own: threads_tune_fake). */
static double waited(void);
static double (*wall_fn)(void) = clock_wall;
static double (*waited_fn)(void) = waited;

static void init(void)
{
    if (g.ready)
        return;
    g.ready = 1;
    g.fixed = getenv("OMP_NUM_THREADS") != NULL; /* the user's choice: no tuning */
    g.max = g.fixed ? icv_get() : threads_available();
    if (g.max < 1)
        g.max = 1;
    g.choice = g.max;
    g.every = 1.0;
    if (!g.fixed)
        icv_set(g.max);
}

int threads_get(void)
{
    init();
    return icv_get();
}

void threads_set(int n)
{
    init();
    g.fixed = 1;
    g.max = g.choice = n > 0 ? n : 1;
    g.on = 0;
    icv_set(g.choice);
}

void threads_set_auto(void)
{
    g.ready = 1;
    g.fixed = 0;
    g.max = g.choice = threads_available() > 0 ? threads_available() : 1;
    g.next = 0;
    g.every = 1.0;
    g.on = 0;
    g.probing = 0;
    g.owner = NULL;
    icv_set(g.choice);
}

int threads_auto(void)
{
    init();
    return !g.fixed;
}

int threads_max(void)
{
    init();
    return g.max;
}

/* Seconds the process's threads have waited on a run queue (ready, another task on the core),
 * from Linux's /proc/self/task/<tid>/schedstat (run, wait, slices); -1 where there is none. */
static double waited(void)
{
    DIR *d = opendir("/proc/self/task");
    if (!d)
        return -1;
    double sum = 0;
    int found = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.')
            continue;
        char path[64];
        snprintf(path, sizeof path, "/proc/self/task/%.20s/schedstat", e->d_name);
        FILE *f = fopen(path, "r");
        if (!f)
            continue;
        unsigned long long run, wait;
        if (fscanf(f, "%llu %llu", &run, &wait) == 2) {
            sum += 1e-9 * (double)wait;
            found = 1;
        }
        fclose(f);
    }
    closedir(d);
    return found ? sum : -1;
}

void threads_tune_begin(const void *owner, int eligible)
{
    init();
    const double now = wall_fn();
    g.on = !g.fixed && g.max > 1 && eligible;
    if (!g.on) {
        if (!g.fixed)
            icv_set(g.max);
        return;
    }
    if (owner != g.owner || g.probing) { /* another scene's steps cost differently */
        g.owner = owner;
        g.probing = 0;
        g.steps = 0;
        g.acc = 0;
        g.best_s = 0;
    }
    g.wait0 = waited_fn(); /* what happened between runs is not the steps' */
    icv_set(g.choice);
    g.last = now;
    if (g.next == 0)
        g.next = now + FIRST_PROBE_S;
}

int threads_tune_step(void)
{
    if (!g.on)
        return 0;
    const int cur = icv_get();
    if (cur == 1)
        g.st.steps_one++;
    else
        g.st.steps_all++;
    const double now = wall_fn();
    g.acc += now - g.last;
    g.last = now;
    g.steps++;
    if (g.acc < (g.probing ? PROBE_S : WINDOW_S) || g.steps < 2)
        return 0;
    const double s = g.acc / (double)g.steps, win = g.acc;
    g.acc = 0;
    g.steps = 0;
    const int other = g.choice == g.max ? 1 : g.max;
    if (!g.probing) {
        g.run_s = s;
        if (g.best_s == 0 || s < g.best_s)
            g.best_s = s;
        /* On all threads, a probe is worth its cost only when our threads waited for a core
         * (another process competes) or the step slowed down; on one, the other process may have
         * gone: probe on schedule (and the waiting is not read). */
        bool competed = true;
        if (g.choice == g.max) {
            const double w = waited_fn();
            competed = w < 0 || g.wait0 < 0 || w - g.wait0 > WAITED * win * g.choice;
            g.wait0 = w;
        }
        const bool slower = s > SLOWER * g.best_s;
        if (!slower && (now < g.next || !competed))
            return 0;
        g.probing = 1;
        g.st.probes++;
        icv_set(other);
        return 1;
    }
    g.probing = 0;
    g.wait0 = waited_fn();
    if (s < MARGIN * g.run_s) { /* the other count is faster: it becomes the choice */
        g.choice = other;
        g.best_s = s;
        g.every = 1.0;
        g.st.switches++;
        g.next = now + g.every;
        return 0;
    }
    g.best_s = g.run_s; /* the choice holds: the new normal, and a longer interval */
    g.next = now + g.every;
    g.every = g.every * 2 < MAX_EVERY_S ? g.every * 2 : MAX_EVERY_S;
    icv_set(g.choice);
    return 1;
}

void threads_tune_end(void)
{
    if (!g.on)
        return;
    g.on = 0;
    icv_set(g.max);
}

void threads_tune_get_stats(threads_tune_stats *out) { *out = g.st; }

void threads_tune_fake(int processors, double (*wall)(void), double (*waiting)(void))
{
    threads_set_auto();
    g.st = (threads_tune_stats){0, 0, 0, 0};
    if (processors > 0) {
        g.max = g.choice = processors;
        icv_set(g.max);
    }
    wall_fn = wall ? wall : clock_wall;
    waited_fn = waiting ? waiting : waited;
}
