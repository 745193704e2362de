/* The REPL as a user meets it: grainlab runs on a pseudo-terminal (forkpty), the test types
 * lines, Tab, Ctrl-C and Ctrl-D, and reads the screen. Covers expression printing, multi-line
 * input, error recovery, Ctrl-C in a running loop and at the prompt, tab completion, help, and
 * the history file (written, and read back by the next session). */
#define _DEFAULT_SOURCE
#include <errno.h>
#include <poll.h>
#include <pty.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <cmocka.h>

typedef struct session {
    pid_t pid;
    int fd;
    char out[1 << 16]; /* screen output, terminal escape sequences removed */
    size_t len, mark;  /* mark: where the next expect() starts looking */
} session;

static char tmpdir[64];
static char history[128];

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int wait_prompt(session *s);

static void start(session *s)
{
    memset(s, 0, sizeof *s);
    struct winsize ws = {.ws_row = 40, .ws_col = 120};
    s->pid = forkpty(&s->fd, NULL, NULL, &ws);
    assert_true(s->pid >= 0);
    if (s->pid == 0) {
        setenv("GRAINLAB_HISTORY", history, 1);
        setenv("HOME", tmpdir, 1);
        setenv("TERM", "xterm", 1);
        setenv("GRAINLAB_PROGRESS_DELAY", "0", 1); /* unasked progress from the first step */
        unsetenv("INPUTRC");
        execl(GRAINLAB_EXE, "grainlab", (char *)NULL);
        _exit(127);
    }
    assert_true(wait_prompt(s));
}

/* Appends what the terminal shows, dropping CSI escape sequences (ESC [ ... final byte). */
static void pump(session *s, int timeout_ms)
{
    struct pollfd p = {.fd = s->fd, .events = POLLIN};
    if (poll(&p, 1, timeout_ms) <= 0)
        return;
    char buf[4096];
    ssize_t n = read(s->fd, buf, sizeof buf);
    for (ssize_t i = 0; i < n; i++) {
        if (buf[i] == '\033' && i + 1 < n && buf[i + 1] == '[') {
            i += 2;
            while (i < n && !(buf[i] >= 0x40 && buf[i] <= 0x7e))
                i++;
            continue;
        }
        if (s->len + 1 < sizeof s->out)
            s->out[s->len++] = buf[i];
    }
    s->out[s->len] = '\0';
}

/* Waits until `text` appears after the mark, then moves the mark past it. */
static int expect(session *s, const char *text)
{
    double deadline = now() + 10;
    while (now() < deadline) {
        char *hit = strstr(s->out + s->mark, text);
        if (hit) {
            s->mark = (size_t)(hit - s->out) + strlen(text);
            return 1;
        }
        pump(s, 50);
    }
    fprintf(stderr, "expected %s\n--- screen since mark ---\n%s\n---\n", text, s->out + s->mark);
    return 0;
}

/* Waits until the screen ends with the primary prompt: keys typed while readline is between
 * lines would meet a terminal in cooked mode, where a lone Ctrl-D is swallowed. */
static int wait_prompt(session *s)
{
    double deadline = now() + 10;
    while (now() < deadline) {
        if (s->len >= 2 && strcmp(s->out + s->len - 2, "> ") == 0)
            return 1;
        pump(s, 20);
    }
    return 0;
}

static void type(session *s, const char *text)
{
    size_t n = strlen(text);
    assert_int_equal(write(s->fd, text, n), (ssize_t)n);
}

/* Types `line` and Enter. */
static void enter(session *s, const char *line)
{
    type(s, line);
    type(s, "\n");
}

static int finish(session *s)
{
    wait_prompt(s);
    type(s, "\004"); /* Ctrl-D at an empty prompt */
    int status = -1;
    double deadline = now() + 10;
    while (now() < deadline) {
        pump(s, 20);
        pid_t r = waitpid(s->pid, &status, WNOHANG);
        if (r == s->pid)
            break;
    }
    close(s->fd);
    if (!WIFEXITED(status)) {
        fprintf(stderr, "grainlab did not exit; screen:\n%s\n", s->out);
        kill(s->pid, SIGKILL);
        waitpid(s->pid, &status, 0);
        return -1;
    }
    return WEXITSTATUS(status);
}

static void test_expressions_and_multiline(void **state)
{
    (void)state;
    session s;
    start(&s);
    assert_true(expect(&s, "> "));
    enter(&s, "6*7");
    assert_true(expect(&s, "42"));
    enter(&s, "'a' .. 'b', 1 + 1"); /* several results, printed through print */
    assert_true(expect(&s, "ab\t2"));
    enter(&s, "=math.max(3, 9)"); /* =expr, as in lua */
    assert_true(expect(&s, "9"));
    enter(&s, "function twice(x)");
    assert_true(expect(&s, ">> "));
    enter(&s, "return 2*x");
    assert_true(expect(&s, ">> "));
    enter(&s, "end");
    enter(&s, "twice(21.5)");
    assert_true(expect(&s, "43.0"));
    assert_int_equal(finish(&s), 0);
}

static void test_error_recovery(void **state)
{
    (void)state;
    session s;
    start(&s);
    enter(&s, "kept = 'yes'");
    enter(&s, "error('boom ' .. 6*7)");
    assert_true(expect(&s, "stdin:1: boom 42"));
    assert_true(expect(&s, "stack traceback"));
    enter(&s, "x = = 1"); /* a syntax error is not a continuation */
    assert_true(expect(&s, "unexpected symbol near '='"));
    enter(&s, "print('still ' .. kept)");
    assert_true(expect(&s, "still yes"));
    assert_int_equal(finish(&s), 0);
}

static void test_ctrl_c(void **state)
{
    (void)state;
    session s;
    start(&s);
    enter(&s, "counter = 0");
    enter(&s, "while true do counter = counter + 1 end");
    usleep(300 * 1000);
    type(&s, "\003");
    assert_true(expect(&s, "interrupted by Ctrl-C"));
    /* State survives: the loop's variable is there and has counted. */
    enter(&s, "print(counter > 1000 and 'counted' or 'no')");
    assert_true(expect(&s, "counted"));
    /* Ctrl-C at the prompt drops the line being typed and gives a fresh prompt. */
    assert_true(wait_prompt(&s));
    type(&s, "this_would_be_an_error(");
    usleep(100 * 1000);
    type(&s, "\003");
    assert_true(expect(&s, "^C"));
    enter(&s, "7*11");
    assert_true(expect(&s, "77"));
    /* ...also in the middle of a multi-line statement. */
    enter(&s, "for i = 1, 3 do");
    assert_true(expect(&s, ">> "));
    type(&s, "\003");
    assert_true(expect(&s, "^C"));
    enter(&s, "8*11");
    assert_true(expect(&s, "88"));
    assert_int_equal(finish(&s), 0);
}

/* Waits for the process to end by itself; returns its exit status (-1: it did not). */
static int wait_exit(session *s)
{
    int status = -1;
    double deadline = now() + 20;
    while (now() < deadline) {
        pump(s, 20);
        if (waitpid(s->pid, &status, WNOHANG) == s->pid) {
            pump(s, 50);
            close(s->fd);
            return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        }
    }
    fprintf(stderr, "grainlab did not exit; screen:\n%s\n", s->out);
    kill(s->pid, SIGKILL);
    waitpid(s->pid, &status, 0);
    close(s->fd);
    return -1;
}

static const char *DEM_SCENE =
    "s = dem.scene{ box = {{0, 0}, {0.01, 0.01}}, gravity = {0, -9.81} }; "
    "s:add_wall{ point = {0, 0}, normal = {0, 1} }; "
    "for i = 1, 4 do s:add_disk{ pos = {0.002 * i, 0.002}, radius = 4e-4 } end";

/* On a terminal every engine's run draws a bar with rate and ETA and closes with a done line. */
static void test_progress_bar(void **state)
{
    (void)state;
    session s;
    start(&s);
    enter(&s, DEM_SCENE);
    enter(&s, "r = s:run{ steps = 3000 }");
    assert_true(expect(&s, "dem run ["));
    assert_true(expect(&s, "steps/s ETA"));
    assert_true(expect(&s, "dem run: done, 3000 steps in"));
    enter(&s, "m = mpm.scene{ cells = {8, 8}, size = {1, 1} }; m:add_disk{ center = {0.5, 0.5}, "
              "radius = 0.2, material = mpm.material{ density = 1000, shear = 1e5, bulk = 2e5 } }");
    enter(&s, "r = m:run{ steps = 400 }");
    assert_true(expect(&s, "mpm run ["));
    assert_true(expect(&s, "mpm run: done, 400 steps in"));
    enter(&s, "g = dsmc.scene{ dim = 2, size = {0.1, 0.1}, cells = {4, 4}, radius = 1e-3 }; "
              "g:fill{ n = 50, speed = 1 }");
    enter(&s, "r = g:run{ steps = 400, dt = 1e-4, warn = false }");
    assert_true(expect(&s, "dsmc run ["));
    assert_true(expect(&s, "dsmc run: done, 400 steps in"));
    assert_int_equal(finish(&s), 0);
}

/* Ctrl-C stops the run between steps: the last line says where, the prompt comes back, the scene
 * is intact. */
static void test_ctrl_c_in_run(void **state)
{
    (void)state;
    session s;
    start(&s);
    enter(&s, DEM_SCENE);
    enter(&s, "s:run{ steps = 1000000000 }");
    assert_true(expect(&s, "dem run ["));
    usleep(200 * 1000);
    type(&s, "\003");
    assert_true(expect(&s, "dem run: interrupted at step "));
    assert_true(expect(&s, " of 1000000000 after"));
    assert_true(expect(&s, "run: interrupted at step "));
    assert_true(expect(&s, "the scene is intact"));
    enter(&s, "print(s:info().steps > 0 and 'intact' or 'no')");
    assert_true(expect(&s, "intact"));
    assert_int_equal(finish(&s), 0);
}

/* SIGTERM ends the session (unlike Ctrl-C), during a run and at the prompt, with 128 + 15. */
static void test_sigterm(void **state)
{
    (void)state;
    session s;
    start(&s);
    enter(&s, DEM_SCENE);
    enter(&s, "s:run{ steps = 1000000000 }");
    assert_true(expect(&s, "dem run ["));
    kill(s.pid, SIGTERM);
    assert_true(expect(&s, "dem run: interrupted at step "));
    assert_true(expect(&s, "grainlab: terminated (SIGTERM) at step "));
    assert_true(expect(&s, " of 1000000000 of 'dem run'; partial outputs removed"));
    assert_int_equal(wait_exit(&s), 143);

    start(&s);
    assert_true(wait_prompt(&s));
    kill(s.pid, SIGTERM);
    assert_true(expect(&s, "grainlab: terminated (SIGTERM); partial outputs removed"));
    assert_int_equal(wait_exit(&s), 143);
}

static void test_completion_and_help(void **state)
{
    (void)state;
    session s;
    start(&s);
    enter(&s, "obj = setmetatable({}, {__index = {add_disk = function() return 'disk!' end, "
              "add_wall = function() end}})");
    type(&s, "obj:add_d\t");
    assert_true(expect(&s, "obj:add_disk("));
    enter(&s, ")");
    assert_true(expect(&s, "disk!"));
    type(&s, "string.rev\t");
    assert_true(expect(&s, "string.reverse("));
    enter(&s, "'xyz')");
    assert_true(expect(&s, "zyx"));
    type(&s, "grainl\t");
    assert_true(expect(&s, "grainlab."));
    type(&s, "rep\t"); /* grainlab.report is the only field starting with rep */
    assert_true(expect(&s, "report("));
    type(&s, "\003");
    enter(&s, "help(grainlab.report)");
    assert_true(expect(&s, "Reports a scenario's figures"));
    enter(&s, "help()");
    assert_true(expect(&s, "Modules:"));
    enter(&s, "help(grainlab.pack.deposit)"); /* Lua-side functions answer help directly */
    assert_true(expect(&s, "gravity deposition"));
    enter(&s, "help('grainlab.rng')");
    assert_true(expect(&s, "grainlab.rng{ seed = 0, stream = 0 }"));
    assert_int_equal(finish(&s), 0);
}

/* Expression results that are tables print readably (grainlab.pretty); print(t) is unchanged. */
static void test_table_results(void **state)
{
    (void)state;
    session s;
    start(&s);
    enter(&s, "t = {3, 0.5, 'x', name = 'q', inner = {k = 1/0}}");
    enter(&s, "t");
    assert_true(expect(&s, "{3, 0.5, \"x\", inner = {k = inf}, name = \"q\"}"));
    enter(&s, "t.inner, 7, 'plain'"); /* several results: tab-separated, strings as print */
    assert_true(expect(&s, "{k = inf}\t7\tplain"));
    enter(&s, "long = {} for i = 1, 2000 do long[i] = i end");
    enter(&s, "long");
    assert_true(expect(&s, "{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, …(1990 more)}"));
    enter(&s, "c = {} c.me = c");
    enter(&s, "c");
    assert_true(expect(&s, "{me = <cycle>}"));
    enter(&s, "print(c == c.me and tostring(c):match('^table: ') and 'print unchanged')");
    assert_true(expect(&s, "print unchanged"));
    enter(&s, "s = dem.scene{ dim = 2, box = {{0, 0}, {0.1, 0.1}} }");
    enter(&s, "s:info()");
    assert_true(expect(&s, "box = {{0.0, 0.0}, {0.1, 0.1}},"));
    assert_true(expect(&s, "dim = 2,"));
    enter(&s, "s"); /* userdata keep their __tostring */
    assert_true(expect(&s, "dem.scene"));
    assert_int_equal(finish(&s), 0);
}

static void test_history_persists(void **state)
{
    (void)state;
    unlink(history);
    session s;
    start(&s);
    enter(&s, "history_marker = 12345");
    enter(&s, "print('marker set')");
    assert_true(expect(&s, "marker set"));
    assert_int_equal(finish(&s), 0);

    FILE *f = fopen(history, "r");
    assert_non_null(f);
    char text[4096];
    size_t n = fread(text, 1, sizeof text - 1, f);
    text[n] = '\0';
    fclose(f);
    assert_non_null(strstr(text, "history_marker = 12345\n"));

    /* The next session reads it: Up twice recalls the first line. */
    start(&s);
    assert_true(expect(&s, "> "));
    type(&s, "\033[A\033[A");
    assert_true(expect(&s, "history_marker = 12345"));
    enter(&s, "");
    enter(&s, "print(history_marker + 1)");
    assert_true(expect(&s, "12346"));
    assert_int_equal(finish(&s), 0);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/grainlab_repl_XXXXXX");
    if (!mkdtemp(tmpdir))
        return 1;
    snprintf(history, sizeof history, "%s/history", tmpdir);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_expressions_and_multiline), cmocka_unit_test(test_error_recovery),
        cmocka_unit_test(test_ctrl_c), cmocka_unit_test(test_completion_and_help),
        cmocka_unit_test(test_table_results),    cmocka_unit_test(test_history_persists),
        cmocka_unit_test(test_progress_bar),     cmocka_unit_test(test_ctrl_c_in_run),
        cmocka_unit_test(test_sigterm),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        return 1;
    return failed;
}
