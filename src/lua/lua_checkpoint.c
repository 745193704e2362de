/* Checkpoint and restart from Lua: s:save(path) on dem.scene and dem.load(path) (over
 * src/dem/checkpoint.c and the core/checkpoint.h container). */
#include <string.h>

#include "core/checkpoint.h"
#include "dem/dem.h"
#include "lua/bind.h"

/* ---- DEM ------------------------------------------------------------------------------------ */
static int l_dem_save(lua_State *L)
{
    dem_scene *s = bind_check_dem_scene(L, 1, "save");
    const char *path = luaL_checkstring(L, 2);
    core_error err;
    if (dem_save(s, path, GRAINLAB_VERSION, &err) != CORE_OK)
        return bind_raise(L, "save", &err);
    return 0;
}

/* The new scene's userdata comes from dem.scene itself (upvalue 1), so that it has the type's
 * metatable and user values; its freshly created kernel scene is then replaced by the loaded
 * one. The dem.scene userdata starts with its dem_scene pointer (lscene in lua_dem.c), which
 * bind_check_dem_scene confirms before the swap. */
static int l_dem_load(lua_State *L)
{
    const char *path = luaL_checkstring(L, 1);
    core_error err;
    dem_scene *loaded;
    if (dem_load(path, &loaded, &err) != CORE_OK)
        return bind_raise(L, "load", &err);
    lua_pushvalue(L, lua_upvalueindex(1));
    const int D = dem_dim(loaded);
    double lo[3], hi[3], g[3];
    dem_box(loaded, lo, hi, g);
    lua_createtable(L, 0, 2);
    lua_pushinteger(L, D);
    lua_setfield(L, -2, "dim");
    lua_createtable(L, 2, 0);
    for (int k = 0; k < 2; k++) {
        lua_createtable(L, D, 0);
        for (int d = 0; d < D; d++) {
            lua_pushnumber(L, k ? hi[d] : lo[d]);
            lua_rawseti(L, -2, d + 1);
        }
        lua_rawseti(L, -2, k + 1);
    }
    lua_setfield(L, -2, "box");
    if (lua_pcall(L, 1, 1, 0) != LUA_OK) {
        dem_destroy(loaded);
        return lua_error(L);
    }
    int u = lua_gettop(L);
    dem_scene **slot = lua_touserdata(L, u);
    if (!slot || bind_check_dem_scene(L, u, "load") != *slot) {
        dem_destroy(loaded);
        return luaL_error(L, "load: internal error: unexpected dem.scene layout");
    }
    dem_destroy(*slot);
    *slot = loaded;
    return 1;
}

void bind_open_checkpoint(lua_State *L)
{
    static const bind_fn scene_methods[] = {
        {"save", l_dem_save, "s:save(path)",
         "Writes a checkpoint of the scene: everything a run continues from (particles, contact "
         "history, walls and servos, the contact law, the integrator's state, time and counters), "
         "by particle id. dem.load(path) in this or another process, with any number of threads, "
         "continues with the same bits. Written whole (temporary file + rename). Scenes with "
         "boundary conditions (s:boundary, springs, ties, spins) are refused."},
        {NULL, NULL, NULL, NULL}};
    luaL_getmetatable(L, "dem.scene");
    lua_getfield(L, -1, "__index");
    bind_register(L, lua_gettop(L), scene_methods);
    lua_pop(L, 2);

    lua_getglobal(L, "dem");
    int dem = lua_gettop(L);
    lua_getfield(L, dem, "scene");
    lua_pushcclosure(L, l_dem_load, 1);
    bind_doc(L, -1, "load", "dem.load(path)",
             "A new dem.scene from a checkpoint written by s:save: continuing it gives the same "
             "bits as if the saved run had gone on. A missing, truncated, corrupt, foreign, "
             "other-engine or newer-format file is refused with an error naming the path and the "
             "problem.");
    lua_setfield(L, dem, "load");
    lua_pop(L, 1);
}
