/* What the bindings of the mpm module share: lua_mpm.c (the module and mpm.scene),
 * lua_mpm_material.c (mpm.material) and lua_mpm_measure.c (the scene's measurements). */
#ifndef GRAINLAB_LUA_MPM_H
#define GRAINLAB_LUA_MPM_H

#include <stddef.h>

#include "lua/bind.h"
#include "mpm/mpm.h"

/* The kernel scene of the mpm.scene at idx, or a Lua error (a closed scene too). */
mpm_scene *bind_mpm_check(lua_State *L, int idx);
/* A grain id in [1, count] at arg, as a 0-based index, or a Lua error naming call. */
size_t bind_mpm_grain_arg(lua_State *L, mpm_scene *s, int arg, const char *call);
/* Sets field k of the table on top to v; pushes {v[0], v[1]}. */
void bind_mpm_set_number(lua_State *L, const char *k, double v);
void bind_mpm_push_pair(lua_State *L, const double v[2]);

/* Adds m:field, m:measure, m:grain, m:points and m:timings to mpm.scene (lua_mpm_measure.c;
 * from bind_open_mpm). */
void bind_open_mpm_measure(lua_State *L);
/* Adds mpm.material (the function, onto the mpm table at idx) and its type (lua_mpm_material.c;
 * from bind_open_mpm). */
void bind_open_mpm_material(lua_State *L, int idx);

#endif
