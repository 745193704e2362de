-- The granular continuum materials of mpm.material ('drucker_prager', 'mu_i') from Lua: bad
-- input named by field, read-only fields, a two-body scene (frictional contact, a friction floor,
-- B-splines) whose checkpoint continues with the same bits and whose forged parameters are
-- refused, the fields rate, inertial and mean_pressure, the VTK files and a PNG of the rate.
local check = grainlab.check
local dir = os.getenv("TMPDIR") or "/tmp"
local base = string.format("%s/grainlab_continuum_%d", dir, math.random(1, 1 << 30))

local function material(t)
  local d = { density = 1500, shear = 2e5, bulk = 4e5 }
  for k, v in pairs(t) do d[k] = v end
  return mpm.material(d)
end

-- ---- bad input ------------------------------------------------------------------------------
local function refused(t, text, what) check.errors(function() material(t) end, text, what) end
local dp = { model = "drucker_prager", friction = 30 }
local function with(t, k, v)
  local c = {}
  for a, b in pairs(t) do c[a] = b end
  c[k] = v
  return c
end
refused(with(dp, "friction", 95),
  "bad field 'friction' in argument #1 to 'material' (angle in degrees in (0, 90) expected, got 95)", "friction > 90")
refused(with(dp, "friction", 0),
  "bad field 'friction' in argument #1 to 'material' (angle in degrees in (0, 90) expected, got 0)", "friction 0")
refused(with(dp, "friction", nil),
  "bad field 'friction' in argument #1 to 'material' (finite number expected, got nil)", "friction missing")
refused(with(dp, "dilatancy", 35),
  "bad field 'dilatancy' in argument #1 to 'material' (angle in degrees in [0, friction = 30] expected, got 35)",
  "dilatancy > friction")
refused(with(dp, "dilatancy", -1),
  "bad field 'dilatancy' in argument #1 to 'material' (angle in degrees in [0, friction = 30] expected, got -1)",
  "negative dilatancy")
refused(with(dp, "cohesion", -5),
  "bad field 'cohesion' in argument #1 to 'material' (non-negative number expected, got -5)", "negative cohesion")
refused(with(dp, "mu_s", 0.4),
  "bad field 'mu_s' in argument #1 to 'material' (nothing for model 'drucker_prager' (use field 'model' = 'mu_i') expected, got 0.4)",
  "mu_i field on drucker_prager")
local mi = { model = "mu_i", mu_s = 0.38, mu_2 = 0.64, grain_diameter = 5e-4 }
refused(with(mi, "mu_2", 0.3),
  "bad field 'mu_2' in argument #1 to 'material' (number > mu_s = 0.38 expected, got 0.3)", "mu_2 below mu_s")
refused(with(mi, "grain_diameter", nil),
  "bad field 'grain_diameter' in argument #1 to 'material' (positive number expected, got nil)", "no grain diameter")
refused(with(mi, "grain_density", 1000),
  "bad field 'grain_density' in argument #1 to 'material' (number >= density = 1500 (the close-packed bulk density) expected, got 1000)",
  "grains lighter than the packing")
refused(with(mi, "i0", 0),
  "bad field 'i0' in argument #1 to 'material' (positive number expected, got 0)", "i0 zero")
refused(with(mi, "friction", 30),
  "bad field 'friction' in argument #1 to 'material' (nothing for model 'mu_i' (use field 'model' = 'drucker_prager') expected, got 30)",
  "drucker_prager field on mu_i")
refused({ friction = 30 },
  "bad field 'friction' in argument #1 to 'material' (nothing for model 'elastic' (use field 'model' = 'drucker_prager') expected, got 30)",
  "drucker_prager field on elastic")

-- ---- fields of the materials ------------------------------------------------------------------
local sand = material{ model = "drucker_prager", friction = 30, dilatancy = 5, cohesion = 10 }
local beads = material{ model = "mu_i", mu_s = 0.38, mu_2 = 0.64, grain_diameter = 5e-4 }
check.eq(sand.friction, 30, "friction readable (degrees)")
check.near(sand.eta, math.sin(math.rad(30)) / (math.sqrt(3 / (3 + math.sin(math.rad(5)) ^ 2)) +
  math.sqrt(3) * math.sin(math.rad(5)) / math.sqrt(3 + math.sin(math.rad(5)) ^ 2) * math.sin(math.rad(30)) / 3),
  1e-14, "eta of the plane-strain match")
check.near(beads.grain_density, 2500, 1e-15, "grain density defaults to density / 0.6")
check.eq(beads.i0, 0.279, "i0 defaults to Jop et al.'s 0.279")
check.eq(beads.friction, nil, "no friction angle on mu_i")
check.contains(tostring(sand), "drucker_prager (density 1500, shear 200000, bulk 400000, friction 30 deg, dilatancy 5 deg, cohesion 10)", "tostring")
check.contains(tostring(beads), "mu_i (density 1500", "tostring mu_i")
check.errors(function() sand.friction = 40 end, "an mpm.material is read-only: field 'friction' cannot be set", "read-only")

-- ---- a scene of both: columns collapsing onto a friction floor, in frictional contact ----------
local function scene()
  local m = mpm.scene{ cells = { 24, 12 }, size = { 0.24, 0.12 }, gravity = { 0, -9.81 },
                       shape = "bspline", wall_gap = 0,
                       walls = { bottom = { kind = "friction", mu = 0.5 }, left = "slip", right = "slip",
                                 top = "none" } }
  m:add_rect{ lo = { 0.02, 0 }, hi = { 0.06, 0.08 }, material = sand }
  m:add_rect{ lo = { 0.06, 0 }, hi = { 0.1, 0.08 }, material = beads }
  m:contact{ model = "friction", mu = 0.4 }
  return m
end

local function dump(m)
  local p, t = m:points(), {}
  for i = 1, p.count do
    t[#t + 1] = string.format("%a %a %a %a %a %a %a %a", p.x[i], p.y[i], p.vx[i], p.vy[i], p.sxx[i],
                              p.szz[i], p.eps_p[i], p.rate[i])
  end
  return table.concat(t, "\n")
end

local m = scene()
m:run{ steps = 300 }
local path = base .. ".ckpt"
m:save(path)
m:run{ steps = 200 }
local l = mpm.load(path)
l:run{ steps = 200 }
check.eq(dump(l), dump(m), "checkpoint: the continuation has the same bits")

local p = m:points()
local maxrate, ep = { 0, 0 }, { 0, 0 }
for i = 1, p.count do
  maxrate[p.grain[i]] = math.max(maxrate[p.grain[i]], p.rate[i])
  ep[p.grain[i]] = math.max(ep[p.grain[i]], p.eps_p[i])
end
check.gt(maxrate[1], 0, "drucker_prager flows (rate)")
check.gt(maxrate[2], 0, "mu_i flows (rate)")
check.gt(ep[1], 0, "drucker_prager accumulates eps_p")
for _, name in ipairs { "rate", "inertial", "mean_pressure" } do
  local f = m:field(name)
  local finite, positive = 0, 0
  for _, v in ipairs(f.values) do
    if v == v then
      finite = finite + 1
      if v > 0 then positive = positive + 1 end
    end
  end
  check.gt(positive, 0, "field " .. name .. " has positive cells")
end
-- an elastic scene has no rate array and zero rate cells
local e = mpm.scene{ cells = { 4, 4 }, size = { 1, 1 } }
e:add_disk{ center = { 0.5, 0.5 }, radius = 0.2, material = mpm.material{ density = 1, shear = 1, bulk = 1 } }
check.eq(e:points().rate, nil, "no rate array without a continuum material")
check.eq(e:field("rate").values[6], 0, "rate 0 in an elastic scene")

-- VTK: the points carry rate and mean_pressure, the grid the three continuum fields
local files = m:write_vtk(base .. ".vtu")
local function read(f)
  local h = assert(io.open(f, "rb"))
  local s = h:read("a")
  h:close()
  return s
end
check.contains(read(files[1]), 'Name="rate"', "points file has rate")
check.contains(read(files[1]), 'Name="mean_pressure"', "points file has mean_pressure")
check.contains(read(files[2]), 'Name="inertial"', "grid file has inertial")
local f = m:field("rate")
render.field{ file = base .. "_rate.png", values = f.values, nx = f.nx, ny = f.ny, title = "rate" }
check.is_true(io.open(base .. "_rate.png", "rb") ~= nil, "PNG of the rate written")

-- ---- forged checkpoints: parameters the engine refuses never reach it --------------------------
local function reseal(s)
  local hsh = -3750763034362895579
  for i = 1, #s - 8 do hsh = (hsh ~ s:byte(i)) * 0x100000001b3 end
  return s:sub(1, #s - 8) .. string.pack("<i8", hsh)
end
local function section(s, tag) -- payload start (0-based) and size
  local at = 64
  while at < #s - 24 do
    local t = s:sub(at + 1, at + 16):gsub("%z+$", "")
    local size = string.unpack("<I8", s, at + 25)
    if t == tag then return at + 32, size end
    at = at + 32 + size + (8 - size % 8) % 8
  end
  error("no section " .. tag)
end
local good = read(path)
local at = section(good, "mpm.continuum")
local function forge(offset, value, text, what)
  local s = good:sub(1, offset) .. string.pack("<d", value) .. good:sub(offset + 9)
  local h = assert(io.open(base .. "_bad.ckpt", "wb"))
  h:write(reseal(s))
  h:close()
  check.errors(function() mpm.load(base .. "_bad.ckpt") end, text, what)
end
-- material 1's friction (after the material count), material 2's mu_2, point 1's rate
forge(at + 8, 95, "is a corrupt mpm checkpoint: the friction angle must be in (0, 90) degrees, got 95",
      "forged friction angle")
forge(at + 8 + 64 + 32, 0.1, "is a corrupt mpm checkpoint: mu_2 must be > mu_s, got 0.1", "forged mu_2")
forge(at + 8 + 2 * 64 + 8, -1, "a point's plastic shear rate is negative or not finite", "forged rate")
for _, suffix in ipairs { ".ckpt", "_bad.ckpt", ".vtu", "_grid.vti", "_rate.png" } do os.remove(base .. suffix) end
check.done()
