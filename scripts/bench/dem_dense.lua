-- Benchmark: DEM steps of a dense, settled pile of polydisperse disks.
--   n disks (default 20,000), r uniform in [0.5, 1] mm, rho = 2650 kg/m^3, E = 30 GPa, nu = 0.3,
--   restitution 0.5 (Brilliantov damping time solved per pair for e at 1 m/s), mu = 0.45, closed
--   0.25 m x 0.30 m box, gravity, Hertz + Brilliantov + Cundall-Strack history, dt = 1e-7 s.
-- Preparation (not timed): Jodrey-Tory style deposition (grainlab.pack.deposit, every disk resting
-- on two supports at zero overlap), then grainlab.pack.settle at full stiffness: a background drag
-- critical for the pile's slowest (whole-pile vertical) mode and a quasi-static dt, until the rms
-- speed is below `quiet` m/s (or only a few creeping grains are left); then 2000 steps at the
-- benchmark's dt without drag, which must not change the contacts. Then `steps` steps are timed
-- without drag, on 1 and then 2 threads (or on `threads` only), continuing the same run.
-- The drag holds the ~1% of grains that sit in frictionally unstable spots of the geometric
-- packing at a creep (~1e-3 m/s); without drag they fail, in small cascades, over ~0.3 s. That
-- leaves the contacts alone over the timed steps (20,000 disks: z changes by ~4e-4 relative), but
-- `collapse` = t lets them fail first (pack.settle's collapse option: weak drag, at most t s of
-- simulated time) for a truly static pile (v_max ~1e-4 m/s): ~0.1 min for 2,000 disks (the
-- default up to 5,000), ~6 min on 1 thread for 20,000.
-- The preparation runs on prep_threads threads (default 1).
--   grainlab scripts/bench/dem_dense.lua [n=20000] [steps=20000] [threads=N] [quiet=1e-5]
--                                        [collapse=0|0.5] [prep_threads=1] [verbose=1]
--   grainlab scripts/bench/dem_dense.lua n=20000 export=out/pile.data
--       prepares the pile and stops before timing; writes it as a LAMMPS data file (atom type 1 =
--       quartz, velocities included) and as a grainlab checkpoint PATH.ckpt (the same state with
--       its walls: a settled pile touches its walls, which add_wall would refuse on a re-read).
--       vs_lammps.sh and scaling.lua run that same pile.
--   grainlab scripts/bench/dem_dense.lua pile=out/pile.data.ckpt [steps=...]
--       times the exported pile as it is (no preparation; the checkpoint keeps the pile's laws
--       and spring histories).
--   valgrind --tool=callgrind --instr-atstart=no grainlab scripts/bench/dem_dense.lua \
--       pile=out/pile.data.ckpt steps=50 callgrind=true
--       counts the instructions of the timed steps on one thread (callgrind=PATTERN when valgrind
--       was given --callgrind-out-file=PATTERN).
-- Report bench_dem_dense: particle_steps_per_s_<k>_threads, wall_s_<k>_threads,
-- contacts_per_particle (before the timed steps) and contacts_per_particle_after; under
-- callgrind, bench_dem_dense_callgrind: instructions_per_particle_step.
local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
local n = params.n or 20000
local steps = params.steps or 20000
local quiet = params.quiet or 1e-5
local collapse = params.collapse or (n <= 5000 and 0.5 or 0)
local W, H = 0.25, 0.30
local dt = 1e-7
local check_steps = 2000 -- drag-free steps at dt after settling that must leave the contacts alone

local quartz = grainlab.material{ name = "quartz", density = 2650, young = 30e9, poisson = 0.3,
                                  friction = 0.45, restitution = 0.5 }
local s, T, t_prep, settle, z
if params.pile then -- a pile prepared by export= (its checkpoint), timed as it is
  s = dem.load(params.pile)
  n = s:particles().count
  T = s:damping_time(1, 2)
  z = s:measure("coordination")
  t_prep = 0
  local p, v2, vmax = s:particles(), 0, 0
  for i = 1, n do
    local q = p.vx[i] ^ 2 + p.vy[i] ^ 2
    v2, vmax = v2 + q, math.max(vmax, q)
  end
  settle = { steps = 0, dt = dt, drag = 0, v_rms = math.sqrt(v2 / n), v_max = math.sqrt(vmax),
             z_settled = z.z }
else
  s = dem.scene{ dim = 2, box = {{0, 0}, {W, H}}, gravity = {0, -9.81} }
  s:add_wall{ point = {0, 0}, normal = {0, 1} }
  s:add_wall{ point = {0, 0}, normal = {1, 0} }
  s:add_wall{ point = {W, 0}, normal = {-1, 0} }
  s:add_wall{ point = {0, H}, normal = {0, -1} }
  local t0 = grainlab.clock()
  grainlab.pack.deposit(s, { n = n, seed = 1, material = quartz, relax_steps = 0 })
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
            tangential = "spring" }
  T = s:damping_time(1, 2) -- each pair has its own T; this is the first pair's
  local t_deposit = grainlab.clock() - t0

  grainlab.threads(params.prep_threads or 1)
  settle = grainlab.pack.settle(s, { quiet = quiet, collapse = collapse, final_steps = check_steps,
                                     dt_final = dt, verbose = params.verbose and true or false })
  z = s:measure("coordination")
  t_prep = grainlab.clock() - t0
  io.stderr:write(string.format(
    "prepared %d disks in %.1f s (deposit %.1f s, %d relaxation steps at dt %.3g s, drag %.4g /s): " ..
    "v_rms %.2g m/s (v_max %.2g), z %.4f; after %d drag-free steps at dt %g: v_rms %.2g m/s, z %.4f\n",
    n, t_prep, t_deposit, settle.steps - check_steps, settle.dt, settle.drag, settle.v_rms_settled,
    settle.v_max_settled, settle.z_settled, check_steps, dt, settle.v_rms, z.z))
end

if params.export and not params.pile then
  s:write_lammps_data(params.export, { types = { [1] = quartz },
                                       title = string.format("dem_dense.lua n=%d, settled", n) })
  s:save(params.export .. ".ckpt")
  io.stderr:write(string.format("wrote %s (%d disks, z %.4f, damping time of pair 1-2 %.4g s)\n",
                                params.export, n, z.z, T))
  return
end

-- Under callgrind, collection is on for the timed steps alone, so the count divided by
-- n * steps is the instructions per particle-step (which a busy machine does not move).
local callgrind = params.callgrind
local instructions
local function timed(threads)
  grainlab.threads(threads)
  local c0, w0 = grainlab.cpu_clock(), grainlab.clock()
  if callgrind then
    instructions = bench.instructions(function() s:run{ steps = steps, dt = dt, progress = false } end,
                                      callgrind)
  else
    s:run{ steps = steps, dt = dt, progress = false }
  end
  local wall = grainlab.clock() - w0
  return n * steps / wall, wall, grainlab.cpu_clock() - c0
end

local metrics = { dt_s = dt, disks = n, steps = steps, damping_time_s = T,
                  contacts_per_particle = z.z, contacts_per_particle_no_rattlers = z.z_no_rattlers,
                  prepare_s = t_prep, relaxation_steps = settle.steps, relaxation_dt_s = settle.dt,
                  relaxation_drag_per_s = settle.drag, v_rms_prepared = settle.v_rms,
                  v_max_prepared = settle.v_max }
local list = callgrind and { 1 } or params.threads and { params.threads } or { 1, 2 }
local total_wall = 0
for _, th in ipairs(list) do
  local rate, wall = timed(th)
  metrics["particle_steps_per_s_" .. th .. "_threads"] = rate
  metrics["wall_s_" .. th .. "_threads"] = wall
  total_wall = total_wall + wall
end
metrics.particle_steps_per_s = metrics["particle_steps_per_s_" .. list[#list] .. "_threads"]
metrics.wall_s = total_wall
local zf = s:measure("coordination")
metrics.contacts_per_particle_after = zf.z
local checks = {
  -- The timed pile must be the quiescent one: a bouncing pile has fewer contacts, runs faster.
  { name = "pile_quiescent_contacts", value = z.z, limit = 3.3, op = ">=" },
  { name = "pile_quiescent_speed", value = settle.v_rms, limit = 1e-4 },
  -- Drag off: the first drag-free steps and the timed steps leave the contacts alone.
  { name = "pile_settled_contacts_rel", value = math.abs(z.z - settle.z_settled) / settle.z_settled, limit = 0.002 },
  { name = "pile_stayed_settled_rel", value = math.abs(zf.z - z.z) / z.z, limit = 0.002 },
}
if callgrind then
  metrics.instructions_per_particle_step = instructions and instructions / (n * steps) or 0
  checks[#checks + 1] = { name = "instructions_counted", pass = instructions ~= nil }
end

grainlab.report{
  scenario = callgrind and "bench_dem_dense_callgrind" or "bench_dem_dense",
  params = { n = n, steps = steps, dt = dt, threads = callgrind and 1 or params.threads or "1,2",
             quiet = quiet, collapse_s = collapse, pile = params.pile },
  metrics = bench.metrics(metrics),
  checks = checks,
}
