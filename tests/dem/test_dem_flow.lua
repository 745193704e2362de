-- Particles in and out during a run (s:inserter, s:outflow, s:flow; src/dem/flow.c):
--  1. conservation: inserted - removed = present, the count exactly and the mass to rounding (the
--     three sums add the same masses in different orders: 1e-12 relative);
--  2. no overlap after inserting into a crowded region (min gap >= 0 against particles and walls),
--     fewer inserted and the rest counted as skipped;
--  3. rate: the count inserted by time t is floor(rate t) within one particle;
--  4. size distributions: uniform radius mean (a+b)/2 and variance (b-a)^2/12, discrete radii with
--     their weights, within 4 standard errors of the sample;
--  5. removal at an open side and in an outflow box (fixed particles stay), counted with their
--     mass; without an outflow a particle leaving the domain still stops the run;
--  6. history: a particle removed from a scene leaves the others with the bits of a scene that
--     never had it (every per-particle array, the list and the spring history renumbered), for
--     each integrator;
--  7. determinism: the same seed gives the same bits, 1 and 2 threads too; checkpoints continue
--     bit for bit with inserters and outflows active;
--  8. a small silo (a hopper of two planar walls, an outflow box below the orifice) discharges
--     steadily: the machinery, not the physics.
local check = grainlab.check
grainlab.threads(1)

local mat = grainlab.material{ density = 2500, young = 1e6, poisson = 0.3, friction = 0.3,
                               restitution = 0.5 }

local function pairs_min_gap(s)
  local p = s:particles()
  local D = p.z and 3 or 2
  local gap = math.huge
  for i = 1, p.count do
    for j = i + 1, p.count do
      local dx, dy = p.x[i] - p.x[j], p.y[i] - p.y[j]
      local dz = D == 3 and p.z[i] - p.z[j] or 0
      gap = math.min(gap, math.sqrt(dx * dx + dy * dy + dz * dz) - p.radius[i] - p.radius[j])
    end
  end
  return gap, p
end

-- ---- 1 and 5: conservation, open side, outflow box -------------------------------------------
do
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.2 } }, gravity = { 0, -9.81 } }
  s:contact{ damping = "viscous", tangential = "spring" }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.1, 0 }, normal = { -1, 0 } }
  s:inserter{ box = { { 0, 0.15 }, { 0.1, 0.2 } }, rate = 2000, count = 200,
              radius = { 0.002, 0.003 }, material = mat, seed = 3 }
  local side = s:outflow{ side = "y-" }
  local box = s:outflow{ box = { { 0.07, 0.0 }, { 0.1, 0.05 } } }
  local worst_n, worst_m, seen_out = 0, 0, 0
  s:run{ time = 0.3, every = 200, on_step = function(sc)
    local f = sc:flow()
    worst_n = math.max(worst_n, math.abs(f.inserted - f.removed - f.count))
    worst_m = math.max(worst_m, math.abs(f.inserted_mass - f.removed_mass - f.mass) / f.inserted_mass)
    seen_out = math.max(seen_out, f.removed)
  end }
  local f = s:flow()
  check.eq(worst_n, 0, "conservation: inserted - removed = present (count, exact)")
  check.is_true(worst_m <= 1e-12, "conservation: mass to rounding (" .. worst_m .. ")")
  check.eq(f.inserted + f.skipped, 200, "conservation: inserted + skipped = count")
  check.is_true(f.outflows[side].removed > 0 and f.outflows[box].removed > 0,
    "both outflows removed particles (" .. f.outflows[side].removed .. ", " .. f.outflows[box].removed .. ")")
  check.eq(f.outflows[side].removed + f.outflows[box].removed, f.removed, "per-outflow counts add up")
  check.near(f.outflows[side].mass + f.outflows[box].mass, f.removed_mass, 1e-12, "per-outflow masses add up")
  check.is_true(seen_out > 0, "removals seen during the run")
end

-- one particle through the open side x+, another into a box, a fixed one in the box stays
do
  local function scene(with_outflow)
    local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } }, gravity = { 0, 0 } }
    s:add_disk{ pos = { 0.09, 0.05 }, radius = 0.002, vel = { 1, 0 }, material = mat }
    s:add_disk{ pos = { 0.02, 0.05 }, radius = 0.002, vel = { 0, -1 }, material = mat }
    s:add_disk{ pos = { 0.05, 0.01 }, radius = 0.003, fixed = true, material = mat }
    s:add_disk{ pos = { 0.05, 0.08 }, radius = 0.001, material = mat }
    if with_outflow then
      s:outflow{ side = "x+" }
      s:outflow{ box = { { 0, 0 }, { 0.1, 0.02 } } }
    end
    return s
  end
  local s = scene(true)
  local m1 = s:particles().mass[1]
  local m2 = s:particles().mass[2]
  s:run{ time = 0.05 }
  local f = s:flow()
  check.eq(f.outflows[1].removed, 1, "open side: one removed")
  check.eq(f.outflows[1].mass, m1, "open side: its mass")
  check.eq(f.outflows[2].removed, 1, "outflow box: one removed (the fixed one stays)")
  check.eq(f.outflows[2].mass, m2, "outflow box: its mass")
  local p = s:particles()
  check.eq(p.count, 2, "two left")
  check.eq(p.tag[1], 3, "tags: the fixed particle keeps its number")
  check.eq(p.tag[2], 4, "tags: the last particle keeps its number (its id is now 2)")
  check.errors(function() scene(false):run{ time = 0.05 } end, "left the domain",
    "without an outflow, leaving the domain still stops the run")
  check.errors(function() dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, periodic = { true, false } }:outflow{ side = "x-" } end,
    "outflow: axis 1 is periodic", "no outflow on a periodic side")
end

-- ---- 2: no overlap in a crowded region ---------------------------------------------------------
for _, dim in ipairs{ 2, 3 } do
  local box = dim == 2 and { { 0, 0 }, { 0.04, 0.04 } } or { { 0, 0, 0 }, { 0.03, 0.03, 0.03 } }
  local s = dem.scene{ dim = dim, box = box, gravity = dim == 2 and { 0, 0 } or { 0, 0, 0 } }
  s:add_wall{ point = dim == 2 and { 0, 0 } or { 0, 0, 0 }, normal = dim == 2 and { 0, 1 } or { 0, 0, 1 } }
  local rng = grainlab.rng{ seed = 11 }
  local add = dim == 2 and s.add_disk or s.add_sphere
  for k = 1, 40 do -- already there: random, possibly overlapping each other, not the wall
    local pos = {}
    for d = 1, dim do pos[d] = 0.005 + 0.03 * rng:uniform() end
    pcall(add, s, { pos = pos, radius = 0.0025, material = mat, fixed = true })
  end
  local lo = dim == 2 and { 0, 0 } or { 0, 0, 0 }
  local hi = dim == 2 and { 0.04, 0.04 } or { 0.03, 0.03, 0.03 }
  local n0 = s:particles().count
  s:inserter{ box = { lo, hi }, count = 400, radius = { 0.001, 0.003 }, material = mat, seed = 5,
              attempts = 30 }
  s:run{ steps = 1, dt = 1e-7, force = true } -- inserted before the step; nothing moves without contacts
  local f = s:flow()
  local gap, p = pairs_min_gap(s)
  -- the new ones only must clear everything (the fixed ones may overlap each other)
  local newgap = math.huge
  for i = n0 + 1, p.count do
    for j = 1, p.count do
      if j ~= i then
        local dx, dy = p.x[i] - p.x[j], p.y[i] - p.y[j]
        local dz = dim == 3 and p.z[i] - p.z[j] or 0
        newgap = math.min(newgap, math.sqrt(dx * dx + dy * dy + dz * dz) - p.radius[i] - p.radius[j])
      end
    end
    local h = dim == 2 and p.y[i] or p.z[i]
    newgap = math.min(newgap, h - p.radius[i])
  end
  check.is_true(newgap >= 0, dim .. "D crowded: min gap of the inserted " .. newgap .. " >= 0")
  check.is_true(f.skipped > 0 and f.inserted > 0, dim .. "D crowded: some inserted (" .. f.inserted ..
    "), the rest skipped (" .. f.skipped .. ")")
  check.eq(f.inserted + f.skipped, 400, dim .. "D crowded: inserted + skipped = count")
  check.eq(p.count, n0 + f.inserted, dim .. "D crowded: the scene holds them")
  local _ = gap
end

-- ---- 3: rate -------------------------------------------------------------------------------------
do
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } }
  local rate = 3000
  s:inserter{ box = { { 0, 0 }, { 1, 1 } }, rate = rate, radius = 0.001, material = mat, seed = 2 }
  local worst, samples = 0, 0
  local dt = 1e-5
  s:run{ steps = 10000, dt = dt, force = true, every = 7, on_step = function(sc)
    local f = sc:flow()
    worst = math.max(worst, math.abs(f.inserted - rate * f.time))
    samples = samples + 1
  end }
  check.is_true(worst <= 1, "rate: |inserted - rate t| = " .. worst .. " <= 1 particle")
  check.eq(s:flow().skipped, 0, "rate: none skipped in an empty region")
  check.is_true(samples > 1000 and s:flow().inserted == 300, "rate: sampled, 300 inserted by 0.1 s")
  -- every = 50 steps: the count follows in steps of rate x 50 dt, still within one at the events
  local s2 = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } }
  s2:inserter{ box = { { 0, 0 }, { 1, 1 } }, rate = rate, radius = 0.001, material = mat, every = 50 }
  s2:run{ steps = 1000, dt = dt, force = true }
  check.is_true(math.abs(s2:flow().inserted - rate * s2:flow().time) <= rate * 50 * dt + 1,
    "rate with every = 50: " .. s2:flow().inserted)
  check.eq(s2:flow().inserters[1].events, 20, "rate with every = 50: one event per 50 steps (the first one empty)")
end

-- ---- 4: size distributions -----------------------------------------------------------------------
do
  local N = 1500
  local a, b = 0.001, 0.002
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } }
  s:inserter{ box = { { 0, 0 }, { 1, 1 } }, count = N, radius = { a, b }, material = mat, seed = 9 }
  s:run{ steps = 1, dt = 1e-6, force = true }
  local r = s:particles().radius
  check.eq(#r, N, "uniform: all placed")
  local mean, var = 0, 0
  for i = 1, N do mean = mean + r[i] end
  mean = mean / N
  for i = 1, N do var = var + (r[i] - mean) ^ 2 end
  var = var / (N - 1)
  local sig2 = (b - a) ^ 2 / 12
  -- standard errors: sqrt(sig2 / N) for the mean; sqrt((mu4 - sig2^2) / N), mu4 = (b-a)^4/80
  check.near_abs(mean, (a + b) / 2, 4 * math.sqrt(sig2 / N), "uniform: mean radius")
  check.near_abs(var, sig2, 4 * math.sqrt(((b - a) ^ 4 / 80 - sig2 ^ 2) / N), "uniform: variance")
  local rmin, rmax = math.huge, 0
  for i = 1, N do rmin, rmax = math.min(rmin, r[i]), math.max(rmax, r[i]) end
  check.is_true(rmin >= a and rmax <= b, "uniform: within [a, b]")

  local radii, weights = { 0.001, 0.0015, 0.002 }, { 1, 2, 5 }
  local s3 = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 0.3, 0.3, 0.3 } }, gravity = { 0, 0, 0 } }
  s3:inserter{ box = { { 0, 0, 0 }, { 0.3, 0.3, 0.3 } }, count = N, radii = radii, weights = weights,
               material = mat, seed = 4 }
  s3:run{ steps = 1, dt = 1e-6, force = true }
  local r3 = s3:particles().radius
  check.eq(#r3, N, "discrete: all placed")
  for k = 1, 3 do
    local c = 0
    for i = 1, N do if r3[i] == radii[k] then c = c + 1 end end
    local pk = weights[k] / 8
    check.near_abs(c / N, pk, 4 * math.sqrt(pk * (1 - pk) / N), "discrete: frequency of radius " .. k)
  end
  -- constant radius, a disk region, velocity with spread
  local s4 = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } }
  s4:inserter{ center = { 0.5, 0.5 }, extent = 0.3, count = 500, radius = 0.002, material = mat,
               velocity = { 1, -2 }, spread = 0.5 }
  s4:run{ steps = 1, dt = 1e-6, force = true }
  local p4, vmin, vmax, dmax = s4:particles(), math.huge, -math.huge, 0
  for i = 1, p4.count do
    vmin, vmax = math.min(vmin, p4.vx[i]), math.max(vmax, p4.vx[i])
    dmax = math.max(dmax, math.sqrt((p4.x[i] - 0.5) ^ 2 + (p4.y[i] - 0.5) ^ 2) + p4.radius[i])
  end
  check.eq(p4.count, 500, "disk region: all placed")
  check.is_true(dmax <= 0.3, "disk region: every particle inside it")
  check.is_true(vmin >= 0.5 and vmax <= 1.5 and vmax - vmin > 0.9, "velocity spread: in [0.5, 1.5], spread out")
end

-- ---- 6: removal leaves the others as if the particle never was -----------------------------------
local function pile(with_p, integ, polyline, steps, p_speed)
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } }, gravity = { 0, -9.81 } }
  s:contact{ damping = "viscous", tangential = "spring" }
  if polyline then -- a floor beyond planes keeps its candidates in its own list (walls.c)
    s:add_polyline{ points = { { 0, 0 }, { 0.05, 0 }, { 0.1, 0 } } }
  else
    s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  end
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.1, 0 }, normal = { -1, 0 } }
  -- P first, so that every other id shifts when it goes; it falls past the pile, into the box
  if with_p then s:add_disk{ pos = { 0.09, 0.09 }, radius = 0.002, vel = { 0, -(p_speed or 3) }, material = mat } end
  for k = 0, 39 do
    local row, col = k // 10, k % 10
    s:add_disk{ pos = { 0.006 + col * 0.0052 + (row % 2) * 0.0026, 0.003 + row * 0.0045 },
                radius = 0.0025 + 0.0003 * ((k * 7) % 3 - 1), material = mat }
  end
  s:outflow{ box = { { 0.08, 0.04 }, { 0.1, 0.06 } } }
  local out = {}
  s:run{ steps = steps or 3000, dt = 5e-6, integrator = integ }
  return s
end
local function dump(s, from)
  local p, out = s:particles(), {}
  for i = from, p.count do
    out[#out + 1] = string.format("%a %a %a %a %a %a %a", p.x[i], p.y[i], p.vx[i], p.vy[i],
      p.omega[i], p.fx[i], p.fy[i])
  end
  return table.concat(out, "\n")
end
for _, integ in ipairs{ "velocity_verlet", "gear", "position_verlet" } do
  local a, b = pile(true, integ), pile(false, integ)
  check.eq(a:flow().removed, 1, integ .. ": P removed")
  local co = b:measure("contacts")
  local tang = 0
  for k = 1, co.count do if co.ft[k] > 0 then tang = tang + 1 end end
  check.is_true(tang > 10, integ .. ": the pile has contacts with spring history (" .. tang .. ")")
  check.is_true(dump(a, 1) == dump(b, 1), integ .. ": the others carry the bits of a scene without P")
  local ca, cb = a:measure("contacts"), b:measure("contacts")
  check.eq(ca.count, cb.count, integ .. ": the same contacts")
end
do -- on a polyline floor: its candidates renumbered with the particles (they were not)
  -- P dropped from rest leaves at ~15,600 steps, when the pile rests on the floor: a stale
  -- candidate list would leave a floor grain unsupported until the next build
  local a, b = pile(true, "velocity_verlet", true, 20000, 0), pile(false, "velocity_verlet", true, 20000)
  check.eq(a:flow().removed, 1, "polyline floor: P removed")
  local floor_contacts = 0
  local co = b:measure("contacts")
  for k = 1, co.count do if co.j[k] < 0 then floor_contacts = floor_contacts + 1 end end
  check.ge(floor_contacts, 5, "polyline floor: the pile rests on it")
  check.is_true(dump(a, 1) == dump(b, 1), "polyline floor: the others carry the bits of a scene without P")
end
do -- insertion next to a polyline: places taken clear of it (the test once saw only planes)
  local s = dem.scene{ dim = 2, box = { { 0, -0.01 }, { 0.03, 0.05 } }, gravity = { 0, -9.81 } }
  s:contact{ damping = "viscous", tangential = "spring" }
  local floor = s:add_polyline{ points = { { 0, 0.01 }, { 0.015, 0.005 }, { 0.03, 0.01 } } }
  s:inserter{ box = { { 0, 0 }, { 0.03, 0.03 } }, count = 60, radius = { 5e-4, 1e-3 }, seed = 4, material = mat }
  s:run{ steps = 1, dt = 1e-6 }
  local f, p = s:flow(), s:particles()
  check.eq(f.inserted + f.skipped, 60, "polyline: every particle drawn")
  check.is_true(f.inserted >= 40, "polyline: most placed (" .. f.inserted .. ")")
  local worst = math.huge
  for i = 1, p.count do -- the distance to the V-shaped floor, less the radius
    local x, y, r = p.x[i], p.y[i], p.radius[i]
    local function seg(ax, ay, bx, by)
      local ux, uy = bx - ax, by - ay
      local q = math.max(0, math.min(1, ((x - ax) * ux + (y - ay) * uy) / (ux * ux + uy * uy)))
      return math.sqrt((x - ax - q * ux) ^ 2 + (y - ay - q * uy) ^ 2)
    end
    worst = math.min(worst, math.min(seg(0, 0.01, 0.015, 0.005), seg(0.015, 0.005, 0.03, 0.01)) - r)
  end
  check.ge(worst, -1e-12, "polyline: no inserted particle overlaps it")
  check.is_true(floor ~= nil, "polyline: a wall id")
end

-- the same in 3D (every 3D array: positions, three angular velocities and torques, wall history)
local function pile3(with_p)
  local s = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 0.03, 0.03, 0.05 } }, gravity = { 0, 0, -9.81 } }
  -- a damped pile (e = 0.1 at 1 m/s) that has settled into contacts by the end
  s:contact{ damping = "viscous", tangential = "spring", restitution = 0.1 }
  s:add_wall{ point = { 0, 0, 0 }, normal = { 0, 0, 1 } }
  if with_p then s:add_sphere{ pos = { 0.027, 0.027, 0.045 }, radius = 0.002, vel = { 0, 0, -3 }, material = mat } end
  for k = 0, 17 do
    local a, b, c = k % 3, (k // 3) % 3, k // 9
    s:add_sphere{ pos = { 0.005 + a * 0.0052 + c * 0.0026, 0.005 + b * 0.0052 + c * 0.0026, 0.003 + c * 0.0042 },
                  radius = 0.0025 + 0.0002 * ((k * 5) % 3 - 1), material = mat }
  end
  s:outflow{ box = { { 0.02, 0.02, 0.02 }, { 0.03, 0.03, 0.03 } } }
  s:run{ steps = 3000, dt = 5e-6 }
  return s
end
do
  local a, b = pile3(true), pile3(false)
  check.eq(a:flow().removed, 1, "3D: P removed")
  local function dump3(s)
    local p, out = s:particles(), {}
    for i = 1, p.count do
      out[#out + 1] = string.format("%a %a %a %a %a %a %a %a %a", p.x[i], p.y[i], p.z[i], p.vx[i], p.vy[i],
        p.vz[i], p.wx[i], p.wy[i], p.fz[i])
    end
    return table.concat(out, "\n")
  end
  check.is_true(#b:measure("contacts").i > 10, "3D: the pile touches")
  check.is_true(dump3(a) == dump3(b), "3D: the others carry the bits of a scene without P")
end

-- the stable step counts the smallest particle an inserter can bring: an empty scene runs
do
  local function ts(with_inserter)
    local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } }, gravity = { 0, -9.81 } }
    if with_inserter then
      s:add_disk{ pos = { 0.05, 0.05 }, radius = 0.004, material = mat }
      s:inserter{ box = { { 0, 0.08 }, { 0.1, 0.1 } }, count = 5, radius = { 0.001, 0.003 }, material = mat }
    else
      s:add_disk{ pos = { 0.05, 0.05 }, radius = 0.001, material = mat }
    end
    return s:timestep{ impact_velocity = 1 }.dt_auto
  end
  check.eq(ts(true), ts(false), "timestep: the inserter's smallest particle sets dt")
  local e = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } }, gravity = { 0, -9.81 } }
  e:inserter{ box = { { 0, 0.05 }, { 0.1, 0.1 } }, count = 20, radius = 0.002, material = mat }
  e:run{ steps = 10 }
  check.eq(e:flow().count, 20, "an empty scene with an inserter runs")
end

-- A particle removed while it presses on another: the next step's first kick must not see its push
-- any more. Without damping the forces depend on positions only, so the survivor's step equals
-- that of a fresh scene without the removed particle (to rounding: the adjusted sum and the fresh
-- one add the same terms in another order). The survivor S rests on a fixed disk F; R on top.
do
  local function scene(S, with_r)
    local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.02 } }, gravity = { 0, -9.81 } }
    s:add_disk{ pos = { 0.01, 0.002 }, radius = 0.002, material = mat, fixed = true }
    s:add_disk{ pos = S.pos, vel = S.vel, radius = 0.002, material = mat }
    if with_r then s:add_disk{ pos = { 0.01, 0.0098 }, radius = 0.002, material = mat } end
    return s
  end
  local a = scene({ pos = { 0.01, 0.0059 }, vel = { 0, 0 } }, true)
  a:run{ steps = 200, dt = 2e-6 }
  check.eq(a:measure("contacts").count, 2, "pressing: both pairs touch at the removal")
  local pa = a:particles()
  local b = scene({ pos = { pa.x[2], pa.y[2] }, vel = { pa.vx[2], pa.vy[2] } }, false)
  a:outflow{ box = { { 0, 0.009 }, { 0.02, 0.02 } } }
  a:run{ steps = 1, dt = 2e-6 }
  b:run{ steps = 1, dt = 2e-6 }
  check.eq(a:flow().removed, 1, "pressing: removed")
  local va, vb = a:particles().vy[2], b:particles().vy[2]
  check.near_abs(va, vb, 1e-12, "pressing: the survivor's step is that of a scene without the removed particle")
end

-- ---- 7: determinism and checkpoints --------------------------------------------------------------
local function flowing(seed)
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.05, 0.1 } }, gravity = { 0, -9.81 } }
  s:contact{ damping = "viscous", tangential = "spring" }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.05, 0 }, normal = { -1, 0 } }
  s:add_wall{ point = { 0, 0.0 }, normal = { 1, 1 } }
  s:inserter{ box = { { 0, 0.07 }, { 0.05, 0.1 } }, rate = 1500, radius = { 0.0015, 0.0025 },
              velocity = { 0, -2 }, spread = 0.5, material = mat, seed = seed, every = 10 }
  s:inserter{ center = { 0.025, 0.05 }, extent = 0.01, count = 5, radii = { 0.001, 0.002 },
              material = mat, seed = seed + 1 }
  s:outflow{ box = { { 0.03, 0.02 }, { 0.05, 0.05 } } }
  s:outflow{ side = "y-" }
  return s
end
local function state(s)
  local f = s:flow()
  return dump(s, 1) .. string.format("\n%d %d %d %a", f.inserted, f.skipped, f.removed, f.removed_mass)
end
local N, M = 3000, 3000
local dt = 5e-6
local a = flowing(7)
a:run{ steps = N + M, dt = dt }
check.is_true(a:flow().inserted > 40 and a:flow().removed > 0,
  "determinism: the scene inserts (" .. a:flow().inserted .. ") and removes (" .. a:flow().removed .. ")")
local b = flowing(7)
b:run{ steps = N + M, dt = dt }
check.is_true(state(a) == state(b), "determinism: the same seed gives the same bits")
check.is_true(state(a) ~= state((function() local c = flowing(8); c:run{ steps = N + M, dt = dt }; return c end)()),
  "determinism: another seed, another run")
grainlab.threads(2)
local t2 = flowing(7)
t2:run{ steps = N + M, dt = dt }
grainlab.threads(1)
check.is_true(state(a) == state(t2), "determinism: 2 threads give the bits of 1")
local dir = os.tmpname()
os.remove(dir)
assert(os.execute("mkdir -p '" .. dir .. "'"))
for _, integ in ipairs{ "velocity_verlet", "gear" } do
  local x = flowing(7)
  x:run{ steps = N + M, dt = dt, integrator = integ }
  local y = flowing(7)
  y:run{ steps = N, dt = dt, integrator = integ }
  y:save(dir .. "/flow.ckpt")
  local z = dem.load(dir .. "/flow.ckpt")
  check.is_true(state(y) == state(z), integ .. ": the loaded scene is the saved one")
  z:run{ steps = M, dt = dt, integrator = integ }
  check.is_true(state(x) == state(z), integ .. ": N + M against N, save, load, M (inserters active)")
  local p = z:particles()
  check.eq(#p.tag, p.count, integ .. ": tags survive the checkpoint")
end
os.execute("rm -rf '" .. dir .. "'")

-- ---- 8: a small silo -------------------------------------------------------------------------------
do
  -- A 2D hopper: two planar walls at 60 degrees through (0.0375, 0) and (0.0625, 0), an orifice
  -- of 25 mm (8 grain diameters) at y = 0; vertical walls above; an outflow box below takes the
  -- grains as they pass the orifice. 300 disks poured in at once, then let go.
  local s = dem.scene{ dim = 2, box = { { 0, -0.02 }, { 0.1, 0.2 } }, gravity = { 0, -9.81 } }
  s:contact{ damping = "viscous", tangential = "spring" }
  local c, sn = math.cos(math.rad(60)), math.sin(math.rad(60))
  s:add_wall{ point = { 0.0375, 0 }, normal = { sn, c } }
  s:add_wall{ point = { 0.0625, 0 }, normal = { -sn, c } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.1, 0 }, normal = { -1, 0 } }
  s:inserter{ box = { { 0, 0.06 }, { 0.1, 0.2 } }, count = 300, radius = { 0.0014, 0.0017 },
              material = mat, seed = 1 }
  s:outflow{ box = { { 0, -0.02 }, { 0.1, 0 } } }
  local t, series = {}, {}
  s:run{ time = 0.6, every = 2000, on_step = function(sc)
    local f = sc:flow()
    t[#t + 1], series[#series + 1] = f.time, f.removed
  end }
  local f = s:flow()
  check.eq(f.inserted, 300, "silo: all poured")
  check.is_true(f.removed >= 100, "silo: discharged " .. f.removed .. " of 300")
  -- steady: once it flows, the count never stops growing in a window while grains remain
  local first, stalls = nil, 0
  for k = 2, #series do
    if series[k] > 0 and not first then first = k end
    if first and k > first and series[k] == series[k - 1] and 300 - series[k] > 40 then stalls = stalls + 1 end
  end
  check.is_true(first ~= nil, "silo: the discharge started")
  check.eq(stalls, 0, "silo: the discharge count grew in every window while grains remained")
  local rate = (series[#series] - series[first]) / (t[#t] - t[first])
  print(string.format("silo: %d of 300 discharged by t = %.3f s, %.0f grains/s after the start",
    f.removed, f.time, rate))
end

-- ---- bad input -------------------------------------------------------------------------------------
do
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } } }
  check.errors(function() s:inserter{ box = { { 0, 0 }, { 0.2, 0.1 } }, count = 1, radius = 0.001 } end,
    "inserter: the region [0, 0.2] on axis 1 is not inside the domain", "region outside the domain")
  check.errors(function() s:inserter{ box = { { 0, 0 }, { 0.1, 0.1 } }, radius = 0.001 } end,
    "bad field 'count' in argument #1 to 'inserter' (a count, a rate or a mass (none given)", "no rate, count or mass")
  check.errors(function() s:inserter{ box = { { 0, 0 }, { 0.1, 0.1 } }, count = 1 } end,
    "bad field 'radius' in argument #1 to 'inserter'", "no radius")
  check.errors(function() s:inserter{ box = { { 0, 0 }, { 0.1, 0.1 } }, count = 1, radius = { 0.002, 0.001 } } end,
    "bad field 'radius' in argument #1 to 'inserter' ({min, max} with 0 < min <= max", "min > max")
  check.errors(function() s:inserter{ box = { { 0, 0 }, { 0.1, 0.1 } }, count = 1, radii = { 0.001 }, weights = { 1, 2 } } end,
    "bad field 'weights' in argument #1 to 'inserter' (array of one weight per entry of 'radii'", "weights per radius")
  check.errors(function() s:outflow{ side = "z+" } end,
    "bad field 'side' in argument #1 to 'outflow' ('x-', 'x+', 'y-' or 'y+' in 2D", "side z+ in 2D")
  check.errors(function() s:outflow{} end, "bad field 'side' in argument #1 to 'outflow' (a side, or a field 'box',", "no region")
  -- an empty scene with an inserter runs; without one it is refused
  check.errors(function() s:run{ steps = 1 } end, "no particles", "empty scene without an inserter")
end
check.done()
