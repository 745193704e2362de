-- Walls beyond planes (docs/dem.md "Walls"): segments, polylines, triangles, circles and
-- cylinders, moving and turning, against closed forms. Each check states its tolerance.
--  1. a disk at rest inside a circle under gravity: the wall carries m g, no torque (1e-6);
--  2. a disk on a drum that starts turning: friction drags it; while it slips the contact point
--     gains 7/2 mu g (a sphere, I = 2/5 m r^2), so slip ends at t* = U / (7/2 mu g) with
--     v = 2U/7 and omega = 5U/(7r), U = Omega R_drum the wall speed (1.5%, the track is curved
--     by x/R ~ 1e-3); and m dv = the impulse of the reported wall load and gravity (trapezoid of
--     the step forces, the velocity-Verlet update: 1e-9);
--  3. a disk thrown at a segment's end point along the diagonal bounces straight back (the
--     contact normal passes through the end point: v' = -v, 1e-9 in direction), and one passing
--     off-axis sees the normal (x - e)/|x - e| at every contact;
--  4. a disk resting on a straight polyline over the shared vertex, and a little to its side,
--     feels one force m g (one contact), as on a plane; one in a concave V corner feels two;
--  5. a sphere dropped on a two-triangle mesh (over the shared edge and a corner) moves as on the
--     equivalent plane (1e-12 m);
--  6. a sphere resting inside a horizontal cylinder and on top of one (outside) carries m g; one
--     beyond a finite post's end touches its rim, the normal through the rim point (1e-12);
--  7. Newton's third law: disks in a rotating polygon, force (frictional: from the particles' total
--     forces) and torque (frictionless: from the contact list) equal and opposite to round-off;
--  8. 1 and 2 threads give the same bits for a wall with more than 4096 candidates (the kernel's
--     parallel loop), particles and wall load alike;
--  9. a turning flat wall (one segment, 2D; a two-triangle square, 3D): after t the contact
--     normal is the first one turned by omega t (1e-12).
local check = grainlab.check
local g = 9.81

-- 1. -------------------------------------------------------------------------------------------
do
  local s = dem.scene{ dim = 2, box = { { -0.06, -0.06 }, { 0.06, 0.06 } }, gravity = { 0, -g } }
  s:contact{ normal = "linear", stiffness = 1e5, damping = "viscous" }
  s:add_disk{ pos = { 0, -0.039 }, radius = 0.01 }
  local w = s:add_cylinder{ center = { 0, 0 }, radius = 0.05 }
  s:run{ time = 0.3 }
  local f, t = s:wall_load(w)
  local m = s:particles().mass[1]
  check.near(f[2], -m * g, 1e-6, "disk in a circle: the wall carries m g")
  check.near_abs(f[1], 0, 1e-9 * m * g, "disk in a circle: no sideways force")
  check.near_abs(t, 0, 1e-9 * m * g * 0.05, "disk in a circle: no torque (a radial force)")
  check.near(s:wall_force(w), m * g, 1e-6, "disk in a circle: wall_force is the normal force")
  check.eq(s:measure("contacts").count, 1, "disk in a circle: one contact")
end

-- 2. -------------------------------------------------------------------------------------------
do
  local Rd, r, mu, Omega, t1 = 0.05, 0.01, 0.5, 1.0, 0.05
  local U = Omega * Rd
  local mat = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3, friction = mu }
  local s = dem.scene{ dim = 2, box = { { -0.06, -0.06 }, { 0.06, 0.06 } }, gravity = { 0, -g } }
  s:contact{ normal = "linear", stiffness = 1e5, damping = "viscous", tangential = "coulomb_regularized",
             v_r = 1e-5 }
  s:add_disk{ pos = { 0, -(Rd - r) }, radius = r, material = mat }
  -- at rest until t1 (settling), then turning at Omega (a step within 1e-9 s)
  local w = s:add_cylinder{ center = { 0, 0 }, radius = Rd, material = mat,
                            motion = { { 0, 0, 0, 0 }, { t1, 0, 0, 0 }, { t1 + 1e-9, 0, 0, Omega } } }
  local dt = 2e-6
  s:run{ time = t1, dt = dt }
  local P = s:particles()
  local m, v0 = P.mass[1], P.vx[1]
  check.near_abs(v0, 0, 1e-6, "drum: settled before it turns")
  -- impulse of the contact force (minus the wall load) over the slipping phase, trapezoid rule
  local tstar = U / (3.5 * mu * g)
  local steps = math.floor(1.5 * tstar / dt)
  local imp, fprev = 0, -s:wall_load(w)[1]
  s:run{ steps = steps, dt = dt, every = 1, on_step = function(sc)
    local fx = -sc:wall_load(w)[1]
    imp = imp + 0.5 * dt * (fprev + fx)
    fprev = fx
  end }
  P = s:particles()
  check.near(m * (P.vx[1] - v0), imp, 1e-9, "drum: m dv = impulse of the wall's reaction")
  check.near(P.vx[1], 2 * U / 7, 0.015, "drum: v = 2U/7 when the slip ends")
  check.near(P.omega[1], 5 * U / (7 * r), 0.015, "drum: omega = 5U/(7r) when the slip ends")
  check.near(P.vx[1] + P.omega[1] * r, U, 0.015, "drum: the contact point moves with the wall")
end

-- 3. -------------------------------------------------------------------------------------------
do
  local r, v = 0.01, 0.5
  local function scene(x, y, vx, vy)
    local s = dem.scene{ dim = 2, box = { { -1, -1 }, { 1, 1 } }, gravity = { 0, 0 } }
    s:contact{ normal = "linear", stiffness = 1e5 }
    s:add_disk{ pos = { x, y }, radius = r, vel = { vx, vy } }
    s:add_polyline{ points = { { -0.5, 0 }, { 0, 0 } } }
    return s
  end
  -- 1 mm from the end point at 0.5 m/s: contact from 2 ms for about t_c = pi sqrt(m/k) = 1 ms
  local c = (r + 1e-3) / math.sqrt(2)
  local s = scene(c, c, -v / math.sqrt(2), -v / math.sqrt(2))
  s:run{ time = 0.005, dt = 1e-6 }
  local P = s:particles()
  -- the direction exactly reversed; the speed within the step's energy error (Verlet, O(dt^2))
  check.near(P.vy[1] / P.vx[1], 1, 1e-12, "end point: bounces straight back (direction)")
  check.near(math.sqrt(P.vx[1] ^ 2 + P.vy[1] ^ 2), v, 1e-5, "end point: elastic (speed)")
  check.gt(P.vx[1], 0, "end point: moving away")
  -- off-axis: the normal is (x - e)/|x - e| whenever the disk touches the end point e = (0, 0)
  s = scene(r + 2e-3, 0.004, -v, 0)
  local seen, worst = 0, 0
  s:run{ time = 0.006, dt = 1e-6, every = 1, on_step = function(sc)
    local C = sc:measure("contacts")
    if C.count > 0 then
      local Q = sc:particles()
      local d = math.sqrt(Q.x[1] ^ 2 + Q.y[1] ^ 2)
      worst = math.max(worst, math.abs(C.nx[1] - Q.x[1] / d), math.abs(C.ny[1] - Q.y[1] / d))
      seen = seen + 1
    end
  end }
  check.gt(seen, 10, "end point off-axis: contact seen")
  check.lt(worst, 1e-12, "end point off-axis: the normal passes through the end point")
  check.gt(s:particles().vy[1], 0, "end point off-axis: deflected upwards")
end

-- 4. -------------------------------------------------------------------------------------------
do
  local r = 0.01
  local function rest(x, wall)
    local s = dem.scene{ dim = 2, box = { { -0.2, -0.1 }, { 0.2, 0.1 } }, gravity = { 0, -g } }
    s:contact{ normal = "linear", stiffness = 1e5, damping = "viscous" }
    s:add_disk{ pos = { x, r }, radius = r }
    local w = wall(s)
    s:run{ time = 0.05 } -- 50 contact times: the bounce is damped to round-off (e = 0.5)
    return s, w
  end
  local poly = function(s) return s:add_polyline{ points = { { -0.1, 0 }, { 0, 0 }, { 0.1, 0 } } } end
  local plane = function(s) return s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } } end
  local sp, wp = rest(0, plane)
  local m = sp:particles().mass[1]
  for _, x in ipairs{ 0, 1e-9, -1e-9, 0.3 * r } do
    local s, w = rest(x, poly)
    local what = string.format("polyline vertex (x = %g): ", x)
    check.eq(s:measure("contacts").count, 1, what .. "one contact")
    check.near(-s:wall_load(w)[2], m * g, 1e-6, what .. "one force m g")
    check.near(s:particles().y[1], sp:particles().y[1], 1e-12, what .. "rests as on a plane")
  end
  -- a concave corner: two faces, two forces (a V of two 45-degree segments)
  local s = dem.scene{ dim = 2, box = { { -0.2, -0.1 }, { 0.2, 0.1 } }, gravity = { 0, -g } }
  s:contact{ normal = "linear", stiffness = 1e5, damping = "viscous" }
  s:add_disk{ pos = { 0, r * math.sqrt(2) + 1e-4 }, radius = r }
  local w = s:add_polyline{ points = { { -0.1, 0.1 }, { 0, 0 }, { 0.1, 0.1 } } }
  s:run{ time = 0.06 }
  local C = s:measure("contacts")
  check.eq(C.count, 2, "concave corner: two contacts")
  check.near(C.fn[1], m * g / math.sqrt(2), 1e-6, "concave corner: each face m g / sqrt 2")
  check.near(-s:wall_load(w)[2], m * g, 1e-6, "concave corner: the wall carries m g")
end

-- 5. -------------------------------------------------------------------------------------------
do
  local r = 0.01
  local function drop(x, y, wall)
    local s = dem.scene{ dim = 3, box = { { -0.2, -0.2, -0.1 }, { 0.2, 0.2, 0.2 } },
                         gravity = { 0, 0, -g } }
    s:contact{ normal = "linear", stiffness = 1e5, damping = "viscous" }
    s:add_sphere{ pos = { x, y, r + 2e-3 }, radius = r } -- lands at 0.2 m/s after 20 ms
    local w = wall(s)
    s:run{ time = 0.08, dt = 2e-5 }
    return s, w
  end
  local a, b, c, d = { -0.1, -0.1, 0 }, { 0.1, -0.1, 0 }, { 0.1, 0.1, 0 }, { -0.1, 0.1, 0 }
  local mesh = function(s) return s:add_mesh{ triangles = { { a, b, c }, { a, c, d } } } end
  local plane = function(s) return s:add_wall{ point = { 0, 0, 0 }, normal = { 0, 0, 1 } } end
  for _, xy in ipairs{ { 0.02, -0.03 }, { 0.01, 0.01 }, { -0.1, -0.1 } } do
    local s1, w1 = drop(xy[1], xy[2], plane)
    local s2, w2 = drop(xy[1], xy[2], mesh)
    local what = string.format("triangle vs plane at (%g, %g): ", xy[1], xy[2])
    if xy[1] == -0.1 then -- on the mesh's corner: a vertex contact, the sphere rests on a point
      check.near_abs(s2:particles().z[1], r - s1:particles().mass[1] * g / 1e5, 1e-9, what .. "rests on the corner")
    else
      check.near_abs(s2:particles().z[1], s1:particles().z[1], 1e-12, what .. "same height")
      check.near(-s2:wall_load(w2)[3], s1:wall_force(w1), 1e-9, what .. "same force")
      check.eq(s2:measure("contacts").count, 1, what .. "one contact")
    end
  end
end

-- 6. -------------------------------------------------------------------------------------------
do
  local r, R = 0.01, 0.05
  local function scene(pos, cyl)
    local s = dem.scene{ dim = 3, box = { { -0.2, -0.2, -0.2 }, { 0.2, 0.2, 0.2 } },
                         gravity = { 0, 0, -g } }
    s:contact{ normal = "linear", stiffness = 1e5, damping = "viscous" }
    s:add_sphere{ pos = pos, radius = r }
    local w = s:add_cylinder(cyl)
    s:run{ time = 0.06, dt = 2e-5 }
    return s, w
  end
  local s, w = scene({ 0.03, 0, -(R - r) + 1e-4 }, { center = { 0, 0, 0 }, radius = R, axis = { 1, 0, 0 } })
  local m = s:particles().mass[1]
  check.near(-s:wall_load(w)[3], m * g, 1e-6, "inside a cylinder: m g")
  check.near_abs(s:particles().x[1], 0.03, 1e-12, "inside a cylinder: no force along the axis")
  s, w = scene({ 0, 0.01, R + r + 1e-4 }, { center = { 0, 0, 0 }, radius = R, axis = { 0, 1, 0 },
                                             inside = false, length = 0.1 })
  check.near(-s:wall_load(w)[3], m * g, 1e-6, "on a cylinder: m g")
  -- beyond the end of a vertical post of length 0.1: the sphere lands on the rim e = (R, 0, 0.05)
  -- and the contact normal is (x - e)/|x - e| (1e-12)
  s = dem.scene{ dim = 3, box = { { -0.2, -0.2, -0.2 }, { 0.2, 0.2, 0.2 } }, gravity = { 0, 0, -g } }
  s:contact{ normal = "linear", stiffness = 1e5 }
  s:add_sphere{ pos = { R + 0.3 * r, 0, 0.05 + r + 1e-4 }, radius = r }
  s:add_cylinder{ center = { 0, 0, 0 }, radius = R, axis = { 0, 0, 1 }, inside = false, length = 0.1 }
  local seen, worst = 0, 0
  s:run{ time = 0.012, dt = 2e-5, every = 1, on_step = function(sc)
    local C = sc:measure("contacts")
    if C.count > 0 then
      local Q = sc:particles()
      local e = { Q.x[1] - R, Q.y[1], Q.z[1] - 0.05 }
      local d = math.sqrt(e[1] ^ 2 + e[2] ^ 2 + e[3] ^ 2)
      worst = math.max(worst, math.abs(C.nx[1] - e[1] / d), math.abs(C.ny[1] - e[2] / d),
                       math.abs(C.nz[1] - e[3] / d))
      seen = seen + 1
    end
  end }
  check.gt(seen, 10, "rim: touched")
  check.lt(worst, 1e-12, "rim: the normal passes through the rim")
  check.gt(s:particles().vx[1], 0, "rim: pushed outwards")
end

-- 7. -------------------------------------------------------------------------------------------
for _, law in ipairs{ "none", "coulomb_regularized" } do
  local s = dem.scene{ dim = 2, box = { { -0.1, -0.1 }, { 0.1, 0.1 } }, gravity = { 0, -g } }
  -- frictionless: undamped too, so that the contact list (recomputed from the final velocities)
  -- has the forces of the last evaluation (made with the half-step velocities)
  s:contact{ normal = "linear", stiffness = 1e5, damping = law == "none" and "none" or "viscous",
             tangential = law }
  local h = 0.07
  local w = s:add_polyline{ points = { { -h, -h }, { h, -h }, { h, h }, { -h, h } }, closed = true,
                            center = { 0.01, 0 }, omega = 3 }
  local k = 0
  for i = 0, 4 do
    for j = 0, 4 do
      s:add_disk{ pos = { -0.05 + 0.022 * i, -0.05 + 0.022 * j }, radius = 0.008 + 0.001 * ((i + j) % 3) }
      k = k + 1
    end
  end
  s:run{ time = 0.05 } -- the lowest row reaches the floor
  local f, t = s:wall_load(w)
  for _ = 1, 200 do -- until the wall is touched (undamped disks bounce)
    if f[1] ~= 0 and f[2] ~= 0 then break end
    s:run{ time = 0.001 }
    f, t = s:wall_load(w)
  end
  local P = s:particles()
  local sx, sy = 0, 0
  for i = 1, P.count do
    sx = sx + P.fx[i]
    sy = sy + P.fy[i] + P.mass[i] * g
  end
  local scale = math.abs(f[2]) + math.abs(f[1])
  check.gt(scale, 0, law .. ": the wall is loaded")
  check.near_abs(sx + f[1], 0, 1e-12 * scale, law .. ": force on the wall = -sum of contact forces (x)")
  check.near_abs(sy + f[2], 0, 1e-12 * scale, law .. ": force on the wall = -sum of contact forces (y)")
  if law == "none" then
    local C = s:measure("contacts")
    local tq, n = 0, 0
    for c = 1, C.count do
      if C.j[c] < 0 then
        local i = C.i[c]
        local d = P.radius[i] - C.overlap[c]
        local px, py = P.x[i] - d * C.nx[c] - 0.01, P.y[i] - d * C.ny[c]
        tq = tq + px * C.fn[c] * C.ny[c] - py * C.fn[c] * C.nx[c]
        n = n + 1
      end
    end
    check.gt(n, 0, "torque: wall contacts")
    check.gt(math.abs(t), 1e-6, "torque: not zero about an off-centre point")
    check.near_abs(t + tq, 0, 1e-9 * math.abs(t), "torque on the wall = -sum of (p - c) x f")
  end
end
-- 8. -------------------------------------------------------------------------------------------
do
  local function row(threads)
    grainlab.threads(threads)
    local s = dem.scene{ dim = 2, box = { { -0.01, -0.01 }, { 11.1, 0.05 } }, gravity = { 0, -9.81 } }
    s:contact{ normal = "linear", stiffness = 1e4, damping = "viscous", tangential = "spring" }
    local w = s:add_polyline{ points = { { 0, 0 }, { 5.5, 0 }, { 11, 0 } }, omega = 1e-4 }
    for k = 0, 4999 do -- resting on the floor, sliding to and fro
      s:add_disk{ pos = { 0.001 + 0.0022 * k, 0.001 }, radius = 0.001, vel = { 0.01 * math.sin(k), 0 } }
    end
    s:run{ steps = 10, dt = 5e-6 }
    local f, t = s:wall_load(w)
    local P = s:particles()
    local out = { string.format("%a %a %a %a", f[1], f[2], t, s:wall_force(w)) }
    for i = 1, P.count, 7 do out[#out + 1] = string.format("%a %a %a", P.x[i], P.y[i], P.omega[i]) end
    return table.concat(out, "\n"), f[2]
  end
  local a, fy = row(1)
  local b = row(2)
  grainlab.threads(1)
  check.lt(fy, 0, "5000 candidates: the wall is loaded")
  check.eq(a, b, "5000 candidates: 1 and 2 threads give the same bits")
end
-- 9. -------------------------------------------------------------------------------------------
-- A turning flat wall is a one-segment polyline (2D) or a two-triangle square (3D) turning about a
-- point on it: after t its normal is the first one turned by omega t, and a frictionless grain
-- lying on it sees that normal (1e-12).
do
  local r, om = 0.01, 0.5
  local s = dem.scene{ dim = 2, box = { { -0.2, -0.2 }, { 0.2, 0.2 } }, gravity = { 0, -g } }
  s:contact{ normal = "linear", stiffness = 1e5, damping = "viscous" }
  s:add_disk{ pos = { 0, r }, radius = r }
  s:add_polyline{ points = { { -0.15, 0 }, { 0.15, 0 } }, center = { 0, 0 }, omega = om }
  s:run{ time = 0.2 }
  local th, C = om * s:info().time, s:measure("contacts")
  check.eq(C.count, 1, "turning segment: the disk lies on it")
  check.near_abs(C.nx[1], -math.sin(th), 1e-12, "turning segment: normal x = -sin(omega t)")
  check.near_abs(C.ny[1], math.cos(th), 1e-12, "turning segment: normal y = cos(omega t)")
  check.lt(s:particles().x[1], -1e-3, "turning segment: the disk slides down the tilt")
  local s3 = dem.scene{ dim = 3, box = { { -0.2, -0.2, -0.2 }, { 0.2, 0.2, 0.2 } }, gravity = { 0, 0, -g } }
  s3:contact{ normal = "linear", stiffness = 1e5, damping = "viscous" }
  s3:add_sphere{ pos = { 0.02, 0, r }, radius = r }
  local a, b, c, d = { -0.15, -0.15, 0 }, { 0.15, -0.15, 0 }, { 0.15, 0.15, 0 }, { -0.15, 0.15, 0 }
  s3:add_mesh{ triangles = { { a, b, c }, { a, c, d } }, center = { 0, 0, 0 }, omega = { om, 0, 0 } }
  s3:run{ time = 0.2 }
  th, C = om * s3:info().time, s3:measure("contacts")
  check.eq(C.count, 1, "turning square: the sphere lies on it")
  check.near_abs(C.nx[1], 0, 1e-12, "turning square: normal x = 0")
  check.near_abs(C.ny[1], -math.sin(th), 1e-12, "turning square: normal y = -sin(omega t)")
  check.near_abs(C.nz[1], math.cos(th), 1e-12, "turning square: normal z = cos(omega t)")
end
check.done()
