-- Strong scaling over MPI ranks and OpenMP threads (issue 14, "Measurements to publish").
--   grainlab scripts/bench/scaling.lua engine=dsmc [n=500000] [steps=30] [warm=5] [threads=1]
--   mpirun -np K grainlab scripts/bench/scaling.lua engine=dsmc threads=1 ...
-- Each invocation measures one configuration (K ranks x threads); run it for 1 rank x 1 thread,
-- 2 ranks x 1 thread and 1 rank x 2 threads, alternating, and compare particle_steps_per_s.
-- (Under mpirun only rank 0's output appears: docs/mpi.md.)
local engine = params.engine or "dsmc"

-- ---- DSMC: Herrmann Fig. 2's gas -------------------------------------------------------------
-- N = 500,000 disks in 2D at volume fraction nu = 0.1 (R = 1 mm, quartz), e = 0.9, periodic
-- square, Maxwellian at T/m = 1 m^2/s^2; cells one mean free path wide (as
-- scripts/bench/largest.lua: lambda = 1 / (2 sqrt2 n_A 2R chi), Henderson's chi); dt a tenth of
-- the mean collision time. `warm` steps (not timed) decompose the gas and settle the layout,
-- then `steps` are timed. Metrics: particle_steps_per_s (wall), and per step per rank the bytes
-- and messages the ranks sent (core/comm.h counters) and the seconds inside communication.
local function dsmc_scaling()
  local n = math.floor(params.n or 500000)
  local steps = params.steps or 30
  local warm = params.warm or 5
  local nu, R = 0.1, 1e-3
  local L = math.sqrt(n * math.pi * R * R / nu)
  local chi = (1 - 7 / 16 * nu) / (1 - nu) ^ 2
  local lambda = 1 / (2 * math.sqrt(2) * (n / (L * L)) * 2 * R * chi)
  local nc = math.ceil(L / lambda)
  if params.threads then grainlab.threads(params.threads) end
  local s = dsmc.scene{ dim = 2, size = { L, L }, cells = { nc, nc }, radius = R, restitution = 0.9,
                        seed = 3 }
  s:fill{ n = n, temperature = s:info().mass * 1.0, seed = 5 }
  local dt = 0.1 / s:measure("temperature").collision_frequency
  s:run{ steps = warm, dt = dt, progress = false, warn = false }
  s:reset_stats()
  local w0 = grainlab.clock()
  s:run{ steps = steps, dt = dt, progress = false, warn = false }
  local wall = grainlab.clock() - w0
  local st = s:measure("stats")
  local T = s:measure("temperature").temperature -- a digest: the same bits on any rank count
  local info = s:info()
  return {
    params = { engine = "dsmc", n = n, steps = steps, warm = warm, cells = nc * nc, packing = nu,
               ranks = st.ranks, threads = params.threads or "default" },
    metrics = {
      particle_steps_per_s = n * steps / wall,
      wall_s = wall,
      step_ms = 1000 * wall / steps,
      comm_bytes_per_step_per_rank = st.comm_bytes_per_step_per_rank,
      comm_messages_per_step_per_rank = st.comm_messages_per_step_per_rank,
      comm_s_per_step = st.comm_s / steps,
      imbalance = st.imbalance,
      collisions_per_particle_per_step = st.collisions_per_particle_per_step,
      bytes_per_particle_this_rank = info.particle_bytes / n * st.ranks,
      temperature_bits = string.format("%a", T),
    },
  }
end

local result
if engine == "dsmc" then
  result = dsmc_scaling()
else
  error("scaling.lua: engine must be 'dsmc' (the DEM part is another section), got " ..
        tostring(engine))
end

do
  local m = result.metrics
  print(string.format("scaling %s: %d ranks x %s threads: %.4g particle-steps/s (%.2f ms/step), " ..
                      "%.0f bytes and %.1f messages per step per rank, %.3f ms/step in comm, " ..
                      "imbalance %.4f, T %s",
                      result.params.engine, result.params.ranks, tostring(result.params.threads),
                      m.particle_steps_per_s, m.step_ms, m.comm_bytes_per_step_per_rank,
                      m.comm_messages_per_step_per_rank, 1000 * m.comm_s_per_step,
                      m.imbalance, m.temperature_bits))
end
