-- Inputs that ask for little work but once ran for minutes: each is refused at entry with its
-- numbers, or finishes in time proportional to the work asked. One case per ctest
-- (`case=NAME`, tests/CMakeLists.txt), each under a TIMEOUT of a few seconds that fails it: the
-- timeout guards against the hang, the checks below decide the rest.
local check = grainlab.check
grainlab.threads(1)
local case = params.case

local quartz = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3, friction = 0.3 }
local cases = {}

-- DSMC: 500 particles, three steps of 1e6 s (once 27 s: ~1e11 candidate pairs a step).
function cases.dsmc_dt()
  local s = dsmc.scene{ dim = 2, size = { 0.1, 0.1 }, cells = { 10, 10 }, radius = 1e-3, restitution = 0.8, seed = 2 }
  s:fill{ n = 500, temperature = s:info().mass * 1.0, seed = 5 }
  check.errors(function() s:run{ steps = 3, dt = 1e6 } end,
    "run: dt = 1e+06 s exceeds the mean collision time 1/omega = 0.00", "dt beyond the collision time is refused")
  check.eq(s:info().steps, 0, "nothing ran")
  -- forced: the first step draws no candidate (every cell over the cap) and the run stops
  check.errors(function() s:run{ steps = 3, dt = 1e6, force = true, warn = false } end,
    "candidate pairs in one step, over the limit of 100 per particle (and ", "forced: the cap stops it")
  check.eq(s:info().steps, 1, "after one step")
  check.eq(s:measure("stats").attempts, 0, "no candidate drawn")
end

-- DSMC flight between mirror walls for 1e6 s at 1 m/s in a 0.1 m box: 1e7 crossings each, folded
-- in closed form (one particle per cell: no collisions to cap).
function cases.dsmc_flight()
  local s = dsmc.scene{ dim = 2, size = { 0.1, 0.1 }, cells = { 2, 2 }, radius = 1e-3, periodic = false, seed = 2 }
  s:add{ x = { 0.02, 0.07 }, y = { 0.02, 0.07 }, vx = { 1, -0.3 }, vy = { 0.5, 0.2 } }
  s:run{ steps = 3, dt = 1e6, force = true, warn = false }
  local p = s:particles()
  for i = 1, p.count do
    check.is_true(p.x[i] >= 0 and p.x[i] <= 0.1 and p.y[i] >= 0 and p.y[i] <= 0.1, "inside the box")
  end
  check.gt(s:measure("stats").wall_hits, 1e7, "every crossing counted")
  check.near(s:measure("temperature").kinetic_energy, 0.5 * s:info().mass * (1.25 + 0.13), 1e-12, "energy kept")
  -- a vibrating wall has no fold: the run stops naming the particle
  s:wall{ side = "bottom", amplitude = 1e-3, frequency = 50 }
  check.errors(function() s:run{ steps = 3, dt = 1e6, force = true, warn = false } end,
    "crossed the walls of the box more than 4 times in one step of dt = 1e+06 s", "other walls stop the run")
end

-- DSMC: the vibrated bed of 600 disks at e = 0.85 in 5 mm cells that ended with 158 disks in one
-- cell: it stops once a cell is past close packing, naming it.
function cases.dsmc_packing()
  local W, R = 0.3, 1e-3
  local s = dsmc.scene{ dim = 2, size = { W, W }, cells = { 60, 60 }, periodic = { true, false },
                        gravity = { 0, -9.81 }, radius = R, restitution = 0.85, seed = 4 }
  s:wall{ side = "bottom", amplitude = 1.5e-3, frequency = 60 }
  s:fill{ n = 600, temperature = s:info().mass * 0.5, region = { { 0, 3e-3 }, { W, 0.1 } }, seed = 9 }
  local ok, msg = pcall(s.run, s, { time = 6, dt = 5e-5, warn = false })
  check.is_true(not ok, "the run stops")
  check.contains(msg, "where at most 12 fit at the packing limit 0.82: a state past close packing", "its message")
  check.contains(msg, "Likely cause: inelastic collapse (restitution 0.85) under gravity, in cells (2.5 diameters)", "the cause")
  check.is_true(s:info().time < 1, "early, not at the end")
  local f, most = s:measure("fields"), 0
  for i = 1, #f.count do most = math.max(most, f.count[i]) end
  check.is_true(most >= 17 and most < 40, "stopped at the first cell past it: " .. most)
end

-- pack.random asked for 2000 disks of 1 mm in a 5 cm square (packing 2.51; once > 5 s, longer
-- with n): refused at entry with the asked fraction, the limit and what fits.
function cases.pack_random()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.05, 0.05 } } }
  check.errors(function() grainlab.pack.random(s, { n = 2000, radius = 1e-3, material = quartz }) end,
    "(at most 435 particles (random addition saturates at a packing fraction of 0.547 of the region; 2000 of mean " ..
    "area 3.14e-06 m^2 ask for 2.51;", "refused at entry")
  check.eq(s:info().count, 0, "nothing added")
  local s3 = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 0.01, 0.01, 0.01 } } }
  check.errors(function() grainlab.pack.random(s3, { n = 1000000, radius = 1e-3, material = quartz }) end,
    "(at most 91 particles (random addition saturates at a packing fraction of 0.384", "3D")
  -- just below saturation: out of tries (1000 n) with the count placed
  local t = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.012, 0.012 } } }
  local ok, msg = pcall(grainlab.pack.random, t, { n = 25, radius = 1e-3, material = quartz, seed = 1 })
  check.is_true(ok or tostring(msg):find("particles in 25000 tries", 1, true) ~= nil, "placed, or out of tries: " .. tostring(msg))
end

-- pack.slab: a size below 4 d_min drew diameters for ever; a sparse slab compacted for millions
-- of steps; an overfull one tried 1e5 times per disk.
function cases.pack_slab()
  check.errors(function() grainlab.pack.slab{ size = 1e-4 } end,
    "bad field 'size' in argument #1 to 'grainlab.pack.slab' (size above 4 d_min = 0.000124", "no diameter to draw")
  check.errors(function() grainlab.pack.slab{ size = 1 } end, "(at least 62", "too sparse")
  check.errors(function() grainlab.pack.slab{ size = 1e-3, n = 100000 } end, "bad field 'n'", "too full")
  check.errors(function() grainlab.pack.slab{ size = 1, n = 12, diameter = { 0.1, 0.15, 0.2 }, width = 1e6 } end,
    "bad field 'width' in argument #1 to 'grainlab.pack.slab' (width at most 4.4", "too wide")
end

-- A DEM inserter asked for every particle there can be in a 2 cm box (room for 127 of 1 mm):
-- each event tries at most what the region holds.
function cases.dem_inserter()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } }, gravity = { 0, -9.81 } }
  s:inserter{ box = { { 0, 0 }, { 0.02, 0.02 } }, count = math.maxinteger, radius = 1e-3, material = quartz, seed = 1 }
  s:run{ steps = 3, progress = false }
  local f = s:flow()
  check.gt(f.inserted, 10, "the region filled")
  check.eq(f.inserted + f.skipped, math.maxinteger, "the rest skipped without a draw")
end

-- A run whose time implies more steps than a count can mean is refused; below, it is a count of
-- steps, shown by the progress line and stopped by Ctrl-C.
function cases.run_time()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } } }
  s:add_disk{ pos = { 0.05, 0.05 }, radius = 1e-3, material = quartz }
  check.errors(function() s:run{ time = 1e20, dt = 1e-6 } end, "time of at most 1e15 steps", "DEM")
  local g = dsmc.scene{ dim = 2, size = { 0.1, 0.1 }, cells = { 10, 10 }, radius = 1e-3 }
  g:fill{ n = 100, temperature = g:info().mass, seed = 1 }
  check.errors(function() g:run{ time = 1e20, dt = 1e-4 } end, "time of at most 1e15 steps", "DSMC")
end

local fn = cases[case]
if not fn then error("bounded_inputs.lua: case= one of the cases, got " .. tostring(case)) end
fn()
check.done()
