-- Benchmark: homogeneous cooling of a granular gas of disks in 2D by DSMC.
--   n disks (default 10^6), R = 1 mm, quartz density, e = 0.9, packing nu = 0.003 in a periodic
--   square, about 20 particles per cell (cell side 0.84 mean free paths), Maxwellian at
--   T/m = 1 m^2/s^2, dt = 0.1 / omega (a tenth of the mean collision time, so ~0.05 accepted
--   collisions per particle per step).
-- Preparation (not timed): fill, then `warm` steps so the gas is mixed and the sort order settled.
-- Then `steps` steps are timed on 1 and then 2 threads (or on `threads` only); the same seed gives
-- the same state on any thread count, so each count times its own copy of the same run.
--   grainlab scripts/bench/dsmc_cooling.lua [n=1000000] [steps=50] [threads=N] [warm=10]
--   valgrind --tool=callgrind --instr-atstart=no grainlab scripts/bench/dsmc_cooling.lua \
--       n=100000 steps=20 callgrind=true
--       counts the instructions of the timed steps on one thread (callgrind=PATTERN when valgrind
--       was given --callgrind-out-file=PATTERN).
-- Report bench_dsmc_cooling: particle_steps_per_s_<k>_threads, wall_s_<k>_threads,
-- collisions_per_particle_per_step, particles_per_cell, bytes_per_particle (particle arrays:
-- position, velocity, cell index, identity) and with the per-cell arrays, SPARTA's
-- particle_moves_per_cpu_s; under callgrind, bench_dsmc_cooling_callgrind:
-- instructions_per_particle_step.
local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
local n = params.n or 1000000
local steps = params.steps or 50
local warm = params.warm or 10
local nu, R, per_cell = 0.003, 1e-3, 20
local L = math.sqrt(n * math.pi * R * R / nu)
local nc = math.floor(math.sqrt(n / per_cell))
local callgrind = params.callgrind

local function make()
  local s = dsmc.scene{ dim = 2, size = { L, L }, cells = { nc, nc }, radius = R, restitution = 0.9,
                        seed = 3 }
  local m = s:info().mass
  s:fill{ n = n, temperature = m * 1.0, seed = 5 }
  return s
end

local list = callgrind and { 1 } or params.threads and { params.threads } or { 1, 2 }
local metrics = { particles = n, steps = steps, cells = nc * nc, particles_per_cell = n / (nc * nc) }
local instructions
local total_wall = 0
for _, th in ipairs(list) do
  grainlab.threads(th)
  local s = make()
  local dt = 0.1 / s:measure("temperature").collision_frequency
  s:run{ steps = warm, dt = dt, progress = false }
  s:reset_stats()
  local w0 = grainlab.clock()
  if callgrind then
    instructions = bench.instructions(function() s:run{ steps = steps, dt = dt, progress = false } end,
                                      callgrind)
  else
    s:run{ steps = steps, dt = dt, progress = false }
  end
  local wall = grainlab.clock() - w0
  local st = s:measure("stats")
  metrics["particle_steps_per_s_" .. th .. "_threads"] = n * steps / wall
  metrics["wall_s_" .. th .. "_threads"] = wall
  metrics["particle_moves_per_cpu_s_" .. th .. "_threads"] = st.particle_moves_per_cpu_s
  metrics.collisions_per_particle_per_step = st.collisions_per_particle_per_step
  metrics.attempts_per_particle_per_step = st.attempts_per_particle_per_step
  local info = s:info()
  metrics.bytes_per_particle = info.particle_bytes / n
  metrics.bytes_per_particle_with_cells = (info.particle_bytes + info.cell_bytes) / n
  total_wall = total_wall + wall
  s = nil
  collectgarbage()
end
metrics.particle_steps_per_s = metrics["particle_steps_per_s_" .. list[#list] .. "_threads"]
metrics.wall_s = total_wall

local checks = {
  -- memory per particle: position and velocity (4 doubles), a 4-byte cell index and a 4-byte
  -- identity (it orders each cell, so results do not depend on the number of MPI ranks)
  { name = "bytes_per_particle", value = metrics.bytes_per_particle, limit = 4 * 8 + 4 + 4 },
}
if callgrind then
  metrics.instructions_per_particle_step = instructions and instructions / (n * steps) or 0
  checks[#checks + 1] = { name = "instructions_counted", pass = instructions ~= nil }
end
grainlab.report{
  scenario = callgrind and "bench_dsmc_cooling_callgrind" or "bench_dsmc_cooling",
  params = { n = n, steps = steps, threads = callgrind and 1 or params.threads or "1,2", packing = nu,
             particles_per_cell = per_cell },
  metrics = bench.metrics(metrics),
  checks = checks,
}
