/* The measurements of an mpm.scene: m:field, m:measure, m:grain, m:points and m:timings, read
 * from the kernel scene (src/mpm/measure.c) into Lua tables. */
#include "lua/lua_mpm.h"

/* m:field(name) -> {nx =, ny =, values = {...} (row-major, nan in empty cells), ...} */
static int l_field(lua_State *L)
{
    static const char *const names[] = {"vx",           "vy",    "speed", "ux",   "uy",
                                        "displacement", "sxx",   "syy",   "sxy",  "pressure",
                                        "psd",          "eps_p", "grain", "mass", "rate",
                                        "inertial",     "mean_pressure", NULL};
    mpm_scene *s = bind_mpm_check(L, 1);
    int kind = bind_check_option(L, 2, NULL, names);
    const mpm_scene_def *d = mpm_def(s);
    size_t n = (size_t)d->cells[0] * (size_t)d->cells[1];
    double *v = lua_newuserdatauv(L, n * sizeof *v, 0);
    mpm_field(s, (mpm_field_kind)kind, v);
    lua_createtable(L, 0, 5);
    bind_push_array(L, v, n, "values");
    lua_pushinteger(L, d->cells[0]);
    lua_setfield(L, -2, "nx");
    lua_pushinteger(L, d->cells[1]);
    lua_setfield(L, -2, "ny");
    bind_mpm_push_pair(L, d->origin);
    lua_setfield(L, -2, "origin");
    bind_mpm_push_pair(L, d->size);
    lua_setfield(L, -2, "size");
    return 1;
}

/* No mode of m:measure takes options: a table given to it may hold no key. */
static const char *const NO_FIELDS[] = {NULL};

static int l_measure(lua_State *L)
{
    static const char *const what_names[] = {"energy", "momentum", "columns", "shear", NULL};
    mpm_scene *s = bind_mpm_check(L, 1);
    int what = bind_check_option(L, 2, NULL, what_names);
    bind_mode_options(L, 3, "measure", what_names[what], NO_FIELDS);
    if (what == 2) {
        const int nx = mpm_def(s)->cells[0];
        double *c = lua_newuserdatauv(L, (size_t)nx * sizeof *c, 0);
        mpm_column_uy(s, c);
        lua_createtable(L, 0, 2);
        bind_push_array(L, c, (size_t)nx, "uy");
        double h[2];
        mpm_cell_size(s, h);
        lua_createtable(L, nx, 0);
        for (int i = 0; i < nx; i++) {
            lua_pushnumber(L, mpm_def(s)->origin[0] + (i + 0.5) * h[0]);
            lua_rawseti(L, -2, i + 1);
        }
        lua_setfield(L, -2, "x");
        return 1;
    }
    if (what == 3) {
        lua_pushnumber(L, mpm_shear_strain(s));
        return 1;
    }
    if (what == 0) {
        mpm_energy e;
        mpm_measure_energy(s, &e);
        lua_createtable(L, 0, 5);
        bind_mpm_set_number(L, "kinetic", e.kinetic);
        bind_mpm_set_number(L, "elastic", e.elastic);
        bind_mpm_set_number(L, "plastic", e.plastic);
        bind_mpm_set_number(L, "potential", e.potential);
        bind_mpm_set_number(L, "total", e.total);
        return 1;
    }
    double p[2], lz;
    mpm_measure_momentum(s, p, &lz);
    lua_createtable(L, 0, 2);
    bind_mpm_push_pair(L, p);
    lua_setfield(L, -2, "linear");
    bind_mpm_set_number(L, "angular", lz);
    return 1;
}

static int l_grain(lua_State *L)
{
    mpm_scene *s = bind_mpm_check(L, 1);
    size_t id = bind_mpm_grain_arg(L, s, 2, "grain");
    mpm_grain_info g;
    core_error err;
    if (mpm_grain(s, id, &g, &err))
        return bind_raise(L, "grain", &err);
    lua_createtable(L, 0, 7);
    bind_mpm_set_number(L, "mass", g.mass);
    bind_mpm_push_pair(L, g.center);
    lua_setfield(L, -2, "center");
    bind_mpm_push_pair(L, g.velocity);
    lua_setfield(L, -2, "velocity");
    bind_mpm_set_number(L, "angular_momentum", g.angular_momentum);
    bind_mpm_set_number(L, "inertia", g.inertia);
    bind_mpm_set_number(L, "omega", g.omega);
    lua_pushinteger(L, (lua_Integer)g.points);
    lua_setfield(L, -2, "points");
    return 1;
}

static int l_points(lua_State *L)
{
    mpm_scene *s = bind_mpm_check(L, 1);
    size_t n = mpm_point_count(s);
    mpm_points p;
    mpm_get_points(s, &p);
    lua_createtable(L, 0, 16);
    bind_push_array(L, p.x, n, "x");
    bind_push_array(L, p.y, n, "y");
    bind_push_array(L, p.vx, n, "vx");
    bind_push_array(L, p.vy, n, "vy");
    bind_push_array(L, p.mass, n, "mass");
    static const char *const sig[4] = {"sxx", "syy", "sxy", "szz"};
    static const char *const F[4] = {"Fxx", "Fxy", "Fyx", "Fyy"};
    for (int k = 0; k < 4; k++) {
        bind_push_array(L, p.sigma[k], n, sig[k]);
        bind_push_array(L, p.F[k], n, F[k]);
    }
    bind_push_array(L, p.eps_p, n, "eps_p");
    if (p.rate)
        bind_push_array(L, p.rate, n, "rate");
    bind_push_array(L, p.ux, n, "ux");
    bind_push_array(L, p.uy, n, "uy");
    lua_createtable(L, (int)n, 0);
    for (size_t i = 0; i < n; i++) {
        lua_pushinteger(L, p.grain[i] + 1);
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_setfield(L, -2, "grain");
    lua_createtable(L, (int)n, 0);
    for (size_t i = 0; i < n; i++) {
        double J = p.F[0][i] * p.F[3][i] - p.F[1][i] * p.F[2][i];
        lua_pushnumber(L, p.volume0[i] * J);
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_setfield(L, -2, "volume");
    lua_pushinteger(L, (lua_Integer)n);
    lua_setfield(L, -2, "count");
    return 1;
}

static int l_timings(lua_State *L)
{
    mpm_scene *s = bind_mpm_check(L, 1);
    double sec[MPM_NSTAGES], total = 0;
    long steps;
    mpm_timings(s, sec, &steps);
    lua_createtable(L, 0, MPM_NSTAGES + 2);
    for (int k = 0; k < MPM_NSTAGES; k++) {
        bind_mpm_set_number(L, mpm_stage_names[k], sec[k]);
        total += sec[k];
    }
    bind_mpm_set_number(L, "total", total);
    lua_pushinteger(L, steps);
    lua_setfield(L, -2, "steps");
    return 1;
}

void bind_open_mpm_measure(lua_State *L)
{
    static const bind_fn methods[] = {
        {"field", l_field,
         "m:field('vx'|'vy'|'speed'|'ux'|'uy'|'displacement'|'sxx'|'syy'|'sxy'|'pressure'|'psd'|"
         "'eps_p'|'grain'|'mass'|'rate'|'inertial'|'mean_pressure')",
         "A cell field: the mass-weighted mean over the points in each cell (nan in empty "
         "cells; 'mass' sums). psd is the principal stress difference sigma_1 - sigma_2, "
         "pressure the in-plane -(sxx + syy)/2, mean_pressure -(sxx + syy + szz)/3 (the "
         "continuum models' p); rate the plastic shear rate of the last step (1/s, "
         "drucker_prager and mu_i, 0 elsewhere), inertial mu_i's inertial number I of it. "
         "Returns {nx, ny, origin, size, values} (row-major, x fastest), ready for "
         "render.field."},
        {"measure", l_measure, "m:measure('energy'|'momentum'|'columns'|'shear')",
         "energy: kinetic, elastic (Hencky stored energy), plastic (plastic work), potential "
         "(gravity), total; per unit depth (J/m). momentum: linear = {px, py}, angular (about "
         "the origin). columns: {x, uy}, the mass-weighted mean vertical displacement per "
         "column of cells (the paper's Fig. 8). shear: the material's average shear strain, "
         "the mass-weighted least-squares slope d u_y / d x of the displacements."},
        {"grain", l_grain, "m:grain(id)",
         "mass, center (centre of mass), velocity, angular_momentum (about the centre of mass), "
         "inertia, omega (= angular_momentum / inertia) and points of grain id."},
        {"points", l_points, "m:points()",
         "Arrays over the material points: x, y, vx, vy, ux, uy (displacement), mass, volume, "
         "grain, sxx, syy, sxy, szz (Cauchy stress, tension positive), Fxx, Fxy, Fyx, Fyy, "
         "eps_p; rate (plastic shear rate of the last step) in scenes with drucker_prager or "
         "mu_i materials; and count."},
        {"timings", l_timings, "m:timings()",
         "Wall seconds spent in each stage of the step, summed over the steps run since the "
         "scene was created or loaded: stencil (0 with friction: p2g takes it), p2g (particle to "
         "grid, with the grain fields), "
         "normals (contact normals), grid (momentum update and walls), contact (the contact "
         "rule), g2p (grid to particle), remap (MUSL), material (stress update), check (the "
         "end-of-step checks); total, and steps. Read on thread 0 once per stage per step "
         "(scripts/bench/mpm_shear.lua prints them)."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields method_fields[] = {{"measure", "energy", NO_FIELDS},
                                                {"measure", "momentum", NO_FIELDS},
                                                {"measure", "columns", NO_FIELDS},
                                                {"measure", "shear", NO_FIELDS},
                                                {NULL, NULL, NULL}};
    luaL_getmetatable(L, "mpm.scene");
    lua_getfield(L, -1, "__index");
    bind_register(L, lua_gettop(L), methods);
    lua_pop(L, 2);
    bind_type_fields(L, "mpm.scene", method_fields);
}
