-- Benchmark: the full MPM shear problem of Bardenhagen, Brackbill & Sulsky (1998), Sec. 4 (issue 5,
-- "Performance"): 369 HMX grains packed by grainlab.pack.slab (area fraction ~0.82, ~74,000
-- points at 4 per cell), 150 x 150 cells over 1.2 mm, periodic in y, frictional contact mu = 0.3,
-- edge grains fixed / moved up at 100 m/s. The time step is fixed so that 80% shear takes 25,124
-- cycles as in the paper (dt = 9.6 us / 25,124 = 3.82e-10 s, Courant number ~0.16; the paper
-- needed about 30 h on a Cray YMP).
-- Preparation (not timed): the packing and `warm` cycles (default 200) so that contacts exist.
-- Then `cycles` cycles (default 400) are timed on 1 and 2 threads (or on `threads` only), each
-- continuing the same run.
--   grainlab scripts/bench/mpm_shear.lua [cycles=400] [warm=200] [threads=N] [model=friction|noslip]
--       [save=prep.ckpt | load=prep.ckpt]   (save the prepared scene / start from it, no packing)
--   valgrind --tool=callgrind --instr-atstart=no grainlab scripts/bench/mpm_shear.lua \
--       cycles=20 warm=20 threads=1 callgrind=true   (instructions per point-step)
-- With callgrind=true the timed cycles alone are collected (callgrind_control -i on/off of this
-- process), dumped (callgrind_control -d) and the bench prints instructions_per_point_step from
-- the dump. Without vgdb (--vgdb=no) run with load=prep.ckpt and divide mpm_run's inclusive count
-- (callgrind_annotate --inclusive=yes) by points x cycles; that is how docs/mpm.md's stage table
-- was taken.
-- Metrics: particle_steps_per_s (per thread count), wall_s, projected_full_run_s (25,124 cycles at
-- the measured rate of the last thread count), points, grains; stage_<name>_ns (wall ns per
-- point-step of each stage of the last thread count's run, from m:timings()), also printed as a
-- table with each stage's share.
local cycles = math.tointeger(params.cycles or 400)
local warm = math.tointeger(params.warm or 200)
local model = params.model or "friction"
local callgrind = params.callgrind == true
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

-- Instructions collected in the newest callgrind dump of this directory, or nil.
local function dumped_instructions()
  local f = io.popen("ls -t callgrind.out.* 2>/dev/null | head -n 1")
  local name = f and f:read("l")
  if f then f:close() end
  if not name then return nil end
  f = io.popen("callgrind_annotate '" .. name .. "' 2>/dev/null")
  local out = f and f:read("a") or ""
  if f then f:close() end
  local n = out:match("([%d,]+)%s+%(?[%d.%%]*%)?%s*PROGRAM TOTALS")
  return n and tonumber((n:gsub(",", ""))) or nil
end

local stages
local function timed(threads)
  grainlab.threads(threads)
  if callgrind then os.execute("callgrind_control -z $PPID >/dev/null; callgrind_control -i on $PPID >/dev/null") end
  local s0 = m:timings()
  local w0 = grainlab.clock()
  m:run{ steps = cycles, dt = dt, progress = false }
  local wall = grainlab.clock() - w0
  local s1 = m:timings()
  stages = {}
  for k, x in pairs(s1) do stages[k] = x - s0[k] end
  if callgrind then os.execute("callgrind_control -i off $PPID >/dev/null; callgrind_control -d $PPID >/dev/null") end
  return np * cycles / wall, wall
end

local metrics = { points = np, grains = ngrains, area_fraction = area_fraction, dt_s = dt, cycles = cycles,
                  warm_cycles = warm, prepare_s = t_prep }
local list = params.threads and { params.threads } or { 1, 2 }
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
-- Issue 16's target (issue 5's was 300 s), reported beside the projection, not checked: timing
-- depends on the load. A projection from the prepared scene understates the full run (its shear
-- band's contacts grow: 144-194 s projected, 209-221 s run to the end, docs/mpm.md).
metrics.projected_full_run_target_s = 60
local names = { "stencil", "p2g", "normals", "grid", "contact", "g2p", "remap", "material", "check" }
print(string.format("stages (%d thread(s), %d cycles): wall ns per point-step, share", last, cycles))
for _, k in ipairs(names) do
  local ns = stages[k] / (np * cycles) * 1e9
  metrics["stage_" .. k .. "_ns"] = ns
  print(string.format("  %-9s %8.1f  %5.1f %%", k, ns, 100 * stages[k] / stages.total))
end
if callgrind then
  local n = dumped_instructions()
  if n then
    metrics.instructions_per_point_step = n / (np * cycles)
  else
    print("callgrind=true: no callgrind.out.* dump found here (run under valgrind --tool=callgrind)")
  end
end

local e = m:measure("energy")
grainlab.report{
  scenario = "bench_mpm_shear",
  params = { cycles = cycles, warm = warm, threads = params.threads or "1,2", model = model, cells = cells },
  metrics = metrics,
  checks = {
    { name = "finite_energy", pass = e.total == e.total and e.total < math.huge },
  },
}
