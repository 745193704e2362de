-- The planes' law parameters are computed once per candidate list (dem_wall.cand_par in
-- src/dem/dem_internal.h) instead of per contact and step. A change of the laws (s:contact) or of
-- the masses (s:scale_mass) during a scene's life must reach the walls' contacts: a scene that
-- ran with one law and then switched must continue exactly as the same state loaded from a
-- checkpoint into a scene that never had the old law (to the bit: the parameters are the same
-- numbers either way). Disks resting on a floor and against a side wall, Brilliantov damping
-- from a restitution (its damping time depends on the law's restitution and on the masses); the
-- floor a plane, then a polyline (the walls beyond planes keep their own candidates).
local check = grainlab.check
grainlab.threads(1)

local dir = os.tmpname()
os.remove(dir)
assert(os.execute("mkdir -p '" .. dir .. "'"))
local ckpt = dir .. "/walls.ckpt"

local mat = grainlab.material{ density = 2650, young = 1e8, poisson = 0.3, friction = 0.4 }
local function law(e)
  return { normal = "hertz", damping = "brilliantov", restitution = e, impact_velocity = 1,
           tangential = "spring" }
end

local function pile(floor)
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.02 } }, gravity = { 0, -9.81 } }
  s:contact(law(0.5))
  if floor == "plane" then s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  else s:add_polyline{ points = { { 0, 0 }, { 0.02, 0 } } } end
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.02, 0 }, normal = { -1, 0 } }
  local rng = grainlab.rng{ seed = 3 }
  for k = 0, 29 do
    s:add_disk{ pos = { 1.1e-3 + (k % 8) * 2.2e-3 + rng:uniform(0, 1e-4), 1.0001e-3 + (k // 8) * 2.0001e-3 },
                radius = 1e-3, material = mat, vel = { rng:normal(0, 0.001), 0 } }
  end
  return s
end

local function state(s)
  local p, t = s:particles(), {}
  for i = 1, p.count do
    t[#t + 1] = string.format("%a %a %a %a", p.x[i], p.y[i], p.vx[i], p.vy[i])
  end
  local f = s:wall_load(1)
  t[#t + 1] = string.format("%a %a", f[1], f[2])
  return table.concat(t, "\n")
end

local dt = 1e-6
for _, case in ipairs{ { "plane", "contact" }, { "plane", "scale_mass" }, { "polyline", "contact" },
                       { "polyline", "scale_mass" } } do
  local floor, change = case[1], case[2]
  local a = pile(floor)
  a:run{ steps = 3000, dt = dt, progress = false } -- the disks settle onto the floor
  local load = -a:wall_load(1)[2] -- the disks push the floor down
  a:save(ckpt)
  local b = dem.load(ckpt)
  local apply = change == "contact" and function(s) s:contact(law(0.3)) end
                or function(s) s:scale_mass(4) end
  apply(a)
  apply(b)
  a:run{ steps = 2000, dt = dt, progress = false }
  b:run{ steps = 2000, dt = dt, progress = false }
  check.gt(load, 0, floor .. ", " .. change .. ": the floor carries the disks before the change (N)")
  check.eq(state(a), state(b), floor .. ", " .. change .. ": continued scene and reloaded scene, bit for bit")
end
os.remove(ckpt)
os.remove(dir)
check.done()
