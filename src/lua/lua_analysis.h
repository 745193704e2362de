/* Shared by the analysis bindings (lua_analysis.c) and the boundary conditions of dem.scene
 * (lua_boundary.c): arrays and particle ids read from tables, with errors naming the field. */
#ifndef GRAINLAB_LUA_ANALYSIS_H
#define GRAINLAB_LUA_ANALYSIS_H

#include <stddef.h>

#include "lua/bind.h"

/* Raises "bad field 'F' in argument #N to 'call' (EXPECTED expected, got GOT)" with GOT given. */
int bind_field_fail(lua_State *L, int arg, const char *call, const char *name,
                    const char *expected, const char *got);
/* Field `name` of the table at arg as an array of exactly *n finite numbers (*n = 0: any length,
 * returned in *n), in a buffer left on the stack; absent and not required: NULL. */
double *bind_read_array(lua_State *L, int arg, const char *call, const char *name, size_t *n,
                        int required);
/* Field `key` of the table at tab as particle ids in [1, max], 0-based in a buffer left on the
 * stack (distinct: a repeated id is refused); errors name field `label` of argument arg. */
long *bind_read_ids_at(lua_State *L, int tab, const char *key, int arg, const char *call,
                       const char *label, size_t max, int distinct, int required, size_t *n);
long *bind_read_ids(lua_State *L, int arg, const char *call, const char *name, size_t max,
                    int distinct, int required, size_t *n);
/* Pushes {xx =, xy =, yx =, yy =}. */
void bind_push_tensor(lua_State *L, const double t[4]);

/* The boundary-condition methods of dem.scene (lua_boundary.c), from bind_open_analysis. */
void bind_open_boundary(lua_State *L);

#endif
