-- Benchmark: coarse-graining 10^5 disks with ~4 contacts each onto a 200 x 200 grid at w = 2 d,
-- on 1 and 2 threads (not a timed test: the times are reported, no check depends on them).
--   The assembly: a square lattice of side m (m^2 ~ n disks) of spacing 0.99 d with radii
--   uniform in [0.495, 0.5] d + 0.005 d jitter of the positions, so that every disk touches its
--   four neighbours (3.9-4 contacts per particle, counted) and nothing else; gravity off, Hertz +
--   viscous damping, a few steps run so that the contacts carry forces. The grid covers the
--   lattice (200 x 200 cells of about 1.6 d).
--   Kernels: the Gaussian (w = 2 d, cut at 3 w) and Lucy (w = 2 d); each call timed `reps` times,
--   the fastest kept (the shared machine's noise only adds).
--   The time average's cost: `steps` DEM steps with avg:add every `every` steps against the same
--   steps without (threads in auto mode); the difference over the samples' own time (avg:info)
--   is what a sample costs a run over what it costs alone.
--   grainlab scripts/bench/cg.lua [n=100000] [cells=200] [reps=3] [threads=1,2] [steps=200]
--                                 [every=50]
--   run_all.sh's quick mode: the same scene, reps=1 steps=100.
-- Report bench_cg: particles, contacts, contacts_per_particle, grid, cell_over_d, width_over_d;
-- <kernel>_seconds_<k>t (one coarse_grain call, its Lua tables included) and
-- <kernel>_sample_seconds_<k>t (one avg:add of an average, no Lua tables) for kernel gauss and
-- lucy on k threads; run_seconds_plain, run_seconds_with_average, average_samples,
-- average_sampling_seconds and added_per_sample_over_sample (the run's added time over the
-- samples' own time); with the machine, load and run (common.lua).
local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
local n = params.n or 100000
local cells = params.cells or 200
local reps = params.reps or 3
local steps, every = params.steps or 200, params.every or 50
local threads = {}
for v in tostring(params.threads or "1,2"):gmatch("[^,]+") do threads[#threads + 1] = math.tointeger(tonumber(v)) end

local d = 1e-3
local m = math.floor(math.sqrt(n) + 0.5)
local a = 0.99 * d
local L = m * a
local s = dem.scene{ dim = 2, box = { { -a, -a }, { L + a, L + a } }, gravity = { 0, 0 }, thickness = d }
local quartz = grainlab.material{ density = 2650, young = 1e9, poisson = 0.3, friction = 0.5, restitution = 0.5 }
local rng = grainlab.rng{ seed = 1 }
local t0 = grainlab.clock()
for j = 0, m - 1 do
  for i = 0, m - 1 do
    s:add_disk{ pos = { (i + 0.5) * a + 0.005 * d * (rng:uniform() - 0.5), (j + 0.5) * a + 0.005 * d * (rng:uniform() - 0.5) },
                radius = d * (0.495 + 0.005 * rng:uniform()), material = quartz }
  end
end
s:contact{ normal = "hertz", damping = "viscous", restitution = 0.5, impact_velocity = 1 }
s:run{ steps = 5, progress = false }
local t_build = grainlab.clock() - t0
local C = s:measure("coordination")
local ncontacts = math.floor(C.z * s:particles().count / 2 + 0.5)

local region = { { 0, 0 }, { L, L } }
local metrics = { particles = m * m, contacts = ncontacts, contacts_per_particle = C.z, grid = { cells, cells },
                  cell_over_d = L / cells / d, width_over_d = 2, build_seconds = t_build }
for _, kernel in ipairs{ "gauss", "lucy" } do
  for _, th in ipairs(threads) do
    grainlab.threads(th)
    local best = math.huge
    for _ = 1, reps do
      local c0 = grainlab.clock()
      analysis.coarse_grain(s, { kernel = kernel, width = 2 * d, cells = { cells, cells }, region = region })
      best = math.min(best, grainlab.clock() - c0)
    end
    metrics[string.format("%s_seconds_%dt", kernel, th)] = best
    -- the same sums without the Lua tables: one sample of an average
    local avg = analysis.cg_average(s, { kernel = kernel, width = 2 * d, cells = { cells, cells }, region = region })
    local bs = math.huge
    for _ = 1, reps do
      local c0 = grainlab.clock()
      avg:add(s)
      bs = math.min(bs, grainlab.clock() - c0)
    end
    metrics[string.format("%s_sample_seconds_%dt", kernel, th)] = bs
  end
end
grainlab.threads("auto")

-- the time average's cost in a run: steps with and without sampling (on all threads)
local dt = s:timestep().dt_auto
local function run(with)
  local avg = with and analysis.cg_average(s, { width = 2 * d, cells = { cells, cells }, region = region }) or nil
  local c0 = grainlab.clock()
  s:run{ steps = steps, dt = dt, every = every, progress = false,
         on_step = with and function(sc) avg:add(sc) end or nil }
  return grainlab.clock() - c0, avg and avg:info().seconds or 0, avg and avg:info().samples or 0
end
local t_plain = run(false)
local t_avg, t_samples, samples = run(true)
metrics.run_seconds_plain = t_plain
metrics.run_seconds_with_average = t_avg
metrics.average_samples = samples
metrics.average_sampling_seconds = t_samples
-- what sampling added to the run, per sample, against the sampling's own measured time
metrics.added_per_sample_over_sample = (t_avg - t_plain) / math.max(t_samples, 1e-9)

grainlab.report{
  scenario = "bench_cg",
  params = { n = m * m, cells = cells, width_d = 2, reps = reps, threads = params.threads or "1,2",
             steps = steps, every = every },
  metrics = bench.metrics(metrics),
  checks = {
    -- the assembly measured: about four contacts per particle
    { name = "contacts_per_particle", value = math.abs(C.z - 4), limit = 0.3 },
  },
}
