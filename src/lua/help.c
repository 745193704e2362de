/* The doc registry behind help(): a weak-keyed table in the registry mapping an API object
 * (function, module table, or a userdata type's metatable) to {name, usage, doc}. */
#include "lua/bind.h"

static const char *DOCS = "grainlab.docs";

static void push_docs(lua_State *L)
{
    if (lua_getfield(L, LUA_REGISTRYINDEX, DOCS) == LUA_TTABLE)
        return;
    lua_pop(L, 1);
    lua_newtable(L);
    lua_newtable(L);
    lua_pushliteral(L, "k");
    lua_setfield(L, -2, "__mode");
    lua_setmetatable(L, -2);
    lua_pushvalue(L, -1);
    lua_setfield(L, LUA_REGISTRYINDEX, DOCS);
}

void bind_doc(lua_State *L, int idx, const char *name, const char *usage, const char *doc)
{
    idx = lua_absindex(L, idx);
    push_docs(L);
    lua_pushvalue(L, idx);
    lua_createtable(L, 0, 3);
    lua_pushstring(L, name);
    lua_setfield(L, -2, "name");
    lua_pushstring(L, usage ? usage : name);
    lua_setfield(L, -2, "usage");
    lua_pushstring(L, doc ? doc : "");
    lua_setfield(L, -2, "doc");
    lua_rawset(L, -3);
    lua_pop(L, 1);
}

void bind_register(lua_State *L, int idx, const bind_fn *fns)
{
    idx = lua_absindex(L, idx);
    for (; fns->name; fns++) {
        lua_pushcfunction(L, fns->fn);
        bind_doc(L, -1, fns->name, fns->usage, fns->doc);
        lua_setfield(L, idx, fns->name);
    }
}

void bind_new_type(lua_State *L, const char *tname, const bind_fn *methods, const luaL_Reg *meta,
                   const char *doc)
{
    luaL_newmetatable(L, tname);
    bind_doc(L, -1, tname, tname, doc);
    lua_newtable(L);
    bind_register(L, -1, methods);
    lua_setfield(L, -2, "__index");
    if (meta)
        luaL_setfuncs(L, meta, 0);
    lua_pop(L, 1);
}

/* grainlab.doc(obj, { name = , usage = , doc = }): documents a Lua-side API object. */
static int l_doc(lua_State *L)
{
    luaL_checkany(L, 1);
    bind_check_table(L, 2, "doc");
    static const char *const fields[] = {"name", "usage", "doc", NULL};
    bind_check_fields(L, 2, "doc", fields);
    const char *name = bind_field_string(L, 2, "doc", "name", NULL, BIND_REQUIRED);
    const char *usage = bind_field_string(L, 2, "doc", "usage", name, 0);
    const char *doc = bind_field_string(L, 2, "doc", "doc", "", 0);
    bind_doc(L, 1, name, usage, doc);
    lua_settop(L, 1);
    return 1;
}

/* grainlab.doc_of(obj) -> {name, usage, doc} or nil (help.lua reads the registry through it). */
static int l_doc_of(lua_State *L)
{
    luaL_checkany(L, 1);
    push_docs(L);
    lua_pushvalue(L, 1);
    lua_rawget(L, -2);
    return 1;
}

void bind_open_help(lua_State *L, int idx)
{
    static const bind_fn fns[] = {
        {"doc", l_doc, "grainlab.doc(obj, { name = 'x', usage = 'x(a, b)', doc = 'what it does' })",
         "Documents a Lua function, table or type so that help(obj) shows it. Returns obj."},
        {"doc_of", l_doc_of, "grainlab.doc_of(obj)",
         "The documentation record {name, usage, doc} of obj, or nil."},
        {NULL, NULL, NULL, NULL}};
    bind_register(L, idx, fns);
}
