/* The MPM scene's private layout: grid geometry, nodal arrays (allocated once at creation),
 * material points in structure-of-arrays, and the per-step stencil (each point's four nodes,
 * weights and weight gradients, computed once per step and reused by every transfer, so per-grain
 * nodal fields can later be accumulated sparsely from the same arrays). */
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

    /* nodal fields (nnodes each) */
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

    mpm_material *mats;
    int nmat, matcap;
    size_t ngrains, gcap;
    size_t *gstart, *gcount;

    mpm_contact_model contact;
    double time;
    long steps;
};

#endif
