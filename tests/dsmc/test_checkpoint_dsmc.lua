-- DSMC checkpoints: run N + M steps, or run N, s:save, dsmc.load, run M: the same bits (every
-- particle's position and velocity printed with %a, in array order, and the collision and wall
-- counters), in 2D and 3D with inelastic collisions, gravity, specular walls with restitution < 1,
-- a diffuse wall (its own random streams) and a vibrating wall; saved on 1 thread and continued
-- on 2, also above the particle count at which the kernels start threads. Then every bad file.
-- (tests/cli/test_checkpoint_mpm_dsmc.sh repeats the continuation in a second grainlab
-- process.)
local check = grainlab.check
local dir = os.getenv("TMPDIR") or "/tmp"
local base = string.format("%s/grainlab_ckpt_dsmc_%d", dir, math.random(1, 1 << 30))

local function gas2d(n, L)
  n, L = n or 1000, L or 0.1
  local c = math.floor(L / 0.01 + 0.5)
  local s = dsmc.scene{ dim = 2, size = { L, 1.5 * L }, cells = { c, (3 * c) // 2 }, radius = 1e-3,
                        restitution = 0.9, gravity = { 0, -9.81 }, periodic = { true, false },
                        seed = 11 }
  s:fill{ n = n, temperature = 1e-4, velocity = { 0.1, 0 }, seed = 5 }
  s:wall{ side = "bottom", restitution = 0.8, amplitude = 2e-3, frequency = 40 }
  s:wall{ side = "top", kind = "diffuse", temperature = 2e-4 }
  return s
end

local function gas3d()
  local s = dsmc.scene{ dim = 3, size = { 0.05, 0.05, 0.08 }, cells = { 5, 5, 8 },
                        radius = 1e-3, restitution = 0.7, gravity = { 0, 0, -9.81 },
                        periodic = { false, true, false }, seed = 23,
                        excluded_volume = "enskog" }
  s:fill{ n = 3000, speed = 2, seed = 9 }
  s:wall{ side = "left", restitution = 0.6 }
  s:wall{ side = "right", kind = "diffuse", temperature = 1e-6, velocity = { 0, 0.2, 0 } }
  s:wall{ side = "bottom", restitution = 0.9, amplitude = 1e-3, frequency = 50, phase = 0.3 }
  return s
end

local function dump(s)
  local p = s:particles()
  local st, t = s:measure("stats"), s:measure("temperature")
  local out = { string.format("t %a steps %d collisions %a %a attempts %a wall_hits %a raised %a",
                              s:info().time, s:info().steps, t.collisions, st.collisions,
                              st.attempts, st.wall_hits, st.vmax_raised) }
  local x, y, z, vx, vy, vz = p.x, p.y, p.z, p.vx, p.vy, p.vz
  local fmt = string.format
  for i = 1, p.count do
    out[i + 1] = z and fmt("%a %a %a %a %a %a", x[i], y[i], z[i], vx[i], vy[i], vz[i])
                 or fmt("%a %a %a %a", x[i], y[i], vx[i], vy[i])
  end
  return out
end

local F = dofile("../lua/lib/ckpt_files.lua")
local same = F.same_lines

local function continuation(make, dt, n1, n2, what)
  grainlab.threads(1)
  local ref = make()
  ref:run{ steps = n1 + n2, dt = dt, warn = false }
  local want = dump(ref)

  local s = make()
  s:run{ steps = n1, dt = dt, warn = false }
  local path = base .. "_" .. what .. ".ckpt"
  local before = dump(s)
  s:save(path)
  same(dump(s), before, what .. ": saving leaves the gas as it was")

  grainlab.threads(2)
  local l = dsmc.load(path)
  same(dump(l), before, what .. ": loaded state")
  local i0, i1 = s:info(), l:info()
  for _, k in ipairs({ "dim", "count", "radius", "mass", "density", "restitution", "packing_limit",
                       "excluded_volume", "chi" }) do
    check.eq(i1[k], i0[k], what .. ": info " .. k)
  end
  l:run{ steps = n2, dt = dt, warn = false }
  same(dump(l), want, what .. ": N + M steps against N, save, load, M")
  grainlab.threads(1)
  os.remove(path)
  return l, ref
end

local l, ref = continuation(gas2d, 2e-4, 60, 60, "2D")
check.gt(ref:measure("stats").wall_hits, 100, "2D: the walls are hit")
check.lt(ref:measure("temperature").kinetic_energy,
         gas2d():measure("temperature").kinetic_energy * 10, "2D: a sane gas")
l, ref = continuation(gas3d, 2e-4, 50, 50, "3D")
check.gt(ref:measure("stats").collisions, 1000, "3D: the gas collides")
check.gt(ref:measure("stats").wall_hits, 100, "3D: the walls are hit")
-- Above 50,000 particles the flight, sort and collisions run on threads: saved on 1, continued
-- on 2, the same bits.
continuation(function() return gas2d(60000, 1.1) end, 2e-4, 2, 2, "threads")

-- The statistics and the collision count carry over; s:reset_stats() afterwards works as usual.
do
  local s = gas2d()
  s:run{ steps = 10, dt = 2e-4, warn = false }
  local path = base .. "_stats.ckpt"
  s:save(path)
  local l2 = dsmc.load(path)
  check.eq(l2:measure("stats").steps, 10, "stats steps carried over")
  check.eq(l2:measure("temperature").collisions, s:measure("temperature").collisions,
           "collision count carried over")
  l2:reset_stats()
  check.eq(l2:measure("stats").steps, 0, "reset_stats after a load")
  l2:fill{ n = 10, temperature = 1e-6, seed = 99 }
  check.eq(l2:info().count, 1010, "a loaded gas takes more particles")
  os.remove(path)
end

-- ---- bad files ------------------------------------------------------------------------------
local read, write, reseal, put = F.read, F.write, F.reseal, F.put

local good, bad = base .. "_good.ckpt", base .. "_bad.ckpt"
local g = dsmc.scene{ dim = 2, size = { 0.05, 0.05 }, cells = { 4, 4 }, radius = 1e-3,
                      periodic = { true, false } }
g:fill{ n = 50, temperature = 1e-6, seed = 1 }
g:run{ steps = 3, dt = 1e-4, warn = false }
g:save(good)
local s = read(good)
check.eq(s:sub(25, 28), "dsmc", "engine kind in the header")

check.errors(function() dsmc.load(base .. "_missing.ckpt") end, "load: cannot read checkpoint",
             "missing file")
write(bad, s:sub(1, #s - 100))
check.errors(function() dsmc.load(bad) end, "truncated", "truncated file")
write(bad, put(s, 200, string.char(s:byte(201) ~ 1)))
check.errors(function() dsmc.load(bad) end, "checksum mismatch", "one flipped bit")
write(bad, reseal(put(s, 24, "dem\0")))
check.errors(function() dsmc.load(bad) end, "is a dem checkpoint, not a dsmc one", "DEM checkpoint")
local mpm_file = base .. "_mpm.ckpt"
local m = mpm.scene{ cells = { 4, 4 }, size = { 1, 1 } }
m:add_disk{ center = { 0.5, 0.5 }, radius = 0.3, material = mpm.material{ density = 1000,
            shear = 1e6, bulk = 1e6 } }
m:save(mpm_file)
check.errors(function() dsmc.load(mpm_file) end, "is an mpm checkpoint, not a dsmc one",
             "MPM checkpoint")
check.errors(function() mpm.load(good) end, "is a dsmc checkpoint, not an mpm one",
             "DSMC checkpoint to mpm.load")
write(bad, reseal(put(s, 12, string.pack("=I4", 2))))
check.errors(function() dsmc.load(bad) end, "format version 2", "newer format")
-- Behind a valid checksum: the particles' section ends with a velocity.
local pend = F.section_end(s, "dsmc.particles")
write(bad, reseal(put(s, pend - 8, string.pack("=d", 1 / 0))))
check.errors(function() dsmc.load(bad) end,
             "corrupt dsmc checkpoint: a particle is outside the box",
             "infinite velocity")
-- The first and the last particle's positions swapped: no longer in cell order. The section is
-- x, vx, y, vy as arrays of a count and n doubles.
do
  local n = 50
  local function at(array, i) return pend - (4 - array) * (8 + 8 * n) + 8 + 8 * (i - 1) end
  local t = s
  for _, array in ipairs({ 0, 2 }) do -- x, y
    local first = t:sub(at(array, 1) + 1, at(array, 1) + 8)
    local last = t:sub(at(array, n) + 1, at(array, n) + 8)
    t = put(put(t, at(array, 1), last), at(array, n), first)
  end
  write(bad, reseal(t))
  check.errors(function() dsmc.load(bad) end,
               "corrupt dsmc checkpoint: the particles are not in cell order", "out of cell order")
end
write(bad, reseal(s))
check.eq(dsmc.load(bad):info().steps, 3, "a resealed copy loads")

check.errors(function() g:save(42) end,
             "bad argument #1 to 'save' (file path (string) expected, got 42)",
             "save with a number")
check.errors(function() g:save(dir .. "/no/such/dir/x.ckpt") end, "save:", "unwritable path")
check.eq(dsmc.load(good):info().steps, 3, "the file is intact after failed saves")

-- An empty gas round-trips and takes particles afterwards.
do
  local e = dsmc.scene{ dim = 3, size = { 0.05, 0.05, 0.05 }, cells = { 2, 2, 2 }, radius = 1e-3 }
  e:save(good)
  local l4 = dsmc.load(good)
  check.eq(l4:info().count, 0, "empty gas: no particles")
  l4:fill{ n = 20, temperature = 1e-6, seed = 2 }
  l4:run{ steps = 2, dt = 1e-4, warn = false }
  check.eq(l4:info().steps, 2, "empty gas: runs once filled")
end

os.remove(good)
os.remove(bad)
os.remove(mpm_file)
check.done()
