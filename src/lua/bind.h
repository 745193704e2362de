/* grainlab's Lua bindings: the state, argument checking with field-naming errors, the doc registry
 * behind help(), and the one place where a kernel's core_error becomes a Lua error. */
#ifndef GRAINLAB_LUA_BIND_H
#define GRAINLAB_LUA_BIND_H

#include <lauxlib.h>
#include <lua.h>

#include "core/error.h"

typedef struct bind_options {
    const char *report_path; /* --report FILE.json, or NULL (then GRAINLAB_REPORT applies) */
    int quiet;               /* --quiet */
} bind_options;

/* A new Lua state with the standard libraries, the embedded grainlab.* modules on
 * package.preload, and the globals grainlab, help and params (empty). NULL if out of memory. */
lua_State *bind_newstate(const bind_options *opt);

/* Number of failed report checks so far (the CLI turns a nonzero count into exit status 1). */
int bind_failed_checks(lua_State *L);

/* Raises err as a Lua error "call: message". Never returns. */
int bind_raise(lua_State *L, const char *call, const core_error *err);

/* ---- argument checking -------------------------------------------------------------------
 * `arg` is the stack index of the argument; messages number it as the user sees it (a method's
 * self does not count) and follow lauxlib's grammar:
 *   bad argument #1 to 'rng' (table expected, got nil)
 *   bad field 'seed' in argument #1 to 'rng' (non-negative integer expected, got -1)
 */
enum {
    BIND_REQUIRED = 1u << 0, /* the field must be present */
    BIND_POSITIVE = 1u << 1, /* > 0 */
    BIND_NONNEG = 1u << 2,   /* >= 0 */
    BIND_ALLOW_INF = 1u << 3 /* numbers are finite unless this is set; NaN is always refused */
};

void bind_check_table(lua_State *L, int arg, const char *call);

/* Refuses any key of the table at arg not in the NULL-terminated list `fields`, naming the key,
 * the closest valid one and all of them:
 *   bad argument #1 to 'add_disk' (unknown field 'raduis'; did you mean 'radius'? Valid …) */
void bind_check_fields(lua_State *L, int arg, const char *call, const char *const fields[]);
/* The same for a table nested in argument arg (at stack index tab), whose errors name it as the
 * field `name` ("bad field 'mbc' in argument #1 to 'boundary' (unknown field 'k'; …)"). */
void bind_check_nested_fields(lua_State *L, int tab, int arg, const char *call, const char *name,
                              const char *const fields[]);
/* The options of a mode argument (s:measure('stress', { volume = })): 0 when arg is none or nil,
 * 1 when it is a table whose keys are all in fields (empty: the mode takes no options, and any
 * key is refused as such); any other value is refused. */
int bind_mode_options(lua_State *L, int arg, const char *call, const char *mode,
                      const char *const fields[]);

double bind_field_number(lua_State *L, int arg, const char *call, const char *field, double def,
                         unsigned flags);
lua_Integer bind_field_integer(lua_State *L, int arg, const char *call, const char *field,
                               lua_Integer def, lua_Integer min, lua_Integer max, unsigned flags);
/* The returned string lives in the table at arg. */
const char *bind_field_string(lua_State *L, int arg, const char *call, const char *field,
                              const char *def, unsigned flags);
/* Index of the field's value in the NULL-terminated `names`, or def when absent. */
int bind_field_option(lua_State *L, int arg, const char *call, const char *field,
                      const char *const names[], int def, unsigned flags);

/* Reads an array of exactly n finite numbers (a position, a velocity) into out: a table of
 * another length is refused, never truncated. Absent: out unchanged (or an error when
 * BIND_REQUIRED). Returns 1 when present. */
int bind_field_vector(lua_State *L, int arg, const char *call, const char *field, int n,
                      double *out, unsigned flags);
int bind_field_boolean(lua_State *L, int arg, const char *call, const char *field, int def);
/* Reads a box {{lower corner}, {upper corner}} of dim finite numbers each into lo, hi (required),
 * the upper corner above the lower one on every axis. */
void bind_field_box(lua_State *L, int arg, const char *call, const char *field, int dim,
                    double *lo, double *hi);

/* Raises "bad field 'F' in argument #N to 'call' (EXPECTED expected, got VALUE)" for the value
 * on top of the stack. */
int bind_field_error(lua_State *L, int arg, const char *call, const char *field,
                     const char *expected);

/* Positional arguments, in the same grammar: "bad argument #N to 'call' (EXPECTED expected, got
 * VALUE)". A number is finite unless BIND_ALLOW_INF; flags as for fields. */
int bind_arg_error(lua_State *L, int arg, const char *call, const char *expected);
/* A file path: a non-empty string without NUL bytes (a number is refused, not converted). Every
 * file name that crosses from Lua into C goes through this or bind_field_path. */
const char *bind_arg_path(lua_State *L, int arg, const char *call);
/* The same for field `field` of the table at arg: NULL when absent (unless BIND_REQUIRED); the
 * string lives in the table. */
const char *bind_field_path(lua_State *L, int arg, const char *call, const char *field,
                            unsigned flags);
double bind_arg_number(lua_State *L, int arg, const char *call, unsigned flags);
lua_Integer bind_arg_integer(lua_State *L, int arg, const char *call, lua_Integer min,
                             lua_Integer max);
/* An array of exactly n finite numbers (a velocity) into out. */
void bind_arg_vector(lua_State *L, int arg, const char *call, int n, double *out);
/* The userdata of type tname at arg, or an error naming the call that says how to call a method
 * (s:run{...}, not s.run{...}) when arg is a method's self. */
void *bind_check_self(lua_State *L, int arg, const char *tname, const char *call);
/* The userdata of type tname at a (non-self) argument, or "bad argument #N to 'call' (tname
 * expected, got …)". */
void *bind_check_udata(lua_State *L, int arg, const char *tname, const char *call);

/* Writes a short description of the value at idx: "-0.1", "'xyz'", "nil", "table". */
void bind_describe(lua_State *L, int idx, char *buf, size_t size);

/* ---- running and bulk results ------------------------------------------------------------ */
struct progress;
typedef struct bind_run {
    const char *label; /* progress label, e.g. "dem run" */
    long steps;        /* at most this many steps (LUA_MAXINTEGER: until advance stops short) */
    long expect;       /* the expected number, for progress and the default `every` */
    /* Advances up to n steps, setting *done to those taken (fewer: the run reached its end, or
     * an error). A kernel with kernel_progress set calls progress_update(p, k) after its k-th
     * step; others are advanced in pieces and p is updated between them. */
    core_status (*advance)(void *ctx, long n, struct progress *p, long *done, core_error *err);
    void *ctx;
    int kernel_progress;
    double dt;         /* the run's fixed time step, checked at its start (0: chosen every step) */
    int forced;        /* force = true: dt was accepted beyond the stability limit */
} bind_run;

/* Reads `every`, `on_step` and `progress` from the options table at arg and advances in chunks
 * of `every` steps, calling on_step(scene) after each; kernel errors are raised named after call.
 * While it runs the scene is marked running (bind_running). Progress: asked (progress = true) from
 * the start, unasked after progress_unasked_delay() seconds and only for the outermost run, none
 * with --quiet; the closing line says "done", or "interrupted|stopped|failed at step k of N".
 * Returns 1 when on_step returned false. */
int bind_run_chunks(lua_State *L, int scene, int arg, const char *call, const bind_run *r);

/* Reads `steps` (a non-negative integer) or `time` (s, non-negative) from the run options at
 * arg, exactly one of them, with errors naming the fields. Returns 1 with *steps set, or 0 with
 * *time set. */
int bind_steps_or_time(lua_State *L, int arg, const char *call, long *steps, double *time);
/* The number of steps of dt that cover `time`, or an error naming field 'time' beyond 1e15 steps
 * (a year at a million steps a second: beyond it a count loses its meaning, and it would soon
 * overflow). */
long bind_time_steps(lua_State *L, int arg, const char *call, double time, double dt);
/* The run in progress of the scene at idx (its on_step is calling), or NULL. */
const bind_run *bind_running(lua_State *L, int idx);
/* The public name of the Lua-side library function the script called and that is running now
 * ("grainlab.pack.deposit", set by grainlab.entry), copied into buf; 0 when none is. */
int bind_entry_name(lua_State *L, char *buf, size_t size);
/* Runs in progress, nested ones included (0: none). */
int bind_run_depth(void);

/* When the scene at idx is running, raises
 *   "CALL: this dem.scene is running (called from its on_step); WHY"
 * ("already running" for call "run"). A binding puts it first in each call that a run in
 * progress cannot take. */
void bind_refuse_running(lua_State *L, int idx, const char *call, const char *why);

/* Sets field `name` of the table on top to an array of the n values. */
void bind_push_array(lua_State *L, const double *a, size_t n, const char *name);

/* ---- documentation for help() ------------------------------------------------------------ */
typedef struct bind_fn {
    const char *name;
    lua_CFunction fn;
    const char *usage; /* "grainlab.rng{ seed = 0, stream = 0 }" */
    const char *doc;   /* what it does, arguments, what it returns */
} bind_fn;

/* The keys a function's options table accepts: the same NULL-terminated array the function
 * passes to bind_check_fields, so that help() and the generated binding tests
 * (tests/<module>/test_fuzz_*.lua) enumerate exactly what the function checks. `mode` is NULL,
 * or the first argument the list goes with (s:measure('stress', { volume = })). */
typedef struct bind_fields {
    const char *name;          /* the registered function or method */
    const char *mode;          /* NULL or the mode argument */
    const char *const *fields; /* NULL-terminated */
} bind_fields;

/* Adds `fields` (or `modes[mode]`) to the doc records of the functions of the table at idx;
 * a name that is not a documented function there is a programming error (luaL_error). The list
 * ends with a NULL name. */
void bind_register_fields(lua_State *L, int idx, const bind_fields *list);
/* The same for the methods of the userdata type `tname` (after bind_new_type). */
void bind_type_fields(lua_State *L, const char *tname, const bind_fields *list);

/* Sets each function as a field of the table at idx and records its doc. */
void bind_register(lua_State *L, int idx, const bind_fn *fns);

/* Records the doc of the value at idx (a function, a module table, or a type's metatable). */
void bind_doc(lua_State *L, int idx, const char *name, const char *usage, const char *doc);

/* Creates the metatable `tname` for a userdata type: methods (with docs) in __index, the
 * metamethods in `meta` (no docs), and a doc for the type itself. Leaves nothing on the stack. */
void bind_new_type(lua_State *L, const char *tname, const bind_fn *methods, const luaL_Reg *meta,
                   const char *doc);

/* Open the C parts of the grainlab table onto the table at idx: lua_core.c (version, clocks,
 * threads, rng, progress, write_file) and help.c (doc, doc_of). */
void bind_open_core(lua_State *L, int idx);
void bind_open_help(lua_State *L, int idx);
/* grainlab.mpi onto the table at idx (lua_mpi.c); on ranks > 0 also turns the Lua functions that
 * write files (io.open for writing, io.output, os.remove, os.rename) into no-ops. */
void bind_open_mpi(lua_State *L, int idx);

/* Registers the global `dem` module (lua_dem.c). */
void bind_open_dem(lua_State *L);

/* The dem_scene of the dem.scene at idx, or a Lua error naming `call` (for other bindings). */
struct dem_scene *bind_check_dem_scene(lua_State *L, int idx, const char *call);
/* Pushes a new, empty dem.scene userdata (metatable, material table) and returns the slot for
 * its kernel scene, NULL until the caller fills it (dem.scene, dem.load). */
struct dem_scene **bind_new_dem_scene(lua_State *L);

/* Registers the global `mpm` module (lua_mpm.c). */
void bind_open_mpm(lua_State *L);

/* Registers the global `dsmc` module (lua_dsmc.c). */
void bind_open_dsmc(lua_State *L);
/* Registers the global `analysis` module and the boundary-condition methods of dem.scene
 * (lua_analysis.c); after bind_open_dem. */
void bind_open_analysis(lua_State *L);
/* analysis.coarse_grain, analysis.cg_average and render.coarse_grain (lua_coarse_grain.c,
 * lua_coarse_grain_render.c); after bind_open_analysis and bind_open_render. */
void bind_open_coarse_grain(lua_State *L);
/* dem.load's restorer of the Delaunay boundary update s:boundary installs (lua_analysis.c). */
const struct dem_boundary_restorer *bind_dem_boundary_restorer(void);
/* s:save and dem.load (lua_checkpoint.c); after bind_open_dem. */
void bind_open_checkpoint(lua_State *L);

/* Registers the global `render` module (lua_render.c). */
void bind_open_render(lua_State *L);

/* luaL_checkoption that helps: the error lists the valid names and suggests the closest one
 * ("invalid option 'stres'; did you mean 'stress'? Valid options: 'energy', 'stress', ...").
 * Same arguments and result as luaL_checkoption. */
int bind_check_option(lua_State *L, int arg, const char *def, const char *const names[]);
/* The name of `names` closest to s (a unique prefix, the same name in another case, or within a
 * few edits of a name of three letters or more), or NULL. */
const char *bind_closest_name(const char *s, const char *const names[]);

/* The kernel scene of the mpm.scene / dsmc.scene at idx, or a Lua error naming `call`; and a new
 * scene userdata pushed closed (NULL), whose slot the caller fills (lua_mpm.c, lua_dsmc.c). */
struct mpm_scene *bind_check_mpm_scene(lua_State *L, int idx, const char *call);
struct mpm_scene **bind_new_mpm_scene(lua_State *L);
struct dsmc_scene *bind_check_dsmc_scene(lua_State *L, int idx, const char *call);
struct dsmc_scene **bind_new_dsmc_scene(lua_State *L);
/* m:save, mpm.load, s:save, dsmc.load (lua_checkpoint_mpm.c); after bind_open_mpm and _dsmc. */
void bind_open_checkpoint_mpm(lua_State *L);
/* Adds write_vtk to the scene and mesh types and grainlab.vtk (lua_vtk.c); after the engines. */
void bind_open_vtk(lua_State *L);

#endif
