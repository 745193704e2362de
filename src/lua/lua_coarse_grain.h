/* What the coarse-graining bindings share: lua_coarse_grain.c (analysis.coarse_grain,
 * analysis.cg_average) and lua_coarse_grain_render.c (render.coarse_grain). */
#ifndef GRAINLAB_LUA_COARSE_GRAIN_H
#define GRAINLAB_LUA_COARSE_GRAIN_H

#include "lua/bind.h"

/* Adds render.coarse_grain to the render table (lua_coarse_grain_render.c; from
 * bind_open_coarse_grain, after bind_open_render). */
void bind_open_coarse_grain_render(lua_State *L);

#endif
