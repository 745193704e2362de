-- A material asking restitution 0.5 under contacts without damping: the first run warns once
-- (the collision is elastic); a second run, and a scene with viscous damping, say nothing.
-- Prints the head-on rebound, so the warning's claim (e = 1) is checked too.
local function pair(damping)
  local s = dem.scene{ dim = 2, box = { { -0.01, -0.01 }, { 0.01, 0.01 } } }
  local m = grainlab.material{ density = 2500, young = 1e7, restitution = 0.5 }
  s:contact{ normal = "hertz", damping = damping, restitution = damping ~= "none" and 0.5 or nil,
             impact_velocity = damping ~= "none" and 1 or nil }
  s:add_disk{ pos = { -1.1e-3, 0 }, radius = 1e-3, material = m, vel = { 0.5, 0 } }
  s:add_disk{ pos = { 1.1e-3, 0 }, radius = 1e-3, material = m, vel = { -0.5, 0 } }
  return s
end
local s = pair("none")
s:run{ time = 1e-3 }
s:run{ time = 1e-3 }
local v = s:particles().vx
print("e", string.format("%.4f", (v[2] - v[1]) / 1.0))
pair("viscous"):run{ time = 1e-3 }
