/* The MPM scene's private layout: grid geometry, nodal arrays (allocated once), material points
 * in structure-of-arrays, the per-step stencil (each point's four nodes, weights and weight
 * gradients, computed once per step and reused by every transfer) and the sparse per-grain nodal
 * fields of the frictional contact (one entry per (grain, node) pair a grain's points touch). */
#ifndef GRAINLAB_MPM_INTERNAL_H
#define GRAINLAB_MPM_INTERNAL_H

#include "mpm/mpm.h"

/* Nodes per point: 4 for linear shape functions, 9 for quadratic B-splines (s->ns). */
#define MPM_STENCIL 9

/* A rigid wall as the nodes see it: n points into the wall (out of the material). The grid's
 * edges are planes 0-3 (MPM_LEFT...), user planes follow. */
typedef struct mpm_plane {
    mpm_wall kind;
    double n[2], v[2], mu, point[2];
} mpm_plane;

struct mpm_scene {
    mpm_scene_def def;
    double hx, hy, inv_hx, inv_hy;
    int nnx, nny;           /* nodes per axis: cells + 1 + 2 gl, or cells on a periodic axis */
    int gl[2];              /* ghost node layers beyond each wall: 1 for B-splines, else 0 */
    int ns;                 /* nodes per point: 4 (linear) or 9 (B-spline) */
    size_t nnodes;

    /* nodal fields: nnodes centre-of-mass entries, then (contact "friction") one entry per
     * (grain, node) pair at index nnodes + q, so the transfers index both the same way */
    double *nm;             /* lumped mass, Eq. 6 */
    double *npx, *npy;      /* momentum m_i v_i^n, Eq. 5 (reused for the MUSL remap) */
    double *nfx, *nfy;      /* internal + external force, Eq. 7 */
    double *nvx, *nvy;      /* v_i^n */
    double *nax, *nay;      /* v_i^{n+1} */
    unsigned char *nwall;   /* bit k: node belongs to plane k */
    unsigned char *nwin;    /* bit k: friction plane k in contact at this node this step */
    mpm_plane planes[4 + MPM_MAX_PLANES];
    int nplanes;
    /* The gap test of friction planes (def.wall_gap > 0): first moments of the nodal mass about
     * the node, sum_p N_ip m_p (x_p - x_i) (nnodes each, NULL without friction planes), and per
     * friction plane the distance from the plane of the centroid a full half-space of material
     * would give each node (NULL for other planes). */
    double *nmx, *nmy;
    double *dref[4 + MPM_MAX_PLANES];
    /* How far a point may sit beyond a grid edge with a wall before the run stops: a quarter
     * cell (a wall's contact engages within a small gap, and material may overshoot it by a
     * fraction of a cell; the shape functions extend there), 0 at edges without a wall. */
    double slack[2][2];

    /* prescribed-velocity grains (allocated when the first is prescribed) */
    int *gpres;             /* per grain: index into pv, or -1 */
    double (*pv)[2];
    int npres;
    int *nforce;            /* per node: 1 + index into pv of the grain forcing it, or 0 */

    /* material points */
    size_t np, cap;
    double *x, *y, *vx, *vy, *m, *v0;
    double *F[4];           /* xx, xy, yx, yy */
    double *be[4];          /* elastic left Cauchy-Green: xx, xy, yy, zz */
    double *sig[4];         /* Cauchy stress: xx, yy, xy, zz */
    double *eps_p;
    double *ux, *uy;        /* displacement */
    /* plastic shear rate of the last step (continuum models), cap entries; allocated when the
     * first drucker_prager or mu_i material is added, else NULL */
    double *rate;
    /* ln(b_e,zz) / 2 per point, a cache the step keeps (material_update_zz), not saved: built
     * from b_e,zz at the start of a run unless lzz_ok (cleared wherever points or b_e are set
     * outside the step) */
    double *lzz;
    bool lzz_ok;
    /* the stress update and G2P one point at a time, for the tests: the reference of their
     * lanes (constitutive in stress.c, to_points in transfer.c); false (calloc) otherwise */
    bool no_lanes;
    int *grain, *mat;
    /* stencil, MPM_STENCIL per point */
    int *sn;
    double *sw, *sgx, *sgy;
    double m_min;           /* nodes lighter than this take no acceleration */
    /* sf: per stencil entry, the nodal-array index of the field the point moves with: sn for
     * noslip; for friction the grain's pair at nodes shared by several grains, else sn */
    int *sf;

    /* frictional contact (Eqs. 12-24): sparse per-grain nodal fields, rebuilt every step */
    double mu;
    size_t paircap;         /* the nodal arrays hold nnodes + paircap entries */
    int *pnode;             /* node of pair q */
    int *pgrain;            /* grain of pair q */
    unsigned char *pin;     /* pair q in contact this step (Eq. 12 at the momentum update) */
    unsigned char *pwin;    /* pair q: bit k, friction plane k in contact (as nwin) */
    double *pvol;           /* sum_p N_ip V_p over the grain (the separation check) */
    mpm_contact_options opt;
    double *pnx, *pny;      /* sum_p m_p G_pi over the grain: its outward normal direction */
    int *ngr;               /* grains touching node i (nnodes) */
    /* Each node's pairs in pair order, rebuilt every step (contact.c, pair_chains): nhead, the
     * node's first pair or -1 (nnodes); pnext, the next pair at the same node or -1; pshared:
     * pair q is at a node of two or more grains. The threads add up a node's pairs along its
     * chain, each over its own range of nodes, so that no pass over all pairs is serial. */
    int *nhead, *pnext;
    unsigned char *pshared;
    int *sv;                /* ns per point: the friction sf */

    mpm_material *mats;
    int nmat, matcap;
    size_t ngrains, gcap;
    size_t *gstart, *gcount;
    mpm_grain_def *gdef;    /* each grain's shape, for the overlap warning */

    mpm_contact_model contact;
    double time;
    long steps;
    /* the step's threads, scratch and timings (step_internal.h), made by the first run */
    struct mpm_step *step;
};

/* Frees the step context of mpm_scene.step (step.c); NULL is a no-op. */
void mpm_step_free(struct mpm_step *c);

/* Sizes the per-grain field arrays for the current points (called before a run with contact
 * "friction"; no allocation happens inside the step loop). */
core_status mpm_contact_reserve(mpm_scene *s, core_error *err);

/* For mpm_add_plane and checkpoints (src/mpm/checkpoint.c): grows the point arrays to n points;
 * appends plane p as given (n already unit and into the wall) and marks its nodes. */
core_status mpm_reserve_points(mpm_scene *s, size_t n, core_error *err);
core_status mpm_install_plane(mpm_scene *s, const mpm_plane *p, core_error *err);

#endif
