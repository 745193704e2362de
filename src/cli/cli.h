/* Shared between the command line (main.c) and the REPL (repl.c). */
#ifndef GRAINLAB_CLI_H
#define GRAINLAB_CLI_H

#include <lua.h>

/* Calls the function below `narg` arguments on the stack in protected mode with a traceback
 * message handler; Ctrl-C during the call raises "interrupted" in Lua and sets the kernels'
 * interrupt flag. Returns the lua_pcall status; on error the message is on the stack. */
int cli_docall(lua_State *L, int narg, int nres);

/* Prints the error message on top of the stack to stderr ("grainlab: msg") and pops it. */
void cli_print_error(lua_State *L);

/* The interactive loop; returns at end of input. */
void repl_run(lua_State *L);

#endif
