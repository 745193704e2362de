-- Benchmark: the MPM shear problem of Bardenhagen, Brackbill & Sulsky (1998), Sec. 4.
--   369 HMX grains packed by grainlab.pack.slab (area fraction ~0.82, 74,047 points at 2 x 2 per
--   cell), 150 x 150 cells over 1.2 mm, periodic in y, frictional contact mu = 0.3 (model=noslip:
--   the single centre-of-mass field, no contact), edge grains fixed / moved up at 100 m/s. The
--   time step is fixed so that 80% shear takes 25,124 cycles as in the paper (dt = 9.6 us /
--   25,124 = 3.82e-10 s, Courant number ~0.16).
-- Preparation (not timed): the packing and `warm` cycles (default 200) so that contacts exist.
-- Then `cycles` cycles (default 400) are timed on 1 and then 2 threads (or on `threads` only),
-- each continuing the same run.
--   grainlab scripts/bench/mpm_shear.lua [cycles=400] [warm=200] [threads=N] [model=friction|noslip]
--       [save=prep.ckpt | load=prep.ckpt]   (save the prepared scene / start from it, no packing)
--   valgrind --tool=callgrind --instr-atstart=no grainlab scripts/bench/mpm_shear.lua \
--       load=prep.ckpt cycles=10 callgrind=true
--       counts the instructions of the timed cycles on one thread (callgrind=PATTERN when
--       valgrind was given --callgrind-out-file=PATTERN).
-- Report bench_mpm_shear (bench_mpm_shear_noslip): particle_steps_per_s_<k>_threads (point-steps
-- per second), projected_full_run_s_<k>_threads (25,124 cycles at that rate; the shear band's
-- contacts grow as it develops, so the full run takes longer than this projection from the
-- prepared scene), points, grains, points_per_cell, stage_<name>_ns (wall ns per point-step of
-- each stage of the last thread count's run, from m:timings(), also printed with each stage's
-- share); under callgrind, bench_mpm_shear_callgrind (_noslip_callgrind):
-- instructions_per_point_step.
local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
local cycles = math.tointeger(params.cycles or 400)
local warm = math.tointeger(params.warm or 200)
local model = params.model or "friction"
local callgrind = params.callgrind
local L, v, cells = 1.2e-3, 100, 150
local full_cycles = 25124
local dt = 0.8 * L / v / full_cycles

local t0 = grainlab.clock()
local m, ngrains, area_fraction
if params.load then
  -- A prepared scene saved by save= (checkpoints continue bit for bit): skips the packing, which
  -- dominates a callgrind run.
  m = mpm.load(params.load)
  ngrains, area_fraction = m:info().grains, nil
  -- the loaded scene's contact model, whatever model= says (the report names what ran)
  if params.model and params.model ~= m:info().contact then
    error(string.format("mpm_shear: model=%s, but %s was saved with contact %q",
                        params.model, params.load, m:info().contact), 0)
  end
  model = m:info().contact
else
  local pk = grainlab.pack.slab{ size = L, n = 369, diameter = { 31e-6, 57e-6, 250e-6 }, seed = 5 }
  local hmx = mpm.material{ model = "vonmises", density = 1900, shear = 7.5e9, bulk = 11.4e9, yield = 0.3e9,
                            hardening = 0.01e9 }
  m = mpm.scene{ cells = { cells, cells }, size = { L, L }, periodic = { false, true },
                 walls = { left = "noslip", right = { kind = "noslip", velocity = { 0, v } } } }
  local h = L / cells
  for i = 1, #pk.x do
    local g = m:add_disk{ center = { pk.x[i], pk.y[i] }, radius = pk.r[i], material = hmx, points_per_cell = 2, clip = true }
    if pk.x[i] - pk.r[i] < h then m:prescribe(g, { 0, 0 }) elseif pk.x[i] + pk.r[i] > L - h then m:prescribe(g, { 0, v }) end
  end
  if model == "friction" then m:contact{ model = "friction", mu = 0.3, normals = params.normals } end
  grainlab.threads(params.prep_threads or 1)
  m:run{ steps = warm, dt = dt, progress = false }
  ngrains, area_fraction = #pk.x, pk.area_fraction
  if params.save then m:save(params.save) end
end
local np = m:info().points
local t_prep = grainlab.clock() - t0

local stages, instructions
local function timed(threads)
  grainlab.threads(threads)
  local s0 = m:timings()
  local w0 = grainlab.clock()
  if callgrind then
    instructions = bench.instructions(function() m:run{ steps = cycles, dt = dt, progress = false } end,
                                      callgrind)
  else
    m:run{ steps = cycles, dt = dt, progress = false }
  end
  local wall = grainlab.clock() - w0
  local s1 = m:timings()
  stages = {}
  for k, x in pairs(s1) do stages[k] = x - s0[k] end
  return np * cycles / wall, wall
end

local metrics = { points = np, grains = ngrains, area_fraction = area_fraction, dt_s = dt, cycles = cycles,
                  warm_cycles = warm, prepare_s = t_prep, cells = cells * cells, points_per_cell = 4 }
local list = callgrind and { 1 } or params.threads and { params.threads } or { 1, 2 }
local total = 0
for _, th in ipairs(list) do
  local rate, wall = timed(th)
  metrics["particle_steps_per_s_" .. th .. "_threads"] = rate
  metrics["wall_s_" .. th .. "_threads"] = wall
  metrics["projected_full_run_s_" .. th .. "_threads"] = wall / cycles * full_cycles
  total = total + wall
end
local last = list[#list]
metrics.particle_steps_per_s = metrics["particle_steps_per_s_" .. last .. "_threads"]
metrics.projected_full_run_s = metrics["projected_full_run_s_" .. last .. "_threads"]
metrics.wall_s = total
local names = { "stencil", "p2g", "normals", "grid", "contact", "g2p", "remap", "material", "check" }
print(string.format("stages (%d thread(s), %d cycles): wall ns per point-step, share", last, cycles))
for _, k in ipairs(names) do
  local ns = stages[k] / (np * cycles) * 1e9
  metrics["stage_" .. k .. "_ns"] = ns
  print(string.format("  %-9s %8.1f  %5.1f %%", k, ns, 100 * stages[k] / stages.total))
end
local e = m:measure("energy")
local checks = { { name = "finite_energy", pass = e.total == e.total and e.total < math.huge } }
if callgrind then
  metrics.instructions_per_point_step = instructions and instructions / (np * cycles) or 0
  checks[#checks + 1] = { name = "instructions_counted", pass = instructions ~= nil }
end
grainlab.report{
  scenario = "bench_mpm_shear" .. (model == "noslip" and "_noslip" or "") .. (callgrind and "_callgrind" or ""),
  params = { cycles = cycles, warm = warm, threads = callgrind and 1 or params.threads or "1,2",
             model = model, cells = cells, load = params.load },
  metrics = bench.metrics(metrics),
  checks = checks,
}
