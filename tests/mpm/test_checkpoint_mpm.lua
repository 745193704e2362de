-- MPM checkpoints: run N + M steps, or run N, m:save, mpm.load, run M: the same bits (every
-- point's position, velocity, stress and deformation printed with %a), for frictional contact
-- (several grains, a friction wall and plane, a prescribed grain, von Mises plasticity) and for
-- noslip (B-splines, USF, a PIC blend, a periodic axis); saved on 1 thread and continued on 2.
-- Then every bad file: missing, empty, truncated, corrupt, another engine's, a newer format, and
-- values that pass the checksum but cannot be a scene. (tests/cli/test_checkpoint_mpm_dsmc.sh
-- repeats the continuation in a second grainlab process.)
local check = grainlab.check
local dir = os.getenv("TMPDIR") or "/tmp"
local base = string.format("%s/grainlab_ckpt_mpm_%d", dir, math.random(1, 1 << 30))

local elastic = mpm.material{ density = 3000, shear = 2.5e6, bulk = 10e6 }
local plastic = mpm.material{ model = "vonmises", density = 2500, shear = 2e6, bulk = 8e6,
                              yield = 4e4, hardening = 1e5 }

-- Several grains under gravity on a friction floor, one on a tilted friction plane (a ramp in the
-- lower right corner), a prescribed rectangle sliding along the top, Coulomb contact between the
-- grains; the disks touch the floor and each other from the first step.
local function friction_scene()
  local m = mpm.scene{ cells = { 24, 20 }, size = { 2.4, 2 }, gravity = { 0.4, -9.8 },
                       walls = { bottom = { kind = "friction", mu = 0.5 }, left = "slip",
                                 right = "noslip", top = "slip" } }
  m:add_disk{ center = { 0.7, 0.32 }, radius = 0.3, material = elastic, velocity = { 0.8, 0 },
              omega = 1.5 }
  m:add_disk{ center = { 1.35, 0.33 }, radius = 0.3, material = plastic, velocity = { -0.6, 0 } }
  m:add_disk{ center = { 1.0, 0.95 }, radius = 0.25, material = elastic, velocity = { 0, -1 } }
  m:add_polygon{ vertices = { { 1.6, 0.9 }, { 2.1, 0.95 }, { 1.9, 1.4 } }, material = plastic,
                 points_per_cell = 3 }
  m:add_disk{ center = { 2.033, 0.284 }, radius = 0.15, material = elastic,
              velocity = { 0.5, -0.5 } }
  local top = m:add_rect{ lo = { 0.3, 1.55 }, hi = { 1.5, 1.75 }, material = elastic }
  m:prescribe(top, { 0.2, 0 })
  m:plane{ point = { 2.4, 0.3 }, normal = { -0.5, 1 }, kind = "friction", mu = 0.3 }
  m:contact{ model = "friction", mu = 0.3 }
  return m
end

local function noslip_scene()
  local m = mpm.scene{ cells = { 20, 16 }, size = { 2, 1.6 }, gravity = { 0, -9.8 },
                       periodic = { true, false }, shape = "bspline", update = "usf", pic = 0.05 }
  m:add_disk{ center = { 0.6, 0.5 }, radius = 0.3, material = plastic, velocity = { 1, 0.2 } }
  m:add_rect{ lo = { 1.1, 0.25 }, hi = { 1.8, 0.7 }, material = elastic, velocity = { -0.5, 0 },
              hydrostatic = true }
  m:contact{ model = "noslip" }
  return m
end

-- Every bit of the state a continuation shows.
local function dump(m)
  local p = m:points()
  local out = { string.format("t %a steps %d", m:info().time, m:info().steps) }
  local fmt = string.rep("%a", 15, " ")
  for i = 1, p.count do
    out[i + 1] = string.format(fmt, p.x[i], p.y[i], p.vx[i], p.vy[i], p.ux[i], p.uy[i], p.sxx[i],
                               p.syy[i], p.sxy[i], p.szz[i], p.Fxx[i], p.Fxy[i], p.Fyx[i],
                               p.Fyy[i], p.eps_p[i])
  end
  return out
end

local F = dofile("../lua/lib/ckpt_files.lua")
local same = F.same_lines

local function continuation(make, n1, n2, what)
  grainlab.threads(1)
  local ref = make()
  ref:run{ steps = n1 + n2 }
  local want = dump(ref)

  local m = make()
  m:run{ steps = n1 }
  local path = base .. "_" .. what .. ".ckpt"
  local before = dump(m)
  m:save(path)
  same(dump(m), before, what .. ": saving leaves the scene as it was")
  m:run{ steps = n2 }
  same(dump(m), want, what .. ": the saved scene runs on as if not saved")

  grainlab.threads(2)
  local l = mpm.load(path)
  same(dump(l), before, what .. ": loaded state")
  local i0, i1 = m:info(), l:info()
  for _, k in ipairs({ "contact", "mu", "update", "shape", "pic", "grains", "points", "normals",
                       "separation", "strain_cap", "conserve" }) do
    check.eq(i1[k], i0[k], what .. ": info " .. k)
  end
  l:run{ steps = n2 }
  same(dump(l), want, what .. ": N + M steps against N, save, load, M")
  grainlab.threads(1)
  os.remove(path)
  return l
end

local l = continuation(friction_scene, 40, 40, "friction")
check.gt(l:measure("energy").plastic, 0, "friction: the run reaches plastic flow")
continuation(noslip_scene, 20, 20, "noslip")

-- Above 8192 points the kernels split the points over threads; with friction the bits do not
-- depend on their number (test_mpm_threads.lua), so a file saved on 1 thread continues on 2.
local function big_scene()
  local m = mpm.scene{ cells = { 60, 60 }, size = { 6, 6 }, gravity = { 0.5, -9.8 },
                       periodic = { false, true } }
  for k = 0, 7 do
    m:add_disk{ center = { 0.9 + 1.4 * (k % 4), 1.5 + 2.5 * (k // 4) + 0.2 * (k % 2) },
                radius = 0.62, material = plastic, points_per_cell = 3,
                velocity = { (k % 2 == 0) and 1 or -1, 0.3 * k } }
  end
  m:contact{ model = "friction", mu = 0.4 }
  return m
end
check.gt(big_scene():info().points, 8192, "enough points for threads")
continuation(big_scene, 3, 3, "threads")

-- Automatic time step with run{time =}: the step is taken from the points every step, so nothing
-- of it is state; a loaded scene lands on the same time with the same bits.
do
  local ref = friction_scene()
  ref:run{ time = 0.02 }
  ref:run{ time = 0.02 }
  local m = friction_scene()
  m:run{ time = 0.02 }
  local path = base .. "_time.ckpt"
  m:save(path)
  local l2 = mpm.load(path)
  l2:run{ time = 0.02 }
  same(dump(l2), dump(ref), "time-based runs")
  os.remove(path)
end

-- A loaded scene takes new grains and materials like any other.
do
  local m = noslip_scene()
  local path = base .. "_grow.ckpt"
  m:save(path)
  local l2 = mpm.load(path)
  local g = l2:add_disk{ center = { 1.0, 1.2 }, radius = 0.15, material = elastic }
  check.eq(g, 3, "a loaded scene numbers new grains after its own")
  l2:run{ steps = 3 }
  os.remove(path)
end

-- ---- bad files ------------------------------------------------------------------------------
local read, write, reseal, put = F.read, F.write, F.reseal, F.put

local good = base .. "_good.ckpt"
local bad = base .. "_bad.ckpt"
local m = friction_scene()
m:run{ steps = 2 }
m:save(good)
local s = read(good)
check.eq(s:sub(1, 8), "GRAINLAB", "magic")
check.eq(s:sub(25, 27), "mpm", "engine kind in the header")

check.errors(function() mpm.load(base .. "_missing.ckpt") end, "load: cannot read checkpoint",
             "missing file")
write(bad, "")
check.errors(function() mpm.load(bad) end, "the file is empty", "empty file")
write(bad, s:sub(1, #s // 2))
check.errors(function() mpm.load(bad) end, "truncated", "truncated file")
write(bad, put(s, #s // 2, string.char(s:byte(#s // 2 + 1) ~ 0x10)))
check.errors(function() mpm.load(bad) end, "checksum mismatch", "one flipped bit")
write(bad, "-- a Lua script, not a checkpoint\nprint(1)\n")
check.errors(function() mpm.load(bad) end, "not a grainlab checkpoint", "foreign file")
local d = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }
d:add_disk{ pos = { 0.5, 0.5 }, radius = 0.1,
            material = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3 } }
d:save(bad)
check.errors(function() mpm.load(bad) end, "is a dem checkpoint, not an mpm one", "DEM checkpoint")
write(bad, reseal(put(s, 24, "dsmc")))
check.errors(function() mpm.load(bad) end, "is a dsmc checkpoint, not an mpm one",
             "DSMC checkpoint")
write(bad, reseal(put(s, 12, string.pack("=I4", 99))))
check.errors(function() mpm.load(bad) end, "format version 99", "newer format")
-- Behind a valid checksum: the section mpm.clock holds time, steps, m_min.
local clock = F.section_end(s, "mpm.clock") - 24
write(bad, reseal(put(s, clock, string.pack("=d", 0 / 0))))
check.errors(function() mpm.load(bad) end, "corrupt mpm checkpoint: time is not finite", "NaN time")
write(bad, reseal(put(s, clock + 16, string.pack("=d", -1))))
check.errors(function() mpm.load(bad) end, "light-node threshold is negative", "negative m_min")
write(bad, reseal(put(s, clock + 8, string.pack("=i8", -5))))
check.errors(function() mpm.load(bad) end, "steps = -5 is outside", "negative step count")
-- the resealed original still loads (the forging above is sound)
write(bad, reseal(s))
check.eq(mpm.load(bad):info().steps, 2, "a resealed copy loads")

-- save: argument errors and an unwritable place; the old file stays whole.
check.errors(function() m:save() end,
             "bad argument #1 to 'save' (file path (string) expected, got no value)",
             "save without a path")
check.errors(function() m:save(dir .. "/no/such/dir/x.ckpt") end, "save:", "unwritable path")
check.errors(function() mpm.load() end, "bad argument #1 to 'load'", "load without a path")
getmetatable(m).__close(m)
check.errors(function() m:save(good) end, "closed", "closed scene")
check.eq(mpm.load(good):info().steps, 2, "the file is intact after failed saves")

-- From on_step: a checkpoint every 5 steps, the last one continues the run.
do
  local ref = friction_scene()
  ref:run{ steps = 20 }
  local m2 = friction_scene()
  local path = base .. "_onstep.ckpt"
  m2:run{ steps = 15, every = 5, on_step = function(sc) sc:save(path) end }
  local l3 = mpm.load(path)
  check.eq(l3:info().steps, 15, "on_step checkpoint: step count")
  l3:run{ steps = 5 }
  same(dump(l3), dump(ref), "checkpoint written from on_step")
  os.remove(path)
end

-- An empty scene round-trips and takes grains afterwards.
do
  local e = mpm.scene{ cells = { 4, 4 }, size = { 1, 1 }, periodic = { true, false } }
  e:save(good)
  local l4 = mpm.load(good)
  check.eq(l4:info().points, 0, "empty scene: no points")
  l4:add_disk{ center = { 0.5, 0.5 }, radius = 0.3, material = elastic }
  l4:run{ steps = 2 }
  check.eq(l4:info().steps, 2, "empty scene: runs once filled")
end

os.remove(good)
os.remove(bad)
check.done()
