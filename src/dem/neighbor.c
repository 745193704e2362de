/* Neighbour search: particles are binned into cells at least one cutoff (2 r_max + skin) wide;
 * the Verlet list keeps every pair closer than r_i + r_j + skin, and is rebuilt when some particle
 * has moved more than skin/2 since the last build. Pairs are sorted by (i, j), so the list, the
 * carried-over contact history and the force sums are the same for any number of threads. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem/cohesion.h"
#include "dem/dem_internal.h"

void dem_free_pairs(dem_pairs *p)
{
    free(p->i), free(p->j), free(p->k), free(p->gamma), free(p->mu);
    for (int d = 0; d < 3; d++)
        free(p->f[d]), free(p->c[d]), free(p->rt[d]);
    for (int d = 0; d < DEM_HIST; d++)
        free(p->hist[d]);
    free(p->start), free(p->jstart), free(p->jpair);
    memset(p, 0, sizeof *p);
}

static double effective_modulus(const dem_material *a, const dem_material *b)
{
    return 1.0 / ((1 - a->poisson * a->poisson) / a->young +
                  (1 - b->poisson * b->poisson) / b->young);
}

/* Damping coefficient that gives restitution e to a linear spring k between masses m_eff:
 * b = -ln(e) w0 / sqrt(pi^2 + ln(e)^2), gamma = 2 m_eff b (the closed form of VALIDATION.md). */
static double linear_gamma(double k, double m_eff, double e)
{
    if (e >= 1)
        return 0;
    double lne = log(e), w0 = sqrt(k / m_eff);
    return 2 * m_eff * (-lne * w0 / sqrt(DEM_PI * DEM_PI + lne * lne));
}

/* Damping a pair of materials ma, mb takes from a restitution: s:contact's if given, else the
 * smaller of its materials' (the larger coefficient: c falls as e rises), at the impact velocity
 * v (restitution.c): viscous gamma = c m* v / d*, d* = (m* v^2 / k)^{1/(beta+1)} (for beta = 1,
 * c sqrt(m* k) at every speed; the unclipped linear spring keeps its closed form); Brilliantov
 * T = lambda v^{-1/5} (m* / K)^{2/5}. Walls: R* = r, m* = m, the wall's material. */
static void law_parameters(const dem_scene *s, int ma, int mb, double r_eff, double m_eff,
                           double mu, double *k, double *gamma, double *mu_out)
{
    const dem_contact_def *c = &s->contact;
    const dem_material *a = &s->mats[ma], *b = &s->mats[mb];
    *k = dem_normal_from_moduli(c->normal) ? 4.0 / 3.0 * effective_modulus(a, b) * sqrt(r_eff)
                                           : c->stiffness;
    *gamma = 0;
    const int given = c->restitution > 0; /* s:contact's restitution */
    if (c->damping == DEM_DAMPING_VISCOUS) {
        const double beta = dem_law_beta(c);
        if (c->gamma_n >= 0) {
            *gamma = c->gamma_n;
        } else if (beta == 1 && !c->clip) { /* the linear law's closed form */
            *gamma = linear_gamma(*k, m_eff,
                                  given ? c->restitution : fmin(a->restitution, b->restitution));
        } else {
            double cc = given ? s->damp_c : fmax(s->mat_damp[ma], s->mat_damp[mb]);
            if (beta == 1) {
                *gamma = cc * sqrt(m_eff * *k);
            } else {
                double v = c->impact_velocity;
                *gamma = cc * m_eff * v / pow(m_eff * v * v / *k, 1 / (beta + 1));
            }
        }
    } else if (c->damping == DEM_DAMPING_BRILLIANTOV) {
        /* gamma carries the damping time T. From a restitution each pair gets its own
         * T = lambda (m_eff / K)^{2/5} v^{-1/5} (dem.h), so a head-on impact at the impact
         * velocity rebounds with e for every pair; brill_c = lambda v^{-1/5} is set once. */
        if (given)
            *gamma = s->brill_c * pow(m_eff / *k, 0.4);
        else if (c->damping_time >= 0)
            *gamma = c->damping_time;
        else
            *gamma = fmax(s->mat_damp[ma], s->mat_damp[mb]) * pow(m_eff / *k, 0.4);
    }
    *mu_out = mu;
}

void dem_pair_parameters(dem_scene *s, size_t i, size_t j, double *k, double *gamma, double *mu)
{
    const dem_material *a = &s->mats[s->mat[i]], *b = &s->mats[s->mat[j]];
    double ri = s->r[i], rj = s->r[j];
    /* A fixed or prescribed particle acts with infinite mass. */
    double inv = s->inv_m[i] + s->inv_m[j];
    double m_eff = inv > 0 ? 1 / inv : 0.5 * (s->m[i] + s->m[j]);
    law_parameters(s, s->mat[i], s->mat[j], ri * rj / (ri + rj), m_eff,
                   fmin(a->friction, b->friction), k, gamma, mu);
}

void dem_probe_parameters(const dem_scene *s, int mat, double r, double m, double *k, double *gamma)
{
    const dem_material *a = &s->mats[mat];
    double mu;
    law_parameters(s, mat, mat, 0.5 * r, 0.5 * m, a->friction, k, gamma, &mu);
}

void dem_wall_parameters(const dem_scene *s, const dem_wall *w, size_t i, double *k,
                         double *gamma, double *mu)
{
    const int ma = s->mat[i], mb = w->material >= 0 ? w->material : ma;
    const dem_material *a = &s->mats[ma], *b = &s->mats[mb];
    double m_eff = s->inv_m[i] > 0 ? 1 / s->inv_m[i] : s->m[i];
    /* The wall's own friction if given; else the pair rule with the wall's material. */
    double mu_w = w->friction >= 0 ? w->friction : fmin(a->friction, b->friction);
    law_parameters(s, ma, mb, s->r[i], m_eff, mu_w, k, gamma, mu);
}

static core_status alloc_u32(uint32_t **a, size_t n, core_error *err)
{
    uint32_t *p = realloc(*a, (n ? n : 1) * sizeof *p);
    if (!p)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu list entries", n);
    *a = p;
    return CORE_OK;
}

static core_status alloc_size(size_t **a, size_t n, core_error *err)
{
    size_t *p = realloc(*a, (n ? n : 1) * sizeof *p);
    if (!p)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu list entries", n);
    *a = p;
    return CORE_OK;
}

static core_status reserve_pairs(dem_scene *s, size_t n, core_error *err)
{
    dem_pairs *p = &s->pairs;
    if (n <= p->cap)
        return CORE_OK;
    size_t cap = p->cap ? p->cap : 1024;
    while (cap < n)
        cap *= 2;
    core_status st = alloc_u32(&p->i, cap, err);
    if (!st)
        st = alloc_u32(&p->j, cap, err);
    if (!st)
        st = dem_alloc_array(&p->k, cap, err);
    if (!st)
        st = dem_alloc_array(&p->gamma, cap, err);
    if (!st)
        st = dem_alloc_array(&p->mu, cap, err);
    for (int d = 0; d < 3 && !st; d++) {
        if (d < s->dim)
            st = dem_alloc_array(&p->f[d], cap, err);
        if (!st && s->rot && (s->dim == 3 || d == 2))
            st = dem_alloc_array(&p->c[d], cap, err);
        if (!st && dem_tangent_history(s->contact.tangential) && d < s->dim)
            st = dem_alloc_array(&p->hist[d], cap, err);
    }
    if (!st && dem_tangent_history(s->contact.tangential))
        st = dem_alloc_array(&p->hist[3], cap, err);
    /* rolling resistance: the torques (rotations are on), the EPSD spring's history */
    for (int d = s->dim == 2 ? 2 : 0; d < 3 && !st && s->contact.rolling_law; d++)
        st = dem_alloc_array(&p->rt[d], cap, err);
    for (int d = 0; d < dem_rolling_slots(s) && !st; d++)
        st = dem_alloc_array(&p->hist[DEM_HIST_ROLL + d], cap, err);
    if (!st && dem_bonds(&s->contact))
        st = dem_alloc_array(&p->hist[DEM_HIST_BOND], cap, err);
    if (!st)
        p->cap = cap;
    return st;
}

/* Cells at least one cutoff wide; not more cells than about 2 per particle, so a sparse scene
 * in a large box does not pay for empty cells. Periodic axes need 3 cells or more. */
static core_status setup_cells(dem_scene *s, double cutoff, core_error *err)
{
    const int D = s->dim;
    /* Distributed: the global count, so that every rank has the same cells (and the same
     * verdict on a periodic axis too short). */
    const size_t count = s->dom ? dem_domain_count(s) : s->n;
    size_t total = 1;
    double size = cutoff;
    for (int pass = 0; pass < 64; pass++) {
        total = 1;
        for (int d = 0; d < D; d++) {
            int nc = (int)floor(s->len[d] / size);
            if (nc < 1)
                nc = 1;
            if (nc > 1 << 20)
                nc = 1 << 20;
            s->ncell[d] = nc;
            s->cell_size[d] = s->len[d] / nc;
            total *= (size_t)nc;
        }
        if (total <= 2 * count + 64)
            break;
        size *= 1.25;
    }
    for (int d = D; d < 3; d++) {
        s->ncell[d] = 1;
        s->cell_size[d] = 1;
    }
    for (int d = 0; d < D; d++)
        if (s->periodic[d] && s->ncell[d] < 3)
            return core_fail(err, CORE_ERR_ARG,
                             "periodic axis %d is %g long, less than 3 neighbour cutoffs "
                             "(3 x %g): make the box longer or the particles smaller",
                             d + 1, s->len[d], cutoff);
    if (total + 1 > s->cell_cap) {
        if (alloc_size(&s->cell_start, total + 1, err))
            return err->status;
        s->cell_cap = total + 1;
    }
    return CORE_OK;
}

static int cell_coord(const dem_scene *s, int d, double x)
{
    int c = (int)floor((x - s->lo[d]) / s->cell_size[d]);
    if (s->periodic[d]) {
        c %= s->ncell[d];
        if (c < 0)
            c += s->ncell[d];
    } else if (c < 0) {
        c = 0;
    } else if (c >= s->ncell[d]) {
        c = s->ncell[d] - 1;
    }
    return c;
}

static size_t cell_index(const dem_scene *s, const int c[3])
{
    return ((size_t)c[2] * (size_t)s->ncell[1] + (size_t)c[1]) * (size_t)s->ncell[0] + (size_t)c[0];
}

/* Squared distance of particles i and j with the minimum image on periodic axes. */
static double dist2(const dem_scene *s, size_t i, size_t j)
{
    double r2 = 0;
    for (int d = 0; d < s->dim; d++) {
        double dx = s->x[d][i] - s->x[d][j];
        if (s->periodic[d])
            dx -= s->len[d] * nearbyint(dx / s->len[d]);
        r2 += dx * dx;
    }
    return r2;
}

/* Visits the neighbours j > i of particle i (within r_i + r_j + skin): count or store them. */
static size_t scan(const dem_scene *s, size_t i, uint32_t *out)
{
    const int D = s->dim;
    int c[3] = {0, 0, 0}, lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int d = 0; d < D; d++) {
        c[d] = cell_coord(s, d, s->x[d][i]);
        lo[d] = c[d] - 1;
        hi[d] = c[d] + 1;
        if (!s->periodic[d]) {
            if (lo[d] < 0)
                lo[d] = 0;
            if (hi[d] >= s->ncell[d])
                hi[d] = s->ncell[d] - 1;
        }
    }
    size_t count = 0;
    /* Distributed: a pair of two ghosts is no owned particle's business. */
    const unsigned char *gh = s->ghost;
    const int gi = gh && gh[i];
    /* Clumps: no pair inside one (bi < 0 for a particle of no clump, and in scenes without) */
    const int32_t *bd = s->clumps ? s->clumps->body : NULL;
    const int32_t bi = bd ? bd[i] : -1;
    int k[3];
    for (k[2] = lo[2]; k[2] <= hi[2]; k[2]++)
        for (k[1] = lo[1]; k[1] <= hi[1]; k[1]++)
            for (k[0] = lo[0]; k[0] <= hi[0]; k[0]++) {
                int cc[3];
                for (int d = 0; d < 3; d++) {
                    cc[d] = k[d];
                    if (d < D && s->periodic[d])
                        cc[d] = (k[d] + s->ncell[d]) % s->ncell[d];
                }
                size_t cell = cell_index(s, cc);
                for (size_t e = s->cell_start[cell]; e < s->cell_start[cell + 1]; e++) {
                    uint32_t j = s->cell_items[e];
                    if (j <= i || (gi && gh[j]) || (bi >= 0 && bd[j] == bi))
                        continue;
                    double cut = s->r[i] + s->r[j] + s->skin + s->reach;
                    if (dist2(s, i, j) < cut * cut) {
                        if (out)
                            out[count] = j;
                        count++;
                    }
                }
            }
    return count;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Wraps positions on periodic axes into the box (the list is built from wrapped positions). */
void dem_wrap_positions(dem_scene *s)
{
    const size_t n = s->n;
    for (int d = 0; d < s->dim; d++) {
        if (!s->periodic[d])
            continue;
        for (size_t i = 0; i < n; i++) {
            double x = s->x[d][i];
            if (x < s->lo[d] || x >= s->hi[d]) {
                double w = x - s->len[d] * floor((x - s->lo[d]) / s->len[d]);
                if (s->gear[0][d])
                    s->gear[0][d][i] += w - x;
                if (s->x_ref[d])
                    s->x_ref[d][i] += w - x; /* displacements stay continuous */
                s->x[d][i] = w;
            }
        }
    }
}

/* Incidence as j: pair indices in pair order, per particle. */
static core_status index_j(dem_scene *s, core_error *err)
{
    dem_pairs *p = &s->pairs;
    const size_t n = s->n, npairs = p->n;
    core_status st;
    if ((st = alloc_size(&p->jstart, n + 1, err)) || (st = alloc_u32(&p->jpair, npairs, err)))
        return st;
    memset(p->jstart, 0, (n + 1) * sizeof(size_t));
    for (size_t q = 0; q < npairs; q++)
        p->jstart[p->j[q] + 1]++;
    for (size_t i = 0; i < n; i++)
        p->jstart[i + 1] += p->jstart[i];
    size_t *fill = malloc((n ? n : 1) * sizeof *fill);
    if (!fill)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the incidence list");
    if (n > 0)
        memcpy(fill, p->jstart, n * sizeof *fill);
    for (size_t q = 0; q < npairs; q++)
        p->jpair[fill[p->j[q]]++] = (uint32_t)q;
    free(fill);
    return CORE_OK;
}

core_status dem_pairs_index(dem_scene *s, core_error *err)
{
    dem_pairs *p = &s->pairs;
    const size_t n = s->n;
    core_status st = alloc_size(&p->start, n + 1, err);
    if (st)
        return st;
    memset(p->start, 0, (n + 1) * sizeof(size_t));
    for (size_t q = 0; q < p->n; q++)
        p->start[p->i[q] + 1]++;
    for (size_t i = 0; i < n; i++)
        p->start[i + 1] += p->start[i];
    p->np = n;
    return index_j(s, err);
}

/* Particles into the cells of the list build (cell_start, cell_items). */
static core_status bin_particles(dem_scene *s, core_error *err)
{
    const int D = s->dim;
    const size_t n = s->n;
    core_status st;
    size_t ncells = (size_t)s->ncell[0] * (size_t)s->ncell[1] * (size_t)s->ncell[2];
    if ((st = alloc_u32(&s->cell_items, n, err)))
        return st;
    memset(s->cell_start, 0, (ncells + 1) * sizeof(size_t));
    uint32_t *cell_of = malloc((n ? n : 1) * sizeof *cell_of);
    if (!cell_of)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate cell indices");
    for (size_t i = 0; i < n; i++) {
        int c[3] = {0, 0, 0};
        for (int d = 0; d < D; d++)
            c[d] = cell_coord(s, d, s->x[d][i]);
        cell_of[i] = (uint32_t)cell_index(s, c);
        s->cell_start[cell_of[i] + 1]++;
    }
    for (size_t c = 0; c < ncells; c++)
        s->cell_start[c + 1] += s->cell_start[c];
    {
        size_t *fill = malloc((ncells ? ncells : 1) * sizeof *fill);
        if (!fill) {
            free(cell_of);
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate cells");
        }
        memcpy(fill, s->cell_start, ncells * sizeof *fill);
        for (size_t i = 0; i < n; i++)
            s->cell_items[fill[cell_of[i]]++] = (uint32_t)i;
        free(fill);
    }
    free(cell_of);
    return CORE_OK;
}

/* The contact history of the new list: from each first particle's bundle when distributed
 * (domain.c), else from the old list (carry: it has one) by merging the two sorted lists. */
static void carry_history(dem_scene *s, const dem_pairs *old_list, int carry)
{
    const size_t n = s->n;
    dem_pairs *p = &s->pairs;
    const size_t *start = p->start;
    const dem_pairs old = *old_list;
    const int any_hist = p->hist[0] || p->hist[DEM_HIST_ROLL] || p->hist[DEM_HIST_BOND];
    if (any_hist && s->dom) {
        /* Distributed: the history came with each first particle (its bundle, domain.c). */
        const int hw = dem_hist_width(s);
#pragma omp parallel for schedule(static) if (n > 4096)
        for (size_t i = 0; i < n; i++) {
            const uint32_t *gj;
            const double *h;
            size_t nb = dem_domain_bundle(s, i, &gj, &h), o = 0;
            for (size_t q = start[i]; q < start[i + 1]; q++) {
                const uint32_t g = s->gid[p->j[q]];
                while (o < nb && gj[o] < g)
                    o++;
                int same = o < nb && gj[o] == g;
                for (int d = 0; d < hw; d++)
                    if (p->hist[d])
                        p->hist[d][q] = same ? h[(size_t)hw * o + d] : 0;
            }
        }
    } else if (any_hist) {
        size_t old_np = carry ? (old.np < n ? old.np : n) : 0;
#pragma omp parallel for schedule(static) if (n > 4096)
        for (size_t i = 0; i < n; i++) {
            size_t q = start[i], e = start[i + 1];
            size_t o = i < old_np ? old.start[i] : 0, oe = i < old_np ? old.start[i + 1] : 0;
            for (; q < e; q++) { /* merge two lists sorted by j */
                while (o < oe && old.j[o] < p->j[q])
                    o++;
                int same = o < oe && old.j[o] == p->j[q];
                for (int d = 0; d < DEM_HIST; d++)
                    if (p->hist[d])
                        p->hist[d][q] = same && old.hist[d] ? old.hist[d][o] : 0;
            }
        }
    }
}

/* A plane's candidates: particles that can touch it before the next build (within r + skin, or
 * already behind it so that the tunnelling check sees them). */
static core_status plane_candidates(dem_scene *s, dem_wall *wl, core_error *err)
{
    const int D = s->dim;
    const size_t n = s->n;
    wl->ncand = 0;
    wl->cand_par_ok = 0;
    for (size_t i = 0; i < n; i++) {
        if (s->ghost && s->ghost[i])
            continue; /* distributed: walls act on owned particles only */
        double dist = 0;
        for (int d = 0; d < D; d++)
            dist += (s->x[d][i] - wl->point[d]) * wl->normal[d];
        if (dist >= s->r[i] + s->skin + s->reach)
            continue;
        if (wl->ncand == wl->cap_cand) {
            size_t cap = wl->cap_cand ? 2 * wl->cap_cand : 256;
            uint32_t *c = realloc(wl->cand, cap * sizeof *c);
            if (!c)
                return core_fail(err, CORE_ERR_NOMEM, "cannot allocate wall candidates");
            wl->cand = c;
            wl->cap_cand = cap;
        }
        wl->cand[wl->ncand++] = (uint32_t)i;
    }
    for (int d = 0; d < 3; d++)
        wl->point_build[d] = wl->point[d];
    if (s->dom) {
        double *c = realloc(wl->cand_fn, (wl->cap_cand ? wl->cap_cand : 1) * sizeof *c);
        if (!c)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate wall candidates");
        wl->cand_fn = c;
    }
    return CORE_OK;
}

/* How far beyond touch a contact of a particle of the largest radius can hold, with another or
 * with a plane (R* = r_max): a JKR contact to its pull-off distance (the largest over pairs of
 * materials, or with the contact's work of adhesion), a liquid bridge to its rupture distance
 * (cohesion.h). A bound: each contact holds to its own. */
double dem_cohesion_reach(const dem_scene *s)
{
    const dem_contact_def *c = &s->contact;
    double reach = 0;
    if (c->normal == DEM_NORMAL_JKR) {
        const double R = s->r_max;
        for (int a = 0; a < s->nmat; a++)
            for (int b = a; b < s->nmat; b++) {
                const dem_material *ma = &s->mats[a], *mb = &s->mats[b];
                const double E = effective_modulus(ma, mb);
                const double G = c->adhesion >= 0 ? c->adhesion : sqrt(ma->adhesion * mb->adhesion);
                const double d = coh_jkr_pulloff_distance(R, E, G);
                reach = d > reach ? d : reach;
            }
    }
    if (c->cohesion == DEM_COHESION_CAPILLARY)
        reach = coh_capillary_rupture(c->liquid_volume, c->contact_angle);
    return reach * 1.0001; /* rounding */
}

core_status dem_build_pairs(dem_scene *s, core_error *err)
{
    const int D = s->dim;
    const size_t n = s->n;
    dem_pairs *p = &s->pairs;
    s->skin = s->skin_def > 0 ? s->skin_def : 0.2 * s->r_max;
    s->reach = dem_cohesive(&s->contact) ? dem_cohesion_reach(s) : 0;

    dem_wrap_positions(s);

    core_status st = setup_cells(s, 2 * s->r_max + s->skin + s->reach, err);
    if (st)
        return st;
    if ((st = bin_particles(s, err)))
        return st;

    /* Count, then fill, the neighbours of each particle: two passes keep the list in (i, j)
     * order whatever the thread count. */
    size_t *start = malloc((n + 1) * sizeof *start);
    if (!start)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the pair list");
    start[0] = 0;
#pragma omp parallel for schedule(static) if (n > 4096)
    for (size_t i = 0; i < n; i++)
        start[i + 1] = scan(s, i, NULL);
    for (size_t i = 0; i < n; i++)
        start[i + 1] += start[i];
    size_t npairs = start[n];

    /* Keep the old list to carry the contact history over. */
    dem_pairs old = *p;
    int carry = (old.hist[0] || old.hist[DEM_HIST_ROLL] || old.hist[DEM_HIST_BOND]) && old.start;
    memset(p, 0, sizeof *p);
    if ((st = reserve_pairs(s, npairs, err))) {
        free(start);
        dem_free_pairs(&old);
        return st;
    }
    p->n = npairs;
    p->np = n;
    p->start = start;
#pragma omp parallel for schedule(static) if (n > 4096)
    for (size_t i = 0; i < n; i++) {
        size_t b = start[i], e = start[i + 1];
        if (e == b)
            continue; /* no neighbours (and p->j may be unallocated when there are no pairs) */
        scan(s, i, p->j + b);
        qsort(p->j + b, e - b, sizeof(uint32_t), cmp_u32);
        for (size_t q = b; q < e; q++) {
            p->i[q] = (uint32_t)i;
            dem_pair_parameters(s, i, p->j[q], &p->k[q], &p->gamma[q], &p->mu[q]);
        }
    }
    for (size_t q = 0; q < npairs; q++) /* the contact normal of two coincident centres is undefined */
        if (dist2(s, p->i[q], p->j[q]) == 0) {
            core_status bad =
                core_fail(err, CORE_ERR_ARG,
                          "particles %u and %u are at the same "
                          "position: the contact normal is undefined",
                          (unsigned)dem_gid(s, p->i[q]) + 1, (unsigned)dem_gid(s, p->j[q]) + 1);
            dem_free_pairs(&old);
            s->need_rebuild = 1;
            return bad;
        }
    carry_history(s, &old, carry);
    for (int d = 0; d < 3; d++) {
        if (p->f[d])
            memset(p->f[d], 0, (npairs ? npairs : 1) * sizeof(double));
        if (p->c[d])
            memset(p->c[d], 0, (npairs ? npairs : 1) * sizeof(double));
    }

    if ((st = index_j(s, err))) {
        dem_free_pairs(&old);
        return st;
    }

    /* Wall candidates */
    for (int w = 0; w < s->nwalls; w++) {
        dem_wall *wl = &s->walls[w];
        if (!wl->active)
            continue;
        if (wl->shape) { /* beyond planes: distance to the surface (walls.c) */
            if ((st = dem_shape_candidates(s, wl, err))) {
                dem_free_pairs(&old);
                return st;
            }
            continue;
        }
        if ((st = plane_candidates(s, wl, err))) {
            dem_free_pairs(&old);
            return st;
        }
    }

    for (int d = 0; d < D && n > 0; d++) /* an empty scene has no arrays yet (memcpy of NULL is UB) */
        memcpy(s->x_build[d], s->x[d], n * sizeof(double));
    dem_free_pairs(&old);
    s->need_rebuild = 0;
    return CORE_OK;
}
