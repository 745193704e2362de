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
    const char *path = bind_arg_path(L, 2, "save");
    core_error err;
    if (dem_save(s, path, GRAINLAB_VERSION, &err) != CORE_OK)
        return bind_raise(L, "save", &err);
    return 0;
}

/* The userdata is made first, empty, so that a refused file leaves nothing to free but it. */
static int l_dem_load(lua_State *L)
{
    const char *path = bind_arg_path(L, 1, "load");
    struct dem_scene **slot = bind_new_dem_scene(L);
    core_error err;
    if (dem_load_with(path, bind_dem_boundary_restorer(), slot, &err) != CORE_OK)
        return bind_raise(L, "load", &err);
    return 1;
}

void bind_open_checkpoint(lua_State *L)
{
    static const bind_fn scene_methods[] = {
        {"save", l_dem_save, "s:save(path)",
         "Writes a checkpoint of the scene: everything a run continues from (particles, contact "
         "history, walls and servos, the contact law, the integrator's state, time and counters), "
         "by particle id. dem.load(path) in this or another process, with any number of threads, "
         "continues with the same bits. Written whole (temporary file + rename). Boundary "
         "conditions are saved (fixed edges, pressure, MBC with its integral term, springs, "
         "ties, spins), also a boundary rebuilt by Delaunay triangulation (mode = 'delaunay'): "
         "its parameters, current edges and schedule, so the rebuilds continue at the same "
         "steps with the same edges."},
        {NULL, NULL, NULL, NULL}};
    luaL_getmetatable(L, "dem.scene");
    lua_getfield(L, -1, "__index");
    bind_register(L, lua_gettop(L), scene_methods);
    lua_pop(L, 2);

    lua_getglobal(L, "dem");
    int dem = lua_gettop(L);
    lua_pushcfunction(L, l_dem_load);
    bind_doc(L, -1, "load", "dem.load(path)",
             "A new dem.scene from a checkpoint written by s:save: continuing it gives the same "
             "bits as if the saved run had gone on. A missing, truncated, corrupt, foreign, "
             "other-engine or newer-format file is refused with an error naming the path and the "
             "problem.");
    lua_setfield(L, dem, "load");
    lua_pop(L, 1);
}
