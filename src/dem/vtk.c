/* DEM scenes as VTK XML unstructured grids for ParaView: particles as vertices with their state,
 * contacts as lines (force chains), walls as the planes clipped to the box. Uses the public
 * accessors of dem.h only (plus dem_forces, defined here because only the output needs it). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/vtk.h"
#include "dem/dem.h"
#include "dem/dem_internal.h"

const double *dem_forces(const dem_scene *s, int d)
{
    return d >= 0 && d < s->dim ? s->f[d] : NULL;
}

/* The id a file gives particle i: its tag + 1 in a scene with insertion or removal (the index
 * shifts at a removal; ParaView and OVITO follow a grain by this array), else index + 1, the
 * same number. */
static int64_t particle_id(const double *tag, size_t i)
{
    return (tag ? (int64_t)tag[i] : (int64_t)i) + 1;
}

/* Copies up to dim component arrays (NULL: zeros) into an interleaved 3-vector array. */
static void interleave(double *out, const double *const c[3], size_t n)
{
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < 3; d++)
            out[3 * i + d] = c[d] ? c[d][i] : 0;
}

core_status dem_vtk_particles(const dem_scene *s, const char *path, core_error *err)
{
    const size_t n = dem_count(s);
    const int D = dem_dim(s);
    vtk_file *f;
    core_status st = vtk_unstructured(n, n, &f, err);
    if (st)
        return st;
    const double *pos[3] = {dem_positions(s, 0), dem_positions(s, 1),
                            D == 3 ? dem_positions(s, 2) : NULL};
    const double *vel[3] = {dem_velocities(s, 0), dem_velocities(s, 1),
                            D == 3 ? dem_velocities(s, 2) : NULL};
    /* 2D: omega is the z component; arrays are NULL when rotations are off (zero spin). */
    const double *omega[3] = {D == 3 ? dem_angular_velocities(s, 0) : NULL,
                              D == 3 ? dem_angular_velocities(s, 1) : NULL,
                              dem_angular_velocities(s, 2)};
    const double *force[3] = {dem_forces(s, 0), dem_forces(s, 1), D == 3 ? dem_forces(s, 2) : NULL};
    double *x = vtk_f64(f, VTK_POINTS, "Points", 3, n, err);
    int64_t *conn = x ? vtk_cells(f, VTK_CELL_VERTEX, 1, err) : NULL;
    int64_t *id = conn ? vtk_i64(f, VTK_POINT_DATA, "id", 1, n, err) : NULL;
    double *r = id ? vtk_f64(f, VTK_POINT_DATA, "radius", 1, n, err) : NULL;
    double *v = r ? vtk_f64(f, VTK_POINT_DATA, "velocity", 3, n, err) : NULL;
    double *w = v ? vtk_f64(f, VTK_POINT_DATA, "angular_velocity", 3, n, err) : NULL;
    double *fo = w ? vtk_f64(f, VTK_POINT_DATA, "force", 3, n, err) : NULL;
    double *m = fo ? vtk_f64(f, VTK_POINT_DATA, "mass", 1, n, err) : NULL;
    int32_t *mat = m ? vtk_i32(f, VTK_POINT_DATA, "material", 1, n, err) : NULL;
    double *angle =
        mat && D == 2 && dem_angles(s) ? vtk_f64(f, VTK_POINT_DATA, "angle", 1, n, err) : NULL;
    /* clump scenes: each member's clump id (1-based, as s:add_clump returns it), 0 for a grain
     * of no clump */
    const int clumps = dem_clump_count(s) > 0;
    int64_t *clump = mat && clumps ? vtk_i64(f, VTK_POINT_DATA, "clump", 1, n, err) : NULL;
    if (!mat || (D == 2 && dem_angles(s) && !angle) || (clumps && !clump))
        return vtk_file_finish(f, path, err ? err->status : CORE_ERR_NOMEM, err);
    interleave(x, pos, n);
    interleave(v, vel, n);
    interleave(w, omega, n);
    interleave(fo, force, n);
    const double *rad = dem_radii(s), *mass = dem_masses(s);
    const int *pm = dem_particle_materials(s);
    const double *tag = dem_tags(s);
    for (size_t i = 0; i < n; i++) {
        conn[i] = (int64_t)i;
        id[i] = particle_id(tag, i);
        r[i] = rad[i];
        m[i] = mass[i];
        mat[i] = pm[i] + 1;
        if (clump)
            clump[i] = dem_particle_clump(s, i) + 1;
    }
    if (angle)
        memcpy(angle, dem_angles(s), n * sizeof *angle);
    st = vtk_set_time(f, dem_time(s), dem_steps_done(s), err);
    if (!st)
        st = vtk_set_active(f, VTK_POINT_DATA, "Scalars", "radius", err);
    if (!st)
        st = vtk_set_active(f, VTK_POINT_DATA, "Vectors", "velocity", err);
    return vtk_file_finish(f, path, st, err);
}

/* ---- clumps ------------------------------------------------------------------------------- */
core_status dem_vtk_clumps(const dem_scene *s, const char *path, core_error *err)
{
    const size_t n = dem_clump_count(s);
    const int D = dem_dim(s);
    vtk_file *f;
    core_status st = vtk_unstructured(n, n, &f, err);
    if (st)
        return st;
    double *x = vtk_f64(f, VTK_POINTS, "Points", 3, n, err);
    int64_t *conn = x ? vtk_cells(f, VTK_CELL_VERTEX, 1, err) : NULL;
    int64_t *id = conn ? vtk_i64(f, VTK_POINT_DATA, "id", 1, n, err) : NULL;
    double *m = id ? vtk_f64(f, VTK_POINT_DATA, "mass", 1, n, err) : NULL;
    double *v = m ? vtk_f64(f, VTK_POINT_DATA, "velocity", 3, n, err) : NULL;
    double *w = v ? vtk_f64(f, VTK_POINT_DATA, "angular_velocity", 3, n, err) : NULL;
    double *L = w ? vtk_f64(f, VTK_POINT_DATA, "angular_momentum", 3, n, err) : NULL;
    const int nq = D == 2 ? 1 : 4;
    double *q = L ? vtk_f64(f, VTK_POINT_DATA, "orientation", nq, n, err) : NULL;
    double *in = q ? vtk_f64(f, VTK_POINT_DATA, "inertia", 3, n, err) : NULL;
    int64_t *cnt = in ? vtk_i64(f, VTK_POINT_DATA, "members", 1, n, err) : NULL;
    int64_t *first = cnt ? vtk_i64(f, VTK_POINT_DATA, "first_member", 1, n, err) : NULL;
    if (!first)
        return vtk_file_finish(f, path, err ? err->status : CORE_ERR_NOMEM, err);
    const double *tag = dem_tags(s);
    for (size_t k = 0; k < n; k++) {
        dem_clump_state c;
        if ((st = dem_clump_get(s, k, &c, err)))
            return vtk_file_finish(f, path, st, err);
        conn[k] = (int64_t)k;
        id[k] = (int64_t)k + 1;
        m[k] = c.mass;
        for (int d = 0; d < 3; d++) {
            x[3 * k + d] = d < D ? c.x[d] : 0;
            v[3 * k + d] = d < D ? c.v[d] : 0;
            w[3 * k + d] = c.omega[d];
            L[3 * k + d] = c.L[d];
            in[3 * k + d] = c.moments[d];
        }
        if (D == 2)
            q[k] = c.angle;
        else
            memcpy(q + 4 * k, c.q, sizeof c.q);
        cnt[k] = (int64_t)c.count;
        first[k] = particle_id(tag, c.first);
    }
    st = vtk_set_time(f, dem_time(s), dem_steps_done(s), err);
    if (!st)
        st = vtk_set_active(f, VTK_POINT_DATA, "Vectors", "velocity", err);
    return vtk_file_finish(f, path, st, err);
}

/* ---- contacts -------------------------------------------------------------------------------- */
typedef struct contact_rec {
    long i, j;
    double fn, ft, overlap, normal[3], force[3], a[3], b[3];
} contact_rec;

typedef struct contact_list {
    contact_rec *c;
    size_t n, cap;
    int failed;
    const dem_scene *s;
} contact_list;

static void collect(const dem_contact_info *c, void *ctx)
{
    contact_list *l = ctx;
    if (l->failed)
        return;
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 256;
        contact_rec *p = realloc(l->c, cap * sizeof *p);
        if (!p) {
            l->failed = 1;
            return;
        }
        l->c = p;
        l->cap = cap;
    }
    contact_rec *r = &l->c[l->n++];
    const int D = dem_dim(l->s);
    const double *rad = dem_radii(l->s);
    r->i = c->i;
    r->j = c->j;
    r->fn = c->fn;
    r->ft = c->ft;
    r->overlap = c->overlap;
    /* The line runs from i's centre to j's centre as i sees it (the minimum image across a
     * periodic boundary: x_i - branch), or to the contact point on a wall. */
    const double branch = c->j >= 0 ? rad[c->i] + rad[c->j] - c->overlap : 0;
    for (int d = 0; d < 3; d++) {
        r->normal[d] = c->normal[d];
        r->force[d] = c->force[d];
        r->a[d] = d < D ? dem_positions(l->s, d)[c->i] : 0;
        r->b[d] = c->j >= 0 ? r->a[d] - branch * c->normal[d] : c->point[d];
    }
}

core_status dem_vtk_contacts(dem_scene *s, const char *path, core_error *err)
{
    contact_list l = {.s = s};
    dem_each_contact(s, collect, &l);
    if (l.failed) {
        free(l.c);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory collecting the contacts for '%s'",
                         path);
    }
    const size_t n = l.n;
    vtk_file *f;
    core_status st = vtk_unstructured(2 * n, n, &f, err);
    if (st) {
        free(l.c);
        return st;
    }
    double *x = vtk_f64(f, VTK_POINTS, "Points", 3, 2 * n, err);
    int64_t *conn = x ? vtk_cells(f, VTK_CELL_LINE, 2, err) : NULL;
    int64_t *ci = conn ? vtk_i64(f, VTK_CELL_DATA, "i", 1, n, err) : NULL;
    int64_t *cj = ci ? vtk_i64(f, VTK_CELL_DATA, "j", 1, n, err) : NULL;
    double *fn = cj ? vtk_f64(f, VTK_CELL_DATA, "fn", 1, n, err) : NULL;
    double *ft = fn ? vtk_f64(f, VTK_CELL_DATA, "ft", 1, n, err) : NULL;
    double *ov = ft ? vtk_f64(f, VTK_CELL_DATA, "overlap", 1, n, err) : NULL;
    double *nn = ov ? vtk_f64(f, VTK_CELL_DATA, "normal", 3, n, err) : NULL;
    double *fo = nn ? vtk_f64(f, VTK_CELL_DATA, "force", 3, n, err) : NULL;
    double *fnv = fo ? vtk_f64(f, VTK_CELL_DATA, "normal_force", 3, n, err) : NULL;
    double *ftv = fnv ? vtk_f64(f, VTK_CELL_DATA, "tangential_force", 3, n, err) : NULL;
    /* Point data too, so that a Tube filter can vary its radius along the chain. */
    double *pfn = ftv ? vtk_f64(f, VTK_POINT_DATA, "fn", 1, 2 * n, err) : NULL;
    if (!pfn) {
        free(l.c);
        return vtk_file_finish(f, path, err ? err->status : CORE_ERR_NOMEM, err);
    }
    const double *tag = dem_tags(s);
    for (size_t k = 0; k < n; k++) {
        const contact_rec *c = &l.c[k];
        conn[2 * k] = (int64_t)(2 * k);
        conn[2 * k + 1] = (int64_t)(2 * k + 1);
        ci[k] = particle_id(tag, (size_t)c->i); /* the particles' id array */
        /* walls: minus the wall id, as s:measure */
        cj[k] = c->j >= 0 ? particle_id(tag, (size_t)c->j) : c->j;
        fn[k] = c->fn;
        ft[k] = c->ft;
        ov[k] = c->overlap;
        pfn[2 * k] = pfn[2 * k + 1] = c->fn;
        for (int d = 0; d < 3; d++) {
            x[6 * k + d] = c->a[d];
            x[6 * k + 3 + d] = c->b[d];
            nn[3 * k + d] = c->normal[d];
            fo[3 * k + d] = c->force[d];
            fnv[3 * k + d] = c->fn * c->normal[d];
            /* walls report their normal force only: the tangential vector stays 0 there */
            ftv[3 * k + d] = c->j >= 0 ? c->force[d] - c->fn * c->normal[d] : 0;
        }
    }
    free(l.c);
    st = vtk_set_time(f, dem_time(s), dem_steps_done(s), err);
    if (!st)
        st = vtk_set_active(f, VTK_CELL_DATA, "Scalars", "fn", err);
    if (!st)
        st = vtk_set_active(f, VTK_CELL_DATA, "Vectors", "force", err);
    return vtk_file_finish(f, path, st, err);
}

/* ---- walls ----------------------------------------------------------------------------------- */
/* The polygon where the plane (p, n) cuts the box [lo, hi] (a segment in 2D): up to 6 vertices,
 * ordered around the plane's normal. Returns the vertex count (< 2 in 2D or < 3 in 3D: the plane
 * misses the box). */
static int clip_plane(int D, const double lo[3], const double hi[3], const double p[3],
                      const double n[3], double out[6][3])
{
    const int ncorner = 1 << D;
    double corner[8][3], dist[8];
    double scale = 0;
    for (int d = 0; d < D; d++)
        scale = fmax(scale, hi[d] - lo[d]);
    const double eps = 1e-12 * scale;
    for (int k = 0; k < ncorner; k++) {
        dist[k] = 0;
        for (int d = 0; d < 3; d++) {
            corner[k][d] = d < D ? ((k >> d) & 1 ? hi[d] : lo[d]) : 0;
            dist[k] += d < D ? (corner[k][d] - p[d]) * n[d] : 0;
        }
    }
    int m = 0;
    for (int a = 0; a < ncorner; a++)
        for (int d = 0; d < D; d++) {
            int b = a | (1 << d);
            if (b == a)
                continue; /* each box edge once: from a corner with bit d clear */
            double q[3];
            if (fabs(dist[a]) <= eps && fabs(dist[b]) <= eps)
                continue; /* the edge lies in the plane: its corners come from other edges */
            if (fabs(dist[a]) <= eps)
                memcpy(q, corner[a], sizeof q);
            else if (fabs(dist[b]) <= eps)
                memcpy(q, corner[b], sizeof q);
            else if ((dist[a] < 0) != (dist[b] < 0)) {
                double t = dist[a] / (dist[a] - dist[b]);
                for (int e = 0; e < 3; e++)
                    q[e] = corner[a][e] + t * (corner[b][e] - corner[a][e]);
            } else {
                continue;
            }
            int dup = 0;
            for (int k = 0; k < m && !dup; k++)
                dup = fabs(out[k][0] - q[0]) + fabs(out[k][1] - q[1]) + fabs(out[k][2] - q[2]) <=
                      3 * eps;
            if (!dup && m < 6)
                memcpy(out[m++], q, sizeof q);
        }
    if (m < 3)
        return m;
    /* Order around the centroid by the angle in an in-plane basis (u, v = n x u). */
    double c[3] = {0, 0, 0};
    for (int k = 0; k < m; k++)
        for (int e = 0; e < 3; e++)
            c[e] += out[k][e] / m;
    double u[3] = {out[0][0] - c[0], out[0][1] - c[1], out[0][2] - c[2]};
    double v[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};
    double ang[6];
    for (int k = 0; k < m; k++) {
        double w[3] = {out[k][0] - c[0], out[k][1] - c[1], out[k][2] - c[2]};
        ang[k] =
            atan2(w[0] * v[0] + w[1] * v[1] + w[2] * v[2], w[0] * u[0] + w[1] * u[1] + w[2] * u[2]);
    }
    for (int a = 1; a < m; a++) /* insertion sort of at most 6 */
        for (int b = a; b > 0 && ang[b] < ang[b - 1]; b--) {
            double t = ang[b];
            ang[b] = ang[b - 1];
            ang[b - 1] = t;
            double q[3];
            memcpy(q, out[b], sizeof q);
            memcpy(out[b], out[b - 1], sizeof q);
            memcpy(out[b - 1], q, sizeof q);
        }
    return m;
}

/* Cells of the walls: a plane clipped to the box (a line in 2D, a polygon in 3D), a shaped
 * wall's outline (dem_wall_outline: a polyline per polyline or circle, a triangle per mesh
 * triangle, the two rims of a cylinder). Counts when the arrays are NULL. */
enum { VTK_CIRCLE_SEGMENTS = 64 };
static void wall_cells(const dem_scene *s, const double *lo, const double *hi, size_t *nc,
                       size_t *np, int *types, int *nv, int *ids, double *pts)
{
    const int D = dem_dim(s), nw = dem_wall_count(s);
    *nc = *np = 0;
    for (int w = 0; w < nw; w++) {
        double p[3], n[3], poly[6][3];
        int active;
        if (dem_wall_kind_of(s, w) != DEM_WALL_PLANE) {
            size_t q;
            const int strips = dem_wall_outline(s, w, VTK_CIRCLE_SEGMENTS, nv ? nv + *nc : NULL,
                                                pts ? pts + 3 * *np : NULL, &q);
            for (int k = 0; k < strips; k++, (*nc)++) {
                if (types)
                    types[*nc] = D == 3 && dem_wall_kind_of(s, w) == DEM_WALL_TRIANGLES
                                     ? VTK_CELL_TRIANGLE
                                     : VTK_CELL_POLY_LINE;
                if (ids)
                    ids[*nc] = w;
            }
            *np += q;
            continue;
        }
        if (dem_wall_geometry(s, w, p, n, &active, NULL) || !active)
            continue;
        int m = clip_plane(D, lo, hi, p, n, poly);
        if (m < D)
            continue; /* the wall has left the box */
        if (types)
            types[*nc] = D == 2 ? VTK_CELL_LINE
                                : (m == 3   ? VTK_CELL_TRIANGLE
                                   : m == 4 ? VTK_CELL_QUAD
                                            : VTK_CELL_POLYGON);
        if (nv)
            nv[*nc] = m;
        if (ids)
            ids[*nc] = w;
        if (pts)
            memcpy(pts + 3 * *np, poly, (size_t)m * 3 * sizeof(double));
        *np += (size_t)m;
        (*nc)++;
    }
}

core_status dem_vtk_walls(const dem_scene *s, const char *path, core_error *err)
{
    double lo[3], hi[3], g[3];
    dem_box(s, lo, hi, g);
    size_t nc, np;
    wall_cells(s, lo, hi, &nc, &np, NULL, NULL, NULL, NULL);
    int *nv = malloc((nc ? nc : 1) * sizeof *nv);
    int *ids = malloc((nc ? nc : 1) * sizeof *ids);
    int *types = malloc((nc ? nc : 1) * sizeof *types);
    double *pts = malloc((np ? np : 1) * 3 * sizeof *pts);
    if (!pts || !nv || !ids || !types) {
        free(pts), free(nv), free(ids), free(types);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the walls of '%s'", path);
    }
    wall_cells(s, lo, hi, &nc, &np, types, nv, ids, pts);
    vtk_file *f = NULL;
    core_status st = vtk_unstructured(np, nc, &f, err);
    if (!st) {
        double *x = vtk_f64(f, VTK_POINTS, "Points", 3, np, err);
        int64_t *conn = x ? vtk_cells_mixed(f, types, nv, err) : NULL;
        int64_t *id = conn ? vtk_i64(f, VTK_CELL_DATA, "id", 1, nc, err) : NULL;
        int64_t *kind = id ? vtk_i64(f, VTK_CELL_DATA, "kind", 1, nc, err) : NULL;
        double *nn = kind ? vtk_f64(f, VTK_CELL_DATA, "normal", 3, nc, err) : NULL;
        double *fn = nn ? vtk_f64(f, VTK_CELL_DATA, "force", 1, nc, err) : NULL;
        double *load = fn ? vtk_f64(f, VTK_CELL_DATA, "load", 3, nc, err) : NULL;
        double *torque = load ? vtk_f64(f, VTK_CELL_DATA, "torque", 3, nc, err) : NULL;
        if (!torque)
            st = err ? err->status : CORE_ERR_NOMEM;
        if (!st) {
            memcpy(x, pts, np * 3 * sizeof *pts);
            for (size_t q = 0; q < np; q++)
                conn[q] = (int64_t)q;
        }
        for (size_t c = 0; c < nc && !st; c++) {
            double p[3];
            int active;
            id[c] = ids[c] + 1;
            kind[c] = (int64_t)dem_wall_kind_of(s, ids[c]);
            if (kind[c] == DEM_WALL_PLANE)
                st = dem_wall_geometry(s, ids[c], p, nn + 3 * c, &active, err);
            if (!st)
                st = dem_wall_force(s, ids[c], &fn[c], err);
            if (!st)
                st = dem_wall_load(s, ids[c], load + 3 * c, torque + 3 * c, err);
        }
        if (!st)
            st = vtk_set_time(f, dem_time(s), dem_steps_done(s), err);
    }
    free(pts), free(nv), free(ids), free(types);
    if (!f)
        return st;
    return vtk_file_finish(f, path, st, err);
}
