-- The biaxial laboratory's plate preload: before the biaxial compression starts, each rigid
-- plate carries the confining load p W t within 5% (grainlab.biax.start), on a 300-disk sample
-- under direct pressure and under the membrane. Also the force-controlled wall on its own: a
-- plate pressed onto a confined pair of disks settles on the commanded force, and s:wall_servo /
-- s:wall_force refuse bad input.
local check = grainlab.check
local biax = grainlab.biax

-- ---- the wall servo alone: a plate pushing two stacked disks onto a fixed floor ------------
do
  local s = dem.scene{ box = { { -0.01, -0.01 }, { 0.01, 0.02 } }, gravity = { 0, 0 }, thickness = 1e-3 }
  s:contact{ normal = "hertz", damping = "brilliantov", damping_time = 0.002 }
  local m = grainlab.material{ density = 2650, young = 1e9, poisson = 0.3 }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  local top = s:add_wall{ point = { 0, 0.0045 }, normal = { 0, -1 } }
  s:add_disk{ pos = { 0, 0.001 }, radius = 0.001, material = m }
  s:add_disk{ pos = { 0, 0.003 }, radius = 0.001, material = m }
  s:scale_mass(1e5)
  s:drag(50)
  s:wall_servo(top, { force = 2.0, mass = 1, rate = 200 })
  s:run{ steps = 30000, dt = 1e-5, impact_velocity = 1e-3, progress = false }
  check.near(s:wall_force(top), 2.0, 1e-3, "servoed plate force")
  check.near(s:wall_force(1), 2.0, 1e-3, "floor force")
  s:wall_servo(top) -- off: the plate keeps its (now tiny) velocity
  check.errors(function() s:wall_servo(top, { force = -1, mass = 1 }) end,
    "bad field 'force' in argument #2 to 'wall_servo'", "negative force")
  check.errors(function() s:wall_servo(top, { force = 1 }) end, "'mass'", "missing mass")
  check.errors(function() s:wall_servo(top, { force = 1, mass = 1, rat = 2 }) end, "unknown field 'rat'", "typo")
  check.errors(function() s:wall_force(7) end, "no wall 7", "no such wall")
end

-- ---- the biaxial plates ------------------------------------------------------------------------
local st = biax.prepare{ n = 300, seed = 2, ramp_steps = 10000, hold_steps = 5000,
                         friction_steps = 3000, rest_steps = 3000 }
for _, bc in ipairs { "pressure", "membrane" } do
  local s, lab = biax.setup(st, bc, {})
  local b, t = biax.start(lab)
  print(string.format("%-8s plate stress / p at the start: bottom %.3f, top %.3f after %d servo steps",
                      bc, b, t, lab.servo_steps))
  check.is_true(lab.servo_converged, bc .. " servo converged")
  check.near(b, 1, 0.05, bc .. " bottom plate load / p W t")
  check.near(t, 1, 0.05, bc .. " top plate load / p W t")
end
check.done()
