/* The names of the contact laws (laws.h), in enum order: s:contact's options, s:info's values. */
#include <stddef.h>

#include "dem/laws.h"

#define DEM_LAW_NAME_(a, ID, name, ...) #name,
const char *const dem_normal_names[] = {DEM_NORMAL_LAWS(DEM_LAW_NAME_, _) NULL};
const char *const dem_damping_names[] = {DEM_DAMPING_LAWS(DEM_LAW_NAME_, _) NULL};
const char *const dem_tangent_names[] = {DEM_TANGENT_LAWS(DEM_LAW_NAME_, _) NULL};
const char *const dem_rolling_names[] = {DEM_ROLLING_LAWS(DEM_LAW_NAME_, _) NULL};
const char *const dem_cohesion_names[] = {DEM_COHESION_LAWS(DEM_LAW_NAME_, _) NULL};
#undef DEM_LAW_NAME_
