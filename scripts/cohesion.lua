-- grainlab DEM validation: cohesive contacts (normal laws 'jkr' and 'dmt', cohesion 'capillary')
-- between two spheres pulled apart quasi-statically, against their closed forms.
--
-- Two spheres of radii r1, r2 (R* = r1 r2/(r1 + r2)), E* from the two materials
-- (1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2), work of adhesion Gamma (J/m^2; LAMMPS's surface
-- energy gamma is Gamma/2). Overlap delta = r1 + r2 - |x2 - x1| (< 0: a gap), F the normal force
-- on sphere 2 along x2 - x1 (> 0 repulsive).
--
-- JKR (Johnson, Kendall & Roberts 1971; Johnson, Contact Mechanics, 1985, Sec. 5.5), in the
-- contact radius a:
--   F = 4 E* a^3/(3 R*) - sqrt(8 pi Gamma E* a^3),  delta = a^2/R* - sqrt(2 pi Gamma a/E*).
-- With a = A u, A^3 = 2 pi Gamma R*^2/E*, D = A^2/R*: delta/D = u^2 - sqrt(u), F/(pi Gamma R*) =
-- 8/3 u^3 - 4 u^{3/2}. At touch (delta = 0) u = 1, F = -4/3 pi Gamma R*; dF/du = 0 at u^{3/2} =
-- 3/4 gives the least force, the pull-off force F_po = 3/2 pi Gamma R*; d delta/du = 0 at u^{3/2}
-- = 1/4 gives the separation where the contact breaks with the overlap imposed,
--   delta_c = -(3/4) (pi^2 Gamma^2 R*/E*^2)^{1/3},  F(delta_c) = -5/6 pi Gamma R*.
-- The contact forms only at touch: approaching, F = 0 until delta = 0; withdrawn, it holds to
-- delta_c (hysteresis). Here a(delta) is found by bisection on u in [u_c, u_max], independent of
-- the engine's Newton solve.
-- DMT (Derjaguin, Muller & Toporov 1975, as LAMMPS's dmt): F = 4/3 E* sqrt(R*) delta^{3/2} -
-- 2 pi Gamma R* for delta > 0, 0 apart: the pull-off force is 2 pi Gamma R*, reached at touch.
-- Capillary bridge (Rabinovich et al. 2005, the sphere-sphere form without the filling angle's
-- term) of volume V, surface tension gamma, contact angle theta, at separation S = -delta >= 0:
--   F = -4 pi R* gamma cos(theta) (1 - S/sqrt(S^2 + V/(pi R*))),
-- formed at touch, ruptured at S_c = (1 + theta/2) V^{1/3} (Lian et al. 1993); in contact the
-- hertz force adds to -4 pi R* gamma cos(theta).
--
-- Part 1 imposes the overlap (sphere 1 fixed, sphere 2 prescribed, moving along a direction that
-- is no axis): approach from a gap to an overlap, then withdraw beyond the break; every step's
-- force is compared with the closed form at that step's overlap. Part 2 is load controlled: a
-- free sphere held by a JKR contact is pulled by a force raised slowly (viscous damping keeps it
-- quasi-static); it tears off when the force passes F_po. steps= sets the resolution of part 1.
--   grainlab scripts/cohesion.lua [steps=2000] [png=out/cohesion_jkr.png] [load=true] [ramp=1600]
--            [damping=0.3]
local steps = tonumber(params.steps) or 2000
local png = params.png or "out/cohesion_jkr.png"
local do_load = params.load ~= false and params.load ~= "false"
local ramp = tonumber(params.ramp) or 1600      -- part 2: the load's rise, in contact periods
local damping = tonumber(params.damping) or 0.3   -- part 2: viscous damping / critical
local pi = math.pi
local t_wall0 = grainlab.clock()

local r1, r2 = 60e-6, 40e-6
local R = r1 * r2 / (r1 + r2)
local E1, nu1, E2, nu2 = 1e9, 0.3, 2e9, 0.25
local Es = 1 / ((1 - nu1 ^ 2) / E1 + (1 - nu2 ^ 2) / E2)
local Gamma_a, Gamma_b = 0.02, 0.08          -- the materials'; a pair takes sqrt(Ga Gb)
local Gamma = math.sqrt(Gamma_a * Gamma_b)
local mat1 = grainlab.material{ density = 2500, young = E1, poisson = nu1, work_of_adhesion = Gamma_a }
local mat2 = grainlab.material{ density = 2500, young = E2, poisson = nu2, work_of_adhesion = Gamma_b }
local dir = { 1 / 3, 2 / 3, 2 / 3 }

local checks, metrics = {}, {}
local function check(name, value, limit)
  checks[#checks + 1] = { name = name, value = value, limit = limit }
end

-- ---- closed forms -------------------------------------------------------------------------
local A = (2 * pi * Gamma * R * R / Es) ^ (1 / 3)
local D = A * A / R
local u_c = 4 ^ (-2 / 3)
local delta_c = -0.75 * (pi * pi * Gamma * Gamma * R / (Es * Es)) ^ (1 / 3)
local u_po = 0.75 ^ (2 / 3)
local delta_po = D * (u_po * u_po - math.sqrt(u_po))   -- the overlap of the least force
local function jkr_closed(delta)        -- F on the stable branch, delta >= delta_c
  local y = delta / D
  local lo, hi = u_c, 1 + math.sqrt(math.max(y, 0)) + 1
  for _ = 1, 200 do
    local mid = 0.5 * (lo + hi)
    if mid * mid - math.sqrt(mid) < y then lo = mid else hi = mid end
  end
  local u = 0.5 * (lo + hi)
  return pi * Gamma * R * (8 / 3 * u ^ 3 - 4 * u ^ 1.5)
end
local K = 4 / 3 * Es * math.sqrt(R)
local function dmt_closed(delta) return delta > 0 and K * delta ^ 1.5 - 2 * pi * Gamma * R or 0 end

-- ---- part 1: the overlap imposed ----------------------------------------------------------
-- Moves sphere 2 from overlap d0 to d1 and back to d2 in `steps` steps per leg; returns the
-- rows { delta, F, leg } of every step.
local function imposed(contact, d0, d1, d2)
  local s = dem.scene{ dim = 3, box = { { -1e-3, -1e-3, -1e-3 }, { 1e-3, 1e-3, 1e-3 } } }
  s:contact(contact)
  s:add_sphere{ pos = { 0, 0, 0 }, radius = r1, material = mat1, fixed = true }
  local c0 = r1 + r2 - d0
  local span1, span2 = d1 - d0, d1 - d2
  local dt = s:timestep().dt_auto
  local v1 = span1 / (steps * dt)
  s:add_sphere{ pos = { c0 * dir[1], c0 * dir[2], c0 * dir[3] }, radius = r2, material = mat2,
                prescribed = true, vel = { -v1 * dir[1], -v1 * dir[2], -v1 * dir[3] } }
  local rows = {}
  local function record(leg)
    local p = s:particles()
    local x = { p.x[2] - p.x[1], p.y[2] - p.y[1], p.z[2] - p.z[1] }
    local dist = math.sqrt(x[1] ^ 2 + x[2] ^ 2 + x[3] ^ 2)
    local f = (p.fx[2] * x[1] + p.fy[2] * x[2] + p.fz[2] * x[3]) / dist
    rows[#rows + 1] = { delta = r1 + r2 - dist, F = f, leg = leg }
  end
  s:run{ steps = steps, dt = dt, every = 1, on_step = function() record(1) end }
  local v2 = span2 / (steps * dt)
  s:set_velocity(2, { v2 * dir[1], v2 * dir[2], v2 * dir[3] })
  s:run{ steps = steps, dt = dt, every = 1, on_step = function() record(2) end }
  return rows, s
end

-- JKR: from a gap of 0.3 |delta_c| to an overlap of 3 |delta_c|, back to a gap of 1.5 |delta_c|.
local jkr_rows = imposed({ normal = "jkr" }, 0.3 * delta_c, -3 * delta_c, 1.5 * delta_c)
local step_delta = -4.5 * delta_c / steps  -- the withdrawal's step in overlap
local curve_err, approach_max, least, break_at = 0, 0, 0, nil
local sim_load, sim_unload = { x = {}, y = {} }, { x = {}, y = {} }
local scale = pi * Gamma * R
for k, row in ipairs(jkr_rows) do
  local d, f = row.delta, row.F
  local tgt = row.leg == 1 and sim_load or sim_unload
  tgt.x[#tgt.x + 1] = d / -delta_c
  tgt.y[#tgt.y + 1] = f / scale
  if row.leg == 1 and d < 0 then
    approach_max = math.max(approach_max, math.abs(f))     -- no force before touch
  elseif f ~= 0 then
    curve_err = math.max(curve_err, math.abs(f - jkr_closed(d)) / scale)
  end
  if row.leg == 2 then
    least = math.min(least, f)
    if f ~= 0 then break_at = d end
  end
  _ = k
end
metrics.jkr_pulloff_ratio = -least / (1.5 * pi * Gamma * R)
metrics.jkr_curve_max_error = curve_err             -- in units of pi Gamma R*
metrics.jkr_break_delta_ratio = break_at / delta_c
metrics.jkr_step_over_delta_c = step_delta / -delta_c
metrics.jkr_force_before_touch = approach_max
check("jkr_pulloff_force_within_1pct", math.abs(metrics.jkr_pulloff_ratio - 1), 0.01)
check("jkr_curve_vs_closed_form", curve_err, 1e-9)
check("jkr_no_force_before_touch", approach_max, 0)
-- the last step with the contact is within one step of delta_c
check("jkr_breaks_at_delta_c", math.abs(break_at - delta_c) / step_delta, 1)

-- DMT: the same path, with the contact's work of adhesion
local dmt_rows = imposed({ normal = "dmt", work_of_adhesion = Gamma }, 0.3 * delta_c, -3 * delta_c,
                         1.5 * delta_c)
local dmt_err, dmt_least = 0, 0
for _, row in ipairs(dmt_rows) do
  dmt_err = math.max(dmt_err, math.abs(row.F - dmt_closed(row.delta)) / scale)
  if row.leg == 2 then dmt_least = math.min(dmt_least, row.F) end
end
metrics.dmt_pulloff_ratio = -dmt_least / (2 * pi * Gamma * R)
metrics.dmt_curve_max_error = dmt_err
check("dmt_pulloff_force_within_1pct", math.abs(metrics.dmt_pulloff_ratio - 1), 0.01)
check("dmt_curve_vs_closed_form", dmt_err, 1e-9)

-- Capillary bridge: water (gamma = 0.072 N/m, theta = 20 deg), V = 1e-3 R*^3 ... pulled beyond
-- its rupture distance.
local V, gam, theta = 1e-3 * (2 * R) ^ 3, 0.072, 20 * pi / 180
local S_c = (1 + theta / 2) * V ^ (1 / 3)
local cap_rows = imposed({ normal = "hertz", cohesion = "capillary", liquid_volume = V,
                           surface_tension = gam, contact_angle = 20 },
                         -0.5 * S_c, 0.05 * S_c, -1.3 * S_c)
local F0 = 4 * pi * R * gam * math.cos(theta)
local function cap_closed(delta)
  if delta > 0 then return K * delta ^ 1.5 - F0 end
  local S = -delta
  return -F0 * (1 - S / math.sqrt(S * S + V / (pi * R)))
end
local cap_err, cap_before, cap_break = 0, 0, nil
for _, row in ipairs(cap_rows) do
  if row.leg == 1 and row.delta < 0 then
    cap_before = math.max(cap_before, math.abs(row.F))
  elseif row.F ~= 0 then
    cap_err = math.max(cap_err, math.abs(row.F - cap_closed(row.delta)) / F0)
  end
  if row.leg == 2 and row.F ~= 0 then cap_break = -row.delta end
end
local cap_step = 1.35 * S_c / steps
metrics.capillary_force_max_error = cap_err          -- relative to 4 pi R* gamma cos(theta)
metrics.capillary_rupture_ratio = cap_break / S_c
metrics.capillary_step_over_rupture = cap_step / S_c
check("capillary_force_vs_closed_form", cap_err, 1e-9)
check("capillary_no_bridge_before_touch", cap_before, 0)
check("capillary_ruptures_at_s_c", math.abs(cap_break - S_c) / cap_step, 1)

-- ---- part 2: the load imposed -------------------------------------------------------------
-- Sphere 2, free, rests on the fixed sphere 1 through a JKR contact; a force along dir pulls it,
-- raised from 0 to 1.2 F_po over t_ramp (viscous damping of a few times critical keeps the
-- sphere at the equilibrium overlap). It tears off at the force F_po: the load when the contact
-- breaks, over 3/2 pi Gamma R*.
if do_load then
  local s = dem.scene{ dim = 3, box = { { -1e-3, -1e-3, -1e-3 }, { 1e-3, 1e-3, 1e-3 } } }
  s:contact{ normal = "jkr", damping = "viscous", gamma_n = 0 }
  s:add_sphere{ pos = { 0, 0, 0 }, radius = r1, material = mat1, fixed = true }
  local c0 = r1 + r2 - 0.1 * D           -- just touching: the contact forms
  s:add_sphere{ pos = { c0 * dir[1], c0 * dir[2], c0 * dir[3] }, radius = r2, material = mat2 }
  local m2 = s:particles().mass[2]
  -- the contact's stiffness at the pull-off point, dF/ddelta; critical damping 2 sqrt(m k)
  local kc = 2 * Es * A * (0.75 ^ (2 / 3))
  local gamma_n = damping * 2 * math.sqrt(m2 * kc)
  s:contact{ normal = "jkr", damping = "viscous", gamma_n = gamma_n }
  local F_po = 1.5 * pi * Gamma * R
  local period = 2 * pi * math.sqrt(m2 / kc)
  local t_ramp = ramp * period
  local dt = s:timestep().dt_auto
  local n_ramp = math.ceil(t_ramp / dt)
  local torn, load_at = false, nil
  local every = 10
  local k = 0
  s:run{ steps = n_ramp, dt = dt, every = every, on_step = function(sc)
    k = k + every
    local F = 1.2 * F_po * k / n_ramp
    sc:set_forces{ ids = { 2 }, fx = { F * dir[1] }, fy = { F * dir[2] }, fz = { F * dir[3] } }
    if not torn then
      local p = sc:particles()
      local x = { p.x[2] - p.x[1], p.y[2] - p.y[1], p.z[2] - p.z[1] }
      local gap = math.sqrt(x[1] ^ 2 + x[2] ^ 2 + x[3] ^ 2) - (r1 + r2)
      if -gap < delta_po then torn, load_at = true, F end
    end
    if torn then return false end
  end }
  metrics.jkr_load_controlled_pulloff_ratio = load_at and load_at / F_po or 0
  metrics.jkr_load_ramp_periods = ramp
  check("jkr_load_controlled_pulloff_within_1pct",
        math.abs(metrics.jkr_load_controlled_pulloff_ratio - 1), 0.01)
end

-- ---- the figure ---------------------------------------------------------------------------
local cf = { x = {}, y = {} }
for kk = 0, 400 do
  local d = delta_c + (-3 * delta_c - delta_c) * kk / 400
  cf.x[#cf.x + 1] = d / -delta_c
  cf.y[#cf.y + 1] = jkr_closed(d) / scale
end
local function thin(series, n)       -- every n-th point, so that the markers stay apart
  local out = { x = {}, y = {} }
  for kk = 1, #series.x, n do
    out.x[#out.x + 1], out.y[#out.y + 1] = series.x[kk], series.y[kk]
  end
  return out
end
local ld, ul = thin(sim_load, math.max(1, steps // 40)), thin(sim_unload, math.max(1, steps // 40))
os.execute("mkdir -p " .. (png:match("^(.*)/[^/]*$") or "."))
render.plot{ file = png, width = 900, height = 560,
             title = "JKR: two spheres loaded and unloaded, overlap imposed",
             xlabel = "overlap / |delta_c|", ylabel = "F / (pi Gamma R*)",
             series = {
               { x = cf.x, y = cf.y, label = "closed form (stable branch)", style = "line" },
               { x = ld.x, y = ld.y, label = "grainlab, loading", style = "points" },
               { x = ul.x, y = ul.y, label = "grainlab, unloading", style = "points" },
             } }

metrics.wall_s = grainlab.clock() - t_wall0
grainlab.report{
  scenario = "dem_cohesion",
  params = { steps = steps, r1_m = r1, r2_m = r2, E_star_pa = Es, gamma_j_per_m2 = Gamma,
             liquid_volume_m3 = V, surface_tension_n_per_m = gam, contact_angle_deg = 20 },
  metrics = metrics,
  checks = checks,
}
