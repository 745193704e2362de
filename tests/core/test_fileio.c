/* Whole-file writes leave either the complete new file or the old state, never a part, and
 * never a temporary file; errors carry the path and the reason. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "core/clock.h"
#include "core/error.h"
#include "core/fileio.h"

static char dir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/grainlab_fileio_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd);
}

static int entries(void)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        n += e->d_name[0] != '.';
    closedir(d);
    return n;
}

static char *slurp(const char *path)
{
    static char buf[256];
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static void test_write_and_replace(void **state)
{
    (void)state;
    char path[300];
    snprintf(path, sizeof path, "%s/out.json", dir);
    core_error err;
    assert_int_equal(atomic_write(path, "first version, longer", 21, &err), CORE_OK);
    assert_string_equal(slurp(path), "first version, longer");
    assert_int_equal(atomic_write(path, "second", 6, &err), CORE_OK);
    assert_string_equal(slurp(path), "second");
    assert_int_equal(entries(), 1); /* no temporary file left */
}

static void test_unwritable_directory(void **state)
{
    (void)state;
    char path[300];
    snprintf(path, sizeof path, "%s/no/such/dir/out.json", dir);
    core_error err;
    assert_int_equal(atomic_write(path, "x", 1, &err), CORE_ERR_IO);
    assert_non_null(strstr(err.msg, "cannot write"));
    assert_non_null(strstr(err.msg, "no/such/dir/out.json"));
    assert_non_null(strstr(err.msg, "No such file or directory"));
    assert_int_equal(entries(), 0);
}

static void test_abort_leaves_old_file(void **state)
{
    (void)state;
    char path[300];
    snprintf(path, sizeof path, "%s/frame.png", dir);
    core_error err;
    assert_int_equal(atomic_write(path, "old", 3, &err), CORE_OK);
    atomic_file f;
    assert_int_equal(atomic_open(&f, path, &err), CORE_OK);
    fputs("half of a new fi", f.fp);
    atomic_abort(&f);
    assert_string_equal(slurp(path), "old");
    assert_int_equal(entries(), 1);
}

static void test_errors(void **state)
{
    (void)state;
    core_error err;
    core_error_clear(&err);
    assert_int_equal(err.status, CORE_OK);
    assert_int_equal(core_fail(&err, CORE_ERR_ARG, "radius %g <= 0 for particle %d", -0.5, 12),
                     CORE_ERR_ARG);
    assert_string_equal(err.msg, "radius -0.5 <= 0 for particle 12");
    assert_int_equal(core_fail(NULL, CORE_ERR_UNSTABLE, "ignored"), CORE_ERR_UNSTABLE);
    assert_string_equal(core_status_name(CORE_ERR_INTERRUPTED), "interrupted");
    assert_int_equal(atomic_write("", "x", 1, &err), CORE_ERR_ARG);
}

static void test_clocks(void **state)
{
    (void)state;
    double w0 = clock_wall(), c0 = clock_cpu();
    volatile double x = 0;
    for (long i = 0; i < 20000000; i++)
        x += 1e-9 * (double)i;
    double w1 = clock_wall(), c1 = clock_cpu();
    assert_true(w1 > w0);
    assert_true(c1 > c0);
    assert_true(w1 - w0 < 60);
}

/* Writes in progress are tracked so that a process ending on SIGTERM can remove their temporary
 * files; committed and aborted ones are forgotten. */
static void test_live_temporaries(void **state)
{
    (void)state;
    char a[300], b[300];
    snprintf(a, sizeof a, "%s/a.dat", dir);
    snprintf(b, sizeof b, "%s/b.dat", dir);
    core_error err;
    atomic_file fa, fb;
    assert_int_equal(fileio_live_temporaries(), 0);
    assert_int_equal(atomic_open(&fa, a, &err), CORE_OK);
    assert_int_equal(atomic_open(&fb, b, &err), CORE_OK);
    fputs("half", fa.fp);
    assert_int_equal(fileio_live_temporaries(), 2);
    assert_int_equal(entries(), 2);
    assert_int_equal(atomic_commit(&fb, &err), CORE_OK); /* b is done: no longer tracked */
    assert_int_equal(fileio_live_temporaries(), 1);
    assert_int_equal(fileio_remove_temporaries(), 1); /* what the CLI does after SIGTERM */
    assert_int_equal(fileio_live_temporaries(), 0);
    assert_int_equal(entries(), 1); /* b.dat only */
    assert_int_equal(fileio_remove_temporaries(), 0);
    atomic_abort(&fa); /* the writer's own cleanup afterwards is harmless */
    assert_int_equal(entries(), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_write_and_replace, setup, teardown),
        cmocka_unit_test_setup_teardown(test_unwritable_directory, setup, teardown),
        cmocka_unit_test_setup_teardown(test_abort_leaves_old_file, setup, teardown),
        cmocka_unit_test_setup_teardown(test_live_temporaries, setup, teardown),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_clocks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
