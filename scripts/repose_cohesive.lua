-- grainlab DEM: the angle of repose of wet (cohesive) piles against the granular Bond number.
--
-- The pile of scripts/repose.lua (scripts/lib/heap_box.lua: N disks settle in a box, its gate is
-- removed, the pile left in the box is fitted by a line; the procedure and its reasons are in
-- repose.lua's header), here with a liquid bridge on every contact, at friction mu = 0.5 and a
-- granular Bond number Bo running through `bos`, several packings (seeds) per Bo.
--
-- Law: Hertz + Brilliantov damping + Cundall-Strack spring (repose.lua's) with cohesion
-- "capillary" (docs/dem.md "Cohesion"): a liquid bridge forms at touch, pulls with
-- 4 pi R* gamma cos(theta_c) while the grains overlap, weakens across a gap S as
-- 1 - S/sqrt(S^2 + V/(pi R*)) (Rabinovich et al. 2005) and ruptures at
-- S_c = (1 + theta_c/2) V^(1/3) (Lian et al. 1993). A bridge rather than JKR because the grains
-- here are soft (E = 1e6 Pa, as in repose.lua, so that the step is long): a bridge's force does
-- not depend on the stiffness, so the cohesion is that of real wet millimetre grains whatever E
-- is, while a JKR contact's radius, snap-in and break separation all scale with E^(-2/3) and
-- would carry the softening into the adhesion. Wet sand is the pendular-bridge case (Samadani &
-- Kudrolli 2001, Mitarai & Nori 2006); JKR is the dry fine powder's. The bridge volume
-- V = `liquid` d^3 (d = 2 R_mean = 1.5 mm; default 1e-3: S_c = 0.1 d), contact angle 0, is the
-- same at every Bo; only the surface tension changes. Planes stick too (the left wall; a bridge
-- to a plane pulls twice as hard as one between equal grains); the fitted bins keep two
-- diameters away from it.
--
-- Bond number: Bo = F_c / (m g), the pull-off force of a pair of grains of the mean radius
-- R = 0.75 mm (R* = R/2: F_c = 4 pi R* gamma = 2 pi R gamma) over the weight of such a grain
-- with a sphere's mass, as heap_box's disks carry (m = 4/3 pi R^3 rho):
--     Bo = 3 gamma / (2 rho g R^2),   gamma = Bo * 2 rho g R^2 / 3  (0.0098 N/m at Bo = 1).
-- Bo = 0 is the dry law (no bridge at all): the runs of repose.lua at mu = 0.5, the same packings.
--
-- What the literature says, and what is compared. Cohesion matters from Bo ~ 1 on (Nase et al.
-- 2001, Powder Technol. 116, 214; Castellanos 2005, Adv. Phys. 54, 263: powders with Bo > 1 are
-- cohesive); wet piles stand steeper as the liquid content, and so the bridges' force, grows
-- (Samadani & Kudrolli 2001, PRE 64, 051301; Mitarai & Nori 2006, Adv. Phys. 55, 1), and in a
-- Mohr-Coulomb picture the cohesion c ~ F_c / d^2 raises tan theta by an amount that grows with
-- c / (rho g H), H the pile's height: the angle of a wet pile depends on its size (Nowak,
-- Samadani & Kudrolli 2005, Nature Phys. 1, 50). 2D disks with no rolling resistance in a box
-- 31 diameters tall are no sand heap: what is compared is the trend (theta_r unchanged within
-- the scatter for Bo << 1, rising clearly from Bo ~ 1, tan theta_r growing with Bo) and its
-- rough size, not a number. The box resolves Bo up to ~3: from Bo ~ 5 the cohesive length
-- (~Bo d) nears the pile's height, the pile fails in blocks that leave a flat top and steps, and
-- its surface is no longer a line (fit rms 1.75 and 2.32 mean diameters at Bo = 5 and 10, one
-- packing, against 0.43-0.95 up to Bo = 3; `rms_limit`, 1.5, lies between: a wet surface is
-- rougher than a dry one, whose limit in repose.lua is 1).
--
-- Output: one grainlab.report: theta_r per Bo (mean and standard deviation over the packings;
-- metric names carry Bo in tenths: bo003 is Bo = 0.3), the fit tan theta_r = a + c Bo over the
-- means (c, its standard error, the rms residual in degrees), the largest overlap in the pile,
-- and checks: theta_r(Bo=0) within twice the standard error of repose.lua's measured dry value
-- (for repose.lua's parameters: n = 2000, mu = 0.5, E = 1e6, aspect 0.5); theta_r never falls
-- from one Bo to the next by more than twice the standard error of a difference of two means
-- (sd_pool sqrt(2 / seeds), sd_pool the packings' scatter pooled over the Bo); theta_r at the
-- largest Bo above theta_r(0) by more than `rise_sd` such standard errors; c > 0 by two of its
-- standard errors; per Bo: theta_r in (0, 60) deg, the fit's rms below `rms_limit` mean
-- diameters, the pile at rest, the basin heap below the box floor, no liquid bridge (a gap below
-- S_c) between the pile and a grain that left the box, the largest overlap in the pile below
-- 10 % of the smaller radius. Grains outside the box but within two largest diameters below its
-- floor are at its edge (on the last floor disk, or hanging below it by a bridge at Bo ~ 3): they
-- have not left, and are counted (grains_at_edge_max). A CSV (bo, surface_tension_n_per_m,
-- theta_r_deg, theta_r_sd_deg, packings, particles_left, fit_points) and a PNG of theta_r
-- against Bo with error bars (+- one sd) and the fit (images/repose_cohesive.png for the default
-- run, out/repose_cohesive.png for any other).
--
-- Measured (default run: n = 2000, mu = 0.5, seeds 1-4; mean +- sd over the 4 packings):
--     Bo     gamma (N/m)   theta_r (seeds 1 / 2 / 3 / 4)       mean +- sd     grains left
--     0      0             18.01 / 19.72 / 21.00 / 17.80       19.13 +- 1.51     750
--     0.1    0.00097       17.86 / 17.28 / 19.38 / 18.79       18.33 +- 0.94     747
--     0.3    0.0029        19.61 / 19.63 / 19.84 / 17.64       19.18 +- 1.03     806
--     1      0.0097        20.36 / 19.61 / 19.35 / 21.52       20.21 +- 0.97     890
--     2      0.0195        20.93 / 21.19 / 21.27 / 21.87       21.31 +- 0.40     956
--     3      0.0292        22.83 / 20.37 / 22.45 / 24.84       22.62 +- 1.83    1046
--   tan theta_r = 0.339 + 0.0259 Bo (slope se 0.0025; atan 0.339 = 18.7 deg), rms residual
--   0.28 deg; pooled sd 1.20 deg; theta_r(3) - theta_r(0) = 3.49 deg = 4.1 standard errors.
--   Below Bo ~ 0.3 the angle is the dry one within the scatter; from Bo ~ 1 it rises, by ~1.1
--   deg per unit Bo, and the pile keeps more grains (750 -> 1046 of 2000). Packings scatter by
--   1-2 deg and the runs are chaotic: a surface tension one rounding error larger moves theta_r
--   at Bo = 3, seed 1, from 22.8 to 25.3 deg. About 9 min on one core (24 runs, 14-35 s each).
--
--   grainlab scripts/repose_cohesive.lua [n=2000] [mu=0.5] [bos=0,0.1,0.3,1,2,3] [seed=1]
--       [seeds=4] [liquid=1e-3] [young=1e6] [aspect=0.5] [v_rest=5e-3] [T_max=4] [rms_limit=1.5]
--       [rise_sd=3] [csv=out/repose_cohesive.csv] [png=FILE] [verbose=false]

local function int(v) return type(v) == "number" and math.tointeger(v) or nil end
local n = int(params.n or 2000)
local mu = params.mu or 0.5
local seed = int(params.seed or 1)
local seeds = int(params.seeds or 4)
local liquid = params.liquid or 1e-3
local young = params.young or 1e6
local aspect = params.aspect or 0.5
local v_rest = params.v_rest or 5e-3
local T_max = params.T_max or 4
local rms_limit = params.rms_limit or 1.5
local rise_sd = params.rise_sd or 3
local csv = params.csv or "out/repose_cohesive.csv"
local verbose = params.verbose == true
assert(n and n >= 50, "n must be an integer >= 50")
assert(type(mu) == "number" and mu >= 0, "mu must be a non-negative number")
assert(seed and seed >= 0, "seed must be a non-negative integer")
assert(seeds and seeds >= 2, "seeds must be an integer >= 2 (the scatter between packings)")
for name, v in pairs { liquid = liquid, young = young, aspect = aspect, v_rest = v_rest,
                       T_max = T_max, rms_limit = rms_limit, rise_sd = rise_sd } do
  assert(type(v) == "number" and v > 0, name .. " must be a positive number")
end
assert(type(csv) == "string", "csv must be a path")
local heap_box = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/heap_box.lua")
local bos = heap_box.mus(params.bos, { 0, 0.1, 0.3, 1, 2, 3 })
assert(#bos >= 2, "bos must hold at least two Bond numbers")
local figures = require("grainlab.figures")
local published = figures.published({ n = n, mu = mu, seed = seed, seeds = seeds, liquid = liquid,
                                      young = young, aspect = aspect, v_rest = v_rest,
                                      T_max = T_max, bos = table.concat(bos, ",") },
                                    { n = 2000, mu = 0.5, seed = 1, seeds = 4, liquid = 1e-3,
                                      young = 1e6, aspect = 0.5, v_rest = 5e-3, T_max = 4,
                                      bos = "0,0.1,0.3,1,2,3" })
local png = params.png or figures.path("repose_cohesive.png", { published = published })

local geometry = heap_box.new{ n = n, mu = mu, seed = seed, young = young, aspect = aspect,
                               geometry_only = true }
local W, rf, rmin, rmax = geometry.W, geometry.rf, geometry.rmin, geometry.rmax
local g, rho = heap_box.gravity, heap_box.density
local R = 0.5 * (rmin + rmax) -- the mean radius
local d = 2 * R
local V = liquid * d ^ 3
local S_c = V ^ (1 / 3) -- rupture separation at contact angle 0
local function surface_tension(bo) return bo * 2 * rho * g * R * R / 3 end

-- repose.lua's measured dry angle at mu = 0.5 (its header: seeds 1-4, n = 2000, E = 1e6,
-- aspect 0.5): the reference for Bo = 0 when the parameters are the same.
local dry = { theta = 19.13, sd = 1.51, packings = 4 }
local same_as_repose = n == 2000 and mu == 0.5 and young == 1e6 and aspect == 0.5
                       and v_rest == 5e-3 and T_max == 4

-- The grains outside the box region (x >= W or y <= 0) sort into those at its edge (resting on
-- the last floor disk, or hanging below it by a bridge at Bo ~ 3) and those that left: centres
-- more than two largest diameters below the floor (y < -2 rf - 4 rmax). Returns the pairs of a
-- grain of the pile (in the box, or the floor) or at the edge and one that left closer than the
-- rupture separation S_c (a bridge may join them), the grains at the edge, the top
-- of the highest resting grain that left (the basin heap), and the largest overlap of the
-- pile's contacts over the smaller radius (planes: the grain's radius).
local function pile_contacts(b)
  local s, nf = b.s, b.nf
  local P = s:particles()
  local low = -2 * rf - 4 * rmax
  local function in_pile(i) return i <= nf or (P.x[i] < W and P.y[i] > 0) end
  local held, left, edge, basin_top = {}, {}, 0, -b.depth
  for i = 1, P.count do
    if in_pile(i) or P.y[i] >= low then
      held[#held + 1] = i
      if not in_pile(i) then edge = edge + 1 end
    else
      left[#left + 1] = i
      if P.vx[i] ^ 2 + P.vy[i] ^ 2 < 0.05 ^ 2 then
        basin_top = math.max(basin_top, P.y[i] + P.radius[i])
      end
    end
  end
  local bridges = 0
  for _, j in ipairs(left) do
    local xj, yj, rj = P.x[j], P.y[j], P.radius[j]
    for _, i in ipairs(held) do
      local dx, dy = P.x[i] - xj, P.y[i] - yj
      local reach = P.radius[i] + rj + S_c
      if math.abs(dx) < reach and math.abs(dy) < reach and dx * dx + dy * dy < reach * reach then
        bridges = bridges + 1
      end
    end
  end
  local c, worst = s:measure("contacts"), 0
  for q = 1, #c.i do
    local i, j = c.i[q], c.j[q]
    if (i > nf and in_pile(i)) or (j > nf and in_pile(j)) then
      local rr = j > 0 and math.min(P.radius[i], P.radius[j]) or P.radius[i]
      worst = math.max(worst, c.overlap[q] / rr)
    end
  end
  return bridges, edge, basin_top, worst
end

-- One Bond number and packing: prepare, collapse, fit (scripts/lib/heap_box.lua).
local function run_one(bo, sd)
  local c0 = grainlab.clock()
  local bridge = bo > 0 and { liquid_volume = V, surface_tension = surface_tension(bo),
                              contact_angle = 0 } or nil
  local b = heap_box.new{ n = n, mu = mu, seed = sd, young = young, aspect = aspect,
                          v_rest = v_rest, bridge = bridge }
  local r = b:collapse(T_max)
  r.bridges, r.edge, r.basin_top, r.overlap = pile_contacts(b)
  r.wall_s = grainlab.clock() - c0
  if verbose then
    io.stderr:write(string.format("Bo %g seed %d: theta %.2f deg, rms %.2f d, %d left, at rest "
                                  .. "after %.2f s, max overlap %.3f r, %.1f s\n", bo, sd, r.theta,
                                  r.rms, r.left, r.t, r.overlap, r.wall_s))
  end
  return r
end

print(string.format("repose_cohesive: n = %d, mu = %g, box %.1f mm wide, V = %.3g m^3 (S_c = "
                    .. "%.3g mm), %d packings per Bo", n, mu, W * 1e3, V, S_c * 1e3, seeds))
local results = heap_box.sweep{ label = "repose_cohesive", mus = bos, seed = seed, seeds = seeds,
                                run = run_one, mean = { "theta", "left", "points" },
                                max = { "rms", "vmax", "t", "basin_top", "bridges", "edge",
                                        "overlap" },
                                sum = { "wall_s" } }

local metrics, checks = { liquid_volume_m3 = V, rupture_separation_m = S_c }, {}
local rows = { "bo,surface_tension_n_per_m,theta_r_deg,theta_r_sd_deg,packings,particles_left,"
               .. "fit_points" }
print(string.format("%6s %10s %9s %7s %7s %7s %7s %9s %7s", "Bo", "gamma N/m", "theta_r", "sd",
                    "left", "points", "rms/d", "overlap/r", "wall s"))
local var_sum = 0
for _, r in ipairs(results) do
  local id = string.format("bo%03d", math.floor(r.mu * 10 + 0.5)) -- Bo in tenths
  r.bo, r.id = r.mu, id
  var_sum = var_sum + r.theta_sd ^ 2
  print(string.format("%6.2f %10.4f %9.2f %7.2f %7.0f %7.1f %7.3f %9.3f %7.1f", r.bo,
                      surface_tension(r.bo), r.theta, r.theta_sd, r.left, r.points, r.rms,
                      r.overlap, r.wall_s))
  rows[#rows + 1] = string.format("%g,%.5f,%.4f,%.4f,%d,%.1f,%.1f", r.bo, surface_tension(r.bo),
                                  r.theta, r.theta_sd, seeds, r.left, r.points)
  metrics["theta_r_deg_" .. id] = r.theta
  metrics["theta_r_sd_deg_" .. id] = r.theta_sd
  metrics["particles_left_" .. id] = r.left
  metrics["fit_rms_over_d_" .. id] = r.rms
  metrics["max_overlap_over_r_" .. id] = r.overlap
  metrics["grains_at_edge_max_" .. id] = r.edge
  metrics["settle_time_s_" .. id] = r.t
  metrics["wall_s_" .. id] = r.wall_s
  checks[#checks + 1] = { name = "theta_r_in_0_60_deg_" .. id, pass = r.theta > 0 and r.theta < 60 }
  heap_box.pile_checks(checks, id, r, rms_limit, v_rest, rf)
  checks[#checks + 1] = { name = "bridges_to_grains_that_left_" .. id, value = r.bridges,
                          limit = 0 }
  checks[#checks + 1] = { name = "max_overlap_over_r_" .. id, value = r.overlap, limit = 0.1 }
end

-- The scatter between packings, pooled over the Bond numbers (each theta_r_sd has seeds - 1
-- degrees of freedom); a mean over the packings scatters by sd / sqrt(seeds).
local sd_pool = math.sqrt(var_sum / #results)
local se_diff = sd_pool * math.sqrt(2 / seeds)
metrics.theta_r_sd_pooled_deg = sd_pool
local first, last = results[1], results[#results]
if first.bo == 0 and same_as_repose then
  -- the dry angle: repose.lua's within twice the standard error of the difference of two means
  local se = math.sqrt(first.theta_sd ^ 2 / seeds + dry.sd ^ 2 / dry.packings)
  metrics.theta_r_dry_repose_lua_deg = dry.theta
  checks[#checks + 1] = { name = "dry_theta_r_minus_repose_lua_deg",
                          value = math.abs(first.theta - dry.theta), limit = 2 * se }
end
local worst_fall = 0
for i = 2, #results do
  worst_fall = math.max(worst_fall, results[i - 1].theta - results[i].theta)
end
metrics.theta_r_largest_fall_deg = worst_fall
checks[#checks + 1] = { name = "theta_r_never_falls_beyond_scatter_deg", value = worst_fall,
                        limit = 2 * se_diff }
local rise = (last.theta - first.theta) / se_diff
metrics.theta_r_rise_deg = last.theta - first.theta
checks[#checks + 1] = { name = "theta_r_rise_over_se", value = rise, limit = rise_sd, op = ">" }

-- tan theta_r = a + c Bo, least squares over the means; c's standard error from the residuals.
local xs, ys = {}, {}
for _, r in ipairs(results) do xs[#xs + 1], ys[#ys + 1] = r.bo, math.tan(math.rad(r.theta)) end
local a, c = heap_box.line(xs, ys)
local k, ss, sxx, xm, res2 = #xs, 0, 0, 0, 0
for i = 1, k do xm = xm + xs[i] / k end
for i = 1, k do
  ss = ss + (ys[i] - a - c * xs[i]) ^ 2
  sxx = sxx + (xs[i] - xm) ^ 2
  res2 = res2 + (results[i].theta - math.deg(math.atan(a + c * xs[i]))) ^ 2
end
local c_se = k > 2 and math.sqrt(ss / (k - 2) / sxx) or 0 / 0
metrics.tan_fit_intercept = a
metrics.tan_fit_slope_per_bo = c
if k > 2 then metrics.tan_fit_slope_se = c_se end
metrics.tan_fit_theta0_deg = math.deg(math.atan(a))
metrics.tan_fit_rms_residual_deg = math.sqrt(res2 / k)
print(string.format("tan theta_r = %.4f + %.4f Bo (slope se %s), rms residual %.2f deg; pooled "
                    .. "sd %.2f deg", a, c, k > 2 and string.format("%.4f", c_se) or "-",
                    math.sqrt(res2 / k), sd_pool))
if k > 2 then
  checks[#checks + 1] = { name = "tan_fit_slope_over_se", value = c / c_se, limit = 2, op = ">" }
end

os.execute("mkdir -p out")
local dir = csv:match("^(.*)/[^/]*$")
if dir and dir ~= "" and dir ~= "out" then
  os.execute("mkdir -p '" .. dir:gsub("'", "'\\''") .. "'")
end
assert(grainlab.write_file(csv, table.concat(rows, "\n") .. "\n"))
print("wrote " .. csv)
do -- theta_r against Bo: the means, +- one sd as bars (NaN breaks the line between them), the fit
  local mx, my, ex, ey, fx, fy = {}, {}, {}, {}, {}, {}
  local cap = 0.012 * last.bo
  for _, r in ipairs(results) do
    mx[#mx + 1], my[#my + 1] = r.bo, r.theta
    local lo, hi, gap = r.theta - r.theta_sd, r.theta + r.theta_sd, { 0 / 0, 0 / 0 }
    for _, p in ipairs { { r.bo, lo }, { r.bo, hi }, gap, { r.bo - cap, lo }, { r.bo + cap, lo },
                         gap, { r.bo - cap, hi }, { r.bo + cap, hi }, gap } do
      ex[#ex + 1], ey[#ey + 1] = p[1], p[2]
    end
  end
  for q = 0, 50 do
    local bo = last.bo * q / 50
    fx[#fx + 1], fy[#fy + 1] = bo, math.deg(math.atan(a + c * bo))
  end
  render.plot{ file = png, width = 900, height = 560,
               title = string.format("angle of repose of wet piles, %d disks, mu = %g "
                                     .. "(mean +- sd of %d packings)", n, mu, seeds),
               xlabel = "granular Bond number Bo = F_c / (m g)", ylabel = "theta_r (degrees)",
               series = { { x = mx, y = my, label = "theta_r measured", style = "points" },
                          { x = ex, y = ey, label = "+- one sd", style = "line" },
                          { x = fx, y = fy, style = "line",
                            label = string.format("tan theta = %.3f + %.3f Bo", a, c) } } }
  print("wrote " .. png)
end

grainlab.report{
  scenario = "repose_cohesive",
  params = { n = n, mu = mu, seed = seed, seeds = seeds, bos = bos, liquid = liquid,
             liquid_volume_m3 = V, contact_angle_deg = 0, young_pa = young, aspect = aspect,
             box_width_m = W, mean_radius_m = R, v_rest_m_per_s = v_rest, t_max_s = T_max,
             rms_limit = rms_limit, rise_sd = rise_sd, csv = csv },
  metrics = metrics,
  checks = checks,
}
