/* One error path from the kernels to Lua: a kernel returns a status and fills a core_error
 * with the context; the Lua binding raises it as an error naming the call. */
#ifndef GRAINLAB_CORE_ERROR_H
#define GRAINLAB_CORE_ERROR_H

typedef enum core_status {
    CORE_OK = 0,
    CORE_ERR_ARG,         /* an argument is out of range or inconsistent */
    CORE_ERR_NOMEM,       /* an allocation failed */
    CORE_ERR_IO,          /* a file could not be read or written */
    CORE_ERR_STATE,       /* the object is not in a state that allows the call */
    CORE_ERR_UNSTABLE,    /* the run went unstable (NaN, blow-up, tunnelling) */
    CORE_ERR_INTERRUPTED  /* Ctrl-C: stopped cleanly between steps, state intact */
} core_status;

typedef struct core_error {
    core_status status;
    char msg[512];
} core_error;

/* Records status and a printf-style message in err (which may be NULL) and returns status,
 * so a kernel writes `return core_fail(err, CORE_ERR_ARG, "radius %g <= 0", r);`. */
core_status core_fail(core_error *err, core_status status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Clears err to CORE_OK with an empty message. */
void core_error_clear(core_error *err);

/* Short name of a status ("invalid argument", "interrupted", ...). */
const char *core_status_name(core_status status);

#endif
