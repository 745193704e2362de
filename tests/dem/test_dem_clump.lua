-- Clumps: rigid bodies of overlapping disks or spheres. The union's area, volume, centre and
-- inertia against closed forms (the lens of two disks, collinear spheres by exact slices), the
-- quadrature's error estimate bounding its error; the free asymmetric top (the intermediate-axis
-- flips, energy and |L| kept); a clump bouncing on a floor (energy kept without dissipation);
-- two clumps colliding with friction (momentum and angular momentum kept); no contact inside a
-- clump; every wall shape; and every bad value refused naming the call, the field and the value.
local check = grainlab.check
grainlab.threads(1)
local pi, sqrt = math.pi, math.sqrt

-- ---- the union against closed forms -------------------------------------------------------
-- Two disks of radius r, centres d apart: the union's area and polar moment by the circular
-- segment's integrals.
do
  local r, d = 1.0, 1.2
  local T = dem.clump_template{ members = { { offset = { -d / 2, 0 }, radius = r },
                                            { offset = { d / 2, 0 }, radius = r } } }
  local info = T:info()
  local a = d / 2
  local th = math.acos(a / r)
  local seg_area = r * r * (th - math.sin(th) * math.cos(th))
  local function I4(p) return 3 * p / 8 - math.sin(2 * p) / 4 + math.sin(4 * p) / 32 end
  local seg_yy = 2 / 3 * r ^ 4 * I4(th)
  local seg_xx = r ^ 4 / 2 * (th / 2 - math.sin(4 * th) / 8)
  local seg_x = 2 / 3 * (r * r - a * a) ^ 1.5
  local lens_J = 2 * (seg_xx - 2 * a * seg_x + a * a * seg_area + seg_yy)
  local A = 2 * pi * r * r - 2 * seg_area
  local J = 2 * (pi * r ^ 4 / 2 + pi * r * r * a * a) - lens_J
  local eA, eJ = math.abs(info.disks.area - A) / A, math.abs(info.disks.inertia - J) / J
  check.is_true(eA < 1e-5, string.format("lens union area: relative error %.2e < 1e-5", eA))
  check.is_true(eJ < 1e-5, string.format("lens union inertia: relative error %.2e < 1e-5", eJ))
  check.is_true(info.disks.error >= math.max(eA, eJ),
                string.format("lens: the error estimate %.2e bounds the error %.2e",
                              info.disks.error, math.max(eA, eJ)))
  check.near_abs(info.disks.centre[1], 0, 1e-9, "symmetric dimer: centre on the middle")
end

-- Collinear spheres of different radii along a skew axis u: a body of revolution, exact by slices
-- (the cross-section is the largest member's disk; Gauss on pieces between the switch points).
do
  local u = { 1 / sqrt(3), 1 / sqrt(3), 1 / sqrt(3) }
  local cs, rs = { -0.9, 0.1, 1.0 }, { 0.8, 0.6, 0.7 }
  local members = {}
  for k = 1, 3 do
    members[k] = { offset = { cs[k] * u[1] + 0.3, cs[k] * u[2], cs[k] * u[3] - 0.2 }, radius = rs[k] }
  end
  local info = dem.clump_template{ members = members, resolution = 256 }:info()
  local function q(x)
    local b = 0
    for k = 1, 3 do b = math.max(b, rs[k] ^ 2 - (x - cs[k]) ^ 2) end
    return b
  end
  local V, S1, Ia, Ib, N = 0, 0, 0, 0, 4000
  local lo, hi = -1.7, 1.7
  local h = (hi - lo) / N
  local gx, gw = { -sqrt(3 / 5), 0, sqrt(3 / 5) }, { 5 / 9, 8 / 9, 5 / 9 }
  for i = 0, N - 1 do
    for g = 1, 3 do
      local x = lo + (i + 0.5) * h + gx[g] * h / 2
      local qq, w = q(x), gw[g] * h / 2
      V, S1 = V + w * pi * qq, S1 + w * pi * qq * x
      Ia, Ib = Ia + w * pi * qq * qq / 2, Ib + w * pi * qq * (qq / 4 + x * x)
    end
  end
  local xc = S1 / V
  Ib = Ib - V * xc * xc
  local m = info.moments
  local worst = math.max(math.abs(info.volume - V) / V, math.abs(m[1] - Ia) / Ia,
                         math.abs(m[2] - Ib) / Ib, math.abs(m[3] - Ib) / Ib)
  check.is_true(worst < 1e-4, string.format("collinear spheres: volume and moments within %.2e < 1e-4", worst))
  check.is_true(info.error >= worst, string.format("collinear spheres: the estimate %.2e bounds %.2e",
                                                    info.error, worst))
  local dot = info.axes[1][1] * u[1] + info.axes[1][2] * u[2] + info.axes[1][3] * u[3]
  check.near(math.abs(dot), 1, 1e-9, "collinear spheres: the least principal axis is the line")
  check.near_abs(info.centre[1], 0.3 + xc * u[1], 5e-5, "collinear spheres: centre x")
  check.near_abs(info.centre[3], -0.2 + xc * u[3], 5e-5, "collinear spheres: centre z")
end

-- A single member is its disk or sphere, whatever the resolution.
do
  local info = dem.clump_template{ members = { { offset = { 0, 0, 0 }, radius = 2 } } }:info()
  check.near(info.volume, 4 / 3 * pi * 8, 1e-5, "one sphere: volume")
  check.near(info.moments[1], 2 / 5 * (4 / 3 * pi * 8) * 4, 1e-5, "one sphere: moment")
end

-- ---- the free asymmetric top: the intermediate-axis flip (Dzhanibekov) --------------------
-- Spun about its middle axis with a small part about the least, the body turns over every
-- half period. The times at which the middle axis' share of the spin changes sign are compared
-- with Euler's equations integrated by RK4 at 1e-4 s (a converged reference: the crossings move
-- by < 1e-9 s from 2e-4 s); energy and |L| are kept by the NO_SQUISH rotation.
do
  local s = dem.scene{ dim = 3, box = { { -10, -10, -10 }, { 10, 10, 10 } }, gravity = { 0, 0, 0 } }
  local T = dem.clump_template{ members = { { offset = { 0, 0, 0 }, radius = 1 },
                                            { offset = { 1.5, 0, 0 }, radius = 1 },
                                            { offset = { 0, 0.8, 0 }, radius = 0.9 } } }
  local info = T:info()
  local w = {}
  for d = 1, 3 do w[d] = 2 * info.axes[2][d] + 0.02 * info.axes[1][d] end
  local mat = grainlab.material{ density = 1000, young = 1e7, poisson = 0.3, friction = 0.5 }
  s:add_clump{ template = T, material = mat, position = { 0, 0, 0 }, spin = w }
  local function body_omega(c) -- the spin in the principal frame: R(q)^T L / I
    local q, L, I = c.orientation, c.angular_momentum, c.inertia
    local qw, x, y, z = q[1], q[2], q[3], q[4]
    local M = { { 1 - 2 * (y * y + z * z), 2 * (x * y - qw * z), 2 * (x * z + qw * y) },
                { 2 * (x * y + qw * z), 1 - 2 * (x * x + z * z), 2 * (y * z - qw * x) },
                { 2 * (x * z - qw * y), 2 * (y * z + qw * x), 1 - 2 * (x * x + y * y) } }
    local o = {}
    for k = 1, 3 do o[k] = (M[1][k] * L[1] + M[2][k] * L[2] + M[3][k] * L[3]) / I[k] end
    return o
  end
  local function norm(v) return sqrt(v[1] ^ 2 + v[2] ^ 2 + v[3] ^ 2) end
  local c0 = s:clump(1)
  local I, w0 = c0.inertia, body_omega(c0)
  check.near(w0[2], 2, 1e-12, "free top: the spin given about the middle principal axis")
  local function euler(v)
    return { (I[2] - I[3]) * v[2] * v[3] / I[1], (I[3] - I[1]) * v[3] * v[1] / I[2],
             (I[1] - I[2]) * v[1] * v[2] / I[3] }
  end
  local function add(a, b, h) return { a[1] + h * b[1], a[2] + h * b[2], a[3] + h * b[3] } end
  local ref, v, t, h = {}, { w0[1], w0[2], w0[3] }, 0, 1e-4
  while #ref < 3 do
    local k1 = euler(v)
    local k2 = euler(add(v, k1, h / 2))
    local k3 = euler(add(v, k2, h / 2))
    local k4 = euler(add(v, k3, h))
    local nv = {}
    for d = 1, 3 do nv[d] = v[d] + h / 6 * (k1[d] + 2 * k2[d] + 2 * k3[d] + k4[d]) end
    if nv[2] * v[2] < 0 then ref[#ref + 1] = t + h * v[2] / (v[2] - nv[2]) end
    v, t = nv, t + h
  end
  local E0, L0 = s:measure("energy").total, norm(c0.angular_momentum)
  local got, prev, dE, dL = {}, w0[2], 0, 0
  t = 0
  while #got < 3 and t < 60 do
    s:run{ steps = 10, dt = 1e-3, force = true }
    t = t + 1e-2
    local c = s:clump(1)
    local w2 = body_omega(c)[2]
    if w2 * prev < 0 then got[#got + 1] = t - 1e-2 + 1e-2 * prev / (prev - w2) end
    prev = w2
    dE = math.max(dE, math.abs(s:measure("energy").total - E0) / E0)
    dL = math.max(dL, math.abs(norm(c.angular_momentum) - L0) / L0)
  end
  for k = 1, 3 do
    check.near(got[k] or 0, ref[k], 1e-5, string.format("free top: flip %d at %.4f s (Euler's equations)", k, ref[k]))
  end
  check.is_true(dE < 1e-6, string.format("free top: energy kept to %.2e < 1e-6 over %.0f steps", dE, t * 1e3))
  check.is_true(dL < 1e-12, string.format("free top: |L| kept to %.2e < 1e-12", dL))
end

-- ---- a clump on a floor, and two clumps in collision --------------------------------------
local members2d = { { offset = { -0.05, 0 }, radius = 0.05 }, { offset = { 0.05, 0 }, radius = 0.05 },
                    { offset = { 0, 0.07 }, radius = 0.04 } }

-- Frictionless and undamped, a tumbling trimer bounces without losing energy (the error of the
-- step is second order: 3.4e-5 measured at the automatic step).
do
  local s = dem.scene{ dim = 2, box = { { -1, 0 }, { 1, 2 } }, gravity = { 0, -9.81 } }
  s:contact{ normal = "hertz" }
  local mat = grainlab.material{ density = 2500, young = 1e8, poisson = 0.3, friction = 0 }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_clump{ members = members2d, material = mat, position = { 0, 0.5 }, orientation = 0.3 }
  local E0 = s:measure("energy").total
  local dE, lowest = 0, 1
  for _ = 1, 50 do
    s:run{ time = 0.02 }
    dE = math.max(dE, math.abs(s:measure("energy").total - E0) / E0)
    lowest = math.min(lowest, s:clump(1).position[2])
  end
  check.is_true(lowest < 0.1, "floor: the trimer reached the floor (lowest centre " .. lowest .. " m)")
  check.is_true(dE < 2e-4, string.format("floor: energy kept to %.2e < 2e-4 through the bounces", dE))
  check.near_abs(s:clump(1).velocity[1], 0, 1e-12, "floor: frictionless, no sideways motion")
end

-- Total momentum and angular momentum (about the origin: orbital + the bodies' own) of two
-- clumps meeting off-centre. Frictionless, the contact forces act along the line of the members'
-- centres and both are kept to rounding. With friction, the tangential spring and rolling
-- resistance, the momentum still is; the angular momentum changes by the overlap times the
-- tangential force (each side's torque has the lever of its own radius, as for lone grains: the
-- two contact points are the overlap apart), here below 1 % of m v 0.2 m (measured 0.7 % in 2D).
local function momenta(s, dim)
  local P, Lz, L3 = { 0, 0, 0 }, 0, { 0, 0, 0 }
  for k = 1, s:clump_count() do
    local c = s:clump(k)
    local x, v, m = c.position, c.velocity, c.mass
    for d = 1, dim do P[d] = P[d] + m * v[d] end
    if dim == 2 then
      Lz = Lz + m * (x[1] * v[2] - x[2] * v[1]) + c.angular_momentum
    else
      local l = c.angular_momentum
      L3[1] = L3[1] + m * (x[2] * v[3] - x[3] * v[2]) + l[1]
      L3[2] = L3[2] + m * (x[3] * v[1] - x[1] * v[3]) + l[2]
      L3[3] = L3[3] + m * (x[1] * v[2] - x[2] * v[1]) + l[3]
    end
  end
  return P, dim == 2 and { 0, 0, Lz } or L3
end
-- One collision: the largest changes of momentum and angular momentum over 0.3 s relative to
-- m v and m v 0.2 m, and clump 1's velocity along x before and after.
local function collide(dim, friction, young)
  local s = dem.scene{ dim = dim, box = dim == 2 and { { -1, -1 }, { 1, 1 } } or { { -1, -1, -1 }, { 1, 1, 1 } } }
  if friction then
    s:contact{ normal = "hertz", damping = "viscous", restitution = 0.6, tangential = "spring",
               rolling_resistance = "epsd", rolling_friction = 0.1 }
  else
    s:contact{ normal = "hertz", damping = "viscous", restitution = 0.6 }
  end
  local mat = grainlab.material{ density = 2500, young = young, poisson = 0.3, friction = friction and 0.5 or 0 }
  local mem = {}
  for k, m in ipairs(members2d) do
    mem[k] = { offset = dim == 2 and m.offset or { 0.9 * m.offset[1], m.offset[2], 0.01 * (k - 2) },
               radius = m.radius }
  end
  local T = dem.clump_template{ members = mem }
  s:add_clump{ template = T, material = mat, position = dim == 2 and { -0.2, 0.03 } or { -0.2, 0.03, 0 },
               velocity = dim == 2 and { 1, 0 } or { 1, 0, 0.1 }, orientation = dim == 2 and 0.4 or nil,
               spin = dim == 2 and 3 or { 0, 0, 3 } }
  s:add_clump{ template = T, material = mat, position = dim == 2 and { 0.2, -0.03 } or { 0.2, -0.03, 0 },
               velocity = dim == 2 and { -1, 0 } or { -1, 0, 0 },
               orientation = dim == 2 and -1.1 or { axis = { 1, 1, 0 }, angle = 0.7 } }
  local P0, L0 = momenta(s, dim)
  local v0 = s:clump(1).velocity[1]
  s:run{ time = 0.3 }
  local P, L = momenta(s, dim)
  local scaleP = s:clump(1).mass * 1
  local dP, dL = 0, 0
  for d = 1, 3 do
    dP = math.max(dP, math.abs(P[d] - P0[d]) / scaleP)
    dL = math.max(dL, math.abs(L[d] - L0[d]) / (0.2 * scaleP))
  end
  return dP, dL, v0, s:clump(1).velocity[1]
end
for _, case in ipairs{ { 2, false }, { 3, false }, { 2, true }, { 3, true } } do
  local dim, friction = case[1], case[2]
  local dP, dL, v0, v1 = collide(dim, friction, 1e7)
  local tag = dim .. "D collision" .. (friction and " with friction: " or ": ")
  local Ltol = friction and 1e-2 or 1e-12
  check.is_true(v1 < 0.9 * v0, tag .. "the clumps met (vx " .. v1 .. ")")
  check.is_true(dP < 1e-12, string.format("%smomentum kept to %.2e < 1e-12 (of m v)", tag, dP))
  check.is_true(dL < Ltol, string.format("%sangular momentum kept to %.2e < %g (of m v 0.2 m)", tag, dL, Ltol))
  if friction then -- 100 times stiffer: overlaps 100^(2/5) = 6.3 times smaller, and so the change
    local _, dL_stiff = collide(dim, friction, 1e9)
    check.is_true(dL / dL_stiff > 4 and dL / dL_stiff < 9,
                  string.format("%sthe change of L follows the overlap: x %.2f from E to 100 E (6.3)", tag, dL / dL_stiff))
  end
end

-- ---- no contact inside a clump; every wall shape ------------------------------------------
do
  local s = dem.scene{ dim = 2, box = { { -1, -1 }, { 1, 1 } }, gravity = { 0, 0 } }
  s:contact{ normal = "hertz", tangential = "spring" }
  local mat = grainlab.material{ density = 2500, young = 1e8, poisson = 0.3, friction = 0.5 }
  s:add_clump{ members = members2d, material = mat, position = { 0, 0 } }
  s:run{ steps = 100, dt = 1e-5 }
  local c = s:clump(1)
  check.eq(c.velocity[1], 0, "members overlap: no force inside a clump (vx)")
  check.eq(c.spin, 0, "members overlap: no torque inside a clump")
  check.eq(s:measure("contacts").count or s:measure("contacts"), 0, "members overlap: no contact counted")
end

-- A trimer dropped onto each wall shape bounces off it (the body rises again).
local function bounces(dim, add_wall)
  local s = dem.scene{ dim = dim, box = dim == 2 and { { -1, -1 }, { 1, 1 } } or { { -1, -1, -1 }, { 1, 1, 1 } },
                       gravity = dim == 2 and { 0, -9.81 } or { 0, -9.81, 0 } }
  s:contact{ normal = "hertz", damping = "viscous", restitution = 0.8, tangential = "spring" }
  local mat = grainlab.material{ density = 2500, young = 1e8, poisson = 0.3, friction = 0.3 }
  add_wall(s, mat)
  local mem = {}
  for k, m in ipairs(members2d) do mem[k] = { offset = dim == 2 and m.offset or { m.offset[1], m.offset[2], 0 }, radius = m.radius } end
  s:add_clump{ members = mem, material = mat, position = dim == 2 and { 0, 0.3 } or { 0, 0.3, 0 } }
  local up, low = false, 1
  for _ = 1, 60 do
    s:run{ time = 0.01 }
    local c = s:clump(1)
    low = math.min(low, c.position[2])
    if c.velocity[2] > 0.5 then up = true end
  end
  return up, low
end
local walls = {
  { 2, "plane", function(s) s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } } end },
  { 2, "polyline", function(s) s:add_polyline{ points = { { -0.5, 0 }, { 0.5, 0 } } } end },
  { 2, "circle", function(s) s:add_cylinder{ center = { 0, 0.4 }, radius = 0.4 } end },
  { 3, "plane", function(s) s:add_wall{ point = { 0, 0, 0 }, normal = { 0, 1, 0 } } end },
  { 3, "mesh", function(s)
      s:add_mesh{ triangles = { { { -0.5, 0, -0.5 }, { 0.5, 0, -0.5 }, { 0.5, 0, 0.5 } },
                                { { -0.5, 0, -0.5 }, { 0.5, 0, 0.5 }, { -0.5, 0, 0.5 } } } } end },
  { 3, "cylinder", function(s) s:add_cylinder{ center = { 0, 0.4, 0 }, radius = 0.4, axis = { 0, 0, 1 } } end },
}
for _, w in ipairs(walls) do
  local up, low = bounces(w[1], w[3])
  check.is_true(up and low > -0.05, string.format("%dD %s: the clump bounces off it (lowest centre %.3f m)",
                                                  w[1], w[2], low))
end

-- ---- pouring: pack.clumps ----------------------------------------------------------------
-- Random sequential addition places every clump with no member overlapping another clump's and
-- every member inside the region, in 2D and 3D, the same placement for the same seed.
for _, dim in ipairs{ 2, 3 } do
  local function scene()
    return dem.scene{ dim = dim, box = dim == 2 and { { 0, 0 }, { 0.05, 0.05 } } or { { 0, 0, 0 }, { 0.05, 0.05, 0.05 } } }
  end
  local mat = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3, friction = 0.5 }
  local function member(x, r) return { offset = dim == 2 and { x, 0 } or { x, 0, 0 }, radius = r } end
  local D = dem.clump_template{ members = { member(-1.5e-3, 2e-3), member(1.5e-3, 2e-3) } }
  local R3 = dem.clump_template{ members = { member(0, 1.5e-3), member(2e-3, 1.5e-3), member(4e-3, 1.5e-3) } }
  local region = dim == 2 and { { 0.005, 0.005 }, { 0.045, 0.045 } } or { { 0.005, 0.005, 0.005 }, { 0.045, 0.045, 0.045 } }
  local s = scene()
  local ids, st = grainlab.pack.clumps(s, { n = 30, template = { D, R3 }, region = region, seed = 4, material = mat })
  check.eq(#ids, 30, dim .. "D pack.clumps: every clump placed")
  check.eq(s:clump_count(), 30, dim .. "D pack.clumps: the scene has them")
  local p = s:particles()
  local worst_gap, outside, kinds = math.huge, 0, {}
  for k = 1, s:clump_count() do kinds[#s:clump(k).members] = true end
  local body = {}
  for k = 1, s:clump_count() do for _, i in ipairs(s:clump(k).members) do body[i] = k end end
  local X = { p.x, p.y, p.z }
  for i = 1, p.count do
    for d = 1, dim do
      if X[d][i] - p.radius[i] < region[1][d] - 1e-12 or X[d][i] + p.radius[i] > region[2][d] + 1e-12 then outside = outside + 1 end
    end
    for j = i + 1, p.count do
      if body[i] ~= body[j] then
        local d2 = 0
        for d = 1, dim do d2 = d2 + (X[d][i] - X[d][j]) ^ 2 end
        worst_gap = math.min(worst_gap, math.sqrt(d2) - p.radius[i] - p.radius[j])
      end
    end
  end
  check.is_true(worst_gap >= 0, string.format("%dD pack.clumps: no overlap between clumps (least gap %.3g m)", dim, worst_gap))
  check.eq(outside, 0, dim .. "D pack.clumps: every member inside the region")
  check.is_true(kinds[2] and kinds[3], dim .. "D pack.clumps: both templates drawn")
  check.is_true(st.fraction > 0 and st.fraction < 1 and st.tries >= 30, dim .. "D pack.clumps: the report")
  local s2 = scene()
  grainlab.pack.clumps(s2, { n = 30, template = { D, R3 }, region = region, seed = 4, material = mat })
  check.eq(s2:particles().x[17], p.x[17], dim .. "D pack.clumps: the same seed, the same placement")
  check.errors(function() grainlab.pack.clumps(scene(), { n = 3, template = 5, material = mat }) end,
               "template", "a number for a template")
  check.errors(function() grainlab.pack.clumps(scene(), { n = 3, material = mat }) end, "template", "no template")
end
check.errors(function()
  local s = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } } }
  grainlab.pack.clumps(s, { n = 1, template = dem.clump_template{ members = { { offset = { 0, 0 }, radius = 0.1 } } },
                            material = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3 } })
end, "2D", "a 2D template in a 3D scene")
check.errors(function()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }
  grainlab.pack.clumps(s, { n = 100, template = dem.clump_template{ members = { { offset = { 0, 0 }, radius = 0.2 } } },
                            max_tries = 2000, material = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3 } })
end, "too full", "more clumps than the region holds")

-- ---- refusals -------------------------------------------------------------------------------
do
  local mat = grainlab.material{ density = 2500, young = 1e8, poisson = 0.3, friction = 0.5 }
  local s2 = dem.scene{ dim = 2, box = { { -1, -1 }, { 1, 1 } } }
  local s3 = dem.scene{ dim = 3, box = { { -1, -1, -1 }, { 1, 1, 1 } } }
  local T2 = dem.clump_template{ members = members2d }
  check.errors(function() dem.clump_template{ members = {} } end, "members", "no members")
  check.errors(function() dem.clump_template{ members = { { offset = { 0, 0 }, radius = -1 } } } end,
               "radius", "a negative radius")
  check.errors(function()
    dem.clump_template{ members = { { offset = { 0, 0 }, radius = 0.1 }, { offset = { 1, 0 }, radius = 0.1 } } }
  end, "connected", "members apart")
  check.errors(function()
    dem.clump_template{ members = { { offset = { 0, 0 }, radius = 0.1 }, { offset = { 0, 0, 0 }, radius = 0.1 } } }
  end, "offset", "offsets of two dimensions")
  check.errors(function() s3:add_clump{ template = T2, material = mat, position = { 0, 0, 0 } } end,
               "2D", "a 2D template in a 3D scene")
  check.errors(function() s2:add_clump{ template = T2, material = mat, position = { 0, 0, 0 } } end,
               "position", "a 3-vector in a 2D scene")
  check.errors(function() s2:add_clump{ material = mat, position = { 0, 0 } } end, "template", "no shape")
  check.errors(function() s2:add_clump{ template = T2, material = mat, position = { 0, 0 }, colour = 1 } end,
               "colour", "an unknown field")
  check.errors(function()
    s3:add_clump{ members = { { offset = { 0, 0, 0 }, radius = 0.1 } }, material = mat, position = { 0, 0, 0 },
                  orientation = { 1, 1, 0, 0 } }
  end, "unit", "a quaternion not of unit length")
  s2:add_clump{ template = T2, material = mat, position = { 0, 0 } }
  check.errors(function() s2:set_velocity(1, { 1, 0 }) end, "member of clump 1", "moving a member alone")
  check.errors(function() s2:clump(2) end, "clump", "a clump that does not exist")
  check.errors(function() s2:run{ steps = 1, integrator = "gear" } end, "gear", "gear")
  check.errors(function() s2:run{ steps = 1, integrator = "position_verlet" } end, "position_verlet",
               "position Verlet")
  local sp = dem.scene{ dim = 2, box = { { -1, -1 }, { 1, 1 } }, periodic = { true, false } }
  sp:add_clump{ template = T2, material = mat, position = { 0, 0 } }
  check.errors(function() sp:run{ steps = 1 } end, "periodic", "a periodic box")
end

check.done()
