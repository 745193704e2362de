-- Benchmark: a granular column collapsing as a continuum in MPM, and the whole collapse of the
-- DEM demo's column against its continuum twin.
--   Throughput: the column of scripts/column_collapse.lua (glass beads, half column L0 = 5 cm
--   against a slip wall, friction floor, B-splines; scripts/lib/mpm_column.lua) at aspect 2
--   with `cells` cells across L0 and 2 x 2 points per cell: cells=160 gives 204,800 points,
--   cells=360 1,036,800, as `strips` grains side by side (default 8: the step's threads split
--   the points by grains, so a column of one grain runs on one thread; with the noslip contact
--   the strips are one continuum). The collapse runs `warm` steps (default 200: the column is
--   moving and its material yielding), then `steps` steps (default 200) are timed on 1 and then
--   2 threads (or on `threads` only), each continuing the same run, at the automatic time step.
--   Whole collapse (whole=false skips it): the column of scripts/demo.lua, 1500 disks in DEM
--   (scripts/lib/dem_column.lua), from the gate's removal to rest, and the same column as the
--   same continuum at the resolution of scripts/column_two_scales.lua (10 cells across W0) until
--   its front stops, both on one thread: wall time, steps, particle- or point-steps.
--   grainlab scripts/bench/continuum.lua [cells=160] [strips=8] [model=mu_i|drucker_prager]
--       [warm=200] [steps=200] [threads=N] [whole=false] [scenario=bench_mpm_continuum_large]
-- Report bench_mpm_continuum (or the name given as scenario=, so that two sizes are two
-- reports): points, cells, particle_steps_per_s_<k>_threads (point-steps per second),
-- wall_s_<k>_threads, stage_<name>_ns and stage_total_ns (wall ns per point-step of each
-- stage and of the whole step in the last thread count's run, from m:timings()); with the
-- whole collapse, whole_dem_wall_s, whole_dem_steps, whole_dem_particle_steps_per_s,
-- whole_mpm_wall_s, whole_mpm_steps, whole_mpm_points, whole_mpm_point_steps_per_s, whole_dem_over_mpm (the wall-time ratio).
local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
local here = (arg[0]:match("^(.*)/") or ".") .. "/.."
local mpm_column = dofile(here .. "/lib/mpm_column.lua")
local cells = math.tointeger(tonumber(params.cells or 160))
local model = params.model or "mu_i"
local warm = math.tointeger(tonumber(params.warm or 200))
local steps = math.tointeger(tonumber(params.steps or 200))
local whole = params.whole ~= false
local strips = math.tointeger(tonumber(params.strips or 8))
local scenario = params.scenario or "bench_mpm_continuum"
assert(cells and cells >= 2, "cells must be an integer >= 2")
assert(model == "mu_i" or model == "drucker_prager", "model must be mu_i or drucker_prager")
assert(scenario:match("^bench_mpm_continuum[%w_]*$"), "scenario must be bench_mpm_continuum[_suffix]")
assert(warm and warm >= 0 and steps and steps >= 1, "warm >= 0 and steps >= 1 must be integers")

local L0, a = 0.05, 2
local beads = { density = 0.6 * 2450, grain_density = 2450, grain_diameter = 5e-4, i0 = 0.279,
                mu_s = math.tan(math.rad(20.9)), mu_2 = math.tan(math.rad(32.76)), shear = 1e6, bulk = 2e6 }
local t0 = grainlab.clock()
grainlab.threads(params.prep_threads or 1)
local c = mpm_column.new{ material = mpm_column.material(model, beads), L0 = L0, H0 = a * L0, cells = cells, ppc = 2,
                          shape = "bspline", floor_mu = 0.6, length = L0 * (2 + 3.2 * a ^ 0.85),
                          strips = strips }
local m = c.m
m:run{ steps = warm, progress = false }
local np = m:info().points
local t_prep = grainlab.clock() - t0

local stages
local function timed(threads)
  grainlab.threads(threads)
  local s0 = m:timings()
  local w0 = grainlab.clock()
  m:run{ steps = steps, progress = false }
  local wall = grainlab.clock() - w0
  local s1 = m:timings()
  stages = {}
  for k, x in pairs(s1) do stages[k] = x - s0[k] end
  return np * steps / wall, wall
end

local metrics = { points = np, cells = c.nx * c.ny, cells_across_l0 = cells, strips = strips, points_per_cell = 4,
                  warm_steps = warm,
                  steps = steps, prepare_s = t_prep, model = model }
local list = params.threads and { params.threads } or { 1, 2 }
for _, th in ipairs(list) do
  local rate, wall = timed(th)
  metrics["particle_steps_per_s_" .. th .. "_threads"] = rate
  metrics["wall_s_" .. th .. "_threads"] = wall
  print(string.format("%d thread(s): %d points x %d steps in %.2f s: %.3g point-steps/s", th, np, steps, wall, rate))
end
local last = list[#list]
metrics.particle_steps_per_s = metrics["particle_steps_per_s_" .. last .. "_threads"]
local names = { "stencil", "p2g", "normals", "grid", "contact", "g2p", "remap", "material", "check" }
print(string.format("stages (%d thread(s), %d steps): wall ns per point-step, share", last, steps))
for _, k in ipairs(names) do
  local ns = stages[k] / (np * steps) * 1e9
  metrics["stage_" .. k .. "_ns"] = ns
  print(string.format("  %-9s %8.1f  %5.1f %%", k, ns, 100 * stages[k] / stages.total))
end
metrics.stage_total_ns = stages.total / (np * steps) * 1e9
local e = m:measure("energy")
local checks = { { name = "finite_energy", pass = e.total == e.total and e.total < math.huge } }

if whole then
  grainlab.threads(1)
  local dem_column = dofile(here .. "/lib/dem_column.lua")
  local col = dem_column.new{ n = 1500, seed = 1, aspect = 2, young = 5e6, mu = 0.5 }
  local st0 = col:prepare()
  col:release()
  local w0 = grainlab.clock()
  col:collapse()
  local dem_wall = grainlab.clock() - w0
  local W0, H0 = col.W0, st0.height
  local area = 0
  local P = col.s:particles()
  for i = col.nf + 1, col.nf + 1500 do area = area + math.pi * P.radius[i] ^ 2 end
  local rho_s, mu_s = dem_column.density, math.tan(math.rad(20.8))
  local twin = mpm_column.new{ material = mpm_column.material(model, {
                                 density = area / (W0 * H0) * rho_s, grain_density = rho_s, grain_diameter = 1.5e-3,
                                 i0 = 0.279, mu_s = mu_s, mu_2 = mu_s + beads.mu_2 - beads.mu_s,
                                 shear = 2.5e5, bulk = 5e5 }),
                               L0 = W0, H0 = H0, cells = 10, ppc = 2, shape = "bspline", floor_mu = 0.5,
                               length = col.L }
  w0 = grainlab.clock()
  local r = twin:collapse{ t_max = 10, slice = 0.1, rest = 1e-3, stall = 0.005 }
  local mpm_wall = grainlab.clock() - w0
  metrics.whole_dem_wall_s = dem_wall
  metrics.whole_dem_steps = col.steps
  metrics.whole_dem_particle_steps_per_s = 1500 * col.steps / col.run_wall
  metrics.whole_mpm_wall_s = mpm_wall
  metrics.whole_mpm_steps = r.steps
  metrics.whole_mpm_points = r.points
  metrics.whole_mpm_point_steps_per_s = r.points * r.steps / mpm_wall
  metrics.whole_dem_over_mpm = dem_wall / mpm_wall
  print(string.format("whole collapse, 1 thread: DEM %d disks %.1f s (%d steps), MPM %s %d points %.2f s (%d steps): DEM / MPM = %.1f",
                      1500, dem_wall, col.steps, model, r.points, mpm_wall, r.steps, dem_wall / mpm_wall))
  checks[#checks + 1] = { name = "whole_mpm_front_at_rest", pass = r.reason ~= "cap" }
end

grainlab.report{
  scenario = scenario,
  params = { cells = cells, strips = strips, model = model, warm = warm, steps = steps, threads = params.threads or "1,2",
             whole = whole },
  metrics = bench.metrics(metrics),
  checks = checks,
}
