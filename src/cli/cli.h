/* Shared between the command line (main.c) and the REPL (repl.c). */
#ifndef GRAINLAB_CLI_H
#define GRAINLAB_CLI_H

#include <signal.h>

#include <lua.h>

/* Calls the function below `narg` arguments on the stack in protected mode with a traceback
 * message handler; Ctrl-C during the call raises "interrupted" in Lua and sets the kernels'
 * interrupt flag. Returns the lua_pcall status; on error the message is on the stack. */
int cli_docall(lua_State *L, int narg, int nres);

/* Prints the error message on top of the stack to stderr ("grainlab: msg") and pops it. */
void cli_print_error(lua_State *L);

/* A descriptor the SIGTERM handler writes a byte to, so that a prompt waiting in select() wakes
 * up whenever the signal arrives (the REPL sets its self-pipe here), or -1. */
extern volatile sig_atomic_t cli_wake_fd;

/* The interactive loop; returns at end of input or when the process is terminating. */
void repl_run(lua_State *L);

#endif
