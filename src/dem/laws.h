/* The contact laws, one row each. From these lists (X macros) come the enums, the names s:contact
 * takes and s:info returns, the range checks of dem_set_contact and of the checkpoint reader, the
 * dispatch to each law's functions and the specialised pair loops. A row's position is the number
 * a checkpoint stores: add rows at the end. docs/development.md ("Adding a contact law") says what
 * else a law needs. */
#ifndef GRAINLAB_DEM_LAWS_H
#define GRAINLAB_DEM_LAWS_H

/* Each list is called as LIST(X, a) and gives X(a, ID, name, columns...) per row: ID makes the
 * enum value (DEM_NORMAL_ID, ...), name is the Lua name and the stem of the law's functions, and
 * `a` is passed through untouched (a loop over two lists passes the outer row's ID in it). */

/* Normal laws. The functions (laws.inc): normal_NAME(c, k, delta, sqrt_delta), the elastic force
 * (> 0: repulsive); normal_NAME_energy(c, k, delta), its potential; normal_NAME_kt(c, k, delta,
 * sqrt_delta), the tangential spring's default stiffness, 2/7 of d f / d delta;
 * normal_NAME_beta(c), the exponent of delta that contact times and restitutions use.
 *   k        MODULI: k = 4/3 E* sqrt(R*) from the materials; STIFFNESS: s:contact's stiffness
 *   tension  1: the law may attract, normal_NAME_tension(c, k, delta, sqrt_delta) <= 0 is added
 *            after the clip (which then keeps only the damping from pulling); 0: it never does
 *   fast     1: the pair kernel has loops with the law as a constant (forces_dim.inc) */
#define DEM_NORMAL_LAWS(X, a)                                                                      \
    X(a, LINEAR, linear, STIFFNESS, 0, 1) /* f = k delta (Herrmann Eq. 1a, beta = 1) */            \
    X(a, POWER, power, STIFFNESS, 0, 0)   /* f = k delta^beta, beta in {1, 3/2, 2} (Eq. 1a) */     \
    X(a, HERTZ, hertz, MODULI, 0, 1)      /* f = K delta^{3/2}, K = 4/3 E* sqrt(R) (Padbidri       \
                                           * Eq. 1.1, 2.16) */                                     \
    X(a, DMT, dmt, MODULI, 0, 0)          /* Hertz minus 2 pi Gamma R* in contact (Derjaguin,      \
                                           * Muller & Toporov 1975): cohesion.h */                 \
    X(a, JKR, jkr, MODULI, 0, 0)          /* Johnson, Kendall & Roberts 1971, with its hysteresis: \
                                           * cohesion.h */

/* Normal damping, added to the elastic force. The function (laws.inc):
 * damping_NAME(f, k, gamma, sqrt_delta, ddelta) returns f plus the damping force; gamma is the
 * pair's coefficient (neighbor.c), from s:contact or solved from a restitution (restitution.c).
 *   a_exp    the exponent a of the dashpot gamma' delta^a ddelta that the restitution solver
 *            integrates (dem_contact_damping) */
#define DEM_DAMPING_LAWS(X, a)                                                                     \
    X(a, NONE, none, 0)                                                                            \
    X(a, VISCOUS, viscous, 0)           /* f = gamma ddelta/dt (Herrmann Eq. 1b); gamma = gamma_n, \
                                         * or per pair from a restitution */                       \
    X(a, BRILLIANTOV, brilliantov, 0.5) /* f = T K delta^{1/2} ddelta/dt (Padbidri Eq. 2.16),      \
                                         * Hertz only; T = damping_time, or per pair */

/* Tangential laws. The functions: tangential_NAME_2 and _3 (forces_dim.inc: the force for a slip,
 * advancing the history), wall_tangential_NAME (measure.c: the force a wall contact carries now).
 *   hist     1: a spring history per contact (hist[0..2] the force, hist[3] the last stiffness) */
#define DEM_TANGENT_LAWS(X, a)                                                                     \
    X(a, NONE, none, 0)                                                                            \
    X(a, VISCOUS, viscous, 0)                 /* f_t = -gamma_t s (Herrmann Eq. 2a) */             \
    X(a, SPRING, spring, 1)                   /* Cundall-Strack spring, Coulomb cap (Eq. 2b) */    \
    X(a, REGULARIZED, coulomb_regularized, 0) /* |f_t| = mu f_n min(1, (s/v_R)^{1/c})              \
                                               * (Padbidri Eq. 1.3, 2.18) */

/* Rolling resistance (rolling.inc): a torque against the relative rolling of the two surfaces,
 * at most mu_r R_eff F_n (R_eff = r_i r_j / (r_i + r_j); against a wall R_eff = r_i). The
 * functions: rolling_NAME_2 and _3 (rolling.inc).
 *   hist     1: an incremental spring per contact (history; k_r defaults to k_t R_eff^2) */
#define DEM_ROLLING_LAWS(X, a)                                                                     \
    X(a, NONE, none, 0)                                                                            \
    X(a, EPSD, epsd, 1)         /* Ai, Chen, Rotter & Ooi (2011) type C: elastic-plastic spring-   \
                                 * dashpot, capped at the limit, a viscous part of damping ratio   \
                                 * eta_r below it */                                               \
    X(a, CONSTANT, constant, 0) /* Ai et al. type A: M = -mu_r R_eff F_n w_rel / |w_rel|, linear   \
                                 * below a rate w_c so that a grain at rest does not chatter */

/* Cohesion added to the normal law of a contact (cohesion.h): a liquid bridge that forms at touch
 * and ruptures at a separation. JKR and DMT are normal laws of their own (above).
 *   holds    1: the contact holds beyond touch (the history slot DEM_HIST_BOND) */
#define DEM_COHESION_LAWS(X, a)                                                                    \
    X(a, NONE, none, 0)                                                                            \
    X(a, CAPILLARY, capillary, 1) /* Rabinovich et al. 2005, rupture (1 + theta/2) V^{1/3} */

/* ---- what the lists make ----------------------------------------------------------------- */
#define DEM_LAW_ENUM_(prefix, ID, ...) prefix##ID,
typedef enum dem_normal_law {
    DEM_NORMAL_LAWS(DEM_LAW_ENUM_, DEM_NORMAL_) DEM_NORMAL_COUNT
} dem_normal_law;
typedef enum dem_damping_law {
    DEM_DAMPING_LAWS(DEM_LAW_ENUM_, DEM_DAMPING_) DEM_DAMPING_COUNT
} dem_damping_law;
typedef enum dem_tangential_law {
    DEM_TANGENT_LAWS(DEM_LAW_ENUM_, DEM_TANGENT_) DEM_TANGENT_COUNT
} dem_tangential_law;
typedef enum dem_rolling_law {
    DEM_ROLLING_LAWS(DEM_LAW_ENUM_, DEM_ROLLING_) DEM_ROLLING_COUNT
} dem_rolling_law;
typedef enum dem_cohesion_law {
    DEM_COHESION_LAWS(DEM_LAW_ENUM_, DEM_COHESION_) DEM_COHESION_COUNT
} dem_cohesion_law;
#undef DEM_LAW_ENUM_

/* The names, in enum order, each list ended by NULL (laws.c). */
extern const char *const dem_normal_names[];
extern const char *const dem_damping_names[];
extern const char *const dem_tangent_names[];
extern const char *const dem_rolling_names[];
extern const char *const dem_cohesion_names[];

/* The columns, for a law known at run time (constants fold where it is a constant). */
#define DEM_LAW_K_MODULI 1
#define DEM_LAW_K_STIFFNESS 0
static inline int dem_normal_from_moduli(dem_normal_law law)
{
    switch (law) {
#define DEM_LAW_(a, ID, name, k, ...)                                                              \
    case DEM_NORMAL_##ID:                                                                          \
        return DEM_LAW_K_##k;
        DEM_NORMAL_LAWS(DEM_LAW_, _)
#undef DEM_LAW_
    default:
        return 0;
    }
}

/* Hertz and the laws with its elastic part (JKR, DMT): Brilliantov damping applies. */
static inline int dem_normal_hertzian(dem_normal_law law)
{
    return law == DEM_NORMAL_HERTZ || law == DEM_NORMAL_JKR || law == DEM_NORMAL_DMT;
}

static inline double dem_damping_exponent(dem_damping_law law)
{
    switch (law) {
#define DEM_LAW_(a, ID, name, a_exp)                                                               \
    case DEM_DAMPING_##ID:                                                                         \
        return a_exp;
        DEM_DAMPING_LAWS(DEM_LAW_, _)
#undef DEM_LAW_
    default:
        return 0;
    }
}

static inline int dem_tangent_history(dem_tangential_law law)
{
    switch (law) {
#define DEM_LAW_(a, ID, name, hist)                                                                \
    case DEM_TANGENT_##ID:                                                                         \
        return hist;
        DEM_TANGENT_LAWS(DEM_LAW_, _)
#undef DEM_LAW_
    default:
        return 0;
    }
}

static inline int dem_rolling_history(dem_rolling_law law)
{
    switch (law) {
#define DEM_LAW_(a, ID, name, hist)                                                                \
    case DEM_ROLLING_##ID:                                                                         \
        return hist;
        DEM_ROLLING_LAWS(DEM_LAW_, _)
#undef DEM_LAW_
    default:
        return 0;
    }
}

#endif
