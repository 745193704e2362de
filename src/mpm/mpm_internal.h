/* The MPM scene's private layout: grid geometry, nodal arrays (allocated once), material points
 * in structure-of-arrays, the per-step stencil (each point's four nodes, weights and weight
 * gradients, computed once per step and reused by every transfer) and the sparse per-grain nodal
 * fields of the frictional contact (one entry per (grain, node) pair a grain's points touch). */
#ifndef GRAINLAB_MPM_INTERNAL_H
#define GRAINLAB_MPM_INTERNAL_H

#include "mpm/mpm.h"

/* Linear tensor-product shape functions: four nodes per point. */
#define MPM_STENCIL 4

struct mpm_scene {
    mpm_scene_def def;
    double hx, hy, inv_hx, inv_hy;
    int nnx, nny;           /* nodes per axis: cells + 1, or cells on a periodic axis */
    size_t nnodes;

    /* nodal fields: nnodes centre-of-mass entries, then (contact "friction") one entry per
     * (grain, node) pair at index nnodes + q, so the transfers index both the same way */
    double *nm;             /* lumped mass, Eq. 6 */
    double *npx, *npy;      /* momentum m_i v_i^n, Eq. 5 (reused for the MUSL remap) */
    double *nfx, *nfy;      /* internal + external force, Eq. 7 */
    double *nvx, *nvy;      /* v_i^n */
    double *nax, *nay;      /* v_i^{n+1} */
    unsigned char *nwall;   /* bit 0: x fixed, bit 1: y fixed */

    /* material points */
    size_t np, cap;
    double *x, *y, *vx, *vy, *m, *v0;
    double *F[4];           /* xx, xy, yx, yy */
    double *be[4];          /* elastic left Cauchy-Green: xx, xy, yy, zz */
    double *sig[4];         /* Cauchy stress: xx, yy, xy, zz */
    double *eps_p;
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
    size_t npairs;
    int *pnode;             /* node of pair q */
    unsigned char *pin;     /* pair q in contact this step (Eq. 12 at the momentum update) */
    double *pnx, *pny;      /* sum_p m_p G_pi over the grain: its outward normal direction */
    int *ngr;               /* grains touching node i (nnodes) */
    double *tgx, *tgy;      /* sum_p m_p G_pi over all grains (nnodes) */
    int *mark;              /* scratch (nnodes, -1): pair of node i for the grain being built */
    int *sv;                /* MPM_STENCIL per point: the friction sf */

    mpm_material *mats;
    int nmat, matcap;
    size_t ngrains, gcap;
    size_t *gstart, *gcount;

    mpm_contact_model contact;
    double time;
    long steps;
};

/* Sizes the per-grain field arrays for the current points (called before a run with contact
 * "friction"; no allocation happens inside the step loop). */
core_status mpm_contact_reserve(mpm_scene *s, core_error *err);

#endif
