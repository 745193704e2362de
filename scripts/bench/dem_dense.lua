-- Benchmark: a dense, settled pile of 20,000 polydisperse disks (issue 3, "Performance").
--   r uniform in [0.5, 1] mm, rho = 2650 kg/m^3, E = 30 GPa, nu = 0.3, restitution 0.5 (Brilliantov
--   damping time solved for the mean pair at 1 m/s), mu = 0.45, closed 0.25 m x 0.30 m box, gravity,
--   Hertz + Brilliantov + Cundall-Strack history, dt = 1e-7 s.
-- Preparation (not timed): Jodrey-Tory style deposition (grainlab.pack.deposit), then relaxation
-- with a background drag until the pile is quiescent (fastest disk below `quiet` m/s). Then
-- `steps` steps are timed without drag, on 1 and 2 threads (or on `threads` only).
--   grainlab scripts/bench/dem_dense.lua [n=20000] [steps=20000] [threads=N] [quiet=1e-3]
-- Metrics: particle_steps_per_s (per thread count), wall_s, contacts_per_particle.
local n = params.n or 20000
local steps = params.steps or 20000
local quiet = params.quiet or 1e-3
local W, H = 0.25, 0.30
local dt = 1e-7

local s = dem.scene{ dim = 2, box = {{0, 0}, {W, H}}, gravity = {0, -9.81} }
local quartz = grainlab.material{ name = "quartz", density = 2650, young = 30e9, poisson = 0.3,
                                  friction = 0.45, restitution = 0.5 }
s:add_wall{ point = {0, 0}, normal = {0, 1} }
s:add_wall{ point = {0, 0}, normal = {1, 0} }
s:add_wall{ point = {W, 0}, normal = {-1, 0} }
s:add_wall{ point = {0, H}, normal = {0, -1} }
local t0 = grainlab.clock()
grainlab.pack.deposit(s, { n = n, seed = 1, material = quartz, relax_steps = 1 })
local T = s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
                     tangential = "spring" }
local t_deposit = grainlab.clock() - t0

-- Relax (a damped stiffness ramp): soften the contacts 1000x so steps can be ~16x longer, settle
-- with a mild drag until the rms speed is below `quiet`, then restore the stiffness a decade at a
-- time, and finally let the pile find its own rest without drag at the benchmark's dt.
local function speeds()
  local P, m, s2 = s:particles(), 0, 0
  for i = 1, P.count do
    local v2 = P.vx[i] ^ 2 + P.vy[i] ^ 2
    m, s2 = math.max(m, v2), s2 + v2
  end
  return math.sqrt(m), math.sqrt(s2 / P.count)
end
local relax_steps = 0
local function settle(min_steps, max_steps, label)
  local done, vmax, vrms = 0, speeds()
  while (vrms > quiet or done < min_steps) and done < max_steps do
    local r = s:run{ steps = 2000, progress = false }
    done = done + r.steps
    vmax, vrms = speeds()
    if params.verbose then
      io.stderr:write(string.format("%s: %d steps (dt %.3g s): v_max %.3g, v_rms %.3g m/s\n", label, done, r.dt, vmax, vrms))
    end
  end
  relax_steps = relax_steps + done
end
s:scale_stiffness(1e-3)
s:drag(params.drag or 20)
settle(20000, 200000, "soft")
for k = 1, 3 do
  s:scale_stiffness(10)
  settle(4000, 40000, "ramp " .. k)
end
s:drag(0)
s:run{ steps = 5000, dt = dt, progress = false }
relax_steps = relax_steps + 5000
local function vmax() return (speeds()) end
local z = s:measure("coordination")
local t_prep = grainlab.clock() - t0
io.stderr:write(string.format("prepared %d disks in %.1f s (deposit %.1f s, %d relaxation steps, v_max %.2g m/s, z %.3f)\n",
                              n, t_prep, t_deposit, relax_steps, vmax(), z.z))

local function timed(threads)
  grainlab.threads(threads)
  local c0, w0 = grainlab.cpu_clock(), grainlab.clock()
  s:run{ steps = steps, dt = dt, progress = false }
  local wall = grainlab.clock() - w0
  return n * steps / wall, wall, grainlab.cpu_clock() - c0
end

local metrics = { dt_s = dt, disks = n, steps = steps, damping_time_s = T,
                  contacts_per_particle = z.z, contacts_per_particle_no_rattlers = z.z_no_rattlers,
                  prepare_s = t_prep, relaxation_steps = relax_steps }
local list = params.threads and { params.threads } or { 1, 2 }
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

grainlab.report{
  scenario = "bench_dem_dense",
  params = { n = n, steps = steps, dt = dt, threads = params.threads or "1,2" },
  metrics = metrics,
  checks = {
    -- The timed pile must be the quiescent one: a bouncing pile has fewer contacts, runs faster.
    { name = "pile_quiescent_contacts", value = z.z, limit = 2.5, op = ">=" },
    { name = "pile_stayed_settled", value = math.abs(zf.z - z.z), limit = 0.1 },
  },
}
