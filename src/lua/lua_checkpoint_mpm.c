/* Checkpoints of MPM and DSMC scenes from Lua: m:save(path) and mpm.load(path), s:save(path) and
 * dsmc.load(path), over src/mpm/checkpoint.c and src/dsmc/checkpoint.c. */
#include "dsmc/dsmc.h"
#include "lua/bind.h"
#include "mpm/mpm.h"

/* m:save(path) and s:save(path) may run from on_step: between steps the scene is whole. */
static int l_mpm_save(lua_State *L)
{
    mpm_scene *s = bind_check_mpm_scene(L, 1, "save");
    const char *path = bind_arg_path(L, 2, "save");
    core_error err;
    if (mpm_save(s, path, GRAINLAB_VERSION, &err))
        return bind_raise(L, "save", &err);
    return 0;
}

static int l_mpm_load(lua_State *L)
{
    const char *path = bind_arg_path(L, 1, "load");
    mpm_scene **slot = bind_new_mpm_scene(L); /* closed until filled: safe on any error */
    core_error err;
    if (mpm_load(path, slot, &err))
        return bind_raise(L, "load", &err);
    return 1;
}

static int l_dsmc_save(lua_State *L)
{
    dsmc_scene *s = bind_check_dsmc_scene(L, 1, "save");
    const char *path = bind_arg_path(L, 2, "save");
    core_error err;
    if (dsmc_save(s, path, GRAINLAB_VERSION, &err))
        return bind_raise(L, "save", &err);
    return 0;
}

static int l_dsmc_load(lua_State *L)
{
    const char *path = bind_arg_path(L, 1, "load");
    dsmc_scene **slot = bind_new_dsmc_scene(L);
    core_error err;
    if (dsmc_load(path, slot, &err))
        return bind_raise(L, "load", &err);
    return 1;
}

/* Adds the methods to the type's __index and the function to the global module. */
static void add_to(lua_State *L, const char *type, const char *module, const bind_fn *method,
                   const bind_fn *fn)
{
    const bind_fn methods[] = {*method, {NULL, NULL, NULL, NULL}};
    const bind_fn fns[] = {*fn, {NULL, NULL, NULL, NULL}};
    luaL_getmetatable(L, type);
    lua_getfield(L, -1, "__index");
    bind_register(L, lua_gettop(L), methods);
    lua_pop(L, 2);
    lua_getglobal(L, module);
    bind_register(L, lua_gettop(L), fns);
    lua_pop(L, 1);
}

void bind_open_checkpoint_mpm(lua_State *L)
{
    static const bind_fn mpm_save_fn = {
        "save", l_mpm_save, "m:save(path)",
        "Writes everything the scene needs to continue into a checkpoint file (grainlab's "
        "versioned binary format, written whole through a temporary file and a rename): grid, "
        "walls and planes, materials, contact model and options, grains and prescribed "
        "velocities, every material point (position, velocity, deformation gradient, elastic "
        "stretch, stress, plastic strain, displacement), time and step count. mpm.load(path) in "
        "any process continues with the same bits. Allowed from on_step."};
    static const bind_fn mpm_load_fn = {
        "load", l_mpm_load, "mpm.load(path)",
        "A new mpm.scene from a checkpoint written by m:save: running it gives the same bits as "
        "continuing the saved scene. A missing, truncated, corrupt, newer-version or other "
        "engine's file is refused with an error saying which."};
    static const bind_fn dsmc_save_fn = {
        "save", l_dsmc_save, "s:save(path)",
        "Writes everything the gas needs to continue into a checkpoint file (grainlab's "
        "versioned binary format, written whole through a temporary file and a rename): box, "
        "cells, walls and their motion, the seed, time and step count, statistics, each cell's "
        "candidate remainder, and the particles in their (cell-sorted) order. dsmc.load(path) "
        "in any process, with any number of threads, continues with the same bits. Allowed from "
        "on_step."};
    static const bind_fn dsmc_load_fn = {
        "load", l_dsmc_load, "dsmc.load(path)",
        "A new dsmc.scene from a checkpoint written by s:save: running it gives the same bits "
        "as continuing the saved gas. A missing, truncated, corrupt, newer-version or other "
        "engine's file is refused with an error saying which."};
    add_to(L, "mpm.scene", "mpm", &mpm_save_fn, &mpm_load_fn);
    add_to(L, "dsmc.scene", "dsmc", &dsmc_save_fn, &dsmc_load_fn);
}
