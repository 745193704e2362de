/* The Lua state grainlab runs scripts in: standard libraries, the embedded grainlab.* modules
 * on package.preload, and the globals grainlab, help and params. */
#include <stdio.h>
#include <string.h>

#include <lualib.h>

#include "lua/bind.h"
#include "lua/embedded.h"

void bind_open_lammps(lua_State *L);

int bind_entry_name(lua_State *L, char *buf, size_t size)
{
    int found = 0;
    if (lua_getfield(L, LUA_REGISTRYINDEX, "grainlab.entry") == LUA_TTABLE &&
        lua_getfield(L, -1, "current") == LUA_TSTRING) {
        snprintf(buf, size, "%s", lua_tostring(L, -1));
        found = 1;
    }
    lua_pop(L, lua_type(L, -1) == LUA_TTABLE ? 1 : 2);
    return found;
}

/* package.preload loader for embedded module number upvalue(1). */
static int load_embedded(lua_State *L)
{
    const embedded_lua *m = &embedded_lua_modules[lua_tointeger(L, lua_upvalueindex(1))];
    if (luaL_loadbufferx(L, m->source, m->size, m->chunkname, "t") != LUA_OK)
        return lua_error(L);
    lua_pushstring(L, m->module);
    lua_call(L, 1, 1);
    return 1;
}

static int open_grainlab(lua_State *L)
{
    const bind_options *opt = lua_touserdata(L, 1);
    luaL_openlibs(L);

    luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_PRELOAD_TABLE);
    for (int i = 0; embedded_lua_modules[i].module; i++) {
        lua_pushinteger(L, i);
        lua_pushcclosure(L, load_embedded, 1);
        lua_setfield(L, -2, embedded_lua_modules[i].module);
    }
    lua_pop(L, 1);

    lua_newtable(L);
    int g = lua_gettop(L);
    bind_open_core(L, g);
    bind_open_help(L, g);
    bind_open_mpi(L, g);
    lua_createtable(L, 0, 2);
    if (opt->report_path) {
        lua_pushstring(L, opt->report_path);
        lua_setfield(L, -2, "report");
    }
    lua_pushboolean(L, opt->quiet);
    lua_setfield(L, -2, "quiet");
    lua_setfield(L, g, "options");
    lua_pushvalue(L, g);
    lua_setglobal(L, "grainlab");

    lua_newtable(L);
    lua_setglobal(L, "params");
    bind_open_dem(L);
    bind_open_analysis(L);
    bind_open_checkpoint(L);
    bind_open_mpm(L);
    bind_open_dsmc(L);
    bind_open_checkpoint_mpm(L);
    bind_open_render(L);
    bind_open_coarse_grain(L); /* analysis.coarse_grain, render.coarse_grain (lua_coarse_grain.c) */
    bind_open_vtk(L); /* after the engines: adds write_vtk to their scene types */
    bind_open_lammps(L); /* LAMMPS files for dem (lua_lammps.c) */

    /* The Lua-side library completes the table: report, check, help. */
    lua_getglobal(L, "require");
    lua_pushliteral(L, "grainlab.init");
    lua_call(L, 1, 0);
    return 0;
}

lua_State *bind_newstate(const bind_options *opt)
{
    lua_State *L = luaL_newstate();
    if (!L)
        return NULL;
    lua_pushcfunction(L, open_grainlab);
    lua_pushlightuserdata(L, (void *)opt);
    if (lua_pcall(L, 1, 0, 0) != LUA_OK) {
        fprintf(stderr, "grainlab: cannot start Lua: %s\n", lua_tostring(L, -1));
        lua_close(L);
        return NULL;
    }
    return L;
}

int bind_failed_checks(lua_State *L)
{
    int failed = 0, top = lua_gettop(L);
    if (lua_getfield(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE) == LUA_TTABLE &&
        lua_getfield(L, -1, "grainlab.report") == LUA_TTABLE) {
        lua_getfield(L, -1, "failed");
        failed = (int)lua_tointeger(L, -1);
        lua_pop(L, 1);
    }
    lua_settop(L, top);
    return failed;
}
