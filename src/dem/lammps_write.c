/* LAMMPS files written from a DEM scene: data files in atom_style sphere (hybrid sphere molecular
 * in a scene with clumps) and `dump custom` frames (lammps.c reads atom_style sphere back). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/fileio.h"
#include "dem/dem_internal.h"

static core_status atom_types(const dem_scene *s, const dem_lammps_write_def *def, int **out,
                              int *ntypes, core_error *err)
{
    int *type = malloc((s->n ? s->n : 1) * sizeof *type);
    if (!type)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu particles", s->n);
    int top = 0;
    for (size_t i = 0; i < s->n; i++) {
        int m = s->mat[i];
        int t = def && def->type_of_material ? def->type_of_material[m] : m + 1;
        if (t < 1) {
            free(type);
            return core_fail(err, CORE_ERR_ARG,
                             "particle %zu's material (number %d of the scene) has no atom type",
                             i + 1, m + 1);
        }
        type[i] = t;
        if (t > top)
            top = t;
    }
    int want = def && def->ntypes > 0 ? def->ntypes : 0;
    if (want && want < top) {
        free(type);
        return core_fail(err, CORE_ERR_ARG, "atom types %d is less than the largest type %d", want,
                         top);
    }
    *ntypes = want ? want : (top > 0 ? top : (s->nmat > 0 ? s->nmat : 1));
    *out = type;
    return CORE_OK;
}

/* The z extent of a 2D scene's file: LAMMPS needs zlo < 0 < zhi there. */
static double slab_half(const dem_scene *s)
{
    if (s->thickness > 0)
        return s->thickness / 2;
    if (s->r_max > 0)
        return s->r_max;
    return 0.5 * (s->len[0] < s->len[1] ? s->len[0] : s->len[1]);
}

static void box3(const dem_scene *s, double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++)
        lo[a] = s->lo[a], hi[a] = s->hi[a];
    if (s->dim == 2)
        lo[2] = -slab_half(s), hi[2] = slab_half(s);
}

/* Position of particle i wrapped into the box on periodic axes, with its image flags. */
static void wrapped(const dem_scene *s, size_t i, double x[3], long img[3])
{
    for (int a = 0; a < 3; a++) {
        x[a] = a < s->dim ? s->x[a][i] : 0;
        img[a] = 0;
        if (a < s->dim && s->periodic[a] && (x[a] < s->lo[a] || x[a] >= s->hi[a])) {
            double f = floor((x[a] - s->lo[a]) / s->len[a]);
            img[a] = (long)f;
            x[a] -= f * s->len[a];
            if (x[a] >= s->hi[a]) /* rounding at the upper side */
                x[a] -= s->len[a], img[a]++;
            if (x[a] < s->lo[a])
                x[a] = s->lo[a];
        }
    }
}

static double omega_of(const dem_scene *s, int a, size_t i) { return s->w[a] ? s->w[a][i] : 0; }

/* The atom id of particle i: its tag + 1 in a scene with insertion or removal (OVITO follows a
 * grain across a removal by it; dem_lammps_add reads it back as the tag), else index + 1. */
static long long atom_id(const dem_scene *s, size_t i)
{
    return (s->tag ? (long long)s->tag[i] : (long long)i) + 1;
}

/* LAMMPS's molecule id of particle i in a scene with clumps, the convention of its rigid bodies
 * (fix rigid/small molecule): the clump id (1-based) of a member of a clump of two or more
 * members; 0 for a grain of no clump and for a clump of one sphere, which LAMMPS refuses as a
 * rigid body and which moves as that sphere would. */
static long mol_id(const dem_scene *s, size_t i)
{
    const long k = dem_particle_clump(s, i);
    return k >= 0 && s->clumps->b[k].count > 1 ? k + 1 : 0;
}

core_status dem_write_lammps_data(const dem_scene *s, const char *path,
                                  const dem_lammps_write_def *def, core_error *err)
{
    /* atom_style hybrid sphere molecular carries the molecule id after sphere's values */
    const int mol = dem_clump_count(s) > 0;
    int *type = NULL, ntypes = 0;
    core_status st = atom_types(s, def, &type, &ntypes, err);
    if (st != CORE_OK)
        return st;
    atomic_file f;
    if ((st = atomic_open(&f, path, err)) != CORE_OK) {
        free(type);
        return st;
    }
    FILE *fp = f.fp;
    char title[256];
    if (def && def->title)
        snprintf(title, sizeof title, "%s", def->title);
    else
        snprintf(title, sizeof title,
                 "LAMMPS data file (atom_style %s) from grainlab: %dD, "
                 "boundary %c %c %c, time %.17g s",
                 mol ? "hybrid sphere molecular" : "sphere", s->dim, s->periodic[0] ? 'p' : 'f',
                 s->periodic[1] ? 'p' : 'f',
                 s->dim == 2 || s->periodic[2] ? 'p' : 'f', s->time);
    for (char *c = title; *c; c++) /* one line */
        if (*c == '\n' || *c == '\r')
            *c = ' ';
    double lo[3], hi[3];
    box3(s, lo, hi);
    fprintf(fp, "%s\n\n%zu atoms\n%d atom types\n\n", title, s->n, ntypes);
    for (int a = 0; a < 3; a++)
        fprintf(fp, "%.17g %.17g %clo %chi\n", lo[a], hi[a], 'x' + a, 'x' + a);
    fprintf(fp, "\nAtoms # %s\n\n", mol ? "hybrid" : "sphere");
    for (size_t i = 0; i < s->n; i++) {
        double x[3];
        long img[3];
        wrapped(s, i, x, img);
        const double dia = 2 * s->r[i], rho = s->mats[s->mat[i]].density;
        if (mol) /* hybrid: id type x y z, then each sub-style's own values */
            fprintf(fp, "%lld %d %.17g %.17g %.17g %.17g %.17g %ld %ld %ld %ld\n", atom_id(s, i),
                    type[i], x[0], x[1], x[2], dia, rho, mol_id(s, i), img[0], img[1], img[2]);
        else
            fprintf(fp, "%lld %d %.17g %.17g %.17g %.17g %.17g %ld %ld %ld\n", atom_id(s, i),
                    type[i], dia, rho, x[0], x[1], x[2], img[0], img[1], img[2]);
    }
    fprintf(fp, "\nVelocities\n\n");
    for (size_t i = 0; i < s->n; i++) {
        double v[3] = {s->v[0][i], s->v[1][i], s->dim == 3 ? s->v[2][i] : 0};
        fprintf(fp, "%lld %.17g %.17g %.17g %.17g %.17g %.17g\n", atom_id(s, i), v[0], v[1], v[2],
                omega_of(s, 0, i), omega_of(s, 1, i), omega_of(s, 2, i));
    }
    free(type);
    return atomic_commit(&f, err);
}

/* Appends printf output to a growing buffer. */
typedef struct strbuf {
    char *p;
    size_t len, cap;
    int failed;
} strbuf;

static void sb_printf(strbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void sb_printf(strbuf *b, const char *fmt, ...)
{
    if (b->failed)
        return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int k = vsnprintf(b->p ? b->p + b->len : NULL, b->p ? b->cap - b->len : 0, fmt, ap);
        va_end(ap);
        if (k < 0) {
            b->failed = 1;
            return;
        }
        if (b->p && b->len + (size_t)k < b->cap) {
            b->len += (size_t)k;
            return;
        }
        size_t cap = b->cap ? b->cap : 4096;
        while (cap <= b->len + (size_t)k)
            cap *= 2;
        char *q = realloc(b->p, cap);
        if (!q) {
            b->failed = 1;
            return;
        }
        b->p = q;
        b->cap = cap;
    }
}

core_status dem_write_lammps_dump(const dem_scene *s, const char *path,
                                  const dem_lammps_write_def *def, core_error *err)
{
    int *type = NULL, ntypes = 0;
    core_status st = atom_types(s, def, &type, &ntypes, err);
    if (st != CORE_OK)
        return st;
    /* The frame is made in memory first, so that it reaches the file in one write. */
    strbuf b = {0};
    double lo[3], hi[3];
    box3(s, lo, hi);
    /* No "ITEM: TIME": read_dump and rerun of LAMMPS 29 Sep 2021 (Debian 12) refuse it. */
    sb_printf(&b, "ITEM: TIMESTEP\n%ld\nITEM: NUMBER OF ATOMS\n%zu\n", s->steps, s->n);
    char bc[3];
    for (int a = 0; a < 3; a++)
        bc[a] = (a >= s->dim || s->periodic[a]) ? 'p' : 'f';
    sb_printf(&b, "ITEM: BOX BOUNDS %c%c %c%c %c%c\n", bc[0], bc[0], bc[1], bc[1], bc[2], bc[2]);
    for (int a = 0; a < 3; a++)
        sb_printf(&b, "%.17g %.17g\n", lo[a], hi[a]);
    const int mol = dem_clump_count(s) > 0; /* clumps: the molecule id after the atom id */
    sb_printf(&b, "ITEM: ATOMS id %stype radius mass x y z vx vy vz fx fy fz omegax omegay "
                  "omegaz\n", mol ? "mol " : "");
    for (size_t i = 0; i < s->n; i++) {
        double x[3];
        long img[3];
        wrapped(s, i, x, img);
        double v[3], f[3];
        for (int a = 0; a < 3; a++) {
            v[a] = a < s->dim ? s->v[a][i] : 0;
            f[a] = a < s->dim ? s->f[a][i] : 0;
        }
        if (mol)
            sb_printf(&b, "%lld %ld ", atom_id(s, i), mol_id(s, i));
        else
            sb_printf(&b, "%lld ", atom_id(s, i));
        sb_printf(&b,
                  "%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g "
                  "%.17g %.17g %.17g\n",
                  type[i], s->r[i], s->m[i], x[0], x[1], x[2], v[0], v[1], v[2],
                  f[0], f[1], f[2], omega_of(s, 0, i), omega_of(s, 1, i), omega_of(s, 2, i));
    }
    free(type);
    if (b.failed) {
        free(b.p);
        return core_fail(err, CORE_ERR_NOMEM, "cannot format a dump frame of %zu atoms", s->n);
    }
    if (!(def && def->append)) {
        st = atomic_write(path, b.p, b.len, err);
        free(b.p);
        return st;
    }
    int fd = open(path, O_WRONLY | O_APPEND | O_CREAT, 0666);
    if (fd < 0) {
        free(b.p);
        return core_fail(err, CORE_ERR_IO, "cannot append to '%s': %s", path, strerror(errno));
    }
    struct stat sb;
    off_t before = fstat(fd, &sb) == 0 ? sb.st_size : -1;
    size_t done = 0;
    int e = 0;
    while (done < b.len) {
        ssize_t k = write(fd, b.p + done, b.len - done);
        if (k < 0) {
            if (errno == EINTR)
                continue;
            e = errno;
            break;
        }
        done += (size_t)k;
    }
    free(b.p);
    if (e && before >= 0 && ftruncate(fd, before) != 0) /* no half frame after a failure */
        e = errno;
    if (close(fd) != 0 && !e)
        e = errno;
    if (e)
        return core_fail(err, CORE_ERR_IO, "cannot append to '%s': %s", path, strerror(e));
    return CORE_OK;
}
