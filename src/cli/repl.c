/* The interactive loop, shaped after lua.c: try `return <line>` first so expressions print,
 * keep reading while the statement is incomplete (the parse error ends in <eof>), print results
 * through the global print. On a terminal, readline's callback interface gives editing, history
 * and completion, and lets Ctrl-C at the prompt drop the line instead of ending the session. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/select.h>
#include <unistd.h>

#include <lauxlib.h>
#include <readline/history.h>
#include <readline/readline.h>

#include "cli/cli.h"
#include "core/interrupt.h"

enum { READ_EOF = 0, READ_LINE = 1, READ_INTERRUPTED = -1 };

static int use_readline;
static char history_path[4096];
static int history_exists;
static lua_State *completion_L;

/* ---- reading a line ------------------------------------------------------------------------ */
static volatile sig_atomic_t prompt_sigint;
static char *accepted_line;
static int line_accepted;

/* The self-pipe: the handler also writes a byte, and the prompt's select() watches the pipe with
 * standard input, so a Ctrl-C arriving just before select() still wakes it. */
static int sigint_pipe[2] = {-1, -1};

static void on_prompt_sigint(int sig)
{
    (void)sig;
    prompt_sigint = 1;
    if (sigint_pipe[1] >= 0) {
        int saved = errno;
        ssize_t w = write(sigint_pipe[1], "i", 1);
        (void)w;
        errno = saved;
    }
}

static void drain_sigint_pipe(void)
{
    char buf[64];
    while (sigint_pipe[0] >= 0 && read(sigint_pipe[0], buf, sizeof buf) > 0) {
    }
}

static void on_line(char *line)
{
    accepted_line = line;
    line_accepted = 1;
    rl_callback_handler_remove();
}

static int read_tty(const char *prompt, char **out)
{
    drain_sigint_pipe();
    prompt_sigint = 0; /* a Ctrl-C between statements only cancels itself */
    line_accepted = 0;
    accepted_line = NULL;
    rl_callback_handler_install(prompt, on_line);
    int result = READ_LINE;
    while (!line_accepted) {
        fd_set fds;
        FD_ZERO(&fds);
        FD_SET(STDIN_FILENO, &fds);
        int maxfd = STDIN_FILENO;
        if (sigint_pipe[0] >= 0) {
            FD_SET(sigint_pipe[0], &fds);
            maxfd = sigint_pipe[0] > maxfd ? sigint_pipe[0] : maxfd;
        }
        int n = prompt_sigint || interrupt_terminating()
                    ? -1
                    : select(maxfd + 1, &fds, NULL, NULL, NULL);
        if (prompt_sigint) {
            drain_sigint_pipe();
            rl_free_line_state();
            rl_callback_sigcleanup();
            rl_callback_handler_remove();
            fputs("^C\n", stdout);
            fflush(stdout);
            result = READ_INTERRUPTED;
            break;
        }
        if (interrupt_terminating()) { /* SIGTERM ends the session, unlike Ctrl-C */
            rl_callback_handler_remove();
            result = READ_EOF;
            break;
        }
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            rl_callback_handler_remove();
            result = READ_EOF;
            break;
        }
        if (FD_ISSET(STDIN_FILENO, &fds))
            rl_callback_read_char();
    }
    if (result == READ_LINE && !accepted_line)
        result = READ_EOF;
    *out = accepted_line;
    return result;
}

static int read_plain(const char *prompt, char **out)
{
    fputs(prompt, stdout);
    fflush(stdout);
    size_t cap = 0;
    char *line = NULL;
    ssize_t n = getline(&line, &cap, stdin);
    if (n < 0) {
        free(line);
        return READ_EOF;
    }
    if (n > 0 && line[n - 1] == '\n')
        line[n - 1] = '\0';
    *out = line;
    return READ_LINE;
}

static const char *get_prompt(lua_State *L, int first)
{
    lua_getglobal(L, first ? "_PROMPT" : "_PROMPT2");
    const char *p = lua_tostring(L, -1);
    if (!p) {
        lua_pop(L, 1);
        p = lua_pushstring(L, first ? "> " : ">> ");
    }
    return p; /* left on the stack so it stays alive */
}

/* Pushes the next line (stripped of its newline); "=expr" is shorthand for "return expr". */
static int push_line(lua_State *L, int first)
{
    const char *prompt = get_prompt(L, first);
    char *line = NULL;
    int r = use_readline ? read_tty(prompt, &line) : read_plain(prompt, &line);
    lua_pop(L, 1);
    if (r != READ_LINE)
        return r;
    if (use_readline && line[0] != '\0') {
        add_history(line);
        if (history_path[0]) {
            if (history_exists)
                append_history(1, history_path);
            else
                history_exists = write_history(history_path) == 0;
        }
    }
    if (first && line[0] == '=')
        lua_pushfstring(L, "return %s", line + 1);
    else
        lua_pushstring(L, line);
    free(line);
    return READ_LINE;
}

/* ---- compiling a statement ------------------------------------------------------------------ */
static int add_return(lua_State *L)
{
    const char *line = lua_tostring(L, -1);
    const char *ret = lua_pushfstring(L, "return %s;", line);
    int status = luaL_loadbuffer(L, ret, strlen(ret), "=stdin");
    if (status == LUA_OK)
        lua_remove(L, -2); /* the "return" text */
    else
        lua_pop(L, 2);
    return status;
}

static int incomplete(lua_State *L, int status)
{
    if (status != LUA_ERRSYNTAX)
        return 0;
    size_t len;
    const char *msg = lua_tolstring(L, -1, &len);
    static const char eof[] = "<eof>";
    if (len >= sizeof eof - 1 && strcmp(msg + len - (sizeof eof - 1), eof) == 0) {
        lua_pop(L, 1);
        return 1;
    }
    return 0;
}

/* Reads continuation lines until the buffer compiles or fails for a reason other than <eof>.
 * Returns a load status, or READ_EOF / READ_INTERRUPTED (as negative codes below). */
static int multiline(lua_State *L, int *read_status)
{
    for (;;) {
        size_t len;
        const char *buf = lua_tolstring(L, 1, &len);
        int status = luaL_loadbuffer(L, buf, len, "=stdin");
        if (!incomplete(L, status))
            return status;
        int r = push_line(L, 0);
        if (r != READ_LINE) {
            *read_status = r;
            return LUA_OK;
        }
        lua_pushliteral(L, "\n");
        lua_insert(L, -2);
        lua_concat(L, 3);
    }
}

/* Leaves a compiled chunk (or an error message) on the stack; returns the load status, or sets
 * *read_status to READ_EOF / READ_INTERRUPTED. */
static int load_statement(lua_State *L, int *read_status)
{
    lua_settop(L, 0);
    *read_status = push_line(L, 1);
    if (*read_status != READ_LINE)
        return LUA_OK;
    int status = add_return(L);
    if (status != LUA_OK)
        status = multiline(L, read_status);
    lua_remove(L, 1);
    return status;
}

/* Pushes the printer of results: grainlab.pretty's show (tables readable and bounded, the rest
 * as print shows it, all through the global print), or print itself if that cannot be had. */
static void push_printer(lua_State *L)
{
    int top = lua_gettop(L);
    lua_getglobal(L, "require");
    lua_pushliteral(L, "grainlab.pretty");
    if (lua_pcall(L, 1, 1, 0) == LUA_OK && lua_istable(L, -1) &&
        lua_getfield(L, -1, "show") == LUA_TFUNCTION) {
        int rows = 0, cols = 0;
        if (use_readline) /* tables break at the terminal's width */
            rl_get_screen_size(&rows, &cols);
        if (cols >= 40) {
            lua_pushinteger(L, cols - 1);
            lua_setfield(L, -3, "width");
        }
        lua_remove(L, -2);
        return;
    }
    lua_settop(L, top);
    lua_getglobal(L, "print");
}

static void print_results(lua_State *L)
{
    int n = lua_gettop(L);
    if (n == 0)
        return;
    luaL_checkstack(L, LUA_MINSTACK, "too many results to print");
    push_printer(L);
    lua_insert(L, 1);
    if (lua_pcall(L, n, 0, 0) != LUA_OK) {
        fprintf(stderr, "grainlab: error calling 'print' (%s)\n", lua_tostring(L, -1));
        lua_pop(L, 1);
    }
}

/* ---- completion --------------------------------------------------------------------------- */
static char **candidates;
static size_t ncandidates;

static char *next_candidate(const char *text, int state)
{
    (void)text;
    static size_t i;
    if (state == 0)
        i = 0;
    return i < ncandidates ? strdup(candidates[i++]) : NULL;
}

static char **complete(const char *text, int start, int end)
{
    (void)start;
    (void)end;
    rl_attempted_completion_over = 1; /* never fall back to file names */
    rl_completion_append_character = '\0';
    lua_State *L = completion_L;
    int top = lua_gettop(L);
    for (size_t i = 0; i < ncandidates; i++)
        free(candidates[i]);
    free(candidates);
    candidates = NULL;
    ncandidates = 0;
    lua_getglobal(L, "require");
    lua_pushliteral(L, "grainlab.complete");
    if (lua_pcall(L, 1, 1, 0) == LUA_OK) {
        lua_pushstring(L, text);
        if (lua_pcall(L, 1, 1, 0) == LUA_OK && lua_istable(L, -1)) {
            size_t n = (size_t)luaL_len(L, -1);
            candidates = calloc(n ? n : 1, sizeof *candidates);
            for (size_t i = 1; candidates && i <= n; i++) {
                lua_rawgeti(L, -1, (lua_Integer)i);
                const char *s = lua_tostring(L, -1);
                if (s)
                    candidates[ncandidates++] = strdup(s);
                lua_pop(L, 1);
            }
        }
    }
    lua_settop(L, top);
    return ncandidates ? rl_completion_matches(text, next_candidate) : NULL;
}

/* ---- the loop -------------------------------------------------------------------------------- */
static void setup_readline(lua_State *L)
{
    completion_L = L;
    rl_readline_name = "grainlab";
    rl_catch_signals = 0; /* SIGINT is ours: see read_tty */
    rl_attempted_completion_function = complete;
    rl_basic_word_break_characters = " \t\n\"\\'><=;+-*/%^~#{}()[],&|";
    using_history();
    const char *env = getenv("GRAINLAB_HISTORY"), *home = getenv("HOME");
    if (env)
        snprintf(history_path, sizeof history_path, "%s", env);
    else if (home && *home)
        snprintf(history_path, sizeof history_path, "%s/.grainlab_history", home);
    if (history_path[0])
        history_exists = read_history(history_path) == 0;
}

static void close_readline(void)
{
    if (history_path[0] && history_exists)
        history_truncate_file(history_path, 2000);
    clear_history();
    for (size_t i = 0; i < ncandidates; i++)
        free(candidates[i]);
    free(candidates);
    candidates = NULL;
    ncandidates = 0;
}

void repl_run(lua_State *L)
{
    use_readline = isatty(STDIN_FILENO);
    /* For the whole session a Ctrl-C only sets a flag (no SA_RESTART, so the prompt's select()
     * returns): pressed between statements it must not end the session. cli_docall installs its
     * own handler while Lua runs and restores this one. */
    struct sigaction sa = {0}, old;
    sa.sa_handler = on_prompt_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old);
    if (use_readline && pipe(sigint_pipe) == 0) {
        for (int k = 0; k < 2; k++)
            fcntl(sigint_pipe[k], F_SETFL, fcntl(sigint_pipe[k], F_GETFL) | O_NONBLOCK);
        cli_wake_fd = sigint_pipe[1]; /* SIGTERM wakes the prompt too */
    }
    if (use_readline)
        setup_readline(L);
    for (;;) {
        int read_status;
        int status = load_statement(L, &read_status);
        if (read_status == READ_EOF)
            break;
        if (read_status == READ_INTERRUPTED)
            continue;
        if (status == LUA_OK)
            status = cli_docall(L, 0, LUA_MULTRET);
        if (interrupt_terminating())
            break;
        if (status == LUA_OK)
            print_results(L);
        else
            cli_print_error(L);
    }
    lua_settop(L, 0);
    if (use_readline) {
        fputc('\n', stdout);
        close_readline();
    }
    sigaction(SIGINT, &old, NULL);
    cli_wake_fd = -1;
    for (int k = 0; k < 2; k++)
        if (sigint_pipe[k] >= 0) {
            close(sigint_pipe[k]);
            sigint_pipe[k] = -1;
        }
    fflush(stdout);
}
