-- Strong scaling of the DEM dense pile over MPI ranks (issue 14, "Measurements to publish"): the
-- DEM section for scripts/bench/scaling.lua (engine=dem there), runnable by itself.
--   grainlab scripts/bench/dem_dense.lua n=20000 export=out/pile20k.data     (prepare once)
--   grainlab scripts/bench/scaling_dem.lua ckpt=out/pile20k.data.ckpt [steps=2000] [warm=200]
--            [threads=1]
--   mpirun -np K grainlab scripts/bench/scaling_dem.lua ckpt=... threads=1
-- The pile of scripts/bench/dem_dense.lua (20,000 polydisperse disks, Hertz + Brilliantov +
-- Cundall-Strack springs, four walls, gravity, dt = 1e-7 s), continued from its checkpoint. `warm`
-- steps decompose it (not timed), then `steps` are timed. Each invocation measures one
-- configuration (K ranks x threads); alternate 1 x 1, 2 x 1 and 1 x 2 and compare
-- particle_steps_per_s. Per step per rank: bytes and messages of the halo and of the rebuilds
-- (s:info().distributed), rebuilds, seconds inside communication (the slowest rank). The final
-- positions' digest is the same bits for any K.
local rank = tonumber(os.getenv("OMPI_COMM_WORLD_RANK") or "0")

local function dem_scaling()
  assert(params.ckpt, "scaling_dem.lua: ckpt=PATH (a checkpoint of scripts/bench/dem_dense.lua's pile)")
  local steps = params.steps or 2000
  local warm = params.warm or 200
  if params.threads then grainlab.threads(params.threads) end
  local s = dem.load(params.ckpt)
  local n = s:info().count
  local dt = 1e-7
  s:run{ steps = warm, dt = dt, progress = false }
  local d0 = s:info().distributed or {}
  local w0 = grainlab.clock()
  s:run{ steps = steps, dt = dt, progress = false }
  local wall = grainlab.clock() - w0
  local info = s:info()
  local d1 = info.distributed or {}
  local K = d1.ranks or 1
  local function per(k) return ((d1[k] or 0) - (d0[k] or 0)) / steps / K end
  local p = s:particles()
  local digest = 0
  for i = 1, n do digest = digest + p.x[i] * i + p.y[i] end
  return {
    params = { engine = "dem", n = n, steps = steps, warm = warm, ranks = K,
               threads = params.threads or "default" },
    metrics = {
      particle_steps_per_s = n * steps / wall,
      wall_s = wall,
      step_ms = 1000 * wall / steps,
      halo_bytes_per_step_per_rank = per("halo_bytes"),
      halo_messages_per_step_per_rank = per("halo_messages"),
      rebuild_bytes_per_step_per_rank = per("rebuild_bytes"),
      rebuild_messages_per_step_per_rank = per("rebuild_messages"),
      comm_bytes_per_step_per_rank = per("halo_bytes") + per("rebuild_bytes"),
      comm_messages_per_step_per_rank = per("halo_messages") + per("rebuild_messages"),
      rebuilds_per_step = ((d1.rebuilds or 0) - (d0.rebuilds or 0)) / steps,
      comm_s_per_step = ((d1.comm_s or 0) - (d0.comm_s or 0)) / steps,
      rebuild_s_per_step = ((d1.rebuild_s or 0) - (d0.rebuild_s or 0)) / steps,
      owned_min = d1.owned_min, owned_max = d1.owned_max,
      digest_bits = string.format("%a", digest),
    },
  }
end

local result = dem_scaling()
if rank == 0 then
  local m = result.metrics
  print(string.format("scaling dem: %d ranks x %s threads: %.4g particle-steps/s (%.2f ms/step), " ..
                      "%.0f bytes and %.2f messages per step per rank (halo %.0f B, rebuilds %.0f B), " ..
                      "%.3f ms/step in comm, %.4f rebuilds/step (%.3f ms/step), owned %s..%s, digest %s",
                      result.params.ranks, tostring(result.params.threads), m.particle_steps_per_s,
                      m.step_ms, m.comm_bytes_per_step_per_rank, m.comm_messages_per_step_per_rank,
                      m.halo_bytes_per_step_per_rank, m.rebuild_bytes_per_step_per_rank,
                      1000 * m.comm_s_per_step, m.rebuilds_per_step, 1000 * m.rebuild_s_per_step,
                      tostring(m.owned_min), tostring(m.owned_max), m.digest_bits))
end
return result
