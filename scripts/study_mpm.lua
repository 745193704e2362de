-- grainlab MPM: speed against accuracy on the incline (Bardenhagen et al. 1998, Fig. 4 case).
--
-- The hardest incline case, th = pi/6, mu = 0.5 (the deformable disk rolls; rigid travel
-- g T^2 sin th / 3, Eq. 25), tilted gravity on the grid's bottom wall, T = 1 s. One knob at a
-- time is swept from the base h = 0.125 R (8 cells per radius), 3 x 3 points per cell, cfl 0.4,
-- linear shape functions:
--   cells per radius 2, 4, 8, 16;  points per cell 1, 2, 3, 4 (per axis);
--   cfl 0.1, 0.2, 0.4, 0.8;        shape functions linear, bspline.
-- Each run reports the relative error of the travel and of the spin against the rigid disk and
-- its CPU time. A second, small measurement shows what B-splines buy against cell-crossing
-- noise: an elastic bar (G = K = 0.1 MPa, 4 m, 10 cells per metre) oscillating axially with a
-- displacement amplitude of 1.7 cells, so points cross cell edges every half period: the
-- spread (max - min) / E0 of the total energy over 4 periods, and the energy kept at the end.
-- Output: a table, out/study_mpm.csv (csv=), images/study_mpm.png (png=): |error| against CPU
-- time, one line per knob (the figure goes to images/ from the default T only, else to out/).
--   grainlab scripts/study_mpm.lua [T=1] [csv=out/study_mpm.csv] [png=images/study_mpm.png]
local csv_path = params.csv or "out/study_mpm.csv"
local T = tonumber(params.T or 1)
-- images/ only from the default study; a shorter run writes to out/ (grainlab.figures).
local figures = require("grainlab.figures")
local png = params.png or figures.path("study_mpm.png", { published = figures.published({ T = T }, { T = 1 }) })
local R, g, th, mu = 0.5, 9.8, math.pi / 6, 0.5
local mat = mpm.material{ density = 3000, shear = 2.5e6, bulk = 10e6 }
local x_rigid = g * T * T * math.sin(th) / 3
local a_rigid = 2 / 3 * g * math.sin(th) / R

local function incline(cpr, ppc, cfl, shape)
  local h = R / cpr
  local Lx, Ly = math.ceil((1.15 * x_rigid + 0.5 + 3 * R) / h) * h, math.ceil(3 * R / h) * h
  local m = mpm.scene{ cells = { math.floor(Lx / h + 0.5), math.floor(Ly / h + 0.5) }, size = { Lx, Ly },
                       gravity = { g * math.sin(th), -g * math.cos(th) }, shape = shape,
                       walls = { bottom = { kind = "friction", mu = mu }, left = "none", right = "none", top = "none" } }
  m:add_disk{ center = { 1.2 * R, R }, radius = R, material = mat, points_per_cell = ppc, hydrostatic = true }
  local c0 = m:grain(1).center
  local t0 = os.clock()
  m:run{ time = T, cfl = cfl }
  local cpu = os.clock() - t0
  local gi = m:grain(1)
  return { err = (gi.center[1] - c0[1] - x_rigid) / x_rigid, spin = (math.abs(gi.omega) / T - a_rigid) / a_rigid,
           cpu = cpu, points = gi.points, steps = m:info().steps }
end

local base = { cpr = 8, ppc = 3, cfl = 0.4, shape = "linear" }
local sweeps = {
  { knob = "cells_per_radius", key = "cpr", values = { 2, 4, 8, 16 } },
  { knob = "points_per_cell", key = "ppc", values = { 1, 2, 3, 4 } },
  { knob = "cfl", key = "cfl", values = { 0.1, 0.2, 0.4, 0.8 } },
  { knob = "shape", key = "shape", values = { "linear", "bspline" } },
}
local lines = { "knob,value,cells_per_radius,points_per_cell,cfl,shape,points,steps,cpu_s,err_travel,err_spin" }
local rows, series, metrics = {}, {}, {}
for _, sw in ipairs(sweeps) do
  local xs, ys = {}, {}
  for _, v in ipairs(sw.values) do
    local c = { cpr = base.cpr, ppc = base.ppc, cfl = base.cfl, shape = base.shape }
    c[sw.key] = v
    local r = incline(c.cpr, c.ppc, c.cfl, c.shape)
    lines[#lines + 1] = string.format("%s,%s,%d,%d,%g,%s,%d,%d,%.4f,%.6f,%.6f", sw.knob, tostring(v), c.cpr, c.ppc,
                                      c.cfl, c.shape, r.points, r.steps, r.cpu, r.err, r.spin)
    rows[#rows + 1] = string.format("%-17s %-8s  %6d points %6d steps  %8.3f s   travel %+7.2f%%   spin %+7.2f%%",
                                    sw.knob, tostring(v), r.points, r.steps, r.cpu, 100 * r.err, 100 * r.spin)
    xs[#xs + 1], ys[#ys + 1] = math.max(r.cpu, 1e-3), math.max(math.abs(r.err), 1e-5)
    metrics[string.format("err_%s_%s", sw.knob, tostring(v):gsub("%.", "p"))] = r.err
    metrics[string.format("cpu_s_%s_%s", sw.knob, tostring(v):gsub("%.", "p"))] = r.cpu
  end
  series[#series + 1] = { x = xs, y = ys, label = sw.knob .. " (" .. table.concat(sw.values, ", ") .. ")", style = "both" }
end

-- cell-crossing noise: the oscillating bar
local function bar(shape)
  local bm = mpm.material{ density = 1000, shear = 1e5, bulk = 1e5 }
  local m = mpm.scene{ cells = { 80, 4 }, size = { 8, 0.4 }, walls = "none", shape = shape }
  m:add_rect{ lo = { 2, 0.1 }, hi = { 6, 0.3 }, material = bm, points_per_cell = 2 }
  local p = m:points()
  local vx = {}
  for i = 1, p.count do vx[i] = 2.0 * math.cos(math.pi * (p.x[i] - 2) / 4) end
  m:set_velocities{ vx = vx, vy = p.vy }
  local e0 = m:measure("energy").total
  local lo, hi = e0, e0
  m:run{ time = 4 * 8 / bm.wave_speed, every = 1, on_step = function(s)
    local e = s:measure("energy").total
    lo, hi = math.min(lo, e), math.max(hi, e)
  end }
  return (hi - lo) / e0, m:measure("energy").total / e0
end
for _, shape in ipairs({ "linear", "bspline" }) do
  local spread, kept = bar(shape)
  metrics["cell_crossing_energy_spread_" .. shape] = spread
  metrics["cell_crossing_energy_kept_" .. shape] = kept
  rows[#rows + 1] = string.format("cell crossing (bar, 1.7-cell amplitude), %-7s: energy spread %.3f of E0, kept %.3f", shape, spread, kept)
end

print(table.concat(rows, "\n"))
if csv_path:find("/") then os.execute("mkdir -p '" .. csv_path:match("^(.*)/[^/]*$") .. "'") end
assert(grainlab.write_file(csv_path, table.concat(lines, "\n") .. "\n"))
render.plot{ file = png, width = 900, height = 600, xlog = true, ylog = true,
             title = "MPM incline (th = pi/6, mu = 0.5): |travel error| against CPU time, one knob at a time",
             xlabel = "CPU time per run (s)", ylabel = "|x(T) / x_rigid(T) - 1|", series = series }
grainlab.report{
  scenario = "study_mpm",
  params = { T = T, base_cells_per_radius = base.cpr, base_points_per_cell = base.ppc, base_cfl = base.cfl,
             base_shape = base.shape, csv = csv_path, png = png },
  metrics = metrics,
  checks = {
    { name = "refinement_converges", pass = math.abs(metrics.err_cells_per_radius_16) < math.abs(metrics.err_cells_per_radius_2) },
    { name = "bspline_reduces_cell_crossing_noise",
      pass = metrics.cell_crossing_energy_spread_bspline < metrics.cell_crossing_energy_spread_linear },
  },
}
