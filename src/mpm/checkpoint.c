/* MPM checkpoints: the state of a scene that a bit-exact continuation needs, as sections of a
 * grainlab checkpoint (core/checkpoint.h), and a strict reader that builds a new scene from them.
 *
 * What is state: the definition (grid, walls, update order, shape functions, PIC fraction), the
 * materials, the contact model and its options, the user planes exactly as stored (unit normal
 * into the wall), the grains (point ranges, shapes for the overlap warning, prescribed
 * velocities), every material point (position, velocity, mass, reference volume, deformation
 * gradient, elastic left Cauchy-Green tensor, stress, plastic strain, displacement, grain,
 * material), with drucker_prager or mu_i materials their parameters and each point's plastic
 * shear rate of the last step ("mpm.continuum", written only then: a grainlab without these
 * models refuses the file), the light-node threshold m_min, the time and the step count.
 * Everything else is
 * rebuilt: the grid's nodal fields, the stencil and the per-grain contact fields are recomputed
 * from the points at the start of every step, the wall flags of the nodes and the gap-test
 * references from the definition and the planes, the thread ranges at each run, and the
 * automatic time step is taken afresh from the points every step. Points are stored in their
 * order, which is their global id (grain by grain, never reordered); nothing depends on threads. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/checkpoint.h"
#include "mpm/mpm_internal.h"

#define TRY(x)                                                                                     \
    do {                                                                                           \
        if ((st = (x)) != CORE_OK)                                                                 \
            goto done;                                                                             \
    } while (0)

/* ---- writing ------------------------------------------------------------------------------ */
static void put_i64(ckpt_writer *w, long long v) { ckpt_put_i64(w, (int64_t)v); }

static void put_ints(ckpt_writer *w, const int *v, size_t n, int64_t *tmp)
{
    for (size_t k = 0; k < n; k++)
        tmp[k] = v[k];
    ckpt_put_i64s(w, tmp, n);
}

static void put_plane(ckpt_writer *w, const mpm_plane *p)
{
    put_i64(w, p->kind);
    ckpt_put_f64(w, p->n[0]);
    ckpt_put_f64(w, p->n[1]);
    ckpt_put_f64(w, p->v[0]);
    ckpt_put_f64(w, p->v[1]);
    ckpt_put_f64(w, p->mu);
    ckpt_put_f64(w, p->point[0]);
    ckpt_put_f64(w, p->point[1]);
}

/* The continuum models' parameters per material in "mpm.continuum" (mpm_material's order). */
enum { NCONT = 8 };
static const char *const CONT_NAMES[NCONT] = {"friction", "dilatancy", "cohesion",
                                              "mu_s",     "mu_2",      "i0",
                                              "grain_diameter", "grain_density"};

/* The point arrays of the scene, in the order of the file. */
static void point_arrays(const mpm_scene *s, double *a[21])
{
    double *list[21] = {s->x,      s->y,      s->vx,     s->vy,     s->m,     s->v0,    s->F[0],
                        s->F[1],   s->F[2],   s->F[3],   s->be[0],  s->be[1], s->be[2], s->be[3],
                        s->sig[0], s->sig[1], s->sig[2], s->sig[3], s->eps_p, s->ux,    s->uy};
    memcpy(a, list, sizeof list);
}

core_status mpm_save(const mpm_scene *s, const char *path, const char *version, core_error *err)
{
    const size_t ng = s->ngrains, np = s->np;
    const size_t ntmp = np > ng ? np : ng;
    int64_t *tmp = malloc((ntmp ? ntmp : 1) * sizeof *tmp);
    if (!tmp)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory saving %zu points", np);
    ckpt_writer *w = NULL;
    core_status st;
    TRY(ckpt_writer_open(&w, path, "mpm", version, err));

    const mpm_scene_def *d = &s->def;
    TRY(ckpt_section_begin(w, "mpm.scene", CKPT_REQUIRED, err));
    for (int a = 0; a < 2; a++) {
        put_i64(w, d->cells[a]);
        ckpt_put_f64(w, d->origin[a]);
        ckpt_put_f64(w, d->size[a]);
        put_i64(w, d->periodic[a]);
        ckpt_put_f64(w, d->gravity[a]);
    }
    for (int k = 0; k < 4; k++) {
        put_i64(w, d->walls[k]);
        ckpt_put_f64(w, d->wall_mu[k]);
        ckpt_put_f64(w, d->wall_velocity[k][0]);
        ckpt_put_f64(w, d->wall_velocity[k][1]);
    }
    put_i64(w, d->shape);
    ckpt_put_f64(w, d->wall_gap);
    put_i64(w, d->update);
    ckpt_put_f64(w, d->pic);
    TRY(ckpt_section_end(w, err));

    TRY(ckpt_section_begin(w, "mpm.materials", CKPT_REQUIRED, err));
    ckpt_put_u64(w, (uint64_t)s->nmat);
    for (int k = 0; k < s->nmat; k++) {
        const mpm_material *m = &s->mats[k];
        put_i64(w, m->model);
        ckpt_put_f64(w, m->density);
        ckpt_put_f64(w, m->shear);
        ckpt_put_f64(w, m->bulk);
        ckpt_put_f64(w, m->yield);
        ckpt_put_f64(w, m->hardening);
    }
    TRY(ckpt_section_end(w, err));

    TRY(ckpt_section_begin(w, "mpm.contact", CKPT_REQUIRED, err));
    put_i64(w, s->contact);
    ckpt_put_f64(w, s->mu);
    put_i64(w, s->opt.normals);
    ckpt_put_f64(w, s->opt.separation);
    ckpt_put_f64(w, s->opt.strain_cap);
    put_i64(w, s->opt.conserve);
    TRY(ckpt_section_end(w, err));

    /* planes 0-3 are the grid's edges, made from the definition */
    TRY(ckpt_section_begin(w, "mpm.planes", CKPT_REQUIRED, err));
    ckpt_put_u64(w, (uint64_t)(s->nplanes - 4));
    for (int k = 4; k < s->nplanes; k++)
        put_plane(w, &s->planes[k]);
    TRY(ckpt_section_end(w, err));

    TRY(ckpt_section_begin(w, "mpm.grains", CKPT_REQUIRED, err));
    ckpt_put_u64(w, (uint64_t)ng);
    for (size_t g = 0; g < ng; g++) {
        const mpm_grain_def *gd = &s->gdef[g];
        ckpt_put_u64(w, (uint64_t)s->gstart[g]);
        ckpt_put_u64(w, (uint64_t)s->gcount[g]);
        put_i64(w, gd->shape);
        ckpt_put_f64(w, gd->center[0]);
        ckpt_put_f64(w, gd->center[1]);
        ckpt_put_f64(w, gd->radius);
        ckpt_put_f64(w, gd->lo[0]);
        ckpt_put_f64(w, gd->lo[1]);
        ckpt_put_f64(w, gd->hi[0]);
        ckpt_put_f64(w, gd->hi[1]);
        put_i64(w, gd->material);
        put_i64(w, gd->points_per_cell);
        ckpt_put_f64(w, gd->velocity[0]);
        ckpt_put_f64(w, gd->velocity[1]);
        ckpt_put_f64(w, gd->omega);
        put_i64(w, gd->clip);
        /* the prescribed velocity, if any */
        const int k = s->gpres ? s->gpres[g] : -1;
        put_i64(w, k >= 0);
        ckpt_put_f64(w, k >= 0 ? s->pv[k][0] : 0);
        ckpt_put_f64(w, k >= 0 ? s->pv[k][1] : 0);
    }
    TRY(ckpt_section_end(w, err));

    TRY(ckpt_section_begin(w, "mpm.points", CKPT_REQUIRED, err));
    double *a[21];
    point_arrays(s, a);
    for (int k = 0; k < 21; k++)
        ckpt_put_f64s(w, a[k], np);
    put_ints(w, s->grain, np, tmp);
    put_ints(w, s->mat, np, tmp);
    TRY(ckpt_section_end(w, err));

    if (s->rate) {
        TRY(ckpt_section_begin(w, "mpm.continuum", CKPT_REQUIRED, err));
        ckpt_put_u64(w, (uint64_t)s->nmat);
        for (int k = 0; k < s->nmat; k++) {
            const mpm_material *m = &s->mats[k];
            const double v[NCONT] = {m->friction, m->dilatancy,      m->cohesion,
                                     m->mu_s,     m->mu_2,           m->i0,
                                     m->grain_diameter, m->grain_density};
            for (int c = 0; c < NCONT; c++)
                ckpt_put_f64(w, v[c]);
        }
        ckpt_put_f64s(w, s->rate, np);
        TRY(ckpt_section_end(w, err));
    }

    TRY(ckpt_section_begin(w, "mpm.clock", CKPT_REQUIRED, err));
    ckpt_put_f64(w, s->time);
    put_i64(w, s->steps);
    ckpt_put_f64(w, s->m_min);
    TRY(ckpt_section_end(w, err));

    st = ckpt_writer_commit(w, err);
    w = NULL;
done:
    ckpt_writer_abort(w);
    free(tmp);
    return st;
}

/* ---- reading ------------------------------------------------------------------------------ */
typedef struct reader {
    ckpt_section sec;
    core_error *err;
    const char *path;
} reader;

static core_status get_int(reader *rd, long lo, long hi, const char *what, long *out)
{
    return ckpt_get_int_in(&rd->sec, lo, hi, what, out, rd->err);
}

static core_status get_num(reader *rd, const char *what, double *out)
{
    return ckpt_get_finite(&rd->sec, what, out, rd->err);
}

static core_status corrupt(const reader *rd, const char *what)
{
    return core_fail(rd->err, CORE_ERR_ARG, "'%s' is a corrupt mpm checkpoint: %s", rd->path, what);
}

/* A refusal of an engine call made for stored values (mpm_create, mpm_add_material, ...), said
 * as the file's: "'PATH' is a corrupt mpm checkpoint: density must be > 0, got -1". */
static core_status named(const reader *rd, core_status st)
{
    return ckpt_blame_file(rd->err, st, rd->path, "mpm");
}

/* The grid against the points, before the grid is sized by the definition's cells: a grain is
 * seeded with points_per_cell^2 points per cell, each of reference volume (hx / ppc) (hy / ppc)
 * (mpm_add_disk and the like), which no step changes. Reads the grains' ranges and points per
 * cell and the points' volumes from the file without building anything. */
static core_status check_cells(ckpt_reader *r, reader *rd, const mpm_scene_def *d)
{
    enum {
        GRAIN = 152,
        PPC = 88,
        V0 = 5
    }; /* bytes of a grain's record (write), offset of its
        * points per cell; v0 is the 6th point array */
    ckpt_section g, p;
    core_status st;
    if ((st = ckpt_find(r, "mpm.grains", &g, rd->err)) ||
        (st = ckpt_find(r, "mpm.points", &p, rd->err)))
        return st;
    uint64_t ng, np;
    if ((st = ckpt_get_u64(&g, &ng, rd->err)) || (st = ckpt_get_u64(&p, &np, rd->err)))
        return st;
    if (ng > (g.size - 8) / GRAIN || np > (p.size - 8) / (21 * sizeof(double)))
        return CORE_OK; /* the readers below say what is wrong */
    const double hx = d->size[0] / d->cells[0], hy = d->size[1] / d->cells[1];
    for (uint64_t k = 0; k < ng; k++) {
        uint64_t a, c;
        int64_t ppc;
        g.pos = 8 + k * GRAIN;
        if ((st = ckpt_get_u64(&g, &a, rd->err)) || (st = ckpt_get_u64(&g, &c, rd->err)))
            return st;
        g.pos = 8 + k * GRAIN + PPC;
        if ((st = ckpt_get_i64(&g, &ppc, rd->err)))
            return st;
        if (a >= np || c == 0 || c > np - a || ppc < 1 || ppc > 64)
            return CORE_OK; /* read_grains refuses it, naming what */
        const double v0 = (hx / (double)ppc) * (hy / (double)ppc);
        for (uint64_t q = a; q < a + c; q++) {
            double v;
            p.pos = V0 * (8 + np * 8) + 8 + q * 8;
            if ((st = ckpt_get_f64(&p, &v, rd->err)))
                return st;
            if (!(fabs(v - v0) <= 1e-9 * v0)) {
                char what[256];
                snprintf(what, sizeof what,
                         "cells %d x %d (cell %g x %g) do not match point %llu's reference volume "
                         "%g (%g with %lld points per cell along an axis)",
                         d->cells[0], d->cells[1], hx, hy, (unsigned long long)q + 1, v, v0,
                         (long long)ppc);
                return corrupt(rd, what);
            }
        }
    }
    return CORE_OK;
}

static core_status read_def(reader *rd, mpm_scene_def *d)
{
    core_status st;
    long v;
    *d = mpm_default_scene_def();
    for (int a = 0; a < 2; a++) {
        TRY(get_int(rd, 1, 1 << 20, "cells", &v));
        d->cells[a] = (int)v;
        TRY(get_num(rd, "origin", &d->origin[a]));
        TRY(get_num(rd, "size", &d->size[a]));
        TRY(get_int(rd, 0, 1, "periodic", &v));
        d->periodic[a] = v != 0;
        TRY(get_num(rd, "gravity", &d->gravity[a]));
    }
    for (int k = 0; k < 4; k++) {
        TRY(get_int(rd, MPM_WALL_NOSLIP, MPM_WALL_FRICTION, "wall kind", &v));
        d->walls[k] = (mpm_wall)v;
        TRY(get_num(rd, "wall mu", &d->wall_mu[k]));
        TRY(get_num(rd, "wall velocity", &d->wall_velocity[k][0]));
        TRY(get_num(rd, "wall velocity", &d->wall_velocity[k][1]));
    }
    TRY(get_int(rd, MPM_SHAPE_LINEAR, MPM_SHAPE_BSPLINE, "shape functions", &v));
    d->shape = (mpm_shape_fn)v;
    TRY(get_num(rd, "wall_gap", &d->wall_gap));
    TRY(get_int(rd, MPM_USL, MPM_USF, "update", &v));
    d->update = (mpm_update)v;
    TRY(get_num(rd, "pic", &d->pic));
    st = ckpt_section_done(&rd->sec, rd->err);
done:
    return st;
}

static bool continuum_model(mpm_model m) { return m == MPM_DRUCKER_PRAGER || m == MPM_MU_I; }

/* The materials, with the continuum models' parameters from "mpm.continuum" when a material
 * needs them; *cont is then that section with its cursor at the point rates (read_rates), and
 * cont->data NULL otherwise. */
static core_status read_materials(ckpt_reader *r, reader *rd, mpm_scene *s, ckpt_section *cont)
{
    core_status st;
    uint64_t n;
    mpm_material *mats = NULL;
    cont->data = NULL;
    TRY(ckpt_get_u64(&rd->sec, &n, rd->err));
    if (n > 1u << 20 || n > rd->sec.size / 48)
        return corrupt(rd, "too many materials");
    mats = malloc((n ? n : 1) * sizeof *mats);
    if (!mats)
        return core_fail(rd->err, CORE_ERR_NOMEM, "out of memory for %llu materials",
                         (unsigned long long)n);
    bool any = false;
    for (uint64_t k = 0; k < n; k++) {
        mpm_material *m = &mats[k];
        *m = mpm_default_material();
        long v;
        TRY(get_int(rd, MPM_ELASTIC, MPM_MU_I, "material model", &v));
        m->model = (mpm_model)v;
        any |= continuum_model(m->model);
        TRY(get_num(rd, "density", &m->density));
        TRY(get_num(rd, "shear", &m->shear));
        TRY(get_num(rd, "bulk", &m->bulk));
        TRY(get_num(rd, "yield", &m->yield));
        TRY(get_num(rd, "hardening", &m->hardening));
    }
    TRY(ckpt_section_done(&rd->sec, rd->err));
    if (any) {
        TRY(ckpt_find(r, "mpm.continuum", &rd->sec, rd->err));
        uint64_t nc;
        TRY(ckpt_get_u64(&rd->sec, &nc, rd->err));
        if (nc != n) {
            st = corrupt(rd, "the continuum parameters do not match the materials");
            goto done;
        }
        for (uint64_t k = 0; k < n; k++) {
            mpm_material *m = &mats[k];
            double *v[NCONT] = {&m->friction, &m->dilatancy,      &m->cohesion,
                                &m->mu_s,     &m->mu_2,           &m->i0,
                                &m->grain_diameter, &m->grain_density};
            for (int c = 0; c < NCONT; c++)
                TRY(get_num(rd, CONT_NAMES[c], v[c]));
        }
        *cont = rd->sec;
    } else if (ckpt_has(r, "mpm.continuum")) {
        st = corrupt(rd, "continuum parameters without a drucker_prager or mu_i material");
        goto done;
    }
    for (uint64_t k = 0; k < n; k++)
        if (mpm_add_material(s, &mats[k], rd->err) < 0) {
            st = named(rd, CORE_ERR_ARG);
            goto done;
        }
done:
    free(mats);
    return st;
}

/* The points' plastic shear rates at the end of "mpm.continuum" (finite, >= 0). */
static core_status read_rates(reader *rd, mpm_scene *s, const ckpt_section *cont)
{
    core_status st;
    rd->sec = *cont;
    TRY(ckpt_get_f64s(&rd->sec, s->rate, s->np, rd->err));
    for (size_t p = 0; p < s->np; p++)
        if (!(s->rate[p] >= 0) || !isfinite(s->rate[p]))
            return corrupt(rd, "a point's plastic shear rate is negative or not finite");
    st = ckpt_section_done(&rd->sec, rd->err);
done:
    return st;
}

static core_status read_contact(reader *rd, mpm_scene *s)
{
    core_status st;
    long model, normals, conserve;
    double mu;
    mpm_contact_options o = mpm_default_contact_options();
    TRY(get_int(rd, MPM_CONTACT_NOSLIP, MPM_CONTACT_FRICTION, "contact model", &model));
    TRY(get_num(rd, "mu", &mu));
    TRY(get_int(rd, MPM_NORMALS_AVERAGED, MPM_NORMALS_LINEAR, "normals", &normals));
    TRY(get_num(rd, "separation", &o.separation));
    TRY(get_num(rd, "strain_cap", &o.strain_cap));
    TRY(get_int(rd, 0, 1, "conserve", &conserve));
    o.normals = (mpm_normals)normals;
    o.conserve = conserve != 0;
    TRY(named(rd, mpm_set_contact_options(s, &o, rd->err)));
    if (model == MPM_CONTACT_FRICTION) {
        TRY(named(rd, mpm_set_friction(s, mu, rd->err)));
    } else {
        TRY(named(rd, mpm_set_contact(s, MPM_CONTACT_NOSLIP, rd->err)));
        s->mu = mu; /* kept as it was, though noslip ignores it */
    }
    st = ckpt_section_done(&rd->sec, rd->err);
done:
    return st;
}

static core_status read_planes(reader *rd, mpm_scene *s)
{
    core_status st;
    uint64_t n;
    TRY(ckpt_get_u64(&rd->sec, &n, rd->err));
    if (n > MPM_MAX_PLANES)
        return corrupt(rd, "more planes than a scene holds");
    for (uint64_t k = 0; k < n; k++) {
        mpm_plane p;
        memset(&p, 0, sizeof p);
        long kind;
        TRY(get_int(rd, MPM_WALL_NOSLIP, MPM_WALL_FRICTION, "plane kind", &kind));
        p.kind = (mpm_wall)kind;
        TRY(get_num(rd, "plane normal", &p.n[0]));
        TRY(get_num(rd, "plane normal", &p.n[1]));
        TRY(get_num(rd, "plane velocity", &p.v[0]));
        TRY(get_num(rd, "plane velocity", &p.v[1]));
        TRY(get_num(rd, "plane mu", &p.mu));
        TRY(get_num(rd, "plane point", &p.point[0]));
        TRY(get_num(rd, "plane point", &p.point[1]));
        if (p.kind == MPM_WALL_NONE || !(p.mu >= 0) || !(fabs(hypot(p.n[0], p.n[1]) - 1) < 1e-9))
            return corrupt(rd, "a plane is not a unit-normal noslip, slip or friction plane");
        TRY(named(rd, mpm_install_plane(s, &p, rd->err)));
    }
    st = ckpt_section_done(&rd->sec, rd->err);
done:
    return st;
}

/* Grain ranges and shapes; prescribed velocities go to pres (3 per grain: flag, vx, vy). */
static core_status read_grains(reader *rd, mpm_scene *s, double **pres)
{
    core_status st;
    uint64_t n;
    TRY(ckpt_get_u64(&rd->sec, &n, rd->err));
    if (n > (uint64_t)INT32_MAX || n > rd->sec.size / 8)
        return corrupt(rd, "the grain count does not fit the file");
    const size_t ng = (size_t)n, cap = ng ? ng : 1;
    if (!(s->gstart = malloc(cap * sizeof *s->gstart)) ||
        !(s->gcount = malloc(cap * sizeof *s->gcount)) ||
        !(s->gdef = calloc(cap, sizeof *s->gdef)) || !(*pres = malloc(3 * cap * sizeof **pres)))
        return core_fail(rd->err, CORE_ERR_NOMEM, "out of memory for %zu grains", ng);
    s->gcap = cap;
    size_t next = 0;
    for (size_t g = 0; g < ng; g++) {
        uint64_t a, c;
        long v;
        mpm_grain_def *gd = &s->gdef[g];
        *gd = mpm_default_grain_def();
        TRY(ckpt_get_u64(&rd->sec, &a, rd->err));
        TRY(ckpt_get_u64(&rd->sec, &c, rd->err));
        if (a != next || c == 0 || c > (uint64_t)INT32_MAX)
            return corrupt(rd, "the grains' point ranges are not consecutive");
        s->gstart[g] = (size_t)a;
        s->gcount[g] = (size_t)c;
        next += (size_t)c;
        TRY(get_int(rd, MPM_DISK, MPM_POLYGON, "grain shape", &v));
        gd->shape = (mpm_shape)v;
        TRY(get_num(rd, "grain center", &gd->center[0]));
        TRY(get_num(rd, "grain center", &gd->center[1]));
        TRY(get_num(rd, "grain radius", &gd->radius));
        TRY(get_num(rd, "grain bounds", &gd->lo[0]));
        TRY(get_num(rd, "grain bounds", &gd->lo[1]));
        TRY(get_num(rd, "grain bounds", &gd->hi[0]));
        TRY(get_num(rd, "grain bounds", &gd->hi[1]));
        TRY(get_int(rd, 0, s->nmat - 1, "grain material", &v));
        gd->material = (int)v;
        TRY(get_int(rd, 1, 64, "points per cell", &v));
        gd->points_per_cell = (int)v;
        TRY(get_num(rd, "grain velocity", &gd->velocity[0]));
        TRY(get_num(rd, "grain velocity", &gd->velocity[1]));
        TRY(get_num(rd, "grain omega", &gd->omega));
        TRY(get_int(rd, 0, 1, "clip", &v));
        gd->clip = v != 0;
        gd->vertices = NULL;
        gd->nvertices = 0;
        TRY(get_int(rd, 0, 1, "prescribed", &v));
        (*pres)[3 * g] = (double)v;
        TRY(get_num(rd, "prescribed velocity", &(*pres)[3 * g + 1]));
        TRY(get_num(rd, "prescribed velocity", &(*pres)[3 * g + 2]));
        s->ngrains = g + 1;
    }
    st = ckpt_section_done(&rd->sec, rd->err);
done:
    return st;
}

static core_status read_points(reader *rd, mpm_scene *s)
{
    core_status st;
    const size_t np = s->ngrains ? s->gstart[s->ngrains - 1] + s->gcount[s->ngrains - 1] : 0;
    size_t n;
    TRY(ckpt_peek_count(&rd->sec, (size_t)INT32_MAX, &n, rd->err));
    /* 21 arrays of doubles must fit the section before anything is allocated for them */
    if (n != np || np > rd->sec.size / (21 * sizeof(double)))
        return corrupt(rd, "the point count does not match the grains or the file");
    TRY(mpm_reserve_points(s, np, rd->err));
    double *a[21];
    point_arrays(s, a);
    for (int k = 0; k < 21; k++)
        TRY(ckpt_get_f64s(&rd->sec, a[k], np, rd->err));
    int64_t *tmp = malloc((np ? np : 1) * sizeof *tmp);
    if (!tmp)
        return core_fail(rd->err, CORE_ERR_NOMEM, "out of memory for %zu points", np);
    int *ints[2] = {s->grain, s->mat};
    for (int k = 0; k < 2 && !st; k++) {
        st = ckpt_get_i64s(&rd->sec, tmp, np, rd->err);
        for (size_t p = 0; p < np && !st; p++)
            ints[k][p] = (int)tmp[p];
    }
    free(tmp);
    if (st)
        return st;
    s->np = np;
    /* every point belongs to the grain whose range holds it, has a material, finite values,
     * positive mass and volume, and lies where a step can take it (the run's own bounds) */
    for (size_t g = 0; g < s->ngrains; g++)
        for (size_t p = s->gstart[g]; p < s->gstart[g] + s->gcount[g]; p++)
            if (s->grain[p] != (int)g)
                return corrupt(rd, "a point's grain does not match the grain ranges");
    const mpm_scene_def *d = &s->def;
    for (size_t p = 0; p < np; p++) {
        if (s->mat[p] < 0 || s->mat[p] >= s->nmat)
            return corrupt(rd, "a point's material does not exist");
        for (int k = 0; k < 21; k++)
            if (!isfinite(a[k][p]))
                return corrupt(rd, "a point has a non-finite value");
        if (!(s->m[p] > 0) || !(s->v0[p] > 0))
            return corrupt(rd, "a point has no mass or volume");
        if (!isfinite(s->m[p] * (s->vx[p] * s->vx[p] + s->vy[p] * s->vy[p])))
            return corrupt(rd, "a point's kinetic energy is not finite");
        const double c[2] = {s->x[p], s->y[p]};
        for (int ax = 0; ax < 2; ax++) {
            const double o = d->origin[ax], L = d->size[ax];
            const bool in = d->periodic[ax]
                                ? c[ax] >= o && c[ax] < o + L
                                : c[ax] >= o - s->slack[ax][0] && c[ax] <= o + L + s->slack[ax][1];
            if (!in)
                return corrupt(rd, "a point lies outside the grid");
        }
    }
    st = ckpt_section_done(&rd->sec, rd->err);
done:
    return st;
}

static core_status read_scene(ckpt_reader *r, reader *rd, mpm_scene **out)
{
    core_status st;
    mpm_scene *s = NULL;
    double *pres = NULL;
    mpm_scene_def def;
    TRY(ckpt_find(r, "mpm.scene", &rd->sec, rd->err));
    TRY(read_def(rd, &def));
    TRY(check_cells(r, rd, &def));
    TRY(named(rd, mpm_create(&def, &s, rd->err)));
    ckpt_section cont;
    TRY(ckpt_find(r, "mpm.materials", &rd->sec, rd->err));
    TRY(read_materials(r, rd, s, &cont));
    TRY(ckpt_find(r, "mpm.contact", &rd->sec, rd->err));
    TRY(read_contact(rd, s));
    TRY(ckpt_find(r, "mpm.planes", &rd->sec, rd->err));
    TRY(read_planes(rd, s));
    TRY(ckpt_find(r, "mpm.grains", &rd->sec, rd->err));
    TRY(read_grains(rd, s, &pres));
    TRY(ckpt_find(r, "mpm.points", &rd->sec, rd->err));
    TRY(read_points(rd, s));
    if (cont.data)
        TRY(read_rates(rd, s, &cont));
    /* prescriptions after the points: mpm_prescribe sets the grain's point velocities, which
     * the saved points already hold (the same values) */
    for (size_t g = 0; g < s->ngrains; g++)
        if (pres[3 * g] != 0) {
            const double v[2] = {pres[3 * g + 1], pres[3 * g + 2]};
            TRY(named(rd, mpm_prescribe(s, g, v, rd->err)));
        }
    TRY(ckpt_find(r, "mpm.clock", &rd->sec, rd->err));
    TRY(get_num(rd, "time", &s->time));
    long steps;
    TRY(get_int(rd, 0, CKPT_COUNTER_MAX, "steps", &steps));
    s->steps = steps;
    TRY(get_num(rd, "m_min", &s->m_min));
    if (!(s->m_min >= 0))
        TRY(corrupt(rd, "the light-node threshold is negative"));
    TRY(ckpt_section_done(&rd->sec, rd->err));
    TRY(ckpt_reader_finish(r, rd->err));
    *out = s;
    s = NULL;
done:
    free(pres);
    mpm_destroy(s);
    return st;
}

core_status mpm_load(const char *path, mpm_scene **out, core_error *err)
{
    *out = NULL;
    ckpt_reader *r = NULL;
    core_status st = ckpt_reader_open(&r, path, "mpm", err);
    if (st)
        return st;
    reader rd = {.err = err, .path = ckpt_reader_path(r)};
    st = read_scene(r, &rd, out);
    ckpt_reader_close(r);
    return st;
}
