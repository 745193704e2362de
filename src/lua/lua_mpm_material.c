/* mpm.material{...}: the materials of the MPM engine (src/mpm/material.c), checked field by
 * field per model, and the read-only mpm.material type. */
#include <stdio.h>
#include <string.h>

#include "lua/lua_mpm.h"

static const char *MATERIAL = "mpm.material";

static const char *const MODEL_NAMES[] = {"elastic", "vonmises", "drucker_prager", "mu_i", NULL};

static const char *const MATERIAL_FIELDS[] = {
    "model",    "density",   "shear",    "bulk", "yield", "hardening",      "friction",
    "dilatancy", "cohesion", "mu_s",     "mu_2", "i0",    "grain_diameter", "grain_density",
    NULL};

/* The fields of each model beyond density, shear and bulk: any other one present is refused. */
static const char *const MODEL_FIELDS[][6] = {
    {NULL},
    {"yield", "hardening", NULL},
    {"friction", "dilatancy", "cohesion", NULL},
    {"mu_s", "mu_2", "i0", "grain_diameter", "grain_density", NULL}};

/* Refuses a field the model does not take, naming the models that do. */
static void refuse_other_fields(lua_State *L, mpm_model model)
{
    static const char *const own[] = {"", "'vonmises'", "'drucker_prager'", "'mu_i'"};
    for (int k = 1; k < 4; k++) {
        if (k == (int)model)
            continue;
        for (int f = 0; MODEL_FIELDS[k][f]; f++) {
            if (lua_getfield(L, 1, MODEL_FIELDS[k][f]) != LUA_TNIL) {
                char expected[96];
                snprintf(expected, sizeof expected,
                         "nothing for model '%s' (use field 'model' = %s)", MODEL_NAMES[model],
                         own[k]);
                bind_field_error(L, 1, "material", MODEL_FIELDS[k][f], expected);
            }
            lua_pop(L, 1);
        }
    }
}

/* An angle field in degrees in (lo, hi), or [lo, hi] with closed; hi_name names the upper
 * bound in the message when it is another field's value. */
static double angle_in(lua_State *L, const char *field, unsigned flags, double lo, double hi,
                       bool closed, const char *hi_name)
{
    const double v = bind_field_number(L, 1, "material", field, 0, flags);
    if (closed ? (v >= lo && v <= hi) : (v > lo && v < hi))
        return v;
    lua_getfield(L, 1, field);
    char expected[128];
    snprintf(expected, sizeof expected, "angle in degrees in %c%g, %s%s%g%c", closed ? '[' : '(',
             lo, hi_name ? hi_name : "", hi_name ? " = " : "", hi, closed ? ']' : ')');
    return bind_field_error(L, 1, "material", field, expected);
}

static int l_material(lua_State *L)
{
    bind_check_table(L, 1, "material");
    bind_check_fields(L, 1, "material", MATERIAL_FIELDS);
    mpm_material m = mpm_default_material();
    m.model = (mpm_model)bind_field_option(L, 1, "material", "model", MODEL_NAMES, MPM_ELASTIC, 0);
    m.density = bind_field_number(L, 1, "material", "density", 0, BIND_REQUIRED | BIND_POSITIVE);
    m.shear = bind_field_number(L, 1, "material", "shear", 0, BIND_REQUIRED | BIND_POSITIVE);
    m.bulk = bind_field_number(L, 1, "material", "bulk", 0, BIND_REQUIRED | BIND_POSITIVE);
    refuse_other_fields(L, m.model);
    if (m.model == MPM_VONMISES) {
        m.yield = bind_field_number(L, 1, "material", "yield", 0, BIND_REQUIRED | BIND_POSITIVE);
        m.hardening = bind_field_number(L, 1, "material", "hardening", 0, BIND_NONNEG);
    } else if (m.model == MPM_DRUCKER_PRAGER) {
        m.friction = angle_in(L, "friction", BIND_REQUIRED, 0, 90, false, NULL);
        m.dilatancy = angle_in(L, "dilatancy", 0, 0, m.friction, true, "friction");
        m.cohesion = bind_field_number(L, 1, "material", "cohesion", 0, BIND_NONNEG);
    } else if (m.model == MPM_MU_I) {
        m.mu_s = bind_field_number(L, 1, "material", "mu_s", 0, BIND_REQUIRED | BIND_POSITIVE);
        m.mu_2 = bind_field_number(L, 1, "material", "mu_2", 0, BIND_REQUIRED | BIND_POSITIVE);
        if (!(m.mu_2 > m.mu_s)) {
            lua_getfield(L, 1, "mu_2");
            char expected[96];
            snprintf(expected, sizeof expected, "number > mu_s = %g", m.mu_s);
            return bind_field_error(L, 1, "material", "mu_2", expected);
        }
        m.i0 = bind_field_number(L, 1, "material", "i0", 0.279, BIND_POSITIVE);
        m.grain_diameter =
            bind_field_number(L, 1, "material", "grain_diameter", 0, BIND_REQUIRED | BIND_POSITIVE);
        m.grain_density = bind_field_number(L, 1, "material", "grain_density", m.density / 0.6,
                                            BIND_POSITIVE);
        if (!(m.grain_density >= m.density)) {
            lua_getfield(L, 1, "grain_density");
            char expected[128];
            snprintf(expected, sizeof expected,
                     "number >= density = %g (the close-packed bulk density)", m.density);
            return bind_field_error(L, 1, "material", "grain_density", expected);
        }
    }
    core_error err;
    if (mpm_check_material(&m, &err))
        return bind_raise(L, "material", &err);
    mpm_material_prepare(&m);
    mpm_material *u = lua_newuserdatauv(L, sizeof *u, 0);
    *u = m;
    luaL_setmetatable(L, MATERIAL);
    return 1;
}

static int material_index(lua_State *L)
{
    const mpm_material *m = luaL_checkudata(L, 1, MATERIAL);
    const char *k = luaL_checkstring(L, 2);
    double E = 9 * m->bulk * m->shear / (3 * m->bulk + m->shear);
    double nu = (3 * m->bulk - 2 * m->shear) / (2 * (3 * m->bulk + m->shear));
    if (strcmp(k, "model") == 0)
        lua_pushstring(L, MODEL_NAMES[m->model]);
    else if (strcmp(k, "density") == 0)
        lua_pushnumber(L, m->density);
    else if (strcmp(k, "shear") == 0)
        lua_pushnumber(L, m->shear);
    else if (strcmp(k, "bulk") == 0)
        lua_pushnumber(L, m->bulk);
    else if (strcmp(k, "yield") == 0)
        lua_pushnumber(L, m->yield);
    else if (strcmp(k, "hardening") == 0)
        lua_pushnumber(L, m->hardening);
    else if (m->model == MPM_DRUCKER_PRAGER && strcmp(k, "friction") == 0)
        lua_pushnumber(L, m->friction);
    else if (m->model == MPM_DRUCKER_PRAGER && strcmp(k, "dilatancy") == 0)
        lua_pushnumber(L, m->dilatancy);
    else if (m->model == MPM_DRUCKER_PRAGER && strcmp(k, "cohesion") == 0)
        lua_pushnumber(L, m->cohesion);
    else if (m->model == MPM_DRUCKER_PRAGER && strcmp(k, "eta") == 0)
        lua_pushnumber(L, m->dp[0]);
    else if (m->model == MPM_DRUCKER_PRAGER && strcmp(k, "xi") == 0)
        lua_pushnumber(L, m->dp[1]);
    else if (m->model == MPM_DRUCKER_PRAGER && strcmp(k, "etabar") == 0)
        lua_pushnumber(L, m->dp[2]);
    else if (m->model == MPM_MU_I && strcmp(k, "mu_s") == 0)
        lua_pushnumber(L, m->mu_s);
    else if (m->model == MPM_MU_I && strcmp(k, "mu_2") == 0)
        lua_pushnumber(L, m->mu_2);
    else if (m->model == MPM_MU_I && strcmp(k, "i0") == 0)
        lua_pushnumber(L, m->i0);
    else if (m->model == MPM_MU_I && strcmp(k, "grain_diameter") == 0)
        lua_pushnumber(L, m->grain_diameter);
    else if (m->model == MPM_MU_I && strcmp(k, "grain_density") == 0)
        lua_pushnumber(L, m->grain_density);
    else if (strcmp(k, "young") == 0)
        lua_pushnumber(L, E);
    else if (strcmp(k, "poisson") == 0)
        lua_pushnumber(L, nu);
    else if (strcmp(k, "wave_speed") == 0)
        lua_pushnumber(L, mpm_wave_speed(m));
    else
        lua_pushnil(L);
    return 1;
}

/* A material is shared by every grain made of it: changing it afterwards would change them
 * behind the scene's back, so it is read-only. */
static int material_newindex(lua_State *L)
{
    char key[64];
    bind_describe(L, 2, key, sizeof key);
    return luaL_error(L,
                      "an mpm.material is read-only: field %s cannot be set (make a new one "
                      "with mpm.material{...})",
                      key);
}

static int material_tostring(lua_State *L)
{
    const mpm_material *m = luaL_checkudata(L, 1, MATERIAL);
    char buf[256];
    if (m->model == MPM_VONMISES)
        snprintf(buf, sizeof buf,
                 "mpm.material vonmises (density %g, shear %g, bulk %g, yield %g, "
                 "hardening %g)",
                 m->density, m->shear, m->bulk, m->yield, m->hardening);
    else if (m->model == MPM_DRUCKER_PRAGER)
        snprintf(buf, sizeof buf,
                 "mpm.material drucker_prager (density %g, shear %g, bulk %g, friction %g deg, "
                 "dilatancy %g deg, cohesion %g)",
                 m->density, m->shear, m->bulk, m->friction, m->dilatancy, m->cohesion);
    else if (m->model == MPM_MU_I)
        snprintf(buf, sizeof buf,
                 "mpm.material mu_i (density %g, shear %g, bulk %g, mu_s %g, mu_2 %g, i0 %g, "
                 "grain_diameter %g, grain_density %g)",
                 m->density, m->shear, m->bulk, m->mu_s, m->mu_2, m->i0, m->grain_diameter,
                 m->grain_density);
    else
        snprintf(buf, sizeof buf, "mpm.material elastic (density %g, shear %g, bulk %g)",
                 m->density, m->shear, m->bulk);
    lua_pushstring(L, buf);
    return 1;
}

void bind_open_mpm_material(lua_State *L, int idx)
{
    idx = lua_absindex(L, idx);
    luaL_newmetatable(L, MATERIAL);
    bind_doc(L, -1, MATERIAL, MATERIAL,
             "An MPM material from mpm.material{...}; read-only fields model, density, shear, "
             "bulk, yield, hardening, young, poisson, wave_speed; drucker_prager: friction, "
             "dilatancy (degrees), cohesion, eta, xi, etabar; mu_i: mu_s, mu_2, i0, "
             "grain_diameter, grain_density.");
    lua_pushcfunction(L, material_index);
    lua_setfield(L, -2, "__index");
    lua_pushcfunction(L, material_tostring);
    lua_setfield(L, -2, "__tostring");
    lua_pushcfunction(L, material_newindex);
    lua_setfield(L, -2, "__newindex");
    lua_pop(L, 1);

    static const bind_fn fns[] = {
        {"material", l_material,
         "mpm.material{ model = 'elastic'|'vonmises'|'drucker_prager'|'mu_i', density =, shear "
         "=, bulk =, yield =, hardening = 0, friction =, dilatancy = 0, cohesion = 0, mu_s =, "
         "mu_2 =, i0 = 0.279, grain_diameter =, grain_density = density / 0.6 }",
         "An MPM material: Hencky (log-strain) hyperelastic, tau = K ln J I + 2 G dev ln V_e, "
         "objective under large rotations and with a stored energy; 'vonmises' adds J2 "
         "plasticity with linear isotropic hardening (q = yield + hardening eps_p, radial "
         "return). The granular continuum models describe the granular material itself: "
         "'drucker_prager' yields at sqrt(J2) = eta p + xi c (p = -tr(sigma)/3) with friction "
         "angle `friction` and dilatancy angle `dilatancy` (both in DEGREES, 0 <= dilatancy <= "
         "friction < 90; non-associated below friction) and cohesion `cohesion` (Pa), eta and "
         "xi matched to Mohr-Coulomb in plane strain (a flowing plane-strain element carries "
         "(s1 - s3)/2 = P sin(friction) + c cos(friction)); tension beyond the cone's apex "
         "returns to the apex (stress-free without cohesion). 'mu_i' is the mu(I) rheology of "
         "Jop, Forterre & Pouliquen (2006) as Dunatunga & Kamrin (2015) put it in MPM: "
         "sqrt(J2) = mu(I) p while flowing, mu(I) = mu_s + (mu_2 - mu_s) / (i0 / I + 1), I = "
         "gdot_p grain_diameter / sqrt(p / grain_density), elastic below mu_s p; density is the "
         "close-packed bulk density: compressed beyond it the pressure is -bulk ln J, dilated "
         "below it the material is disconnected and stress-free. Read-only fields: those given, "
         "young, poisson, wave_speed, and drucker_prager's eta, xi, etabar. SI units."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fn_fields[] = {{"material", NULL, MATERIAL_FIELDS},
                                            {NULL, NULL, NULL}};
    bind_register(L, idx, fns);
    bind_register_fields(L, idx, fn_fields);
}
