/* The dem bindings' shared parts (lua_dem.c and lua_dem_*.c): the scene argument, materials,
 * particle ids, vectors, and the registration of each file's methods of dem.scene. */
#ifndef GRAINLAB_LUA_DEM_H
#define GRAINLAB_LUA_DEM_H

#include <stddef.h>

#include "dem/dem.h"
#include "lua/bind.h"

/* The scene at idx as its run left it (distributed after a run on several ranks: s:run only),
 * or gathered back to every rank first (every other call). */
dem_scene *ldem_check_scene_local(lua_State *L, int idx);
dem_scene *ldem_check_scene(lua_State *L, int idx);
/* Material index for the field `field` of the table at arg (of the scene at `scene`): a
 * grainlab.material (registered on first use) or, when absent, grainlab's default quartz. */
int ldem_material_index(lua_State *L, int scene, int arg, const char *call, const char *field,
                        int absent);
/* The note that a call used the default material (once, unless quiet). */
void ldem_default_material_notice(lua_State *L, dem_scene *s, int scene, int arg, const char *call);
/* The particle id at arg (1-based in Lua), as a 0-based index. */
size_t ldem_particle_arg(lua_State *L, dem_scene *s, int arg, const char *call);
void ldem_push_vector(lua_State *L, const double *v, int n);

/* Adds methods (and the fields of their options tables) to dem.scene (after bind_open_dem made
 * the type); each file adds its own. */
void ldem_add_methods(lua_State *L, const bind_fn *methods, const bind_fields *fields);
void ldem_open_contact(lua_State *L);
void ldem_open_walls(lua_State *L);
void ldem_open_run(lua_State *L);
void ldem_open_measure(lua_State *L);
void ldem_open_clump(lua_State *L); /* after the global dem exists */

#endif
