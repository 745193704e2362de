/* Progress output: a line at every 10% when not on a terminal, a redrawn bar with rate and ETA,
 * nothing when quiet. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <cmocka.h>

#include "core/progress.h"

static int count(const char *s, const char *what)
{
    int n = 0;
    for (const char *p = s; (p = strstr(p, what)); p += strlen(what))
        n++;
    return n;
}

static void test_lines_every_tenth(void **state)
{
    (void)state;
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    progress p;
    progress_begin_on(&p, out, PROGRESS_LINES, "deposit", 1000, "steps");
    for (int i = 1; i <= 1000; i++)
        progress_update(&p, i);
    progress_end(&p);
    fclose(out);
    /* 10%..90% once each, then the closing line (100% is the closing line). */
    assert_int_equal(count(buf, "\n"), 10);
    for (int t = 10; t <= 90; t += 10) {
        char mark[64];
        snprintf(mark, sizeof mark, "deposit: %3d%% (%d/1000 steps)", t, t * 10);
        assert_non_null(strstr(buf, mark));
    }
    assert_non_null(strstr(buf, "ETA"));
    assert_non_null(strstr(buf, "deposit: done, 1000 steps in"));
    assert_null(strchr(buf, '\r'));
    free(buf);
}

static void test_bar_redraws(void **state)
{
    (void)state;
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    progress p;
    progress_begin_on(&p, out, PROGRESS_BAR, "run", 10, "steps");
    struct timespec pause = {0, 120 * 1000 * 1000}; /* bars are redrawn at most every 0.1 s */
    for (int i = 1; i <= 3; i++) {
        nanosleep(&pause, NULL);
        progress_update(&p, i);
    }
    progress_end(&p);
    fclose(out);
    assert_int_equal(count(buf, "\rrun ["), 3);
    assert_non_null(strstr(buf, " 30.0%"));
    assert_non_null(strstr(buf, "steps/s ETA"));
    assert_non_null(strstr(buf, "run: done, 3 steps in"));
    free(buf);
}

static void test_quiet_prints_nothing(void **state)
{
    (void)state;
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    progress p;
    progress_begin_on(&p, out, PROGRESS_QUIET, "run", 10, "steps");
    for (int i = 1; i <= 10; i++)
        progress_update(&p, i);
    progress_end(&p);
    fclose(out);
    assert_int_equal(len, 0);
    free(buf);
}

static void test_unknown_total(void **state)
{
    (void)state;
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    progress p;
    progress_begin_on(&p, out, PROGRESS_LINES, "relax", 0, "steps");
    for (int i = 1; i <= 100; i++)
        progress_update(&p, i); /* no 10% marks without a total; lines only every 30 s */
    progress_end(&p);
    fclose(out);
    assert_int_equal(count(buf, "\n"), 1);
    assert_non_null(strstr(buf, "relax: done, 100 steps"));
    free(buf);
}

/* An unasked reporter says nothing before its delay, and nothing at all for work that ended
 * within it; once the delay has passed (simulated by moving the start back) it reports at once. */
static void test_delay(void **state)
{
    (void)state;
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    progress p;
    progress_begin_on(&p, out, PROGRESS_LINES, "quick", 1000, "steps");
    p.delay = 1000;
    for (int i = 1; i <= 1000; i++)
        progress_update(&p, i);
    progress_end(&p);
    fflush(out);
    assert_int_equal(len, 0);

    progress_begin_on(&p, out, PROGRESS_LINES, "slow", 1000, "steps");
    p.delay = 1000;
    for (int i = 1; i <= 350; i++)
        progress_update(&p, i);
    fflush(out);
    assert_int_equal(len, 0);
    p.t_start -= 2000; /* the delay is over */
    progress_update(&p, 351);
    fflush(out);
    assert_non_null(strstr(buf, "slow:  35% (351/1000 steps)"));
    for (int i = 352; i <= 1000; i++)
        progress_update(&p, i);
    progress_end(&p);
    fclose(out);
    assert_int_equal(count(buf, "\n"), 8); /* 35%, 40..90%, done */
    assert_non_null(strstr(buf, "slow: done, 1000 steps in"));
    free(buf);
}

/* A run advancing in chunks counts from base; the closing line of work ended early says where. */
static void test_base_and_early_end(void **state)
{
    (void)state;
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    progress p;
    progress_begin_on(&p, out, PROGRESS_LINES, "dem run", 1000, "steps");
    p.base = 400;
    progress_update(&p, 20);
    assert_true(p.done == 420);
    progress_end_early(&p, "interrupted");
    progress_begin_on(&p, out, PROGRESS_LINES, "sweep", 50, "cases");
    progress_update(&p, 7);
    progress_end_early(&p, "stopped");
    progress_end(&p); /* already closed: nothing more */
    fclose(out);
    assert_non_null(strstr(buf, "dem run: interrupted at step 420 of 1000 after 0:00\n"));
    assert_non_null(strstr(buf, "sweep: stopped at 7 of 50 cases after 0:00\n"));
    assert_null(strstr(buf, "done"));
    /* an inactive reporter still counts (runs read the steps taken from it) */
    memset(&p, 0, sizeof p);
    p.base = 5;
    progress_update(&p, 3);
    assert_true(p.done == 8);
    free(buf);
}

static void test_durations(void **state)
{
    (void)state;
    char buf[32];
    progress_format_duration(buf, sizeof buf, 3723);
    assert_string_equal(buf, "1:02:03");
    progress_format_duration(buf, sizeof buf, 65.4);
    assert_string_equal(buf, "1:05");
    progress_format_duration(buf, sizeof buf, -1);
    assert_string_equal(buf, "--:--");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lines_every_tenth), cmocka_unit_test(test_bar_redraws),
        cmocka_unit_test(test_quiet_prints_nothing), cmocka_unit_test(test_unknown_total),
        cmocka_unit_test(test_durations), cmocka_unit_test(test_delay),
        cmocka_unit_test(test_base_and_early_end),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
