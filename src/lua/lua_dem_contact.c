/* The dem bindings: s:contact{...}, the contact law of a scene (its laws' names from
 * src/dem/laws.h), and s:damping_time. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/progress.h"
#include "dem/dem.h"
#include "lua/bind.h"
#include "lua/lua_dem.h"

/* ---- s:contact{...} ------------------------------------------------------------------------ */
/* The laws' names: dem_normal_names and its kin, from laws.h's lists. */

static const char *const CONTACT_FIELDS[] = {"normal",
                                             "stiffness",
                                             "beta",
                                             "damping",
                                             "gamma_n",
                                             "damping_time",
                                             "restitution",
                                             "impact_velocity",
                                             "tangential",
                                             "gamma_t",
                                             "kt",
                                             "v_r",
                                             "exponent",
                                             "clip",
                                             "rolling",
                                             "rolling_resistance",
                                             "rolling_friction",
                                             "rolling_stiffness",
                                             "rolling_damping",
                                             "rolling_rate",
                                             "work_of_adhesion",
                                             "cohesion",
                                             "liquid_volume",
                                             "surface_tension",
                                             "contact_angle",
                                             NULL};

/* The normal laws whose k is s:contact's stiffness (moduli 0), or comes from the materials
 * (moduli 1), as "'linear' or 'power'" (quoted) or "hertz" (plain). */
static void normal_names_by_k(int moduli, int quoted, char *buf, size_t size)
{
    int count = 0;
    for (int i = 0; dem_normal_names[i]; i++)
        count += dem_normal_from_moduli((dem_normal_law)i) == moduli;
    buf[0] = 0;
    for (int i = 0, k = 0; dem_normal_names[i]; i++) {
        if (dem_normal_from_moduli((dem_normal_law)i) != moduli)
            continue;
        const char *parts[4] = {k == 0           ? ""
                                : k == count - 1 ? " or "
                                                 : ", ",
                                quoted ? "'" : "", dem_normal_names[i], quoted ? "'" : ""};
        for (int p = 0; p < 4; p++)
            strncat(buf, parts[p], size - 1 - strlen(buf));
        k++;
    }
}

/* A field given although the chosen law ignores it is refused: a typo'd law must not leave the
 * user believing a value took effect. `why` names the field and value that give it meaning. */
static void only_with(lua_State *L, const char *field, int meaningful, const char *why)
{
    if (!meaningful && lua_getfield(L, 2, field) != LUA_TNIL) {
        char expected[320];
        snprintf(expected, sizeof expected, "nothing unless %s", why);
        bind_field_error(L, 2, "contact", field, expected);
    }
    lua_settop(L, 2);
}

/* s:contact's laws: the options, which combinations exist, and the fields each law ignores. */
static void read_laws(lua_State *L, dem_contact_def *c)
{
    c->normal = (dem_normal_law)bind_field_option(L, 2, "contact", "normal", dem_normal_names,
                                                  DEM_NORMAL_HERTZ, 0);
    c->damping = (dem_damping_law)bind_field_option(L, 2, "contact", "damping", dem_damping_names,
                                                    DEM_DAMPING_NONE, 0);
    c->tangential = (dem_tangential_law)bind_field_option(L, 2, "contact", "tangential",
                                                          dem_tangent_names, DEM_TANGENT_NONE, 0);
    lua_settop(L, 2);
    if (c->damping == DEM_DAMPING_BRILLIANTOV && !dem_normal_hertzian(c->normal)) {
        lua_getfield(L, 2, "damping");
        bind_field_error(L, 2, "contact", "damping",
                         "'none' or 'viscous' with the linear and power laws (brilliantov "
                         "damping needs normal = 'hertz', 'jkr' or 'dmt'; viscous damping "
                         "honours a restitution with every law)");
    }
    char given[96], moduli[96], why[256];
    normal_names_by_k(0, 1, given, sizeof given);
    normal_names_by_k(1, 0, moduli, sizeof moduli);
    snprintf(why, sizeof why, "'normal' is %s (%s takes the materials' moduli)", given, moduli);
    only_with(L, "stiffness", !dem_normal_from_moduli(c->normal), why);
    only_with(L, "beta", c->normal == DEM_NORMAL_POWER, "'normal' is 'power'");
    only_with(L, "gamma_n", c->damping == DEM_DAMPING_VISCOUS, "'damping' is 'viscous'");
    only_with(L, "damping_time", c->damping == DEM_DAMPING_BRILLIANTOV,
              "'damping' is 'brilliantov'");
    only_with(L, "gamma_t", c->tangential == DEM_TANGENT_VISCOUS, "'tangential' is 'viscous'");
    only_with(L, "kt", c->tangential == DEM_TANGENT_SPRING, "'tangential' is 'spring'");
    only_with(L, "v_r", c->tangential == DEM_TANGENT_REGULARIZED,
              "'tangential' is 'coulomb_regularized'");
    only_with(L, "exponent", c->tangential == DEM_TANGENT_REGULARIZED,
              "'tangential' is 'coulomb_regularized'");
}

/* The normal law's stiffness and exponent, its damping and the restitution it honours (e; -1 when
 * not given) at the impact velocity v_imp. */
static void read_damping(lua_State *L, dem_contact_def *c, double *e_out, double *v_imp)
{
    unsigned need_k = dem_normal_from_moduli(c->normal) ? 0 : BIND_REQUIRED;
    c->stiffness = bind_field_number(L, 2, "contact", "stiffness", 0, BIND_POSITIVE | need_k);
    c->beta = bind_field_number(L, 2, "contact", "beta", c->normal == DEM_NORMAL_LINEAR ? 1 : 1.5,
                                BIND_POSITIVE);
    /* Absent optional values are -1 ("not given"); given ones must be in range. */
    c->gamma_n = bind_field_number(L, 2, "contact", "gamma_n", -1, 0);
    if (c->gamma_n < 0 && lua_getfield(L, 2, "gamma_n") != LUA_TNIL)
        bind_field_error(L, 2, "contact", "gamma_n", "non-negative number");
    c->damping_time = bind_field_number(L, 2, "contact", "damping_time", -1, 0);
    if (c->damping_time < 0 && lua_getfield(L, 2, "damping_time") != LUA_TNIL)
        bind_field_error(L, 2, "contact", "damping_time", "non-negative number");
    double e = *e_out = bind_field_number(L, 2, "contact", "restitution", -1, 0);
    if (c->damping_time >= 0 && lua_getfield(L, 2, "restitution") != LUA_TNIL)
        bind_field_error(L, 2, "contact", "restitution",
                         "nothing when 'damping_time' is given: give damping_time (one T "
                         "for every pair) or restitution (a T per pair), not both");
    lua_settop(L, 2);
    if (c->gamma_n >= 0 && lua_getfield(L, 2, "restitution") != LUA_TNIL)
        bind_field_error(L, 2, "contact", "restitution",
                         "nothing when 'gamma_n' is given: give gamma_n (one coefficient "
                         "for every pair) or restitution (one per pair), not both");
    lua_settop(L, 2);
    if (e >= 0 || lua_getfield(L, 2, "restitution") != LUA_TNIL) {
        lua_getfield(L, 2, "restitution");
        if (!(e > 0 && e <= 1))
            bind_field_error(L, 2, "contact", "restitution", "number in (0, 1]");
        if (c->damping == DEM_DAMPING_NONE && e < 1)
            bind_field_error(L, 2, "contact", "restitution",
                             dem_normal_hertzian(c->normal)
                                 ? "1 when 'damping' is 'none' (for a rebound below 1 "
                                   "give damping = 'viscous' or 'brilliantov')"
                                 : "1 when 'damping' is 'none' (for a rebound below 1 "
                                   "give damping = 'viscous')");
        lua_pop(L, 1);
    }
    /* The speed at which a restitution holds: meaningful when the damping comes from one (the
     * contact's or the materials') and e depends on speed, i.e. all but the linear spring with
     * viscous damping. */
    const char *no_speed =
        c->damping == DEM_DAMPING_NONE ? "nothing unless 'damping' is 'viscous' or 'brilliantov' "
                                         "(the speed at which a restitution holds)"
        : c->gamma_n >= 0              ? "nothing when 'gamma_n' is given (the speed at which a "
                                         "restitution holds)"
        : c->damping_time >= 0 ? "nothing when 'damping_time' is given (the speed at which a "
                                 "restitution holds)"
        : c->damping == DEM_DAMPING_VISCOUS && c->beta == 1
            ? "nothing with viscous damping of a linear spring (beta = 1): its restitution holds "
              "at every speed"
            : NULL;
    if (no_speed && lua_getfield(L, 2, "impact_velocity") != LUA_TNIL)
        bind_field_error(L, 2, "contact", "impact_velocity", no_speed);
    lua_settop(L, 2);
    *v_imp = bind_field_number(L, 2, "contact", "impact_velocity", 1, BIND_POSITIVE);
    lua_settop(L, 2);
}

/* Rolling resistance (dem.h, rolling.inc) */
static void read_rolling(lua_State *L, dem_contact_def *c)
{
    c->rolling_law = (dem_rolling_law)bind_field_option(L, 2, "contact", "rolling_resistance",
                                                        dem_rolling_names, DEM_ROLLING_NONE, 0);
    lua_settop(L, 2);
    const int roll = c->rolling_law != DEM_ROLLING_NONE;
    only_with(L, "rolling_friction", roll, "'rolling_resistance' is 'epsd' or 'constant'");
    only_with(L, "rolling_stiffness", c->rolling_law == DEM_ROLLING_EPSD,
              "'rolling_resistance' is 'epsd'");
    only_with(L, "rolling_damping", c->rolling_law == DEM_ROLLING_EPSD,
              "'rolling_resistance' is 'epsd'");
    only_with(L, "rolling_rate", c->rolling_law == DEM_ROLLING_CONSTANT,
              "'rolling_resistance' is 'constant'");
    /* absent: -1, the materials' mu_r and k_t R_eff^2 (dem.h) */
    c->rolling_friction = bind_field_number(L, 2, "contact", "rolling_friction", -1, BIND_NONNEG);
    c->rolling_stiffness =
        bind_field_number(L, 2, "contact", "rolling_stiffness", -1, BIND_POSITIVE);
    c->rolling_damping = bind_field_number(L, 2, "contact", "rolling_damping", 0, BIND_NONNEG);
    if (c->rolling_damping > 1) {
        lua_getfield(L, 2, "rolling_damping");
        bind_field_error(L, 2, "contact", "rolling_damping", "number in [0, 1]");
    }
    c->rolling_rate = bind_field_number(L, 2, "contact", "rolling_rate", 0, BIND_POSITIVE);
}

/* Cohesion (dem.h, src/dem/cohesion.h): JKR's and DMT's work of adhesion, the liquid bridge. */
static void read_cohesion(lua_State *L, dem_contact_def *c)
{
    c->cohesion = (dem_cohesion_law)bind_field_option(L, 2, "contact", "cohesion",
                                                      dem_cohesion_names, DEM_COHESION_NONE, 0);
    lua_settop(L, 2);
    const int adh = c->normal == DEM_NORMAL_JKR || c->normal == DEM_NORMAL_DMT;
    const int cap = c->cohesion == DEM_COHESION_CAPILLARY;
    if (cap && adh) {
        lua_getfield(L, 2, "cohesion");
        bind_field_error(L, 2, "contact", "cohesion",
                         "'none' with normal = 'jkr' or 'dmt', which have their own adhesion (a "
                         "liquid bridge adds to the linear, power and hertz laws)");
    }
    only_with(L, "work_of_adhesion", adh, "'normal' is 'jkr' or 'dmt'");
    only_with(L, "liquid_volume", cap, "'cohesion' is 'capillary'");
    only_with(L, "surface_tension", cap, "'cohesion' is 'capillary'");
    only_with(L, "contact_angle", cap, "'cohesion' is 'capillary'");
    /* absent: -1, the materials' (dem.h) */
    c->adhesion = bind_field_number(L, 2, "contact", "work_of_adhesion", -1, BIND_NONNEG);
    const unsigned need = cap ? BIND_REQUIRED : 0;
    c->liquid_volume =
        bind_field_number(L, 2, "contact", "liquid_volume", 0, BIND_POSITIVE | need);
    c->surface_tension =
        bind_field_number(L, 2, "contact", "surface_tension", 0, BIND_NONNEG | need);
    const double deg = bind_field_number(L, 2, "contact", "contact_angle", 0, BIND_NONNEG);
    if (!(deg < 180)) {
        lua_getfield(L, 2, "contact_angle");
        bind_field_error(L, 2, "contact", "contact_angle", "number of degrees in [0, 180)");
    }
    c->contact_angle = deg * (3.14159265358979323846 / 180);
    lua_settop(L, 2);
}

static int l_contact(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    bind_refuse_running(L, 1, "contact",
                        "the contact law cannot change under the time step its "
                        "run was checked at: change it between runs");
    bind_check_table(L, 2, "contact");
    bind_check_fields(L, 2, "contact", CONTACT_FIELDS);
    dem_contact_def c = dem_default_contact_def();
    read_laws(L, &c);
    double e, v_imp;
    read_damping(L, &c, &e, &v_imp);
    c.gamma_t = bind_field_number(L, 2, "contact", "gamma_t", 0, BIND_NONNEG);
    c.kt = bind_field_number(L, 2, "contact", "kt", -1, 0);
    if (c.kt <= 0 && lua_getfield(L, 2, "kt") != LUA_TNIL)
        return bind_field_error(L, 2, "contact", "kt", "positive number");
    c.v_r = bind_field_number(L, 2, "contact", "v_r", c.v_r, BIND_POSITIVE);
    c.exponent = bind_field_number(L, 2, "contact", "exponent", c.exponent, BIND_POSITIVE);
    c.clip = bind_field_boolean(L, 2, "contact", "clip", 1);
    c.rolling = bind_field_boolean(L, 2, "contact", "rolling", 0);
    read_rolling(L, &c);
    read_cohesion(L, &c);
    /* From a restitution (this one, else the materials') each pair gets its own damping when
     * the pair list is built: nothing depends on the particles present now. */
    c.restitution = e;
    c.impact_velocity = v_imp;
    core_error err;
    if (dem_set_contact(s, &c, &err) != CORE_OK)
        return bind_raise(L, "contact", &err);
    if (c.damping == DEM_DAMPING_BRILLIANTOV && c.damping_time >= 0) {
        lua_pushnumber(L, c.damping_time);
        return 1;
    }
    return 0;
}

/* s:damping_time(i, j) or s:damping_time(i, { wall = w }): the pair's Brilliantov T as the force
 * loop uses it (per pair when solved from a restitution). */
static const char *const DAMPING_TIME_FIELDS[] = {"wall", NULL};

static int l_damping_time(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    size_t i = ldem_particle_arg(L, s, 2, "damping_time"), j = 0;
    int wall = -1;
    if (lua_istable(L, 3)) {
        bind_check_fields(L, 3, "damping_time", DAMPING_TIME_FIELDS);
        wall = (int)bind_field_integer(L, 3, "damping_time", "wall", 0, 1, INT_MAX, BIND_REQUIRED) -
               1; /* 1.5 is no wall id */
    } else
        j = ldem_particle_arg(L, s, 3, "damping_time");
    if (dem_contact(s)->damping != DEM_DAMPING_BRILLIANTOV)
        return luaL_error(L, "damping_time: the contact law has no brilliantov damping");
    core_error err;
    double T;
    if (dem_pair_damping(s, i, j, wall, &T, &err) != CORE_OK)
        return bind_raise(L, "damping_time", &err);
    lua_pushnumber(L, T);
    return 1;
}

void ldem_open_contact(lua_State *L)
{
    static const bind_fn methods[] = {
        {"contact", l_contact,
         "s:contact{ normal = 'hertz'|'linear'|'power'|'dmt'|'jkr', stiffness =, beta =, damping = "
         "'none'|'viscous'|'brilliantov', gamma_n =, damping_time =, restitution =, "
         "impact_velocity =, tangential = 'none'|'viscous'|'spring'|'coulomb_regularized', "
         "gamma_t =, kt =, v_r =, exponent =, clip = true, rolling = false, rolling_resistance = "
         "'none'|'epsd'|'constant', rolling_friction =, rolling_stiffness =, rolling_damping = 0, "
         "rolling_rate =, work_of_adhesion =, cohesion = 'none'|'capillary', liquid_volume =, "
         "surface_tension =, contact_angle = 0 }",
         "Sets the contact law of the scene. Normal: linear f = k d (Herrmann Eq. 1a, beta = 1), "
         "power f = k d^beta (beta 1, 1.5 or 2), hertz f = 4/3 E* sqrt(R) d^1.5 (Padbidri Eq. "
         "1.1). Damping: viscous gamma_n d' (Eq. 1b), brilliantov T K d^0.5 d' (Eq. 2.16, hertz "
         "only). gamma_n or damping_time, when given, holds for every pair; otherwise each pair "
         "(walls too) gets its own from a restitution e, restitution = e here or else the smaller "
         "of the pair's two materials' restitution, so that a head-on impact at impact_velocity "
         "(default 1 m/s) rebounds with e whatever the radii, masses and materials: with "
         "d* = (m* v^2/k)^(1/(beta+1)), gamma = c(e) m* v/d* or T = lambda(e) (m*/K)^(2/5) "
         "v^(-1/5), K = 4/3 E* sqrt(R*). The linear spring with viscous damping holds e at every "
         "speed (no impact_velocity); elsewhere e moves with speed (viscous: lower when slower; "
         "brilliantov: higher when slower). damping = 'none' rebounds with 1 (restitution < 1 is "
         "refused). s:damping_time(i, j) gives a pair's T. Tangential: "
         "viscous -gamma_t s (Eq. 2a), spring (Cundall-Strack, Eq. 2b; kt defaults to 2/7 of "
         "the normal tangent stiffness), coulomb_regularized mu f_n min(1, (s/v_r)^(1/exponent)) "
         "(Eq. 2.18). clip = true forbids attractive normal forces; rolling = true allocates "
         "rotations without a tangential law. Rolling resistance (Ai et al. 2011; a torque "
         "against the relative rolling w_i - w_j, or w_i on a wall, at most mu_r R_eff |F_n|): "
         "epsd, type C, an elastic-plastic spring k_r (rolling_stiffness, N m/rad; default "
         "k_t R_eff^2) with a dashpot of damping ratio rolling_damping in [0, 1] below the "
         "limit; constant, type A, the limit torque against w, linear below rolling_rate w_c "
         "(rad/s; default: the rate that stops a contact's relative rotation in ten steps). "
         "mu_r: rolling_friction, or the smaller of the two materials' rolling_friction. "
         "Cohesion: normal = 'dmt' is hertz minus 2 pi Gamma R* while the grains overlap; "
         "normal = 'jkr' is Johnson-Kendall-Roberts, F = 4 E* a^3/(3 R*) - sqrt(8 pi Gamma E* "
         "a^3), delta = a^2/R* - sqrt(2 pi Gamma a/E*): the contact forms at touch and holds "
         "until the separation (3/4) (pi^2 Gamma^2 R*/E*^2)^(1/3), pull-off force 3/2 pi Gamma "
         "R*. Gamma is work_of_adhesion (J/m^2, twice LAMMPS's surface energy), or the geometric "
         "mean of the two materials' work_of_adhesion. cohesion = 'capillary' adds a liquid "
         "bridge to the linear, power or hertz law (Rabinovich et al. 2005): F = 4 pi R* "
         "surface_tension cos(contact_angle) (1 - S/sqrt(S^2 + V/(pi R*))) at separation S, "
         "formed at touch, ruptured at S = (1 + theta/2) V^(1/3); liquid_volume V (m^3) of each "
         "bridge, surface_tension (N/m), contact_angle in degrees [0, 180). Planes stick as "
         "partners of infinite radius (R* = r); other walls feel the Hertzian part. Returns "
         "damping_time when one is given, else nothing."},
        {"damping_time", l_damping_time, "s:damping_time(i, j) or s:damping_time(i, { wall = w })",
         "The Brilliantov damping time T (s) of particles i and j, or of particle i against wall "
         "w, "
         "as the force loop uses it (one T for all, or each pair's own when s:contact solved it "
         "from a restitution)."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fields[] = {{"contact", NULL, CONTACT_FIELDS},
                                         {"damping_time", NULL, DAMPING_TIME_FIELDS},
                                         {NULL, NULL, NULL}};
    ldem_add_methods(L, methods, fields);
}
