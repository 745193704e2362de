/* grainlab's command line: options, name=value params, then -e chunks, a script, standard input
 * or the REPL. Exit status: 0 ok, 1 a Lua error or a failed report check, 2 bad usage, 143 ended
 * by SIGTERM. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <lauxlib.h>

#include "cli/cli.h"
#include "core/clones.h"
#include "core/comm.h"
#include "core/fileio.h"
#include "core/interrupt.h"
#include "core/progress.h"
#include "core/threads.h"
#include "lua/bind.h"

static const char *USAGE =
    "usage: grainlab [options] [FILE.lua] [name=value ...]\n"
    "\n"
    "  grainlab                    interactive REPL (standard input is run as a chunk when it is\n"
    "                              not a terminal)\n"
    "  grainlab FILE.lua a=1 b=x   run a script; the pairs arrive in the global table `params`\n"
    "                              (numbers converted, true/false as booleans, text as strings);\n"
    "                              FILE '-' reads the script from standard input\n"
    "  mpirun -np K grainlab FILE.lua\n"
    "                              run distributed: every rank runs the script (SPMD), output\n"
    "                              is written once, by rank 0 (docs/mpi.md)\n"
    "\n"
    "options:\n"
    "  -i               enter the REPL after running the script and -e chunks\n"
    "  -e CODE          run the Lua chunk CODE (repeatable; runs before the script)\n"
    "  --threads N      worker threads for the kernels (default: all processors; on a shared\n"
    "                   machine one while that is faster)\n"
    "  --quiet, -q      no progress output\n"
    "  --report FILE    also write the run's grainlab.report as JSON to FILE\n"
    "                   (environment: GRAINLAB_REPORT)\n"
    "  --version, -v    print version, libraries and the kernels' instruction set, then exit\n"
    "  --help, -h       print this help, then exit\n"
    "  --               end of options\n"
    "\n"
    "In the REPL, help() gives an overview and help(x) documents any API object.\n"
    "Exit status: 0 success, 1 Lua error or failed report check, 2 bad command line,\n"
    "143 ended by SIGTERM (the run stops between steps, unfinished output files are removed).\n";

typedef struct cli_args {
    int interactive, quiet, version, help;
    long threads;
    const char *report;
    const char *script;
    int nchunks, nparams;
    const char **chunks;
    const char **params;
} cli_args;

static int usage_error(const char *fmt, const char *what)
{
    fprintf(stderr, "grainlab: ");
    fprintf(stderr, fmt, what);
    fprintf(stderr, " (see grainlab --help)\n");
    return 2;
}

static int valid_name(const char *s, size_t len)
{
    if (len == 0 || !(isalpha((unsigned char)s[0]) || s[0] == '_'))
        return 0;
    for (size_t i = 1; i < len; i++)
        if (!(isalnum((unsigned char)s[i]) || s[i] == '_'))
            return 0;
    return 1;
}

/* Reads the value of an option given as "--opt VALUE" or "--opt=VALUE". */
static const char *option_value(int argc, char **argv, int *i, const char *name)
{
    size_t n = strlen(name);
    if (argv[*i][n] == '=')
        return argv[*i] + n + 1;
    if (*i + 1 < argc)
        return argv[++*i];
    return NULL;
}

static int parse_args(int argc, char **argv, cli_args *a)
{
    int options_done = 0;
    for (int i = 1; i < argc; i++) {
        const char *s = argv[i];
        if (options_done || s[0] != '-' || strcmp(s, "-") == 0) {
            const char *eq = strchr(s, '=');
            if (!a->script && !eq && a->nparams == 0) {
                a->script = s;
            } else if (eq) {
                if (!valid_name(s, (size_t)(eq - s)))
                    return usage_error("bad parameter '%s': the name must be a Lua identifier", s);
                a->params[a->nparams++] = s;
            } else {
                return usage_error("argument '%s' is not name=value", s);
            }
        } else if (strcmp(s, "--") == 0) {
            options_done = 1;
        } else if (strcmp(s, "-i") == 0) {
            a->interactive = 1;
        } else if (strcmp(s, "-q") == 0 || strcmp(s, "--quiet") == 0) {
            a->quiet = 1;
        } else if (strcmp(s, "-v") == 0 || strcmp(s, "--version") == 0) {
            a->version = 1;
        } else if (strcmp(s, "-h") == 0 || strcmp(s, "--help") == 0) {
            a->help = 1;
        } else if (strcmp(s, "-e") == 0) {
            if (i + 1 >= argc)
                return usage_error("%s needs a Lua chunk", "-e");
            a->chunks[a->nchunks++] = argv[++i];
        } else if (strncmp(s, "--threads", 9) == 0 && (s[9] == '\0' || s[9] == '=')) {
            const char *v = option_value(argc, argv, &i, "--threads");
            char *end;
            errno = 0;
            a->threads = v ? strtol(v, &end, 10) : 0;
            if (!v || *end || errno || a->threads < 1 || a->threads > 4096)
                return usage_error("--threads needs an integer in [1, 4096], got '%s'",
                                   v ? v : "nothing");
        } else if (strncmp(s, "--report", 8) == 0 && (s[8] == '\0' || s[8] == '=')) {
            a->report = option_value(argc, argv, &i, "--report");
            if (!a->report || !*a->report)
                return usage_error("%s needs a file name", "--report");
        } else {
            return usage_error("unknown option '%s'", s);
        }
    }
    return 0;
}

/* ---- running Lua with a traceback and Ctrl-C ---------------------------------------------- */
static lua_State *running_L;

static void stop_hook(lua_State *L, lua_Debug *ar)
{
    (void)ar;
    if (interrupt_terminating()) /* stays set: a script's pcall cannot swallow a termination */
        luaL_error(L, "terminated (SIGTERM)");
    lua_sethook(L, NULL, 0, 0);
    /* Handled: the interrupt becomes this error. Inside a run (its on_step) the run lowers the
     * flag when it stops; outside one, here, so that a later run starts clean. */
    if (bind_run_depth() == 0)
        interrupt_clear();
    luaL_error(L, "interrupted by Ctrl-C");
}

/* Only async-signal-safe work: a flag for the kernels and a hook for the Lua VM (lua.c does the
 * same). A second Ctrl-C before the first is handled (the flag still up: neither a run nor the
 * hook has turned it into an error yet) ends the process, without leaving the temporary files of
 * writes in progress behind. */
static void on_sigint(int sig)
{
    if (interrupt_pending_here() && !interrupt_terminating()) {
        fileio_remove_temporaries();
        signal(sig, SIG_DFL);
        raise(sig);
        return;
    }
    interrupt_request();
    /* Distributed, the ranks stop together where the engines agree (between steps): a hook would
     * raise in each rank's Lua at a different place, and leave the others waiting. */
    if (comm_size() == 1)
        lua_sethook(running_L, stop_hook, LUA_MASKCALL | LUA_MASKRET | LUA_MASKCOUNT, 1);
}

/* SIGTERM (a batch scheduler's time limit) stops the run between steps like Ctrl-C, then ends the
 * process (main: cleanup, message, status 128 + 15), also from the REPL. A second SIGTERM before
 * that ends it at once, removing the temporary files of writes in progress. */
volatile sig_atomic_t cli_wake_fd = -1;

static void on_sigterm(int sig)
{
    if (cli_wake_fd >= 0) {
        int saved = errno;
        ssize_t w = write(cli_wake_fd, "t", 1);
        (void)w;
        errno = saved;
    }
    if (interrupt_terminating()) {
        fileio_remove_temporaries();
        _exit(128 + sig);
    }
    interrupt_terminate(sig);
    if (running_L && comm_size() == 1) /* distributed: see on_sigint */
        lua_sethook(running_L, stop_hook, LUA_MASKCALL | LUA_MASKRET | LUA_MASKCOUNT, 1);
}

static void catch_sigterm(lua_State *L)
{
    running_L = L;
    struct sigaction sa = {0};
    sa.sa_handler = on_sigterm; /* no SA_RESTART: a prompt waiting for input wakes up */
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, NULL);
}

/* After SIGTERM: removes what was being written, says where the work stopped, and returns the
 * exit status (128 + signal). */
static int terminated(void)
{
    int sig = interrupt_terminating(), n = fileio_remove_temporaries();
    const char *where = interrupt_where();
    char files[48];
    snprintf(files, sizeof files, n ? "%d file%s" : "none was open", n, n == 1 ? "" : "s");
    fprintf(stderr, "grainlab: terminated (%s)%s%s; partial outputs removed (%s)\n",
            sig == SIGTERM ? "SIGTERM" : "signal", *where ? " at " : "", where, files);
    fflush(stderr);
    return 128 + sig;
}

/* The chunk names of the embedded library (cmake/embed_lua.cmake), as a traceback shows them. */
static const char LIBRARY_FRAME[] = "\n\tlua/grainlab/";

/* Lua's traceback without the frames of the embedded library, nor the C functions it called:
 * an error from inside grainlab.pack.deposit shows the lines of the user's script that led to
 * it. A message that already holds a traceback (grainlab.entry gives one to a runtime error in
 * the library's code) or whose position is in the library (such an error outside an entry) keeps
 * every frame. */
static void push_traceback(lua_State *L, const char *msg)
{
    if (strstr(msg, "\nstack traceback:\n")) {
        lua_pushstring(L, msg);
        return;
    }
    luaL_traceback(L, L, msg, 1);
    if (strncmp(msg, LIBRARY_FRAME + 2, sizeof LIBRARY_FRAME - 3) == 0)
        return;
    const char *tb = lua_tostring(L, -1), *head = strstr(tb, "\nstack traceback:");
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    luaL_addlstring(&b, tb, (size_t)(head - tb) + 17);
    /* one line per frame, innermost first: a C frame goes with the library when its caller, on
     * the next line, is a library frame */
    for (const char *p = head + 17; *p;) {
        const char *end = strchr(p + 1, '\n');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        int library = strncmp(p, LIBRARY_FRAME, sizeof LIBRARY_FRAME - 1) == 0;
        if (!library && strncmp(p, "\n\t[C]: ", 7) == 0 && end)
            library = strncmp(end, LIBRARY_FRAME, sizeof LIBRARY_FRAME - 1) == 0;
        if (!library)
            luaL_addlstring(&b, p, n);
        p += n;
    }
    luaL_pushresult(&b);
    lua_remove(L, -2);
}

static int message_handler(lua_State *L)
{
    const char *msg = lua_tostring(L, 1);
    if (msg == NULL) {
        if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING)
            return 1;
        msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
    }
    push_traceback(L, msg);
    return 1;
}

int cli_docall(lua_State *L, int narg, int nres)
{
    if (interrupt_terminating()) { /* nothing more runs once the process is ending */
        lua_pop(L, narg + 1);
        lua_pushliteral(L, "terminated (SIGTERM)");
        return LUA_ERRRUN;
    }
    int base = lua_gettop(L) - narg;
    lua_pushcfunction(L, message_handler);
    lua_insert(L, base);
    running_L = L;
    struct sigaction sa = {0}, old;
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old);
    int status = lua_pcall(L, narg, nres, base);
    sigaction(SIGINT, &old, NULL);
    if (lua_gethook(L) == stop_hook)
        lua_sethook(L, NULL, 0, 0);
    interrupt_clear();
    lua_remove(L, base);
    return status;
}

/* ---- distributed runs: output once, errors once ----------------------------------------------
 * Ranks other than 0 write their standard output and error to the null device (every rank runs
 * the same script, so rank 0 says it all), keeping the real stderr for messages of their own. */
static int rank_stderr = STDERR_FILENO;
static char *spmd_error; /* the first error of a distributed run, printed after the agreement */

/* The sanitizers' reports (a crash, a leak) must not vanish with a rank's stderr. */
void __sanitizer_set_report_fd(void *fd) __attribute__((weak));

static void quiet_other_ranks(void)
{
    const char *all = getenv("GRAINLAB_MPI_OUTPUT"); /* "all": debugging, every rank speaks */
    if (comm_rank() == 0 || (all && strcmp(all, "all") == 0))
        return;
    fflush(stdout);
    fflush(stderr);
    int keep = dup(STDERR_FILENO), null = open("/dev/null", O_WRONLY);
    if (keep < 0 || null < 0)
        return;
    rank_stderr = keep;
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    close(null);
    if (__sanitizer_set_report_fd)
        __sanitizer_set_report_fd((void *)(intptr_t)keep);
}

static uint64_t digest(const char *s)
{
    uint64_t h = 1469598103934665603u; /* FNV-1a */
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 1099511628211u;
    return h ? h : 1;
}

/* Seconds a failed rank waits for the others to reach the end of the script too (the same
 * error on every rank: one message, a clean exit) before it ends the run alone. */
static double error_wait(void)
{
    const char *env = getenv("GRAINLAB_MPI_ERROR_WAIT");
    char *end;
    double d = env && *env ? strtod(env, &end) : 5.0;
    return env && *env && (*end || !(d >= 0)) ? 5.0 : d;
}

/* The end of a distributed run: the ranks agree on the exit status (the highest), and each
 * distinct error message is printed once, by the lowest rank that raised it (rank 0's as in a
 * plain run, others tagged with their rank). A rank that failed while the others run on (an
 * error on that rank only) cannot be waited for: after error_wait() it prints its message and
 * ends the whole run. */
static int spmd_finish(int status, double wait)
{
    int P = comm_size(), me = comm_rank();
    if (P == 1)
        return status;
    int64_t mine[2] = {status, spmd_error ? (int64_t)digest(spmd_error) : 0};
    int64_t *all = malloc(2 * (size_t)P * sizeof *all);
    if (!all || comm_agree(mine, all, wait) != 0) {
        if (spmd_error)
            dprintf(rank_stderr, "grainlab: rank %d: %s\n", me, spmd_error);
        dprintf(rank_stderr,
                "grainlab: rank %d %s alone (the other ranks did not reach the end within %g s): "
                "ending the run\n",
                me, spmd_error ? "failed" : "ended", wait);
        comm_abort(status ? status : 1);
    }
    int agreed = 0, first = spmd_error != NULL;
    for (int r = 0; r < P; r++) {
        agreed = all[2 * r] > agreed ? (int)all[2 * r] : agreed;
        if (r < me && all[2 * r] && all[2 * r + 1] == mine[1])
            first = 0;
    }
    if (first && me == 0)
        fprintf(stderr, "grainlab: %s\n", spmd_error);
    else if (first)
        dprintf(rank_stderr, "grainlab: rank %d: %s\n", me, spmd_error);
    free(all);
    free(spmd_error);
    spmd_error = NULL;
    return agreed;
}

/* os.exit in a distributed run: the ranks agree on the status as at the end of a script, then
 * MPI is ended properly (a bare exit() is reported by mpirun as a crash); a rank that calls it
 * alone, with the others running on, ends the run after error_wait(). */
static int l_spmd_exit(lua_State *L)
{
    int status = lua_isboolean(L, 1) ? (lua_toboolean(L, 1) ? EXIT_SUCCESS : EXIT_FAILURE)
                                     : (int)luaL_optinteger(L, 1, EXIT_SUCCESS);
    fflush(stdout);
    status = spmd_finish(status, error_wait());
    if (lua_toboolean(L, 2))
        lua_close(L);
    comm_finalize();
    exit(status);
}

void cli_print_error(lua_State *L)
{
    if (interrupt_terminating()) { /* main says it once, with where the work stopped */
        lua_pop(L, 1);
        return;
    }
    if (comm_size() > 1) { /* said once, at the end (spmd_finish) */
        const char *msg = lua_tostring(L, -1);
        if (!spmd_error)
            spmd_error = strdup(msg ? msg : "(error object is not a string)");
        lua_pop(L, 1);
        return;
    }
    const char *msg = lua_tostring(L, -1);
    fprintf(stderr, "grainlab: %s\n", msg ? msg : "(error object is not a string)");
    fflush(stderr);
    lua_pop(L, 1);
}

static int run_chunk(lua_State *L, int load_status)
{
    if (load_status == LUA_OK)
        load_status = cli_docall(L, 0, 0);
    if (load_status != LUA_OK) {
        cli_print_error(L);
        return 1;
    }
    return 0;
}

/* ---- globals from the command line ------------------------------------------------------- */
static void push_param_value(lua_State *L, const char *v)
{
    if (strcmp(v, "true") == 0)
        lua_pushboolean(L, 1);
    else if (strcmp(v, "false") == 0)
        lua_pushboolean(L, 0);
    else if (*v == '\0' || lua_stringtonumber(L, v) == 0)
        lua_pushstring(L, v);
}

static void set_params(lua_State *L, const cli_args *a, char *argv0)
{
    lua_getglobal(L, "params");
    for (int i = 0; i < a->nparams; i++) {
        const char *eq = strchr(a->params[i], '=');
        lua_pushlstring(L, a->params[i], (size_t)(eq - a->params[i]));
        push_param_value(L, eq + 1);
        lua_settable(L, -3);
    }
    lua_pop(L, 1);
    /* arg as in lua: arg[0] the script, arg[-1] the interpreter, arg[1..] the pairs. */
    lua_createtable(L, a->nparams, 2);
    lua_pushstring(L, argv0);
    lua_rawseti(L, -2, -1);
    if (a->script) {
        lua_pushstring(L, a->script);
        lua_rawseti(L, -2, 0);
    }
    for (int i = 0; i < a->nparams; i++) {
        lua_pushstring(L, a->params[i]);
        lua_rawseti(L, -2, i + 1);
    }
    lua_setglobal(L, "arg");
}

/* Lets a scenario script require Lua modules that sit beside it. */
static void add_script_dir_to_path(lua_State *L, const char *script)
{
    const char *slash = strrchr(script, '/');
    lua_getglobal(L, "package");
    if (slash)
        lua_pushlstring(L, script, (size_t)(slash - script + 1));
    else
        lua_pushliteral(L, "./");
    lua_pushliteral(L, "?.lua;");
    lua_getfield(L, -3, "path");
    lua_concat(L, 3);
    lua_setfield(L, -2, "path");
    lua_pop(L, 1);
}

static int run_script(lua_State *L, const char *script)
{
    int status;
    if (strcmp(script, "-") == 0) {
        status = luaL_loadfilex(L, NULL, "t");
    } else {
        add_script_dir_to_path(L, script);
        status = luaL_loadfilex(L, script, "t");
    }
    return run_chunk(L, status);
}

static int cli_main(int argc, char **argv)
{
    cli_args a = {0};
    a.chunks = calloc((size_t)argc, sizeof *a.chunks);
    a.params = calloc((size_t)argc, sizeof *a.params);
    if (!a.chunks || !a.params) {
        fprintf(stderr, "grainlab: out of memory\n");
        return 1;
    }
    int status = parse_args(argc, argv, &a);
    if (status == 0 && a.help)
        fputs(USAGE, stdout);
    else if (status == 0 && a.version)
        printf("grainlab %s (%s; %d threads available; kernels: %s)\n", GRAINLAB_VERSION,
               GRAINLAB_DEPS, threads_available(), clones_kernels());
    if (status != 0 || a.help || a.version) {
        free(a.chunks);
        free(a.params);
        return status;
    }
    /* stdin reaches rank 0 only, and a prompt is one person's: SPMD runs scripts from files. */
    if (comm_size() > 1 && (a.interactive || (!a.script && a.nchunks == 0) ||
                            (a.script && strcmp(a.script, "-") == 0))) {
        fprintf(stderr, "grainlab: under mpirun, give the script as a file (the REPL, -i and "
                        "scripts on standard input do not run distributed: standard input reaches "
                        "rank 0 only); run without mpirun for an interactive session\n");
        free(a.chunks);
        free(a.params);
        return 2;
    }
    if (a.quiet)
        progress_set_default_style(PROGRESS_QUIET);
    if (a.threads)
        threads_set((int)a.threads);

    bind_options opt = {.report_path = a.report, .quiet = a.quiet};
    lua_State *L = bind_newstate(&opt);
    if (!L) {
        if (comm_size() > 1) /* the other ranks would wait for this one */
            comm_abort(1);
        return 1;
    }
    catch_sigterm(L);
    set_params(L, &a, argv[0]);
    if (comm_size() > 1) {
        lua_getglobal(L, "os");
        lua_pushcfunction(L, l_spmd_exit);
        lua_setfield(L, -2, "exit");
        lua_pop(L, 1);
    }

    for (int i = 0; i < a.nchunks && status == 0; i++)
        status = run_chunk(
            L, luaL_loadbufferx(L, a.chunks[i], strlen(a.chunks[i]), "=(command line)", "t"));
    if (status == 0 && a.script)
        status = run_script(L, a.script);
    else if (status == 0 && a.nchunks == 0 && !a.interactive) {
        if (isatty(STDIN_FILENO))
            repl_run(L);
        else
            status = run_chunk(L, luaL_loadfilex(L, NULL, "t"));
    }
    if (a.interactive && !interrupt_terminating()) /* also after an error: state to inspect */
        repl_run(L);
    if (interrupt_terminating()) {
        status = spmd_finish(terminated(), error_wait());
        lua_close(L);
        free(a.chunks);
        free(a.params);
        return status;
    }

    int failed = bind_failed_checks(L);
    if (failed) {
        fprintf(stderr, "grainlab: %d report check%s failed\n", failed, failed == 1 ? "" : "s");
        status = 1;
    }
    status = spmd_finish(status, status ? error_wait() : -1);
    lua_close(L);
    free(a.chunks);
    free(a.params);
    return status;
}

int main(int argc, char **argv)
{
    /* Line-buffered even into a pipe, so printed results and progress lines on stderr
     * interleave in logs the way they happened. */
    setvbuf(stdout, NULL, _IOLBF, 0);
    /* Under mpirun every rank runs the same script (SPMD); without it, no MPI at all. */
    comm_init(&argc, &argv);
    quiet_other_ranks();
    int status = cli_main(argc, argv);
    comm_finalize();
    return status;
}
