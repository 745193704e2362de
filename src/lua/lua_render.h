/* Shared by the render bindings (lua_render.c) and its fields and point clouds
 * (lua_render_field.c): the GL context, images, files written by frame pattern, colour options. */
#ifndef GRAINLAB_LUA_RENDER_H
#define GRAINLAB_LUA_RENDER_H

#include <stddef.h>

#include "lua/bind.h"
#include "render/render.h"

/* The names of the colour maps, in render_colormap's order. */
extern const char *const bind_render_colormaps[];

/* The state's shared GL context, created on first use (errors raised named after call). */
render_context *bind_render_context(lua_State *L, const char *call);
/* A new, empty render.image userdata on the stack. */
render_image *bind_push_image(lua_State *L);
/* Writes img to the file pattern (frame < 0: the pattern's own counter), frees its pixels and
 * returns the file name written. */
int bind_write_image(lua_State *L, render_image *img, const char *pattern, long frame,
                     const char *call);
/* A buffer of size bytes placed below the value on top of the stack. */
void *bind_buffer_below_top(lua_State *L, size_t size);
/* range = {lo, hi} of the options at arg into range (absent: left as it is). */
void bind_read_range(lua_State *L, int arg, const char *call, double range[2]);

/* render.field and render.points onto the render table at idx (lua_render_field.c). */
void bind_open_render_fields(lua_State *L, int idx);

#endif
