-- MPM frictional multi-grain contact (contact model "friction", Sec. 3 of Bardenhagen, Brackbill
-- & Sulsky 1998, Eqs. 12-24): an isolated grain is not corrected, frictionless head-on collisions
-- conserve momentum and separate, friction limits the tangential transfer of a glancing collision,
-- and the binding's argument errors.
local check = grainlab.check
local mat = mpm.material{ density = 3000, shear = 2.5e6, bulk = 10e6 } -- the paper's incline disk

-- An isolated grain's field equals the centre-of-mass field: with "friction" it evolves exactly
-- as with "noslip" (two grains far apart, spinning, under gravity; measured difference 0).
local function isolated(model)
  local m = mpm.scene{ cells = { 20, 20 }, size = { 2, 2 }, gravity = { 0.3, -2 } }
  m:add_disk{ center = { 0.6, 1.2 }, radius = 0.3, material = mat, velocity = { 1.5, -0.5 }, omega = 2 }
  m:add_disk{ center = { 1.5, 0.5 }, radius = 0.25, material = mat, velocity = { -0.5, 0.2 } }
  if model == "friction" then m:contact{ model = "friction", mu = 0.3 } end
  m:run{ time = 0.2 }
  return m:points()
end
local a, b = isolated("noslip"), isolated("friction")
local dmax = 0
for i = 1, a.count do
  dmax = math.max(dmax, math.abs(a.x[i] - b.x[i]), math.abs(a.y[i] - b.y[i]),
    math.abs(a.vx[i] - b.vx[i]), math.abs(a.vy[i] - b.vy[i]))
end
check.near_abs(dmax, 0, 1e-12, "isolated grain: friction equals noslip")

-- Two disks R = 0.4 (4 cells) on one grid row; B offset by `off` across the line of motion.
local function collide(mu, va, vb, off, time)
  local m = mpm.scene{ cells = { 60, 40 }, size = { 6, 4 } }
  local A = m:add_disk{ center = { 2.45, 2 }, radius = 0.4, material = mat, velocity = { va, 0 } }
  local B = m:add_disk{ center = { 3.55, 2 + off }, radius = 0.4, material = mat, velocity = { vb, 0 } }
  if mu then m:contact{ model = "friction", mu = mu } end
  local r = { p0 = m:measure("momentum").linear, ke0 = m:measure("energy").kinetic,
              ref = m:grain(A).mass * math.abs(va) }
  m:run{ time = time }
  r.p1 = m:measure("momentum").linear
  r.ke1 = m:measure("energy").kinetic
  r.a, r.b = m:grain(A), m:grain(B)
  r.dist = math.sqrt((r.b.center[1] - r.a.center[1]) ^ 2 + (r.b.center[2] - r.a.center[2]) ^ 2)
  return r
end

-- Frictionless head-on, a moving disk on one at rest: the normals (the grain's mass gradient
-- against everything else's) are opposite at every shared node, so the momentum along the line
-- of centres is conserved (measured 1e-16 relative); the disks separate, A slower than B.
local r = collide(0, 2, 0, 0, 0.5)
check.near_abs(r.p1[1], r.p0[1], 1e-6 * r.ref, "head-on mu = 0: momentum along the line of centres")
check.near_abs(r.p1[2], 0, 1e-6 * r.ref, "head-on mu = 0: no transverse momentum")
check.lt(r.a.velocity[1], r.b.velocity[1], "head-on mu = 0: the disks separate")
check.gt(r.dist, 0.8 + 0.3, "head-on mu = 0: gap larger than the contact range after the rebound")
check.lt(r.ke1, r.ke0, "head-on mu = 0: no energy created") -- measured 0.78 (the rest is vibration)
-- Symmetric head-on: both rebound at 0.943 of the impact speed (noslip: 0.945).
r = collide(0, 1, -1, 0, 0.5)
check.near_abs(r.p1[1], r.p0[1], 1e-6 * r.ref, "symmetric head-on: momentum")
check.near(r.a.velocity[1], -0.943, 0.02, "symmetric head-on: rebound speed")

-- Glancing collision (B offset by 0.5 = 5/8 of the contact distance): the tangential momentum
-- given to B, along the tangent at first contact, grows with mu up to the noslip value (measured
-- |v_B . t| at t = 1 s: mu = 0: 0.069, mu = 0.3: 0.221, noslip: 0.292). Noslip glues the disks: they
-- still share nodes at t = 1 s (centre distance 0.97 < 0.8 + 2 cells), where friction separates them.
local nx, ny = math.sqrt(0.8 ^ 2 - 0.5 ^ 2) / 0.8, 0.5 / 0.8
local function tangential(res) return math.abs(-ny * res.b.velocity[1] + nx * res.b.velocity[2]) end
local ns, f3, f0 = collide(nil, 2, 0, 0.5, 1), collide(0.3, 2, 0, 0.5, 1), collide(0, 2, 0, 0.5, 1)
check.lt(tangential(f3), 0.9 * tangential(ns), "glancing: mu = 0.3 transfers less tangential momentum than noslip")
check.lt(tangential(f0), 0.5 * tangential(f3), "glancing: mu = 0 transfers less than mu = 0.3")
check.lt(f3.b.omega, ns.b.omega, "glancing: friction spins B less than noslip")
check.near_abs(f3.p1[1], f3.p0[1], 1e-6 * f3.ref, "glancing: x momentum")
check.near_abs(f3.p1[2], f3.p0[2], 1e-6 * f3.ref, "glancing: y momentum")
check.lt(ns.dist, 1.0, "glancing: noslip keeps the disks stuck together")
check.gt(f3.dist, 1.4, "glancing: friction lets them separate")

-- Argument errors and the scene's report of the model.
local m = mpm.scene{ cells = { 10, 10 }, size = { 1, 1 } }
check.errors(function() m:contact{ model = "friction", mu = -0.1 } end,
  "bad field 'mu' in argument #1 to 'contact' (non-negative number expected, got -0.1)", "negative mu")
check.errors(function() m:contact{ model = "friction" } end,
  "bad field 'mu' in argument #1 to 'contact' (non-negative number expected, got nil)", "friction needs mu")
check.errors(function() m:contact{ model = "coulomb", mu = 0.3 } end,
  "bad field 'model' in argument #1 to 'contact' (one of 'noslip', 'friction' expected, got 'coulomb')", "unknown model")
check.errors(function() m:contact{ model = "friction", mu = 0.3, mu_s = 1 } end,
  "bad argument #1 to 'contact' (unknown field 'mu_s'", "unknown field")
m:contact{ model = "friction", mu = 0.3 }
check.eq(m:info().contact, "friction", "info: contact")
check.eq(m:info().mu, 0.3, "info: mu")
m:contact{ model = "noslip" }
check.eq(m:info().contact, "noslip", "back to noslip")
check.eq(m:info().mu, 0, "noslip: mu 0")
check.done()
