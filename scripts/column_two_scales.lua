-- grainlab: one granular column at two scales. The column of scripts/demo.lua (1500 disks, DEM)
-- collapses once grain by grain and twice as a continuum in MPM (drucker_prager and mu_i), and
-- the three are compared: final profile, runout, the front against time, CPU time.
--
-- DEM (scripts/lib/dem_column.lua, the demo's set-up and reasons): 1500 disks, radii uniform in
-- [0.5, 1] mm (mean diameter 1.5 mm), density 2650 kg/m^3, Coulomb friction mu = 0.5 between
-- grains and with the floor of fixed disks, Hertz + Brilliantov damping (restitution 0.5), no
-- rolling resistance; a column W0 = 41 mm wide filled to H0 = 2 W0 against the wall at x = 0,
-- the gate removed at t = 0, run until the fastest grain is below 5 mm/s.
--
-- Continuum (scripts/lib/mpm_column.lua): the same width W0 and settled height H0 (the DEM's, at
-- the gate's removal), the same wall at x = 0 (slip: the disks roll and slide along a plain
-- wall), a friction floor with the grains' mu = 0.5, and the DEM packing's density: rho_c = phi
-- rho_s with phi the area fraction the disks fill in W0 x H0. The friction is the DEM packing's
-- macroscopic one: mu_s = tan theta_r with theta_r = 20.8 deg, the angle of repose these disks
-- form at mu = 0.5 (scripts/repose.lua, docs/dem.md); mu(I)'s mu_2 - mu_s = 0.26 and I_0 =
-- 0.279 are Jop et al.'s glass beads' (no measurement of them from grainlab's DEM), d = 1.5 mm
-- the disks' mean diameter; Drucker-Prager takes sin phi = mu_s, psi = 0 (phi = 22.3 deg). G =
-- 0.25 MPa, K = 0.5 MPa (elastic strain under the column 0.4 %). `cells` cells across W0 (2.7
-- grain diameters each at 10), 2 x 2 points per cell, B-splines; the run ends when the front
-- has advanced less than 0.005 W0 over a t_c = sqrt(H0 / g) (or the kinetic energy is below
-- 1e-3 of the energy released).
--
-- Measured as in the demo: the front, the 99th percentile of the grains' (points') right edges
-- (points: x plus half a point spacing); the height over the column's footprint (DEM: the top of
-- the highest grain with x < W0; MPM: the top of the points within one cell of the wall); the
-- final profiles, DEM: the top of the highest grain whose centre lies in each bin of one cell
-- width, MPM: the mass in each cell column over (rho_c h), both averaged over bins of W0 / 4;
-- the time the front takes to 90 % of its final runout (t90); CPU time by os.clock (DEM: the
-- preparation and the collapse apart).
--
-- Checks: each continuum's runout within 35 % of the DEM's (the friction is the DEM's; 35 % is
-- the spread of the quasi-2D experiments' prefactors, 1.2 to 1.8 at a = 2, between materials of
-- similar friction); the three runs end at rest; the continuum runs cost less CPU than the DEM's
-- collapse. Reported, not checked: the final heights and their ratio to the DEM's, and the slope
-- of each deposit's surface over its first 2 W0 (a least-squares line through the bins of W0 / 4
-- whose centres lie there), where the continua and the disks differ most (docs/mpm.md).
--
-- params: cells (across W0, default 10), n (disks, default 1500), out (figure prefix; the
-- default run writes images/column_two_scales_*.png, any other out/).
local cells = math.tointeger(tonumber(params.cells or 10))
local n = math.tointeger(tonumber(params.n or 1500))
assert(cells and cells >= 2, "cells must be an integer >= 2")
assert(n and n >= 100, "n must be an integer >= 100")
local figures = require("grainlab.figures")
local out = params.out or figures.path("column_two_scales", {
  published = figures.published({ cells = cells, n = n }, { cells = 10, n = 1500 }) })
local here = (arg[0]:match("^(.*)/") or ".")
local dem_column = dofile(here .. "/lib/dem_column.lua")
local mpm_column = dofile(here .. "/lib/mpm_column.lua")
local g = dem_column.gravity

-- DEM
local cpu0 = os.clock()
local col = dem_column.new{ n = n, seed = 1, aspect = 2, young = 5e6, mu = 0.5 }
local st0 = col:prepare()
local cpu_prep = os.clock() - cpu0
local W0, H0 = col.W0, st0.height
local area = 0
do
  local P = col.s:particles()
  for i = col.nf + 1, col.nf + n do area = area + math.pi * P.radius[i] ^ 2 end
end
local phi = area / (W0 * H0)
col:release()
local dem_t, dem_front = { 0 }, { st0.front }
cpu0 = os.clock()
local t_dem, st_dem = col:collapse(function(t, st)
  dem_t[#dem_t + 1], dem_front[#dem_front + 1] = t, st.front
end)
local cpu_dem = os.clock() - cpu0
local dem = { runout = (st_dem.front - W0) / W0, height = st_dem.height / H0, t = t_dem, cpu = cpu_dem,
              rest = st_dem.vmax < dem_column.v_rest }
print(string.format("DEM:            runout %.3f W0, height %.3f H0, at rest after %.3f s, CPU %.1f s (+ %.1f s preparation), %d grains, %d steps",
                    dem.runout, dem.height, t_dem, cpu_dem, cpu_prep, n, col.steps))

-- Continuum
local rho_s, d = dem_column.density, 1.5e-3
local mu_s = math.tan(math.rad(20.8))
local mat_o = { density = phi * rho_s, grain_density = rho_s, grain_diameter = d, i0 = 0.279, mu_s = mu_s,
                mu_2 = mu_s + math.tan(math.rad(32.76)) - math.tan(math.rad(20.9)), shear = 2.5e5, bulk = 5e5 }
local bin = W0 / 4
local nb = math.ceil(col.L / bin)
local function binned(xs, hs, h)
  local sum, cnt = {}, {}
  for b = 1, nb do sum[b], cnt[b] = 0, 0 end
  for i = 1, #xs do
    local b = math.floor(xs[i] / bin) + 1
    if b >= 1 and b <= nb then sum[b], cnt[b] = sum[b] + hs[i], cnt[b] + 1 end
  end
  local bx, by = {}, {}
  for b = 1, nb do
    bx[b], by[b] = (b - 0.5) * bin, cnt[b] > 0 and sum[b] / cnt[b] or 0
  end
  return bx, by
end
local runs = {}
for _, model in ipairs({ "drucker_prager", "mu_i" }) do
  local c = mpm_column.new{ material = mpm_column.material(model, mat_o), L0 = W0, H0 = H0, cells = cells, ppc = 2,
                            shape = "bspline", floor_mu = 0.5, length = col.L }
  local r = c:collapse{ t_max = 10, slice = 0.1, rest = 1e-3, stall = 0.005 }
  r.runout, r.height = (r.state.front - W0) / W0, r.state.height / H0
  r.xs, r.hs = c:surface()
  r.bx, r.by = binned(r.xs, r.hs)
  r.tc, r.model = c.tc, model
  runs[#runs + 1] = r
  print(string.format("MPM %-14s runout %.3f W0, height %.3f H0, %s at %.2f s (%.1f t_c), CPU %.1f s, %d points, %d steps",
                      model, r.runout, r.height, r.reason, r.t * c.tc, r.t, r.cpu, r.points, r.steps))
end

-- DEM profile: the top of the highest grain per cell-wide bin, averaged over the bins of W0 / 4
local hcell = W0 / cells
local k = math.ceil(col.L / hcell)
local tops = col:surface(0, hcell, k)
local dxs = {}
for i = 1, k do dxs[i] = (i - 0.5) * hcell end
local dbx, dby = binned(dxs, tops)

-- the time the front takes to 90 % of its final runout
local function t90(ts, fronts, scale)
  local final = fronts[#fronts] - W0
  for i, f in ipairs(fronts) do
    if f - W0 >= 0.9 * final then return ts[i] * scale end
  end
end

-- the surface's slope (degrees) over x in [0, 2 W0]: a least-squares line through the bins there
local function slope(bx, by)
  local n, sx, sy, sxx, sxy = 0, 0, 0, 0, 0
  for i = 1, #bx do
    if bx[i] <= 2 * W0 then
      n, sx, sy, sxx, sxy = n + 1, sx + bx[i], sy + by[i], sxx + bx[i] ^ 2, sxy + bx[i] * by[i]
    end
  end
  return math.deg(math.atan(-(n * sxy - sx * sy) / (n * sxx - sx * sx)))
end

local metrics = { column_width_m = W0, column_height_m = H0, aspect = H0 / W0, area_fraction = phi,
                  mu_s = mu_s, mu_2 = mat_o.mu_2, dp_friction_deg = math.deg(math.asin(mu_s)),
                  runout_over_w0_dem = dem.runout, height_over_h0_dem = dem.height, t_rest_s_dem = t_dem,
                  cpu_s_dem = cpu_dem, cpu_s_dem_preparation = cpu_prep, steps_dem = col.steps, grains = n,
                  surface_slope_deg_dem = slope(dbx, dby), t90_s_dem = t90(dem_t, dem_front, 1) }
local checks = { { name = "dem_at_rest", pass = dem.rest } }
local names = { drucker_prager = "dp", mu_i = "mu_i" }
for _, r in ipairs(runs) do
  local key = names[r.model]
  metrics["runout_over_w0_" .. key] = r.runout
  metrics["height_over_h0_" .. key] = r.height
  metrics["t_end_s_" .. key] = r.t * r.tc
  metrics["cpu_s_" .. key] = r.cpu
  metrics["points_" .. key] = r.points
  metrics["steps_" .. key] = r.steps
  metrics["end_" .. key] = r.reason
  metrics["ke_over_released_" .. key] = r.state.ke / r.state.drop
  metrics["cpu_ratio_dem_over_" .. key] = cpu_dem / r.cpu
  checks[#checks + 1] = { name = "runout_vs_dem_" .. key, value = math.abs(r.runout / dem.runout - 1), limit = 0.35 }
  metrics["height_over_dem_" .. key] = r.height / dem.height
  metrics["surface_slope_deg_" .. key] = slope(r.bx, r.by)
  metrics["t90_s_" .. key] = t90(r.series.t, r.series.front, r.tc)
  checks[#checks + 1] = { name = "at_rest_" .. key, pass = r.reason ~= "cap" }
  checks[#checks + 1] = { name = "cheaper_than_dem_" .. key, value = r.cpu, limit = cpu_dem, op = "<" }
end

-- Figures
local mm = function(v) return v * 1e3 end
local function scaled(xs, f)
  local o = {}
  for i, v in ipairs(xs) do o[i] = f(v) end
  return o
end
local label = { drucker_prager = "Drucker-Prager (MPM)", mu_i = "mu(I) (MPM)" }
local prof = { { x = { 0, mm(W0), mm(W0) }, y = { mm(H0), mm(H0), 0 }, label = "the column at t = 0" },
               { x = scaled(dbx, mm), y = scaled(dby, mm), style = "both", label = "DEM (1500 disks)" } }
for _, r in ipairs(runs) do
  prof[#prof + 1] = { x = scaled(r.bx, mm), y = scaled(r.by, mm), style = "both", label = label[r.model] }
end
render.plot{ file = out .. "_profiles.png", width = 1000, height = 560,
             title = string.format("One column at two scales: final deposits (bins of W0/4; %d cells across W0)", cells),
             xlabel = "x (mm)", ylabel = "height (mm)", series = prof }
local fronts = { { x = dem_t, y = scaled(dem_front, function(f) return mm(f - W0) end), label = "DEM (1500 disks)" } }
for _, r in ipairs(runs) do
  fronts[#fronts + 1] = { x = scaled(r.series.t, function(t) return t * r.tc end),
                          y = scaled(r.series.front, function(f) return mm(f - W0) end), label = label[r.model] }
end
render.plot{ file = out .. "_front.png", width = 1000, height = 560,
             title = "One column at two scales: the front (99th percentile) against time",
             xlabel = "t (s)", ylabel = "runout L(t) - W0 (mm)", series = fronts }

grainlab.report{
  scenario = "column_two_scales",
  params = { cells = cells, n = n, floor_mu = 0.5, grain_diameter = d, grain_density = rho_s,
             shear = mat_o.shear, bulk = mat_o.bulk, i0 = mat_o.i0 },
  metrics = metrics,
  checks = checks,
}
