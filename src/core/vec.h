/* Small 2D/3D vector functions for cold paths and tests; hot loops work on SoA arrays directly. */
#ifndef GRAINLAB_CORE_VEC_H
#define GRAINLAB_CORE_VEC_H

#include <math.h>

typedef struct vec2 { double x, y; } vec2;
typedef struct vec3 { double x, y, z; } vec3;

static inline vec2 vec2_make(double x, double y) { return (vec2){x, y}; }
static inline vec2 vec2_add(vec2 a, vec2 b) { return (vec2){a.x + b.x, a.y + b.y}; }
static inline vec2 vec2_sub(vec2 a, vec2 b) { return (vec2){a.x - b.x, a.y - b.y}; }
static inline vec2 vec2_scale(vec2 a, double s) { return (vec2){s * a.x, s * a.y}; }
static inline double vec2_dot(vec2 a, vec2 b) { return a.x * b.x + a.y * b.y; }
/* z-component of the 3D cross product of (a,0) and (b,0). */
static inline double vec2_cross(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }
static inline double vec2_norm(vec2 a) { return hypot(a.x, a.y); }
/* a rotated by +90 degrees. */
static inline vec2 vec2_perp(vec2 a) { return (vec2){-a.y, a.x}; }

static inline vec3 vec3_make(double x, double y, double z) { return (vec3){x, y, z}; }
static inline vec3 vec3_add(vec3 a, vec3 b) { return (vec3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static inline vec3 vec3_sub(vec3 a, vec3 b) { return (vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline vec3 vec3_scale(vec3 a, double s) { return (vec3){s * a.x, s * a.y, s * a.z}; }
static inline double vec3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 vec3_cross(vec3 a, vec3 b)
{
    return (vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static inline double vec3_norm(vec3 a) { return sqrt(vec3_dot(a, a)); }

#endif
