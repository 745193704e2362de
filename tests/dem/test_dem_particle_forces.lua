-- s:particles().fx/fy/fz: the total force of the last evaluation (what scripts/bench/vs_lammps.sh
-- compares with LAMMPS's dump fx fy). Two overlapping disks and one on the floor, under gravity:
-- each force must be the Hertz force 4/3 E* sqrt(R*) delta^(3/2) plus the weight. 3D gives fz.
local E, nu, rho = 30e9, 0.3, 2650
local mat = grainlab.material{ density = rho, young = E, poisson = nu, friction = 0.45 }
local s = dem.scene{ dim = 2, box = {{0, 0}, {0.01, 0.01}}, gravity = {0, -9.81} }
s:add_wall{ point = {0, 0}, normal = {0, 1} }
local r1, r2, d = 1e-3, 0.6e-3, 1e-7
s:add_disk{ pos = {0.004, 0.005}, radius = r1, material = mat }
s:add_disk{ pos = {0.004 + r1 + r2 - d, 0.005}, radius = r2, material = mat }
s:add_disk{ pos = {0.008, 0.001}, radius = r1, material = mat }
local p0 = s:particles()
assert(p0.fx and p0.fy and p0.fz == nil, "2D scenes give fx, fy only")
for i = 1, 3 do assert(p0.fx[i] == 0 and p0.fy[i] == 0, "no force before any evaluation") end
s:contact{ normal = "hertz", tangential = "spring" }
s:run{ steps = 1, dt = 1e-20, progress = false }
local p = s:particles()
local Es = E / (2 * (1 - nu * nu))
local pair = 4 / 3 * Es * math.sqrt(r1 * r2 / (r1 + r2)) * d ^ 1.5
local function near(a, b, what)
  assert(math.abs(a - b) <= 1e-9 * math.abs(b) + 1e-18, string.format("%s: %.17g, expected %.17g", what, a, b))
end
near(p.fx[1], -pair, "fx of disk 1")
near(p.fx[2], pair, "fx of disk 2")
near(p.fy[1], -p.mass[1] * 9.81, "fy of disk 1 (its weight)")
near(p.fy[3], -p.mass[3] * 9.81, "fy of disk 3 (just touching the floor: its weight)")
-- without gravity and contacts, no force at all
local t = dem.scene{ dim = 2, box = {{0, 0}, {0.01, 0.01}} }
t:add_wall{ point = {0, 0}, normal = {0, 1} }
t:add_disk{ pos = {0.005, 0.002}, radius = r1, material = mat }
t:contact{ normal = "hertz" }
t:run{ steps = 1, dt = 1e-20, progress = false }
near(t:particles().fy[1], 0, "a free disk without gravity")
local u = dem.scene{ dim = 3, box = {{0, 0, 0}, {0.01, 0.01, 0.01}}, gravity = {0, 0, -9.81} }
u:add_sphere{ pos = {0.005, 0.005, 0.005}, radius = r1, material = mat }
u:run{ steps = 1, dt = 1e-20, progress = false }
local q = u:particles()
near(q.fz[1], -q.mass[1] * 9.81, "fz of a falling sphere")
near(q.fx[1], 0, "fx of a falling sphere")
print("ok")
