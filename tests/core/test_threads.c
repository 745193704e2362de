/* The thread-count tuner of auto mode (core/threads.h), on a simulated clock: the steps of a fake
 * engine cost what a quiet or a contended 2-core machine would make them cost, and the run-queue
 * waiting grows as it would there. What is checked is what the tuner controls: on a quiet
 * machine it never probes; under contention it settles on one thread within a second of
 * simulated time; it returns to all threads within its longest interval when the contention
 * ends; it keeps all threads (probing rarely) when they stay faster in spite of some waiting; a
 * fixed count and a loop that does not take part are never touched; without the kernel's
 * waiting meter it probes on schedule. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "core/threads.h"

static double now_s, waited_s;
static double cost_all, cost_one; /* seconds per step on 2 threads and on 1 */
static double wait_frac;          /* of the threads' time spent waiting for a core */

static double fake_wall(void) { return now_s; }
static double fake_waited(void) { return waited_s; }

/* Steps for `seconds` of simulated time; returns the steps taken on one thread. */
static long run_for(double seconds)
{
    const double end = now_s + seconds;
    long one = 0;
    while (now_s < end) {
        const int n = threads_get();
        const double c = n == 1 ? cost_one : cost_all;
        now_s += c;
        waited_s += wait_frac * c * n;
        one += n == 1;
        threads_tune_step();
    }
    return one;
}

static void machine(double all, double one, double wait)
{
    cost_all = all;
    cost_one = one;
    wait_frac = wait;
}

static int setup(void **state)
{
    (void)state;
    now_s = 100;
    waited_s = 0;
    threads_tune_fake(2, fake_wall, fake_waited);
    if (threads_get() != 2) /* a build without OpenMP: nothing to tune */
        skip();
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    threads_tune_fake(0, NULL, NULL);
    return 0;
}

static void quiet_never_probes(void **state)
{
    (void)state;
    machine(1e-3, 1.8e-3, 0.001);
    threads_tune_begin(&now_s, 1);
    assert_int_equal(run_for(30), 0);
    threads_tune_end();
    threads_tune_stats st;
    threads_tune_get_stats(&st);
    assert_int_equal(st.probes, 0);
    assert_int_equal(st.steps_one, 0);
    assert_int_equal(threads_get(), 2);
}

static void contended_settles_on_one(void **state)
{
    (void)state;
    machine(4e-3, 1.1e-3, 0.5); /* the second thread shares its core: every barrier waits */
    threads_tune_begin(&now_s, 1);
    run_for(0.5);
    assert_int_equal(threads_get(), 1);
    const long steps = (long)(20 / cost_one);
    const long one = run_for(20);
    threads_tune_stats st;
    threads_tune_get_stats(&st);
    assert_int_equal(st.switches, 1);
    /* after the switch: probes of all threads every 1, 2, 4, 8, 8 s, each ~2 steps */
    assert_true(one > 0.98 * steps);
    assert_true(st.probes <= 8);
    /* between runs the count is all processors: nothing outside a run depends on timings */
    threads_tune_end();
    assert_int_equal(threads_get(), 2);
    /* the next run of the same scene keeps the choice */
    threads_tune_begin(&now_s, 1);
    assert_int_equal(threads_get(), 1);
    threads_tune_end();
}

static void returns_when_contention_ends(void **state)
{
    (void)state;
    machine(4e-3, 1.1e-3, 0.5);
    threads_tune_begin(&now_s, 1);
    run_for(5);
    assert_int_equal(threads_get(), 1);
    machine(1e-3, 1.8e-3, 0.001); /* the other process ended */
    run_for(8.5);                 /* at most the longest interval, and a window */
    assert_int_equal(threads_get(), 2);
    threads_tune_stats st0, st1;
    threads_tune_get_stats(&st0);
    run_for(30);
    threads_tune_get_stats(&st1);
    assert_int_equal(st1.probes, st0.probes); /* quiet again: no more probes */
    threads_tune_end();
}

static void mild_contention_keeps_all(void **state)
{
    (void)state;
    machine(1.2e-3, 1.8e-3, 0.2); /* waiting, but two threads stay faster */
    threads_tune_begin(&now_s, 1);
    const long one = run_for(60);
    threads_tune_stats st;
    threads_tune_get_stats(&st);
    assert_int_equal(st.switches, 0);
    assert_true(st.probes >= 3 && st.probes <= 12); /* 0.1 s, then every 1, 2, 4, 8, 8, ... s */
    assert_true(one < 0.01 * (60 / cost_all));
    assert_int_equal(threads_get(), 2);
    threads_tune_end();
}

static void fixed_and_ineligible_untouched(void **state)
{
    (void)state;
    machine(4e-3, 1.1e-3, 0.5);
    threads_tune_begin(&now_s, 0); /* a loop whose bits follow the count */
    assert_int_equal(run_for(10), 0);
    threads_tune_end();
    threads_set(2); /* --threads 2 */
    threads_tune_begin(&now_s, 1);
    assert_int_equal(run_for(10), 0);
    threads_tune_end();
    threads_tune_stats st;
    threads_tune_get_stats(&st);
    assert_int_equal(st.probes, 0);
    assert_int_equal(threads_auto(), 0);
}

static double fake_unknown(void) { return -1; }

/* Without the kernel's schedstat, probes run on schedule: contention is still found. */
static void unknown_waiting_probes_on_schedule(void **state)
{
    (void)state;
    threads_tune_fake(2, fake_wall, fake_unknown);
    machine(4e-3, 1.1e-3, 0.5);
    threads_tune_begin(&now_s, 1);
    run_for(0.5);
    assert_int_equal(threads_get(), 1);
    threads_tune_end();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(quiet_never_probes, setup, teardown),
        cmocka_unit_test_setup_teardown(contended_settles_on_one, setup, teardown),
        cmocka_unit_test_setup_teardown(returns_when_contention_ends, setup, teardown),
        cmocka_unit_test_setup_teardown(mild_contention_keeps_all, setup, teardown),
        cmocka_unit_test_setup_teardown(fixed_and_ineligible_untouched, setup, teardown),
        cmocka_unit_test_setup_teardown(unknown_waiting_probes_on_schedule, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
