-- MPM conservation with the noslip (single centre-of-mass field) contact model: a free elastic
-- disk translating and spinning, two disks colliding head-on, a disk falling under gravity.
local check = grainlab.check
local mat = mpm.material{ density = 3000, shear = 2.5e6, bulk = 10e6 } -- the paper's incline disk

-- Translation: a free disk keeps its linear momentum to machine precision (FLIP, Eq. 11:
-- sum_p m_p dv_p = dt sum_i f_i = 0) and moves rigidly.
local m = mpm.scene{ cells = { 20, 20 }, size = { 2, 2 } }
local g = m:add_disk{ center = { 0.7, 1 }, radius = 0.3, material = mat, velocity = { 1.5, -0.5 } }
local p0 = m:measure("momentum").linear
m:run{ time = 0.2 }
local p1 = m:measure("momentum").linear
check.near_abs(p1[1], p0[1], 1e-12 * math.abs(p0[1]), "translation: x momentum")
check.near_abs(p1[2], p0[2], 1e-12 * math.abs(p0[1]), "translation: y momentum")
local c = m:grain(g).center
check.near(c[1], 0.7 + 1.5 * 0.2, 1e-9, "translation: x of the centre of mass")
check.near(c[2], 1 - 0.5 * 0.2, 1e-9, "translation: y of the centre of mass")
check.near_abs(m:measure("energy").elastic, 0, 1e-12, "translation: no strain")

-- Spin: omega R = 1 m/s (c = 67 m/s), one radian of rotation. FLIP with linear shape functions
-- does not conserve angular momentum exactly; measured loss 3.8% (MUSL, 10 cells across, 2 x 2
-- points per cell); tolerance 5%. Linear momentum stays at machine precision.
m = mpm.scene{ cells = { 20, 20 }, size = { 2, 2 } }
g = m:add_disk{ center = { 1, 1 }, radius = 0.5, material = mat, omega = 2 }
local L0 = m:grain(g).angular_momentum
local e0 = m:measure("energy").total
m:run{ time = 0.5 }
check.near(m:grain(g).angular_momentum, L0, 0.05, "spin: angular momentum")
check.near(m:grain(g).omega, 2, 0.06, "spin: omega")
check.near(m:measure("energy").total, e0, 0.01, "spin: total energy")
check.near_abs(m:measure("momentum").linear[1], 0, 1e-12 * L0, "spin: no drift")

-- Head-on collision with noslip: the disks stick; total momentum conserved to 1e-6 relative.
m = mpm.scene{ cells = { 40, 20 }, size = { 4, 2 } }
local a = m:add_disk{ center = { 1.2, 1 }, radius = 0.4, material = mat, velocity = { 3, 0 } }
local b = m:add_disk{ center = { 2.8, 1 }, radius = 0.3, material = mat, velocity = { -2, 0 } }
p0 = m:measure("momentum").linear
m:run{ time = 0.4 }
p1 = m:measure("momentum").linear
check.near(p1[1], p0[1], 1e-6, "collision: x momentum")
check.near_abs(p1[2], 0, 1e-6 * math.abs(p0[1]), "collision: y momentum")
local ga, gb = m:grain(a), m:grain(b)
check.lt(ga.velocity[1], 3, "collision: disk a slowed down")
check.gt(gb.velocity[1], -2, "collision: disk b slowed down")

-- Free fall: every node accelerates at exactly g; with the symplectic position update (Eq. 10
-- uses v^{n+1}) a fixed step gives y = y0 - g dt^2 n (n + 1) / 2 = y0 - g (t^2 + t dt) / 2.
local gy = 9.8
m = mpm.scene{ cells = { 20, 40 }, size = { 2, 4 }, gravity = { 0, -gy } }
g = m:add_disk{ center = { 1, 3.4 }, radius = 0.3, material = mat }
local y0 = m:grain(g).center[2]
local dt = m:timestep().dt_auto
local n = math.floor(0.5 / dt)
m:run{ steps = n, dt = dt }
local t = n * dt
check.near(m:grain(g).center[2] - y0, -gy * (t * t + t * dt) / 2, 1e-9, "fall: discrete g t^2 / 2")
check.near(m:grain(g).center[2] - y0, -gy * t * t / 2, 2 * dt / t, "fall: g t^2 / 2")
check.near(m:grain(g).velocity[2], -gy * t, 1e-9, "fall: velocity g t")
check.done()
