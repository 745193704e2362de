-- s:contact{ damping = "brilliantov", restitution = e, impact_velocity = v }: every pair gets its
-- own damping time T = lambda(e) (m*/K)^(2/5) v^(-1/5), K = 4/3 E* sqrt(R*), so a head-on impact
-- at v rebounds with e whatever the radii, masses and materials (the kernel test
-- tests/dem/test_restitution.c sweeps the cases; here the binding). Re-derived here: the ratio of
-- two pairs' T from the closed form, and the measured e of an unequal pair and of a wall impact.
local check = grainlab.check
grainlab.threads(1)

local pi = math.pi
local quartz = { density = 2650, young = 30e9, poisson = 0.3 }
local stiff = { density = 2650, young = 70e9, poisson = 0.3 }
local function estar(a, b) return 1 / ((1 - a.poisson ^ 2) / a.young + (1 - b.poisson ^ 2) / b.young) end
local function mass(m, r) return m.density * 4 / 3 * pi * r ^ 3 end -- 2D without thickness: spheres

-- The contact comes first, as in the README: nothing is solved from the particles.
local s = dem.scene{ dim = 2, box = { { -0.01, -0.01 }, { 0.01, 0.01 } } }
check.eq(s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.7, impact_velocity = 1 }, nil,
         "contact from a restitution before any particle (returns nothing: T is per pair)")
local mq, ms = grainlab.material(quartz), grainlab.material(stiff)
local r1, r2, v = 0.7e-3, 1.3e-3, 1
local gap = 1e-7
s:add_disk{ pos = { -r1 - gap / 2, 0 }, radius = r1, material = mq, vel = { v / 2, 0 } }
s:add_disk{ pos = { r2 + gap / 2, 0 }, radius = r2, material = ms, vel = { -v / 2, 0 } }
s:add_disk{ pos = { 0, 0.005 }, radius = 1e-3, material = mq }
s:add_disk{ pos = { 0.004, 0.005 }, radius = 1e-3, material = mq }
s:add_wall{ point = { 0, -0.008 }, normal = { 0, 1 }, material = ms }

-- T of (1, 2) against T of (3, 4) from the closed form
local function T_ratio()
  local ma, mb, mc = mass(quartz, r1), mass(stiff, r2), mass(quartz, 1e-3)
  local function scale(m_eff, K) return (m_eff / K) ^ 0.4 end
  local a = scale(ma * mb / (ma + mb), 4 / 3 * estar(quartz, stiff) * math.sqrt(r1 * r2 / (r1 + r2)))
  local b = scale(mc / 2, 4 / 3 * estar(quartz, quartz) * math.sqrt(0.5e-3))
  return a / b
end
local T12, T34 = s:damping_time(1, 2), s:damping_time(3, 4)
check.near(T12 / T34, T_ratio(), 1e-12, "T ratio of two pairs = ((m*/K)_12 / (m*/K)_34)^(2/5)")
local Tw = s:damping_time(3, { wall = 1 })
local mc = mass(quartz, 1e-3)
check.near(Tw / T34, ((mc / (4 / 3 * estar(quartz, stiff) * math.sqrt(1e-3))) /
                      (mc / 2 / (4 / 3 * estar(quartz, quartz) * math.sqrt(0.5e-3)))) ^ 0.4, 1e-12,
           "a wall pair: R* = r, m* = m, E* with the wall's material")
check.eq(s:damping_time(1, 2), s:damping_time(2, 1), "T is symmetric")

-- the unequal pair collides at v: e = 0.7 (the mean-pair solve gave 0.593)
local dt = s:timestep{ impact_velocity = v }.contact_time / 400
s:run{ time = gap / v + 6 * 400 * dt, dt = dt, progress = false }
local p = s:particles()
check.near_abs((p.vx[2] - p.vx[1]) / v, 0.7, 1e-3, "radii 0.7/1.3 mm, E 30/70 GPa: e at the impact velocity")

-- a disk dropped on the wall at v (its own material: E* of the pair quartz/quartz)
local w = dem.scene{ dim = 2, box = { { -0.01, -0.01 }, { 0.01, 0.01 } } }
w:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.3, impact_velocity = 2 }
w:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
w:add_disk{ pos = { 0, 1e-3 + gap }, radius = 1e-3, material = mq, vel = { 0, -2 } }
dt = w:timestep{ impact_velocity = 2 }.contact_time / 400
w:run{ time = gap / 2 + 6 * 400 * dt, dt = dt, progress = false }
check.near_abs(w:particles().vy[1] / 2, 0.3, 1e-3, "disk against a wall: e at the impact velocity")

-- a fixed T is still one T for every pair, and returned
local f = dem.scene{ dim = 2, box = { { -0.01, -0.01 }, { 0.01, 0.01 } } }
check.eq(f:contact{ normal = "hertz", damping = "brilliantov", damping_time = 2e-6 }, 2e-6, "damping_time returned")
f:add_disk{ pos = { 0, 0 }, radius = 0.7e-3, material = mq }
f:add_disk{ pos = { 0.003, 0 }, radius = 1.3e-3, material = ms }
check.eq(f:damping_time(1, 2), 2e-6, "a fixed damping_time holds for every pair")

-- nothing silently accepted
check.errors(function() f:contact{ damping = "brilliantov", damping_time = 1e-6, restitution = 0.5 } end,
             "give damping_time (one T for every pair) or restitution (a T per pair), not both", "both")
check.errors(function() f:contact{ damping = "brilliantov", damping_time = 1e-6, impact_velocity = 2 } end,
             "bad field 'impact_velocity' in argument #1 to 'contact' (nothing when 'damping_time' is given (the speed at which a restitution holds)", "impact_velocity with damping_time")
check.errors(function() f:damping_time(1, 3) end, "particle id in [1, 2] expected, got 3", "pair out of range")
check.errors(function() f:damping_time(1, { wall = 1 }) end, "wall 1 out of range", "no such wall")
local nd = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }
nd:add_disk{ pos = { 0.5, 0.5 }, radius = 0.01, material = mq }
nd:add_disk{ pos = { 0.6, 0.5 }, radius = 0.01, material = mq }
check.errors(function() nd:damping_time(1, 2) end, "the contact law has no brilliantov damping", "no damping")

check.done()
