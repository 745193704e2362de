/* The Lua-side library (every .lua file in lua/grainlab), compiled into the binary by cmake/embed_lua.cmake. */
#ifndef GRAINLAB_LUA_EMBEDDED_H
#define GRAINLAB_LUA_EMBEDDED_H

#include <stddef.h>

typedef struct embedded_lua {
    const char *module;     /* "grainlab.report" */
    const char *chunkname;  /* "@lua/grainlab/report.lua", shown in errors and tracebacks */
    const char *source;
    size_t size;
} embedded_lua;

extern const embedded_lua embedded_lua_modules[]; /* ends with a zeroed entry */

#endif
