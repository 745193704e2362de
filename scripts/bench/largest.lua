-- The largest runs one machine holds: how much memory each particle costs at scale, and the rate
-- at that size.
--   grainlab scripts/bench/largest.lua engine=dsmc [n=2e8] [steps=4]
--       Herrmann & Mueller's Fig. 2 gas (fig2_gas.lua): 2D, volume fraction nu = 0.1, e = 0.9,
--       cells one mean free path wide (0.76 particles per cell), Maxwellian at T/m = 1 m^2/s^2,
--       periodic square, dt = a tenth of the mean collision time.
--   grainlab scripts/bench/largest.lua engine=dem [n=5e6] [steps=200]
--       n disks of r = 1 mm, quartz, Hertz + Brilliantov + Cundall-Strack springs (the benchmark
--       pile's laws), on a square lattice whose pitch is 0.2 um less than a diameter (each disk
--       presses on its four neighbours with 2e-4 r of overlap: 4 contacts per particle), random
--       velocities of 0.01 m/s, periodic on both axes, no gravity.
-- Add mpirun -np K in front for a distributed run (then memory is per rank; the figures printed
-- are rank 0's resident set and the whole run's rate).
-- Report largest_<engine>: particles, bytes_per_particle (the peak resident set of the process
-- less its size before the particles were made, divided by n), peak_resident_gib,
-- particle_steps_per_s, wall_s, build_s, and the load: contacts_per_particle (dem) or
-- particles_per_cell and collisions_per_particle_per_step (dsmc).
local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
local engine = params.engine or "dsmc"
local steps = params.steps
local n

local function rss_kib(field) -- VmRSS or VmHWM of this process, KiB (Linux /proc)
  local f = io.open("/proc/self/status", "r")
  if not f then return 0 end
  local txt = f:read("a")
  f:close()
  return tonumber(txt:match(field .. ":%s*(%d+)")) or 0
end

local base = rss_kib("VmRSS")
local t0 = grainlab.clock()
local s, run_def, extra
if engine == "dsmc" then
  n = math.floor(params.n or 2e8)
  steps = steps or 4
  local fig2_gas = dofile((arg[0]:match("^(.*)/") or ".") .. "/fig2_gas.lua")
  local nc
  s, nc = fig2_gas(n)
  run_def = { steps = steps, dt = 0.1 / s:measure("temperature").collision_frequency, progress = false }
  extra = function(metrics)
    local st = s:measure("stats")
    metrics.particles_per_cell = n / (nc * nc)
    metrics.collisions_per_particle_per_step = st.collisions_per_particle_per_step
    return string.format("%.2f particles per cell, collisions per particle per step %.4f", n / (nc * nc),
                         st.collisions_per_particle_per_step)
  end
elseif engine == "dem" then
  n = math.floor(params.n or 5e6)
  steps = steps or 200
  local pitch = 2e-3 - 2e-7
  local side = math.ceil(math.sqrt(n))
  local L = side * pitch
  s = dem.scene{ dim = 2, box = { { 0, 0 }, { L, L } }, periodic = { true, true } }
  local quartz = grainlab.material{ name = "quartz", density = 2650, young = 30e9, poisson = 0.3,
                                    friction = 0.45, restitution = 0.5 }
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
             tangential = "spring" }
  local seed = 12345
  local function uniform() -- a small LCG: the same disks on every machine and rank
    seed = (seed * 1103515245 + 12345) % 2147483648
    return seed / 2147483648
  end
  local k = 0
  for iy = 0, side - 1 do
    for ix = 0, side - 1 do
      if k == n then break end
      k = k + 1
      local a = 2 * math.pi * uniform()
      s:add_disk{ pos = { (ix + 0.5) * pitch, (iy + 0.5) * pitch }, radius = 1e-3,
                  material = quartz, vel = { 0.01 * math.cos(a), 0.01 * math.sin(a) } }
    end
  end
  run_def = { steps = steps, dt = 1e-7, progress = false }
  extra = function(metrics)
    metrics.contacts_per_particle = s:measure("coordination").z
    return string.format("contacts per particle %.3f", metrics.contacts_per_particle)
  end
else
  error("largest.lua: engine must be 'dsmc' or 'dem', got " .. tostring(engine))
end
local build_s = grainlab.clock() - t0
local w0 = grainlab.clock()
s:run(run_def)
local wall = grainlab.clock() - w0
local peak = rss_kib("VmHWM")
local bpp = (peak - base) * 1024 / n
local metrics = { particles = n, bytes_per_particle = bpp, peak_resident_gib = peak / 1048576,
                  particle_steps_per_s = n * steps / wall, wall_s = wall, build_s = build_s,
                  steps = steps, threads = select(1, grainlab.threads()) }
local load = extra(metrics)
print(string.format("%s: %d particles, %.0f bytes per particle (peak resident %.2f GiB), built in %.1f s; " ..
                    "%d steps in %.1f s: %.3g particle-steps/s; %s", engine, n, bpp, peak / 1048576,
                    build_s, steps, wall, n * steps / wall, load))
grainlab.report{
  scenario = "largest_" .. engine,
  params = { engine = engine, n = n, steps = steps },
  metrics = bench.metrics(metrics),
}
