/* LAMMPS exchange for DEM scenes: data files in atom_style sphere (read here, written by
 * lammps_write.c with `dump custom` frames), the formats LAMMPS, LIGGGHTS and OVITO read. The
 * parser is strict: every line it does not understand is an error naming the file and the line,
 * because a packing that loads half right is worse than one that does not load. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "dem/dem_internal.h"

/* Densities this close are the same material's: LAMMPS writes density = rmass / (4/3 pi r^3)
 * with rmass = density 4/3 pi r^3, which comes back within a few ulps, never exactly. */
#define DENSITY_RTOL 1e-9
#define MAX_TOKENS 16

int dem_material_count(const dem_scene *s) { return s->nmat; }

const dem_material *dem_material_get(const dem_scene *s, int index)
{
    return index >= 0 && index < s->nmat ? &s->mats[index] : NULL;
}

/* ---- reading ----------------------------------------------------------------------------------
 */
typedef struct reader {
    FILE *fp;
    const char *path;
    long line;
    char *buf;
    size_t cap;
    char *tok[MAX_TOKENS];
    int ntok;
    char *comment; /* text after '#' on the current line, or NULL */
    int cut;       /* the current line is the file's last and has no newline */
    int nul;       /* the current line holds a NUL byte: reading stopped there */
    uint64_t size; /* of the file, in bytes */
} reader;

/* Reads the next line, strips its comment and splits it into tokens; 0 at end of file. */
static int next_line(reader *r)
{
    ssize_t len = getline(&r->buf, &r->cap, r->fp);
    if (len < 0)
        return 0;
    r->line++;
    r->cut = r->buf[len - 1] != '\n';
    if ((size_t)len != strlen(r->buf)) { /* a NUL byte: not a text file; read as its end */
        r->nul = 1;
        r->ntok = 0;
        return 0;
    }
    char *hash = strchr(r->buf, '#');
    r->comment = NULL;
    if (hash) {
        *hash = 0;
        r->comment = hash + 1;
    }
    r->ntok = 0;
    char *p = r->buf;
    while (*p) {
        while (*p && isspace((unsigned char)*p))
            p++;
        if (!*p)
            break;
        if (r->ntok == MAX_TOKENS) { /* keep counting nothing more: the caller sees too many */
            r->ntok = MAX_TOKENS + 1;
            break;
        }
        r->tok[r->ntok++] = p;
        while (*p && !isspace((unsigned char)*p))
            p++;
        if (*p)
            *p++ = 0;
    }
    return 1;
}

/* Skips blank and comment-only lines; 0 at end of file. */
static int next_content(reader *r)
{
    while (next_line(r))
        if (r->ntok > 0)
            return 1;
    return 0;
}

/* A line the parser refuses; when the file ends inside it (no newline), that is said first:
 * a cut file is the likelier cause than a bad value. */
static core_status bad_line(core_error *err, const reader *r, const char *what)
{
    if (r->nul)
        return core_fail(err, CORE_ERR_ARG,
                         "%s:%ld: the line holds a NUL byte (not a text file, or a damaged one)",
                         r->path, r->line);
    if (r->cut && r->ntok > 0)
        return core_fail(err, CORE_ERR_ARG,
                         "%s:%ld: the file ends inside this line, without a newline (cut "
                         "short?): %s",
                         r->path, r->line, what);
    return core_fail(err, CORE_ERR_ARG, "%s:%ld: %s", r->path, r->line, what);
}

static int parse_double(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

static int parse_ll(const char *s, long long lo, long long hi, long long *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end || errno == ERANGE || v < lo || v > hi)
        return 0;
    *out = v;
    return 1;
}

/* Header lines that describe topology grainlab has no use for: allowed only with a count of 0. */
static const char *const ZERO_ONLY[] = {"bonds",
                                        "angles",
                                        "dihedrals",
                                        "impropers",
                                        "bond types",
                                        "angle types",
                                        "dihedral types",
                                        "improper types",
                                        "extra bond per atom",
                                        "extra angle per atom",
                                        "extra dihedral per atom",
                                        "extra improper per atom",
                                        "extra special per atom",
                                        "ellipsoids",
                                        "lines",
                                        "triangles",
                                        "bodies",
                                        NULL};

/* Joins tokens from..ntok-1 with single spaces into buf. */
static void join_tokens(const reader *r, int from, char *buf, size_t size)
{
    buf[0] = 0;
    for (int k = from; k < r->ntok && k < MAX_TOKENS; k++) {
        if (k > from)
            strncat(buf, " ", size - strlen(buf) - 1);
        strncat(buf, r->tok[k], size - strlen(buf) - 1);
    }
}

static int is_section(const char *name)
{
    static const char *const known[] = {
        "Atoms", "Velocities", "Masses", "Pair Coeffs", "PairIJ Coeffs", "Atom Type Labels", NULL};
    for (int k = 0; known[k]; k++)
        if (!strcmp(name, known[k]))
            return 1;
    return isupper((unsigned char)name[0]); /* every LAMMPS section starts with a capital */
}

static core_status alloc_atoms(dem_lammps_data *d, size_t n, core_error *err)
{
    size_t m = n ? n : 1;
    d->id = calloc(m, sizeof *d->id);
    d->type = calloc(m, sizeof *d->type);
    d->radius = calloc(m, sizeof(double));
    d->density = calloc(m, sizeof(double));
    d->line = calloc(m, sizeof *d->line);
    int ok = d->id && d->type && d->radius && d->density && d->line;
    for (int a = 0; a < 3; a++) {
        d->x[a] = calloc(m, sizeof(double));
        d->v[a] = calloc(m, sizeof(double));
        d->w[a] = calloc(m, sizeof(double));
        d->image[a] = calloc(m, sizeof(int));
        ok = ok && d->x[a] && d->v[a] && d->w[a] && d->image[a];
    }
    if (!ok)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu atoms", n);
    return CORE_OK;
}

void dem_lammps_free(dem_lammps_data *d)
{
    free(d->path), free(d->id), free(d->type), free(d->radius), free(d->density), free(d->line);
    for (int a = 0; a < 3; a++)
        free(d->x[a]), free(d->v[a]), free(d->w[a]), free(d->image[a]);
    memset(d, 0, sizeof *d);
}

typedef struct id_index {
    long long id;
    size_t k;
} id_index;

static int cmp_id(const void *a, const void *b)
{
    long long x = ((const id_index *)a)->id, y = ((const id_index *)b)->id;
    return (x > y) - (x < y);
}

static core_status read_atoms(reader *r, dem_lammps_data *d, size_t *count, core_error *err)
{
    char msg[256];
    if (r->comment) { /* "Atoms # sphere": a style hint written by write_data */
        char style[64] = "";
        if (sscanf(r->comment, " %63s", style) == 1 && strcmp(style, "sphere") &&
            strcmp(style, "granular")) {
            snprintf(msg, sizeof msg,
                     "the Atoms section is for atom_style %s; grainlab reads atom_style sphere "
                     "(LIGGGHTS: granular): id type diameter density x y z",
                     style);
            return bad_line(err, r, msg);
        }
    }
    int columns = 0; /* of the first line: image flags are on every line or on none */
    for (size_t k = 0; k < d->n; k++) {
        if (!next_content(r)) {
            snprintf(msg, sizeof msg,
                     "the file ends in the Atoms section after %zu of %zu atoms (truncated?)", k,
                     d->n);
            return bad_line(err, r, msg);
        }
        if (r->ntok != 7 && r->ntok != 10) {
            if (r->ntok == 1 && is_section(r->tok[0]))
                snprintf(msg, sizeof msg,
                         "section '%s' starts after %zu of the %zu atoms the header announces",
                         r->tok[0], k, d->n);
            else
                snprintf(msg, sizeof msg,
                         "an Atoms line has %d values; atom_style sphere needs 7 (id type "
                         "diameter density x y z) or 10 (with image flags ix iy iz)",
                         r->ntok > MAX_TOKENS ? MAX_TOKENS : r->ntok);
            return bad_line(err, r, msg);
        }
        if (columns && r->ntok != columns) {
            snprintf(msg, sizeof msg,
                     "an Atoms line has %d values where the lines before have %d (image flags "
                     "ix iy iz on every line or on none)",
                     r->ntok, columns);
            return bad_line(err, r, msg);
        }
        columns = r->ntok;
        long long id, type, img[3] = {0, 0, 0};
        double diam, dens, x[3];
        if (!parse_ll(r->tok[0], 1, INT64_MAX, &id))
            return snprintf(msg, sizeof msg, "atom id '%s' is not a positive integer", r->tok[0]),
                   bad_line(err, r, msg);
        if (!parse_ll(r->tok[1], 1, d->ntypes, &type))
            return snprintf(msg, sizeof msg,
                            "atom %lld: type '%s' is not an integer in [1, %d] (the header's "
                            "atom types)",
                            id, r->tok[1], d->ntypes),
                   bad_line(err, r, msg);
        if (!parse_double(r->tok[2], &diam) || !(diam > 0))
            return snprintf(msg, sizeof msg,
                            "atom %lld: diameter '%s' must be a positive number (grainlab has no "
                            "point particles)",
                            id, r->tok[2]),
                   bad_line(err, r, msg);
        if (!parse_double(r->tok[3], &dens) || !(dens > 0))
            return snprintf(msg, sizeof msg, "atom %lld: density '%s' must be a positive number",
                            id, r->tok[3]),
                   bad_line(err, r, msg);
        for (int a = 0; a < 3; a++)
            if (!parse_double(r->tok[4 + a], &x[a]))
                return snprintf(msg, sizeof msg, "atom %lld: coordinate %c '%s' is not a number",
                                id, "xyz"[a], r -> tok[4 + a]),
                       bad_line(err, r, msg);
        for (int a = 0; r->ntok == 10 && a < 3; a++)
            if (!parse_ll(r->tok[7 + a], INT32_MIN, INT32_MAX, &img[a]))
                return snprintf(msg, sizeof msg, "atom %lld: image flag %c '%s' is not an integer",
                                id, "xyz"[a], r -> tok[7 + a]),
                       bad_line(err, r, msg);
        d->id[k] = id;
        d->type[k] = (int)type;
        d->radius[k] = diam / 2;
        d->density[k] = dens;
        for (int a = 0; a < 3; a++) {
            d->x[a][k] = x[a];
            d->image[a][k] = (int)img[a];
        }
        d->line[k] = r->line;
    }
    *count = d->n;
    return CORE_OK;
}

static core_status read_velocities(reader *r, dem_lammps_data *d, const id_index *order,
                                   unsigned char *seen, core_error *err)
{
    char msg[256];
    for (size_t k = 0; k < d->n; k++) {
        if (!next_content(r)) {
            snprintf(msg, sizeof msg,
                     "the file ends in the Velocities section after %zu of %zu atoms "
                     "(truncated?)",
                     k, d->n);
            return bad_line(err, r, msg);
        }
        if (r->ntok != 7) {
            snprintf(msg, sizeof msg,
                     "a Velocities line has %d values; atom_style sphere needs 7 (id vx vy vz wx "
                     "wy wz)",
                     r->ntok > MAX_TOKENS ? MAX_TOKENS : r->ntok);
            return bad_line(err, r, msg);
        }
        long long id;
        double v[6];
        if (!parse_ll(r->tok[0], 1, INT64_MAX, &id))
            return snprintf(msg, sizeof msg, "atom id '%s' is not a positive integer", r->tok[0]),
                   bad_line(err, r, msg);
        for (int a = 0; a < 6; a++)
            if (!parse_double(r->tok[1 + a], &v[a]))
                return snprintf(msg, sizeof msg, "atom %lld: %s '%s' is not a number", id,
                                (const char *[]){"vx", "vy", "vz", "wx", "wy", "wz"}[a],
                                r->tok[1 + a]),
                       bad_line(err, r, msg);
        id_index key = {id, 0};
        const id_index *hit = bsearch(&key, order, d->n, sizeof *order, cmp_id);
        if (!hit)
            return snprintf(msg, sizeof msg, "atom %lld has a velocity but is not in Atoms", id),
                   bad_line(err, r, msg);
        size_t i = (size_t)(hit - order); /* atoms are already sorted: position = index */
        if (seen[i])
            return snprintf(msg, sizeof msg, "atom %lld has a second velocity line", id),
                   bad_line(err, r, msg);
        seen[i] = 1;
        for (int a = 0; a < 3; a++) {
            d->v[a][i] = v[a];
            d->w[a][i] = v[3 + a];
        }
    }
    return CORE_OK;
}

/* Sorts the atoms by id (grainlab's particle order) and refuses duplicates. */
static core_status sort_atoms(const reader *r, dem_lammps_data *d, id_index **order_out,
                              core_error *err)
{
    id_index *order = malloc((d->n ? d->n : 1) * sizeof *order);
    if (!order)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu atoms", d->n);
    for (size_t k = 0; k < d->n; k++)
        order[k] = (id_index){d->id[k], k};
    qsort(order, d->n, sizeof *order, cmp_id);
    for (size_t k = 1; k < d->n; k++)
        if (order[k].id == order[k - 1].id) {
            core_status st =
                core_fail(err, CORE_ERR_ARG, "%s:%ld: atom id %lld appears twice (also line %ld)",
                          r->path, d->line[order[k].k], order[k].id, d->line[order[k - 1].k]);
            free(order);
            return st;
        }
    /* Permute every column into id order. */
    dem_lammps_data s = *d;
    dem_lammps_data t;
    memset(&t, 0, sizeof t);
    core_status st = alloc_atoms(&t, d->n, err);
    if (st != CORE_OK) {
        t.path = NULL;
        dem_lammps_free(&t);
        free(order);
        return st;
    }
    for (size_t k = 0; k < d->n; k++) {
        size_t j = order[k].k;
        t.id[k] = s.id[j], t.type[k] = s.type[j], t.radius[k] = s.radius[j];
        t.density[k] = s.density[j], t.line[k] = s.line[j];
        for (int a = 0; a < 3; a++)
            t.x[a][k] = s.x[a][j], t.v[a][k] = s.v[a][j], t.w[a][k] = s.w[a][j],
            t.image[a][k] = s.image[a][j];
        order[k].k = k;
    }
    free(s.id), free(s.type), free(s.radius), free(s.density), free(s.line);
    for (int a = 0; a < 3; a++)
        free(s.x[a]), free(s.v[a]), free(s.w[a]), free(s.image[a]);
    d->id = t.id, d->type = t.type, d->radius = t.radius, d->density = t.density, d->line = t.line;
    for (int a = 0; a < 3; a++)
        d->x[a] = t.x[a], d->v[a] = t.v[a], d->w[a] = t.w[a], d->image[a] = t.image[a];
    *order_out = order;
    return CORE_OK;
}

/* The header: counts and box, up to the first section (*in_body: one was found, its title
 * line read); d->n, d->ntypes and the box from it. */
static core_status parse_header(reader *r, dem_lammps_data *d, long long *ntypes_out,
                                int *in_body_out, core_error *err)
{
    char msg[320], key[128];
    long long natoms = -1, ntypes = -1;
    long natoms_line = 0;
    int have_box[3] = {0, 0, 0};
    int in_body = 0;
    while (!in_body) {
        if (!next_content(r))
            break;
        char *first = r->tok[0];
        double lo, hi;
        if (r->ntok == 4 && parse_double(r->tok[0], &lo) && parse_double(r->tok[1], &hi) &&
            r->tok[2][1] == 'l' && r->tok[2][2] == 'o' && !r->tok[2][3] && r->tok[3][1] == 'h' &&
            r->tok[3][2] == 'i' && !r->tok[3][3] && r->tok[2][0] == r->tok[3][0] &&
            strchr("xyz", r->tok[2][0])) {
            int a = r->tok[2][0] - 'x';
            if (!(hi > lo))
                return snprintf(msg, sizeof msg, "%clo %g must be below %chi %g", 'x' + a, lo,
                                'x' + a, hi),
                       bad_line(err, r, msg);
            if (have_box[a])
                return bad_line(err, r, "the box bounds of this axis are given twice");
            if (fabs(lo) > 1e100 || fabs(hi) > 1e100) /* what dem.scene takes for a box */
                return snprintf(msg, sizeof msg,
                                "%clo %chi %g %g: box bounds of magnitude at most 1e100 expected",
                                'x' + a, 'x' + a, lo, hi),
                       bad_line(err, r, msg);
            d->lo[a] = lo, d->hi[a] = hi, have_box[a] = 1;
            continue;
        }
        if (r->ntok == 6 && !strcmp(r->tok[3], "xy") && !strcmp(r->tok[4], "xz") &&
            !strcmp(r->tok[5], "yz")) {
            double t[3];
            for (int a = 0; a < 3; a++)
                if (!parse_double(r->tok[a], &t[a]))
                    return bad_line(err, r, "tilt factors must be numbers");
            if (t[0] != 0 || t[1] != 0 || t[2] != 0)
                return bad_line(err, r,
                                "a triclinic box (nonzero xy xz yz): grainlab's DEM box is "
                                "orthogonal");
            continue;
        }
        long long count;
        if (r->ntok >= 2 && parse_ll(first, 0, INT64_MAX, &count)) {
            join_tokens(r, 1, key, sizeof key);
            if (!strcmp(key, "atoms")) {
                natoms = count;
                natoms_line = r->line;
                continue;
            }
            if (!strcmp(key, "atom types")) {
                if (count < 1 || count > 1000000)
                    return bad_line(err, r, "atom types must be between 1 and 1000000");
                ntypes = count;
                continue;
            }
            for (int k = 0; ZERO_ONLY[k]; k++)
                if (!strcmp(key, ZERO_ONLY[k])) {
                    if (count != 0)
                        return snprintf(msg, sizeof msg,
                                        "%lld %s: grainlab's DEM reads spheres only (no bonds, "
                                        "angles or bodies)",
                                        count, key),
                               bad_line(err, r, msg);
                    goto next;
                }
            return snprintf(msg, sizeof msg, "unknown header line '%lld %s'", count, key),
                   bad_line(err, r, msg);
        }
        if (isupper((unsigned char)first[0])) {
            in_body = 1;
            break;
        }
        join_tokens(r, 0, key, sizeof key);
        return snprintf(msg, sizeof msg, "unknown header line '%s'", key), bad_line(err, r, msg);
    next:;
    }
    if (r->nul)
        return bad_line(err, r, "");
    if (natoms < 0)
        return core_fail(err, CORE_ERR_ARG, "%s: the header has no 'atoms' count", r->path);
    if (ntypes < 0)
        return core_fail(err, CORE_ERR_ARG, "%s: the header has no 'atom types' count", r->path);
    for (int a = 0; a < 3; a++)
        if (!have_box[a])
            return core_fail(err, CORE_ERR_ARG, "%s: the header has no '%clo %chi' box bounds",
                             r->path, 'x' + a, 'x' + a);
    if ((unsigned long long)natoms > (unsigned long long)(UINT32_MAX - 2))
        return core_fail(err, CORE_ERR_ARG, "%s:%ld: %lld atoms is more than a scene holds",
                         r->path, natoms_line, natoms);
    /* Each atom has an Atoms line of 14 bytes or more ("1 1 1 1 0 0 0" and its newline): a count
     * the rest of the file cannot hold is refused before anything is sized by it. */
    if (in_body) {
        long here = ftell(r->fp);
        uint64_t left = here >= 0 && (uint64_t)here <= r->size ? r->size - (uint64_t)here : 0;
        if ((uint64_t)natoms > left / 14)
            return core_fail(err, CORE_ERR_ARG,
                             "%s:%ld: the header announces %lld atoms, but the %llu bytes after "
                             "it hold at most %llu Atoms lines (14 bytes or more each): a wrong "
                             "count, or a truncated file",
                             r->path, natoms_line, natoms, (unsigned long long)left,
                             (unsigned long long)(left / 14));
    }
    d->n = (size_t)natoms;
    d->ntypes = (int)ntypes;
    *ntypes_out = ntypes;
    *in_body_out = in_body;
    return CORE_OK;
}

/* A section of per-type data (Masses, Pair Coeffs, PairIJ Coeffs, Atom Type Labels) whose title
 * line was read: skipped, its lines counted. */
static core_status skip_section(reader *r, const char *key, long long ntypes, core_error *err)
{
    char msg[320];
    core_status st = CORE_OK;
    /* Per-type data grainlab takes elsewhere (masses come from diameter and density,
     * contact laws from s:contact): skipped, but still checked for its line count. */
    long long lines = !strcmp(key, "PairIJ Coeffs") ? ntypes * (ntypes + 1) / 2 : ntypes;
    long start = r->line;
    for (long long k = 0; k < lines && st == CORE_OK; k++) {
        if (!next_content(r)) {
            snprintf(msg, sizeof msg,
                     "the file ends in the %s section started on line %ld (truncated?)",
                     key, start);
            st = bad_line(err, r, msg);
        } else if (r->ntok == 1 && is_section(r->tok[0]) &&
                   strcmp(key, "Atom Type Labels")) {
            snprintf(msg, sizeof msg,
                     "section '%s' starts inside the %s section (%lld lines expected)",
                     r->tok[0], key, lines);
            st = bad_line(err, r, msg);
        }
    }
    return st;
}

static core_status parse(reader *r, dem_lammps_data *d, core_error *err)
{
    char msg[320], key[128];
    if (!next_line(r))
        return r->nul ? bad_line(err, r, "")
                      : core_fail(err, CORE_ERR_ARG, "%s: the file is empty", r->path);
    /* The title line keeps its '#' text: it is free text. */
    rewind(r->fp);
    {
        ssize_t len = getline(&r->buf, &r->cap, r->fp);
        if (len > 0) {
            while (len > 0 && (r->buf[len - 1] == '\n' || r->buf[len - 1] == '\r'))
                r->buf[--len] = 0;
            snprintf(d->title, sizeof d->title, "%s", r->buf);
        }
    }
    long long ntypes = 0;
    int in_body = 0;
    core_status st = parse_header(r, d, &ntypes, &in_body, err);
    if (st != CORE_OK)
        return st;
    st = alloc_atoms(d, d->n, err);
    if (st != CORE_OK)
        return st;

    /* ---- body: sections ---- */
    size_t atoms_read = 0;
    int have_atoms = 0;
    id_index *order = NULL;
    unsigned char *seen = NULL;
    while (in_body && st == CORE_OK) {
        join_tokens(r, 0, key, sizeof key);
        if (!strcmp(key, "Atoms")) {
            if (have_atoms)
                st = bad_line(err, r, "a second Atoms section");
            else if ((st = read_atoms(r, d, &atoms_read, err)) == CORE_OK &&
                     (st = sort_atoms(r, d, &order, err)) == CORE_OK)
                have_atoms = 1;
        } else if (!strcmp(key, "Velocities")) {
            if (!have_atoms)
                st = bad_line(err, r, "Velocities before Atoms (LAMMPS needs Atoms first as well)");
            else if (d->has_velocities)
                st = bad_line(err, r, "a second Velocities section");
            else if (!(seen = calloc(d->n ? d->n : 1, 1)))
                st = core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu atoms", d->n);
            else if ((st = read_velocities(r, d, order, seen, err)) == CORE_OK)
                d->has_velocities = 1;
        } else if (!strcmp(key, "Masses") || !strcmp(key, "Pair Coeffs") ||
                   !strcmp(key, "PairIJ Coeffs") || !strcmp(key, "Atom Type Labels")) {
            st = skip_section(r, key, ntypes, err);
        } else {
            snprintf(msg, sizeof msg,
                     "section '%s' is not read by grainlab (it reads Atoms and Velocities of "
                     "atom_style sphere, and skips Masses, Pair Coeffs, PairIJ Coeffs and Atom "
                     "Type Labels)",
                     key);
            st = bad_line(err, r, msg);
        }
        if (st == CORE_OK && !next_content(r))
            break;
        if (st == CORE_OK && !isupper((unsigned char)r->tok[0][0])) {
            join_tokens(r, 0, key, sizeof key);
            snprintf(msg, sizeof msg,
                     "'%s' after the end of a section (more lines than the header's counts?)", key);
            st = bad_line(err, r, msg);
        }
    }
    free(seen);
    free(order);
    if (st != CORE_OK)
        return st;
    if (r->nul || (r->cut && r->ntok > 0)) /* read whole, but its last line is cut */
        return bad_line(err, r,
                        "a whole data file ends its last line with a newline (LAMMPS's "
                        "write_data does)");
    if (!have_atoms && d->n > 0)
        return core_fail(err, CORE_ERR_ARG,
                         "%s: the header announces %zu atoms but the file has no Atoms section "
                         "(truncated?)",
                         r->path, d->n);
    int flat = d->lo[2] < 0 && d->hi[2] > 0;
    for (size_t k = 0; k < d->n && flat; k++)
        flat = d->x[2][k] == 0 && d->v[2][k] == 0 && d->w[0][k] == 0 && d->w[1][k] == 0;
    d->flat = flat;
    return CORE_OK;
}

core_status dem_lammps_read(const char *path, dem_lammps_data *out, core_error *err)
{
    memset(out, 0, sizeof *out);
    out->path = strdup(path ? path : "");
    if (!out->path)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate a file name");
    reader r = {.path = out->path};
    core_status opened = fileio_open_read(path, "LAMMPS data file", &r.fp, &r.size, err);
    if (opened != CORE_OK)
        return opened;
    core_status st = parse(&r, out, err);
    if (st == CORE_OK && ferror(r.fp))
        st = core_fail(err, CORE_ERR_IO, "cannot read '%s': %s", path, strerror(errno));
    fclose(r.fp);
    free(r.buf);
    return st;
}

/* ---- adding to a scene ------------------------------------------------------------------------
 */
static int same_material(const dem_material *a, const dem_material *b)
{
    return a->density == b->density && a->young == b->young && a->poisson == b->poisson &&
           a->friction == b->friction && a->restitution == b->restitution;
}

/* The index of a material equal to m (an existing one, or a new one). */
static int material_for(dem_scene *s, const dem_material *m, core_error *err)
{
    for (int k = 0; k < s->nmat; k++)
        if (same_material(&s->mats[k], m))
            return k;
    return dem_add_material(s, m, err);
}

static int close_density(double a, double b) { return fabs(a - b) <= DENSITY_RTOL * fabs(b); }

typedef struct dens_key {
    int type;
    double density;
    size_t k;
} dens_key;

static int cmp_dens(const void *pa, const void *pb)
{
    const dens_key *a = pa, *b = pb;
    if (a->type != b->type)
        return a->type < b->type ? -1 : 1;
    if (a->density != b->density)
        return a->density < b->density ? -1 : 1;
    return (a->k > b->k) - (a->k < b->k);
}

static void rollback(dem_scene *s, size_t n0, int nmat0)
{
    s->n = n0;
    s->nmat = nmat0;
    s->r_max = 0;
    for (size_t i = 0; i < s->n; i++)
        if (s->r[i] > s->r_max)
            s->r_max = s->r[i];
    dem_invalidate(s, 1);
}

/* The checks of atom k of d against scene s, before the scene changes. */
static core_status check_atom(const dem_scene *s, const dem_lammps_data *d,
                              const dem_lammps_type *types, size_t k, core_error *err)
{
    const int D = s->dim;
    const dem_lammps_type *ty = &types[d->type[k] - 1];
    if (!ty->mapped)
        return core_fail(err, CORE_ERR_ARG,
                         "%s:%ld: atom %lld has type %d, which has no material (give it one "
                         "in types, or give material)",
                         d->path, d->line[k], d->id[k], d->type[k]);
    if (ty->density == DEM_LAMMPS_DENSITY_STRICT &&
        !close_density(d->density[k], ty->material.density))
        return core_fail(err, CORE_ERR_ARG,
                         "%s:%ld: atom %lld has density %.17g but type %d's material has "
                         "density %.17g (density = 'file' keeps the file's densities, "
                         "'material' the material's)",
                         d->path, d->line[k], d->id[k], d->density[k], d->type[k],
                         ty->material.density);
    if (D == 2 && (d->x[2][k] != 0 || d->v[2][k] != 0 || d->w[0][k] != 0 || d->w[1][k] != 0))
        return core_fail(err, CORE_ERR_ARG,
                         "%s:%ld: atom %lld has z = %g, vz = %g, wx = %g, wy = %g: a 2D scene "
                         "needs all four 0 (is this a 3D file?)",
                         d->path, d->line[k], d->id[k], d->x[2][k], d->v[2][k], d->w[0][k],
                         d->w[1][k]);
    if (D == 2 && d->image[2][k] != 0)
        return core_fail(err, CORE_ERR_ARG,
                         "%s:%ld: atom %lld has image flag %d on axis z of a 2D scene (a 2D "
                         "file's iz is 0)",
                         d->path, d->line[k], d->id[k], d->image[2][k]);
    for (int a = 0; a < D; a++) {
        double x = d->x[a][k];
        if (!s->periodic[a] && d->image[a][k] != 0)
            return core_fail(err, CORE_ERR_ARG,
                             "%s:%ld: atom %lld has image flag %d on axis %c, which is not "
                             "periodic in this scene (periodic = {...} as in the LAMMPS "
                             "run's boundary?)",
                             d->path, d->line[k], d->id[k], d->image[a][k], 'x' + a);
        if (!s->periodic[a] && (x < s->lo[a] || x > s->hi[a]))
            return core_fail(err, CORE_ERR_ARG,
                             "%s:%ld: atom %lld: %c = %.17g is outside the scene's box [%g, "
                             "%g] on an axis that is not periodic",
                             d->path, d->line[k], d->id[k], 'x' + a, x, s->lo[a], s->hi[a]);
        /* wrapped below; beyond LAMMPS's image range (512 box lengths) a coordinate is no
         * image of an atom, and wrapping it would keep little of its digits */
        double boxes = (x < s->lo[a] ? s->lo[a] - x : x - s->hi[a]) / s->len[a];
        if (s->periodic[a] && boxes > 512)
            return core_fail(err, CORE_ERR_ARG,
                             "%s:%ld: atom %lld: %c = %.17g is more than 512 box lengths "
                             "(LAMMPS's image range) outside the periodic box [%g, %g]",
                             d->path, d->line[k], d->id[k], 'x' + a, x, s->lo[a], s->hi[a]);
    }
    /* a speed whose kinetic energy overflows is no grain's (the energy measures sum v^2) */
    for (int a = 0; a < 3; a++) {
        const double v = d->v[a][k], w = d->w[a][k] * d->radius[k];
        if (!isfinite(v * v) || !isfinite(w * w))
            return core_fail(err, CORE_ERR_ARG,
                             "%s:%ld: atom %lld: %s = %g is too large (its square, in the "
                             "kinetic energy, overflows)",
                             d->path, d->line[k], d->id[k],
                             !isfinite(v * v) ? (const char *[]){"vx", "vy", "vz"}[a]
                                              : (const char *[]){"wx", "wy", "wz"}[a],
                             !isfinite(v * v) ? v : d->w[a][k]);
    }
    return CORE_OK;
}

/* Densities within DENSITY_RTOL of a run's first share one copy, whose density is the most
 * frequent exact value of the run (LAMMPS's round-off scatters a few ulps around it): the copies
 * of the atoms of keys (a density the file gives, not the type's), their indices into mat. */
static core_status density_copies(dem_scene *s, const dem_lammps_type *types, dens_key *keys,
                                  size_t nkeys, int *mat, core_error *err)
{
    core_status st = CORE_OK;
    qsort(keys, nkeys, sizeof *keys, cmp_dens);
    for (size_t a = 0; a < nkeys && st == CORE_OK;) {
        size_t b = a + 1;
        while (b < nkeys && keys[b].type == keys[a].type &&
               close_density(keys[b].density, keys[a].density))
            b++;
        double best = keys[a].density;
        size_t best_run = 0;
        for (size_t c = a; c < b;) {
            size_t e = c + 1;
            while (e < b && keys[e].density == keys[c].density)
                e++;
            if (e - c > best_run)
                best_run = e - c, best = keys[c].density;
            c = e;
        }
        dem_material m = types[keys[a].type].material;
        m.density = best;
        int idx = material_for(s, &m, err);
        if (idx < 0)
            st = err ? err->status : CORE_ERR_ARG;
        for (size_t c = a; c < b; c++)
            mat[keys[c].k] = idx;
        a = b;
    }
    return st;
}

core_status dem_lammps_add(dem_scene *s, const dem_lammps_data *d, const dem_lammps_type *types,
                           int *type_material, size_t *first, core_error *err)
{
    const int D = s->dim;
    *first = s->n;
    for (int t = 0; t < d->ntypes; t++)
        type_material[t] = -1;
    /* ---- every check before the scene changes ---- */
    for (size_t k = 0; k < d->n; k++) {
        core_status st = check_atom(s, d, types, k, err);
        if (st != CORE_OK)
            return st;
    }
    /* Ids other than 1..n (a scene written after removals) become the particles' tags, so that
     * a grain keeps its number across the round trip; 1..n is what the particles get anyway. */
    int adopt = 0;
    for (size_t k = 0; k < d->n && !adopt; k++)
        adopt = d->id[k] != (long long)k + 1;
    if (adopt) {
        size_t k = 0;
        long i = dem_flow_tag_clash(s, d->id, d->n, &k);
        if (i >= 0)
            return core_fail(err, CORE_ERR_ARG,
                             "%s:%ld: atom id %lld is already the tag of particle %ld of the "
                             "scene (ids other than 1..n become tags: read such a file into an "
                             "empty scene)",
                             d->path, d->line[k], d->id[k], i + 1);
        if (d->n > 0 && d->id[d->n - 1] > (1LL << 53))
            return core_fail(err, CORE_ERR_ARG,
                             "%s:%ld: atom id %lld is too large to keep as a tag (at most 2^53)",
                             d->path, d->line[d->n - 1], d->id[d->n - 1]);
    }
    /* ---- materials: each type's own, then copies for densities that differ ---- */
    size_t n0 = s->n;
    int nmat0 = s->nmat;
    core_status st = CORE_OK;
    int *mat = malloc((d->n ? d->n : 1) * sizeof *mat);
    dens_key *keys = malloc((d->n ? d->n : 1) * sizeof *keys);
    if (!mat || !keys) {
        free(mat), free(keys);
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu atoms", d->n);
    }
    /* Materials are made in type order, so that a scene read from a file writes the same types
     * back (type k = material k - 1 when the scene starts empty). */
    size_t nkeys = 0;
    for (size_t k = 0; k < d->n; k++) {
        int t = d->type[k] - 1;
        const dem_lammps_type *ty = &types[t];
        mat[k] = -1;
        if (ty->density == DEM_LAMMPS_DENSITY_FILE &&
            !close_density(d->density[k], ty->material.density)) {
            keys[nkeys++] = (dens_key){t, d->density[k], k};
            mat[k] = -3; /* a copy, below */
        } else
            type_material[t] = -2; /* needed */
    }
    for (int t = 0; t < d->ntypes && st == CORE_OK; t++)
        if (type_material[t] == -2 &&
            (type_material[t] = material_for(s, &types[t].material, err)) < 0)
            st = err ? err->status : CORE_ERR_ARG;
    for (size_t k = 0; k < d->n && st == CORE_OK; k++)
        if (mat[k] == -1 && type_material[d->type[k] - 1] >= 0)
            mat[k] = type_material[d->type[k] - 1];
    if (st == CORE_OK)
        st = density_copies(s, types, keys, nkeys, mat, err);
    free(keys);
    /* Angular velocities in the file are kept: they need the rotational state. */
    int spin = 0;
    for (size_t k = 0; k < d->n && !spin; k++)
        spin = d->w[0][k] != 0 || d->w[1][k] != 0 || d->w[2][k] != 0;
    if (st == CORE_OK && spin)
        st = dem_ensure_rotation(s, err);
    /* ---- particles ---- */
    for (size_t k = 0; k < d->n && st == CORE_OK; k++) {
        dem_particle_def p;
        memset(&p, 0, sizeof p);
        for (int a = 0; a < D; a++) {
            double x = d->x[a][k];
            if (s->periodic[a] && (x < s->lo[a] || x >= s->hi[a])) {
                /* into the box, as grainlab keeps periodic positions (image flags say nothing
                 * more: grainlab does not count crossings) */
                double len = s->hi[a] - s->lo[a];
                x -= floor((x - s->lo[a]) / len) * len;
                if (!(x >= s->lo[a] && x <= s->hi[a]))
                    x = s->lo[a];
            }
            p.x[a] = x;
            p.v[a] = d->v[a][k];
        }
        for (int a = 0; a < 3; a++)
            p.omega[a] = d->w[a][k];
        p.radius = d->radius[k];
        p.material = mat[k];
        p.flags = types[d->type[k] - 1].flags;
        long i = dem_add_particle(s, &p, err);
        if (i < 0) {
            char why[sizeof err->msg];
            snprintf(why, sizeof why, "%s", err ? err->msg : "");
            st = core_fail(err, CORE_ERR_ARG, "%s:%ld: atom %lld: %s", d->path, d->line[k],
                           d->id[k], why);
            break;
        }
    }
    free(mat);
    if (st == CORE_OK && adopt)
        st = dem_flow_adopt_tags(s, n0, d->id, d->n, err);
    if (st != CORE_OK) {
        rollback(s, n0, nmat0);
        for (int t = 0; t < d->ntypes; t++)
            if (type_material[t] >= nmat0 || type_material[t] == -2)
                type_material[t] = -1;
        return st;
    }
    dem_invalidate(s, 1);
    return CORE_OK;
}
