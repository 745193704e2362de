/* LAMMPS files from Lua: dem.read_lammps_data creates a scene from a data file; the dem.scene
 * methods read_lammps_data, write_lammps_data and write_lammps_dump add to, save and dump one.
 * Kernels in src/dem/lammps.c; this file maps atom types to grainlab.material tables. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dem/dem.h"
#include "lua/bind.h"

void bind_open_lammps(lua_State *L);

static const char *const DENSITY_NAMES[] = {"strict", "file", "material", NULL};
static const char *const SCENE_READ_FIELDS[] = {"types", "material", "density", "fixed_types",
                                                NULL};
static const char *const READ_FIELDS[] = {"types",   "material", "density",   "fixed_types", "dim",
                                          "gravity", "periodic", "thickness", "skin",        NULL};
static const char *const DATA_FIELDS[] = {"types", "title", NULL};
static const char *const DUMP_FIELDS[] = {"types", "append", NULL};

/* The parsed file lives in a userdata so that a Lua error anywhere frees it. */
static int data_gc(lua_State *L)
{
    dem_lammps_free(lua_touserdata(L, 1));
    return 0;
}

static dem_lammps_data *new_data(lua_State *L)
{
    dem_lammps_data *d = lua_newuserdatauv(L, sizeof *d, 0);
    memset(d, 0, sizeof *d);
    if (luaL_newmetatable(L, "dem.lammps_data")) {
        lua_pushcfunction(L, data_gc);
        lua_setfield(L, -2, "__gc");
    }
    lua_setmetatable(L, -2);
    return d;
}

static int is_material(lua_State *L, int idx)
{
    if (lua_type(L, idx) != LUA_TTABLE || !luaL_getmetafield(L, idx, "__name"))
        return 0;
    int ok =
        lua_type(L, -1) == LUA_TSTRING && strcmp(lua_tostring(L, -1), "grainlab.material") == 0;
    lua_pop(L, 1);
    return ok;
}

static dem_material material_of(lua_State *L, int idx)
{
    idx = lua_absindex(L, idx);
    dem_material m = dem_default_material();
    static const char *const f[] = {"density",  "young",       "poisson",
                                    "friction", "restitution", "rolling_friction"};
    double *dst[] = {&m.density,  &m.young,       &m.poisson,
                     &m.friction, &m.restitution, &m.rolling_friction};
    for (int k = 0; k < 6; k++) {
        lua_getfield(L, idx, f[k]);
        *dst[k] = lua_tonumber(L, -1);
        lua_pop(L, 1);
    }
    return m;
}

/* Reads the read options common to both entry points into types[ntypes]; leaves the types table
 * (or nil) at *types_idx and the material (or nil) at *mat_idx for registering afterwards. */
static void read_type_options(lua_State *L, int opts, const char *call, int ntypes,
                              dem_lammps_type *types, int *types_idx, int *mat_idx)
{
    int policy = opts ? bind_field_option(L, opts, call, "density", DENSITY_NAMES, 0, 0) : 0;
    dem_lammps_density explicit = (dem_lammps_density)policy;
    for (int t = 0; t < ntypes; t++) {
        types[t].mapped = 1;
        types[t].material = dem_default_material();
        types[t].density = DEM_LAMMPS_DENSITY_FILE; /* no material named: the file's density */
        types[t].flags = 0;
    }
    if (opts)
        lua_getfield(L, opts, "material");
    else
        lua_pushnil(L);
    *mat_idx = lua_gettop(L);
    if (!lua_isnil(L, -1)) {
        if (!is_material(L, -1))
            bind_field_error(L, opts, call, "material", "grainlab.material");
        for (int t = 0; t < ntypes; t++) {
            types[t].material = material_of(L, *mat_idx);
            types[t].density = explicit;
        }
    }
    if (opts)
        lua_getfield(L, opts, "types");
    else
        lua_pushnil(L);
    *types_idx = lua_gettop(L);
    if (!lua_isnil(L, -1)) {
        if (lua_type(L, -1) != LUA_TTABLE)
            bind_field_error(L, opts, call, "types", "table { [type] = grainlab.material }");
        if (lua_isnil(L, *mat_idx)) /* a map without a fallback: unmapped types are errors */
            for (int t = 0; t < ntypes; t++)
                types[t].mapped = 0;
        lua_pushnil(L);
        while (lua_next(L, *types_idx)) {
            char field[64];
            lua_Integer t = lua_isinteger(L, -2) ? lua_tointeger(L, -2) : 0;
            if (t < 1 || t > ntypes) {
                char key[48], expected[96];
                bind_describe(L, -2, key, sizeof key);
                snprintf(expected, sizeof expected, "atom types in [1, %d] (the file's) as keys",
                         ntypes);
                lua_pushvalue(L, -2);
                bind_field_error(L, opts, call, "types", expected);
            }
            snprintf(field, sizeof field, "types[%d]", (int)t);
            if (!is_material(L, -1))
                bind_field_error(L, opts, call, field, "grainlab.material");
            types[t - 1].mapped = 1;
            types[t - 1].material = material_of(L, -1);
            types[t - 1].density = explicit;
            lua_pop(L, 1);
        }
    }
    if (!opts)
        return;
    if (lua_getfield(L, opts, "fixed_types") != LUA_TNIL) {
        if (lua_type(L, -1) != LUA_TTABLE)
            bind_field_error(L, opts, call, "fixed_types", "array of atom types");
        lua_Integer n = luaL_len(L, -1), keys = 0;
        lua_pushnil(L);
        while (lua_next(L, -2)) {
            lua_pop(L, 1);
            keys++;
        }
        if (keys != n)
            bind_field_error(L, opts, call, "fixed_types", "array of atom types");
        for (lua_Integer k = 1; k <= n; k++) {
            lua_rawgeti(L, -1, k);
            lua_Integer t = lua_isinteger(L, -1) ? lua_tointeger(L, -1) : 0;
            if (t < 1 || t > ntypes) {
                char expected[64];
                snprintf(expected, sizeof expected, "atom types in [1, %d]", ntypes);
                bind_field_error(L, opts, call, "fixed_types", expected);
            }
            types[t - 1].flags |= DEM_FIXED;
            lua_pop(L, 1);
        }
    }
    lua_pop(L, 1);
}

/* After a successful load: the Lua materials now stand for these scene materials (so that a
 * later add_disk{ material = m } shares them). */
static void register_materials(lua_State *L, int scene, const dem_lammps_data *d,
                               const dem_lammps_type *types, const int *type_material,
                               int types_idx, int mat_idx)
{
    lua_getiuservalue(L, scene, 1);
    int map = lua_gettop(L);
    for (int t = 0; t < d->ntypes; t++) {
        if (type_material[t] < 0 || !types[t].mapped)
            continue;
        int have = 0;
        if (!lua_isnil(L, types_idx)) {
            lua_rawgeti(L, types_idx, t + 1);
            have = !lua_isnil(L, -1);
            if (!have)
                lua_pop(L, 1);
        }
        if (!have && !lua_isnil(L, mat_idx)) {
            lua_pushvalue(L, mat_idx);
            have = 1;
        }
        if (!have)
            continue;
        lua_pushvalue(L, -1);
        if (lua_rawget(L, map) == LUA_TNIL) {
            lua_pop(L, 1);
            lua_pushinteger(L, type_material[t]);
            lua_rawset(L, map);
        } else {
            lua_pop(L, 2);
        }
    }
    lua_pop(L, 1);
}

static void push_info(lua_State *L, const dem_lammps_data *d, size_t first)
{
    lua_createtable(L, 0, 8);
    lua_pushinteger(L, (lua_Integer)d->n);
    lua_setfield(L, -2, "count");
    lua_pushinteger(L, (lua_Integer)first + 1);
    lua_setfield(L, -2, "first");
    lua_pushinteger(L, (lua_Integer)(first + d->n));
    lua_setfield(L, -2, "last");
    lua_pushinteger(L, d->ntypes);
    lua_setfield(L, -2, "atom_types");
    lua_pushstring(L, d->title);
    lua_setfield(L, -2, "title");
    lua_pushboolean(L, d->has_velocities);
    lua_setfield(L, -2, "velocities");
    lua_createtable(L, (int)d->n, 0);
    for (size_t k = 0; k < d->n; k++) {
        lua_pushinteger(L, (lua_Integer)d->id[k]);
        lua_rawseti(L, -2, (lua_Integer)k + 1);
    }
    lua_setfield(L, -2, "ids");
    lua_createtable(L, (int)d->n, 0);
    for (size_t k = 0; k < d->n; k++) {
        lua_pushinteger(L, d->type[k]);
        lua_rawseti(L, -2, (lua_Integer)k + 1);
    }
    lua_setfield(L, -2, "types");
    lua_createtable(L, 2, 0);
    for (int c = 0; c < 2; c++) {
        lua_createtable(L, 3, 0);
        for (int a = 0; a < 3; a++) {
            lua_pushnumber(L, c ? d->hi[a] : d->lo[a]);
            lua_rawseti(L, -2, a + 1);
        }
        lua_rawseti(L, -2, c + 1);
    }
    lua_setfield(L, -2, "box");
}

/* Loads the parsed file into the scene at index `scene`; pushes the info table. */
static void load(lua_State *L, int scene, int opts, const char *call, dem_lammps_data *d)
{
    dem_scene *s = bind_check_dem_scene(L, scene, call);
    size_t nt = (size_t)d->ntypes;
    dem_lammps_type *types = lua_newuserdatauv(L, nt * sizeof *types, 0);
    int *type_material = lua_newuserdatauv(L, nt * sizeof *type_material, 0);
    int types_idx, mat_idx;
    read_type_options(L, opts, call, d->ntypes, types, &types_idx, &mat_idx);
    for (size_t k = 0; k < d->n; k++)
        if (!types[d->type[k] - 1].mapped) {
            char expected[160];
            snprintf(expected, sizeof expected,
                     "a grainlab.material for atom type %d (atom %lld, %s line %ld), or the "
                     "field 'material'",
                     d->type[k], d->id[k], d->path, d->line[k]);
            lua_pushvalue(L, types_idx);
            bind_field_error(L, opts, call, "types", expected);
        }
    size_t first;
    core_error err;
    if (dem_lammps_add(s, d, types, type_material, &first, &err) != CORE_OK)
        bind_raise(L, call, &err);
    register_materials(L, scene, d, types, type_material, types_idx, mat_idx);
    push_info(L, d, first);
}

static dem_lammps_data *parse_file(lua_State *L, const char *path, const char *call)
{
    dem_lammps_data *d = new_data(L);
    core_error err;
    if (dem_lammps_read(path, d, &err) != CORE_OK)
        bind_raise(L, call, &err);
    return d;
}

/* s:read_lammps_data(path, opts) -> info */
static int l_scene_read(lua_State *L)
{
    const char *call = "read_lammps_data";
    bind_check_dem_scene(L, 1, call);
    bind_refuse_running(L, 1, call,
                        "new particles can shorten the stability limit the run's dt was checked "
                        "at: read the file between runs");
    const char *path = bind_arg_path(L, 2, call);
    int opts = 0;
    if (!lua_isnoneornil(L, 3)) {
        bind_check_table(L, 3, call);
        bind_check_fields(L, 3, call, SCENE_READ_FIELDS);
        opts = 3;
    }
    lua_settop(L, 3);
    dem_lammps_data *d = parse_file(L, path, call);
    load(L, 1, opts, call, d);
    return 1;
}

/* dem.read_lammps_data(path, opts) -> scene, info */
static int l_read(lua_State *L)
{
    const char *call = "read_lammps_data";
    const char *path = bind_arg_path(L, 1, call);
    int opts = 0;
    if (!lua_isnoneornil(L, 2)) {
        bind_check_table(L, 2, call);
        bind_check_fields(L, 2, call, READ_FIELDS);
        opts = 2;
    }
    lua_settop(L, 2);
    dem_lammps_data *d = parse_file(L, path, call); /* 3 */
    int dim = d->flat ? 2 : 3;
    if (opts)
        dim = (int)bind_field_integer(L, opts, call, "dim", dim, 2, 3, 0);
    if (dim == 2 && !(d->lo[2] < 0 && d->hi[2] > 0)) {
        char msg[160];
        snprintf(msg, sizeof msg, "a 2D file needs zlo < 0 < zhi (as LAMMPS does), got %g %g",
                 d->lo[2], d->hi[2]);
        luaL_error(L, "%s: %s: %s", call, path, msg);
    }
    /* The scene through dem.scene{...}, so that it is made and checked as any other. */
    lua_getglobal(L, "dem");
    lua_getfield(L, -1, "scene");
    lua_createtable(L, 0, 6);
    lua_pushinteger(L, dim);
    lua_setfield(L, -2, "dim");
    lua_createtable(L, 2, 0);
    for (int c = 0; c < 2; c++) {
        lua_createtable(L, dim, 0);
        for (int a = 0; a < dim; a++) {
            lua_pushnumber(L, c ? d->hi[a] : d->lo[a]);
            lua_rawseti(L, -2, a + 1);
        }
        lua_rawseti(L, -2, c + 1);
    }
    lua_setfield(L, -2, "box");
    static const char *const pass[] = {"gravity", "periodic", "thickness", "skin", NULL};
    for (int k = 0; opts && pass[k]; k++) {
        lua_getfield(L, opts, pass[k]);
        lua_setfield(L, -2, pass[k]);
    }
    if (lua_pcall(L, 1, 1, 0) != LUA_OK) {
        /* dem.scene's checks of gravity, periodic, thickness, skin, said as this call's */
        const char *m = luaL_tolstring(L, -1, NULL);
        m = luaL_gsub(L, m, "argument #1 to 'scene'", "argument #2 to 'read_lammps_data'");
        if (strncmp(m, "scene: ", 7) == 0)
            lua_pushfstring(L, "%s: %s", call, m + 7);
        return lua_error(L);
    }
    int scene = lua_gettop(L);
    load(L, scene, opts, call, d);
    lua_pushvalue(L, scene);
    lua_insert(L, -2);
    return 2;
}

/* Reads the write options: the types map into type_of_material (a userdata left on the stack). */
static void write_options(lua_State *L, dem_scene *s, int opts, const char *call,
                          dem_lammps_write_def *def)
{
    memset(def, 0, sizeof *def);
    if (!opts || lua_getfield(L, opts, "types") == LUA_TNIL) {
        if (opts)
            lua_pop(L, 1);
        return;
    }
    if (lua_type(L, -1) != LUA_TTABLE)
        bind_field_error(L, opts, call, "types", "table { [type] = grainlab.material }");
    int tmap = lua_gettop(L);
    int nmat = dem_material_count(s);
    int *tom = lua_newuserdatauv(L, (size_t)(nmat ? nmat : 1) * sizeof *tom, 0);
    for (int k = 0; k < nmat; k++)
        tom[k] = 0;
    lua_getiuservalue(L, 1, 1); /* grainlab.material -> material index */
    int map = lua_gettop(L);
    int top = 0;
    lua_pushnil(L);
    while (lua_next(L, tmap)) {
        lua_Integer t = lua_isinteger(L, -2) ? lua_tointeger(L, -2) : 0;
        if (t < 1 || t > 1000000) {
            lua_pushvalue(L, -2);
            bind_field_error(L, opts, call, "types", "positive integer keys (atom types)");
        }
        char field[64];
        snprintf(field, sizeof field, "types[%d]", (int)t);
        if (!is_material(L, -1))
            bind_field_error(L, opts, call, field, "grainlab.material");
        if (t > top)
            top = (int)t;
        lua_pushvalue(L, -1);
        if (lua_rawget(L, map) == LUA_TNUMBER) { /* a material the scene knows */
            int m = (int)lua_tointeger(L, -1);
            if (m >= 0 && m < nmat) {
                if (tom[m] && tom[m] != t) {
                    char expected[96];
                    snprintf(expected, sizeof expected,
                             "a material other than types[%d]'s (one type per material)", tom[m]);
                    bind_field_error(L, opts, call, field, expected);
                }
                tom[m] = (int)t;
            }
        }
        lua_pop(L, 2);
    }
    lua_pop(L, 1); /* map */
    /* Every particle's material needs a type: say so here, naming the field. */
    const int *pm = dem_particle_materials(s);
    for (size_t i = 0; i < dem_count(s); i++)
        if (tom[pm[i]] == 0) {
            char expected[128];
            snprintf(expected, sizeof expected,
                     "a type for every particle's material (particle %zu's has none)", i + 1);
            lua_pushvalue(L, tmap);
            bind_field_error(L, opts, call, "types", expected);
        }
    lua_remove(L, tmap);
    def->type_of_material = tom;
    def->ntypes = top;
}

static int write_common(lua_State *L, int dump)
{
    const char *call = dump ? "write_lammps_dump" : "write_lammps_data";
    dem_scene *s = bind_check_dem_scene(L, 1, call);
    const char *path = bind_arg_path(L, 2, call);
    int opts = 0;
    if (!lua_isnoneornil(L, 3)) {
        bind_check_table(L, 3, call);
        bind_check_fields(L, 3, call, dump ? DUMP_FIELDS : DATA_FIELDS);
        opts = 3;
    }
    lua_settop(L, 3);
    dem_lammps_write_def def;
    write_options(L, s, opts, call, &def);
    if (opts && !dump)
        def.title = bind_field_string(L, opts, call, "title", NULL, 0);
    if (opts && dump)
        def.append = bind_field_boolean(L, opts, call, "append", 0);
    core_error err;
    core_status st = dump ? dem_write_lammps_dump(s, path, &def, &err)
                          : dem_write_lammps_data(s, path, &def, &err);
    if (st != CORE_OK)
        return bind_raise(L, call, &err);
    return 0;
}

static int l_write_data(lua_State *L) { return write_common(L, 0); }
static int l_write_dump(lua_State *L) { return write_common(L, 1); }

void bind_open_lammps(lua_State *L)
{
    static const bind_fn methods[] = {
        {"read_lammps_data", l_scene_read,
         "s:read_lammps_data(path, { types = { [1] = m1, ... }, material = m, density = "
         "'strict'|'file'|'material', fixed_types = {...} })",
         "Adds the atoms of a LAMMPS data file (atom_style sphere; LIGGGHTS: granular) to the "
         "scene, in atom-id order; all or nothing. types maps atom types to grainlab.materials, "
         "material is the one for every other type; with neither, grainlab's default material "
         "with each atom's density. density: 'strict' (a mapped material's density must be the "
         "file's), 'file' (a copy of the material per density), 'material' (the file's is "
         "ignored). fixed_types: those atoms become fixed particles. Returns {count, first, "
         "last, ids (LAMMPS ids in grainlab order), types, atom_types, box, title, velocities}."},
        {"write_lammps_data", l_write_data,
         "s:write_lammps_data(path, { types = { [1] = m1, ... }, title = '...' })",
         "Writes the scene as a LAMMPS data file (atom_style sphere, with image flags and "
         "Velocities), whole. Atom type k is the scene's k-th material unless types maps them. "
         "2D: z = 0 and zlo < 0 < zhi (read it with dimension 2). A scene with clumps is "
         "written in atom_style hybrid sphere molecular (id type x y z diameter density mol) for "
         "fix rigid/small molecule: mol is the clump id of a member of a clump of two or more "
         "members, 0 for a loose grain or a one-sphere clump."},
        {"write_lammps_dump", l_write_dump,
         "s:write_lammps_dump(path, { types = {...}, append = false })",
         "Writes one `dump custom` frame (id type radius mass x y z vx vy vz fx fy fz omegax "
         "omegay omegaz; with clumps, mol after id, as in the data file) for OVITO or LAMMPS's "
         "rerun: a new file, or with append = true added to the end (from on_step for a time "
         "series)."},
        {NULL, NULL, NULL, NULL}};
    luaL_getmetatable(L, "dem.scene");
    lua_getfield(L, -1, "__index");
    bind_register(L, lua_gettop(L), methods);
    lua_pop(L, 2);
    static const bind_fields method_fields[] = {{"read_lammps_data", NULL, SCENE_READ_FIELDS},
                                                {"write_lammps_data", NULL, DATA_FIELDS},
                                                {"write_lammps_dump", NULL, DUMP_FIELDS},
                                                {NULL, NULL, NULL}};
    bind_type_fields(L, "dem.scene", method_fields);
    static const bind_fn fns[] = {
        {"read_lammps_data", l_read,
         "dem.read_lammps_data(path, { dim =, gravity =, periodic =, thickness =, skin =, types "
         "=, material =, density = 'strict', fixed_types = })",
         "A new scene with the data file's box (x y, or x y z) holding its atoms: see "
         "s:read_lammps_data for the options on types. dim defaults to 2 when every z, vz, wx "
         "and wy is 0 and zlo < 0 < zhi, else 3; periodic, gravity, thickness and skin are "
         "dem.scene's (a data file does not say them). Returns the scene and the info table."},
        {NULL, NULL, NULL, NULL}};
    lua_getglobal(L, "dem");
    bind_register(L, lua_gettop(L), fns);
    static const bind_fields fn_fields[] = {{"read_lammps_data", NULL, READ_FIELDS},
                                            {NULL, NULL, NULL}};
    bind_register_fields(L, -1, fn_fields);
    lua_pop(L, 1);
}
