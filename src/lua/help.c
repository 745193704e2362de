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
    /* A later doc for the same object (a richer text) keeps the field lists recorded with its
     * registration: they belong to the function's checks, not to its prose. */
    lua_pushvalue(L, idx);
    if (lua_rawget(L, -4) == LUA_TTABLE) {
        lua_getfield(L, -1, "fields");
        lua_setfield(L, -3, "fields");
        lua_getfield(L, -1, "modes");
        lua_setfield(L, -3, "modes");
    }
    lua_pop(L, 1);
    lua_pushstring(L, name);
    lua_setfield(L, -2, "name");
    lua_pushstring(L, usage ? usage : name);
    lua_setfield(L, -2, "usage");
    lua_pushstring(L, doc ? doc : "");
    lua_setfield(L, -2, "doc");
    lua_rawset(L, -3);
    lua_pop(L, 1);
}

/* Pushes the doc record of the function t[name] (t at idx) or raises: a field list for a function
 * that is not registered is a bug in the binding. */
static void push_record(lua_State *L, int idx, const char *name)
{
    lua_getfield(L, idx, name);
    push_docs(L);
    lua_rotate(L, -2, 1); /* docs, fn */
    if (lua_rawget(L, -2) != LUA_TTABLE)
        luaL_error(L, "bind_register_fields: '%s' is not a documented function", name);
    lua_remove(L, -2);
}

static void push_strings(lua_State *L, const char *const *list)
{
    lua_newtable(L);
    for (int i = 0; list[i]; i++) {
        lua_pushstring(L, list[i]);
        lua_rawseti(L, -2, i + 1);
    }
}

void bind_register_fields(lua_State *L, int idx, const bind_fields *list)
{
    idx = lua_absindex(L, idx);
    for (; list->name; list++) {
        push_record(L, idx, list->name);
        if (list->mode) {
            if (lua_getfield(L, -1, "modes") != LUA_TTABLE) {
                lua_pop(L, 1);
                lua_newtable(L);
                lua_pushvalue(L, -1);
                lua_setfield(L, -3, "modes");
            }
            push_strings(L, list->fields);
            lua_setfield(L, -2, list->mode);
            lua_pop(L, 1);
        } else {
            push_strings(L, list->fields);
            lua_setfield(L, -2, "fields");
        }
        lua_pop(L, 1);
    }
}

void bind_type_fields(lua_State *L, const char *tname, const bind_fields *list)
{
    luaL_getmetatable(L, tname);
    lua_getfield(L, -1, "__index");
    bind_register_fields(L, -1, list);
    lua_pop(L, 2);
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

static const char *const DOC_FIELDS[] = {"name", "usage", "doc", "fields", NULL};

/* grainlab.doc(obj, { name = , usage = , doc = , fields = }): documents a Lua-side API object;
 * fields lists the keys of its options table (as the C bindings record them). */
static int l_doc(lua_State *L)
{
    int t1 = lua_type(L, 1); /* the registry is keyed by the object: only API objects qualify */
    if (t1 != LUA_TFUNCTION && t1 != LUA_TTABLE && t1 != LUA_TUSERDATA)
        bind_arg_error(L, 1, "doc", "function, table or userdata");
    bind_check_table(L, 2, "doc");
    bind_check_fields(L, 2, "doc", DOC_FIELDS);
    const char *name = bind_field_string(L, 2, "doc", "name", NULL, BIND_REQUIRED);
    const char *usage = bind_field_string(L, 2, "doc", "usage", name, 0);
    const char *doc = bind_field_string(L, 2, "doc", "doc", "", 0);
    int t = lua_getfield(L, 2, "fields");
    if (t != LUA_TNIL) {
        int ok = t == LUA_TTABLE;
        lua_Integer n = ok ? (lua_Integer)lua_rawlen(L, -1) : 0, keys = 0;
        for (lua_pushnil(L); ok && lua_next(L, -2); lua_pop(L, 1))
            keys++; /* {a = 'x'} is no list of names */
        ok = ok && keys == n;
        for (lua_Integer i = 1; ok && i <= n; i++) {
            ok = lua_rawgeti(L, -1, i) == LUA_TSTRING;
            lua_pop(L, 1);
        }
        if (!ok)
            return bind_field_error(L, 2, "doc", "fields", "array of strings");
    }
    lua_pop(L, 1);
    bind_doc(L, 1, name, usage, doc);
    if (t != LUA_TNIL) {
        push_docs(L);
        lua_pushvalue(L, 1);
        lua_rawget(L, -2);
        lua_getfield(L, 2, "fields");
        lua_setfield(L, -2, "fields");
        lua_pop(L, 2);
    }
    lua_settop(L, 1);
    return 1;
}

/* grainlab.doc_of(obj) -> {name, usage, doc[, fields][, modes]} or nil (help.lua reads the registry
 * through it). */
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
         "The documentation record {name, usage, doc} of obj, or nil. For a function that takes "
         "an options table, `fields` lists its keys (the very list the function checks), or "
         "`modes[m]` the keys for the mode argument m (s:measure('stress', {...}))."},
        {NULL, NULL, NULL, NULL}};
    bind_register(L, idx, fns);
    static const bind_fields fields[] = {{"doc", NULL, DOC_FIELDS}, {NULL, NULL, NULL}};
    bind_register_fields(L, idx, fields);
}
