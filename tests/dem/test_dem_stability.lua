-- DEM stability at the extremes: friction 0 and 10, restitution near 0 and no damping, Young's
-- modulus from 1e3 to 1e12 Pa at the automatic dt, a particle 100x faster than the rest, and the
-- time-step guard: a dt above the limit is refused, a forced blow-up stops with an error naming
-- the particle and the step.
local check = grainlab.check

-- Runs s for `steps` (or `time`) calling watch(particles) after every step.
local function watched_run(s, opts, watch)
  opts.every, opts.progress = 1, false
  opts.on_step = function(sc) watch(sc:particles()) end
  return s:run(opts)
end

local function finite(x) return x == x and x > -math.huge and x < math.huge end

-- ---- friction: a disk launched sliding on the floor ----------------------------------------
-- A 2D disk (a sphere moving in the plane: I = 2/5 m r^2) slides at v0 with no spin. With mu = 0
-- it keeps sliding at v0 and never turns. With mu = 10 Coulomb friction mu m g stops the slip
-- within t = 2 v0 / (7 mu g) (3 ms here) and it rolls on at v = 5/7 v0, omega = -v/r, having lost
-- 2/7 of its energy. Both tangential laws that use mu, both dimensions.
for _, law in ipairs { "spring", "coulomb_regularized" } do
  for _, dim in ipairs { 2, 3 } do
    for _, mu in ipairs { 0, 10 } do
      local what = string.format("%s %dD mu=%g", law, dim, mu)
      local r, v0, g = 1e-3, 1.0, 9.81
      local mat = grainlab.material{ density = 2650, young = 1e9, poisson = 0.3, friction = mu }
      local s
      if dim == 2 then
        s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 0.01 } }, gravity = { 0, -g } }
        s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
      else
        s = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 0.01, 0.01 } }, gravity = { 0, -g, 0 } }
        s:add_wall{ point = { 0, 0, 0 }, normal = { 0, 1, 0 } }
      end
      s:contact{ normal = "hertz", tangential = law }
      if dim == 2 then s:add_disk{ pos = { 0.1, r }, radius = r, material = mat, vel = { v0, 0 } }
      else s:add_sphere{ pos = { 0.1, r, 0.005 }, radius = r, material = mat, vel = { v0, 0, 0 } } end
      local e0 = s:measure("energy")
      local r1 = s:run{ time = 0.02, progress = false }
      local p = s:particles()
      local e1 = s:measure("energy")
      local w = dim == 2 and p.omega[1] or p.wz[1]
      check.is_true(finite(p.x[1]) and finite(p.vx[1]) and finite(w), what .. ": finite state")
      check.near_abs(p.y[1], r, 1e-3 * r, what .. ": stays on the floor")
      if mu == 0 then
        check.near(p.vx[1], v0, 1e-9, what .. ": keeps sliding")
        check.eq(w, 0.0, what .. ": never turns")
        check.near(e1.total, e0.total, 1e-6, what .. ": energy conserved")
      else
        check.near(p.vx[1], 5 / 7 * v0, 1e-3, what .. ": rolls at 5/7 v0")
        check.near_abs(p.vx[1] + r * w, 0, 1e-3 * v0, what .. ": no slip (v + r omega = 0)")
        check.near(e1.kinetic + e1.rotational, 5 / 7 * e0.kinetic, 2e-3, what .. ": energy 5/7")
      end
      check.is_true(r1.steps > 1000, what .. ": ran")
    end
  end
end

-- mu = 10 in a pile: 30 disks dropped into a box with the spring law and viscous damping settle
-- without blowing up (the sticking springs are the stiff part).
do
  local mat = grainlab.material{ density = 2650, young = 1e8, poisson = 0.3, friction = 10, restitution = 0.5 }
  local L, r = 0.01, 0.8e-3
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { L, 3 * L } }, gravity = { 0, -9.81 } }
  s:contact{ normal = "hertz", damping = "viscous", tangential = "spring" }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { L, 0 }, normal = { -1, 0 } }
  local rng = grainlab.rng{ seed = 5 }
  for i = 0, 29 do
    s:add_disk{ pos = { (i % 5 + 0.5) * L / 5 + rng:uniform(-1e-4, 1e-4), (i // 5 + 0.5) * 2e-3 + 1e-3 },
                radius = r * rng:uniform(0.8, 1.0), material = mat }
  end
  local e0 = s:measure("energy")
  s:run{ time = 0.05, progress = false }
  local e1 = s:measure("energy")
  check.is_true(finite(e1.total), "mu=10 pile: finite energy")
  check.lt(e1.total, e0.total, "mu=10 pile: dissipates")
  local p = s:particles()
  for i = 1, p.count do
    check.is_true(p.x[i] > 0 and p.x[i] < L and p.y[i] > 0 and p.y[i] < 3 * L, "mu=10 pile: disk " .. i .. " in the box")
  end
end

-- ---- restitution: none to overdamped -------------------------------------------------------
-- A disk hits the floor at v0 = 0.1 m/s under the linear law k = 1e4 N/m (no gravity unless said).
local function floor_hit(contact, restitution, g, steps)
  local r = 1e-3
  local mat = grainlab.material{ density = 2650, young = 1e9, restitution = restitution }
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, g or 0 } }
  s:contact(contact)
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_disk{ pos = { 0.005, r }, radius = r, material = mat, vel = { 0, -0.1 } }
  local ts = s:timestep()
  local up, lowest, highest_after = -math.huge, math.huge, -math.huge
  watched_run(s, { steps = steps or 1000 }, function(p)
    up = math.max(up, p.vy[1])
    lowest = math.min(lowest, p.y[1])
    if lowest < r then highest_after = math.max(highest_after, p.y[1]) end
  end)
  local p = s:particles()
  return { s = s, ts = ts, vy = p.vy[1], y = p.y[1], up = up, lowest = lowest, highest_after = highest_after,
           m = p.mass[1], r = r }
end

do -- no damping at all: the disk comes back at v0
  local h = floor_hit({ normal = "linear", stiffness = 1e4, damping = "none" }, 1)
  check.near(h.vy, 0.1, 1e-3, "no damping: rebound speed = impact speed")
  check.gt(h.y, h.r, "no damping: left the floor")
end

do -- restitution 1e-3 from the material, viscous dashpot, default clip = true
  local h = floor_hit({ normal = "linear", stiffness = 1e4, damping = "viscous" }, 1e-3)
  check.is_true(finite(h.vy), "e=1e-3 clipped: finite")
  -- The dashpot's gamma is the closed form for e = 1e-3, but clipping the attractive force lets
  -- the disk go early: it leaves at ~0.155 v0. What matters here: it is small and finite.
  check.ge(h.vy, 0, "e=1e-3 clipped: not pulled into the floor")
  check.le(h.vy, 0.2 * 0.1, "e=1e-3 clipped: rebound well below elastic")
  check.lt(h.ts.limit, h.ts.contact_time / 10, "e=1e-3: the dashpot lowers the dt limit")
end

do -- the same without clipping: the linear closed form applies, e ~ 1e-3
  local h = floor_hit({ normal = "linear", stiffness = 1e4, damping = "viscous", clip = false }, 1e-3)
  -- The dashpot sees velocities half a step old; near critical damping that is ~9% on ln(e) at
  -- the automatic dt (e = 5.4e-4 measured). Same order as 1e-3, and positive.
  check.gt(h.vy, 0.25e-3 * 0.1, "e=1e-3 unclipped: rebounds")
  check.lt(h.vy, 2e-3 * 0.1, "e=1e-3 unclipped: rebound ~ 1e-3 v0")
  check.gt(h.y, h.r, "e=1e-3 unclipped: left the floor")
end

do -- overdamped: gamma_n = 3x critical, under gravity: it never bounces and settles at mg/k
  local k, r = 1e4, 1e-3
  local m = 2650 * 4 / 3 * math.pi * r ^ 3
  local gamma = 3 * 2 * math.sqrt(k * m)
  local h = floor_hit({ normal = "linear", stiffness = k, damping = "viscous", gamma_n = gamma }, 1, -9.81, 20000)
  -- The time-step limit is the dashpot's: 0.2 / b with b = gamma / (2 m_eff), m_eff = m/2.
  check.near(h.ts.limit, 0.2 / (gamma / m), 1e-9, "overdamped: limit from the damping rate")
  check.le(h.highest_after, r, "overdamped: never leaves the floor once in contact")
  check.near(r - h.y, m * 9.81 / k, 1e-6, "overdamped: rests at the static overlap mg/k")
  check.near_abs(h.vy, 0, 1e-9, "overdamped: at rest")
end

-- ---- Young's modulus from 1e3 to 1e12 Pa at the automatic dt -------------------------------
-- A disk (r = 1 cm, 100 kg/m^3) touching the floor moves down at v0 = 0.5 m/s under gravity;
-- Hertz, no damping. For every modulus the run is stable, conserves energy, and the deepest
-- overlap is the one where 2/5 K d^5/2 = 1/2 m v0^2 + m g d (K = 4/3 E* sqrt(r)).
for ex = 3, 12 do
  local E, nu, r, rho, v0, g = 10.0 ^ ex, 0.3, 0.01, 100, 0.5, 9.81
  local what = string.format("E=1e%d", ex)
  local mat = grainlab.material{ density = rho, young = E, poisson = nu }
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } }, gravity = { 0, -g } }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_disk{ pos = { 0.05, r }, radius = r, material = mat, vel = { 0, -v0 } }
  local e0 = s:measure("energy")
  local lowest, highest, up = math.huge, -math.huge, -math.huge
  local res = watched_run(s, { steps = 1000 }, function(p)
    lowest, highest, up = math.min(lowest, p.y[1]), math.max(highest, p.y[1]), math.max(up, p.vy[1])
  end)
  check.eq(res.steps, 1000, what .. ": steps")
  local e1 = s:measure("energy")
  check.near_abs(e1.total, e0.total, 1e-3 * e0.kinetic, what .. ": energy conserved")
  local m = s:particles().mass[1]
  local K = 4 / 3 * E / (2 * (1 - nu * nu)) * math.sqrt(r)
  local lo, hi = 0, r
  for _ = 1, 200 do
    local d = 0.5 * (lo + hi)
    if 0.4 * K * d ^ 2.5 - m * g * d < 0.5 * m * v0 ^ 2 then lo = d else hi = d end
  end
  check.near(r - lowest, lo, 0.01, what .. ": deepest overlap as Hertz says")
  check.le(highest, r + v0 ^ 2 / (2 * g) * (1 + 1e-3), what .. ": no higher than the energy allows")
  check.gt(up, 0.9 * v0, what .. ": bounced")
end

-- ---- a particle 100x faster than the rest ---------------------------------------------------
-- 20 disks at ~1 m/s and one at 100 m/s fired at the right wall along an empty lane. The
-- automatic dt follows the fastest particle (Hertz: t_c ~ v^-1/5), so the fast disk is resolved:
-- it comes back at -100 m/s with the Hertz overlap, and does not tunnel.
do
  local r, L, E, nu, rho, fast = 0.5e-3, 0.01, 30e9, 0.3, 2650, 100
  local mat = grainlab.material{ density = rho, young = E, poisson = nu }
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { L, L } }, gravity = { 0, 0 } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { L, 0 }, normal = { -1, 0 } }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_wall{ point = { 0, L }, normal = { 0, -1 } }
  local rng = grainlab.rng{ seed = 3 }
  local vmax = 0
  for i = 0, 4 do
    for j = 0, 3 do -- rows 0..3; row 4 (y = 0.9 L) is the fast disk's lane
      local v = { rng:normal(0, 1), rng:normal(0, 1) }
      vmax = math.max(vmax, math.sqrt(v[1] ^ 2 + v[2] ^ 2))
      s:add_disk{ pos = { (i + 0.5) * L / 5, (j + 0.5) * L / 5 }, radius = r, material = mat, vel = v }
    end
  end
  local slow = s:timestep()
  check.near(slow.impact_velocity, vmax, 1e-12, "impact velocity: the fastest disk")
  local id = s:add_disk{ pos = { 0.5 * L, 0.9 * L }, radius = r, material = mat, vel = { fast, 0 } }
  local ts = s:timestep()
  check.near(ts.impact_velocity, fast, 1e-12, "impact velocity follows the fast disk")
  check.near(ts.dt_auto / slow.dt_auto, (vmax / fast) ^ 0.2, 1e-9, "dt_auto scales as v^-1/5")
  local e0 = s:measure("energy").total
  local deepest = 0
  local res = s:run{ time = 70e-6, every = 1, progress = false, on_step = function(sc)
    local c = sc:measure("contacts")
    for k = 1, c.count do
      if c.i[k] == id then deepest = math.max(deepest, c.overlap[k]) end
    end
  end }
  check.near(res.dt, ts.dt_auto, 1e-12, "run used the adapted dt")
  local p = s:particles()
  check.near(p.vx[id], -fast, 1e-3, "fast disk bounced back at 100 m/s")
  check.is_true(p.x[id] > r and p.x[id] < L - r, "fast disk inside the box")
  local m = p.mass[id]
  local K = 4 / 3 * E / (2 * (1 - nu * nu)) * math.sqrt(r)
  check.near(deepest, (5 * m * fast ^ 2 / (4 * K)) ^ 0.4, 0.01, "fast disk: Hertz overlap at the wall")
  check.lt(deepest, 0.2 * r, "fast disk: shallow overlap")
  check.near(s:measure("energy").total, e0, 1e-3, "fast disk: energy conserved")
end

-- ---- forced blow-up: an error naming the particle and the step, never a crash --------------
-- 50 disks resting in a box under gravity, every integrator, dt = 30x the limit with force = true.
local function pile()
  local mat = grainlab.material{ density = 2650, young = 30e9 }
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.01, 0 }, normal = { -1, 0 } }
  for i = 0, 9 do
    for j = 0, 4 do
      s:add_disk{ pos = { (i + 0.5) * 1e-3, (j + 0.5) * 1e-3 }, radius = 0.5e-3, material = mat }
    end
  end
  return s
end

for _, integ in ipairs { "velocity_verlet", "position_verlet", "gear", "two_timescales" } do
  local s = pile()
  local ts = s:timestep()
  local n = integ == "two_timescales" and 5 or 1 -- two timescales' large step is n dt
  local msg = check.errors(function() s:run{ steps = 1000, dt = 30 * ts.limit / n, force = true, integrator = integ } end,
    "run: particle ", integ .. ": forced blow-up raises an error")
  -- Caught either as the centre crossing a wall during the force evaluation, or, when one step
  -- carries it past the wall and out of the box, as leaving the domain after the step.
  local id, step = msg:match("run: particle (%d+) went through a wall at step (%d+) %(t = ")
  if not id then id, step = msg:match("run: particle (%d+) left the domain %b() at step (%d+) %(t = ") end
  check.is_true(id ~= nil, integ .. ": message names the particle, the wall and the step: " .. msg)
  check.is_true(tonumber(id) >= 1 and tonumber(id) <= 50, integ .. ": particle id in range")
  check.is_true(tonumber(step) >= 1 and tonumber(step) <= 1000, integ .. ": step in range")
  check.contains(msg, "the time step is too large", integ .. ": message gives the likely cause")
  check.contains(msg, "test_dem_stability.lua:", integ .. ": error at the caller's line")
  check.eq(s:info().count, 50, integ .. ": scene still usable after the error")
end

-- The other path: no walls (periodic box), two disks colliding at dt = 1e8x the limit go
-- non-finite; the run stops naming the particle and the step.
do
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, 0 }, periodic = { true, true } }
  s:add_disk{ pos = { 0.004, 0.005 }, radius = 0.5e-3, vel = { 1, 0 } }
  s:add_disk{ pos = { 0.006, 0.005 }, radius = 0.5e-3, vel = { -1, 0 } }
  local limit = s:timestep().limit
  -- Stops either on the non-finite check or, when the wrapped positions collapse onto one point,
  -- on the undefined contact normal; both name the particle(s) and the step.
  local msg = check.errors(function() s:run{ steps = 100, dt = 1e8 * limit, force = true } end,
    "run: particle", "non-finite blow-up")
  check.is_true(msg:match("run: particle [12] has a non%-finite position or velocity at step %d+ %(t = ") ~= nil
                or msg:match("run: particles 1 and 2 are at the same position: the contact normal is undefined %(at step %d+, t = ") ~= nil,
    "non-finite: names the particle and the step: " .. msg)
end

-- force = true lets a dt above the limit through; the limit itself needs no force.
do
  local s = pile()
  local ts = s:timestep()
  check.near(ts.limit, ts.contact_time / 10, 1e-12, "undamped limit = contact time / 10")
  check.near(ts.dt_auto, ts.limit / 5, 1e-12, "dt_auto = limit / 5")
  check.eq(s:run{ steps = 5, dt = ts.limit, progress = false }.steps, 5, "dt at the limit accepted")
  check.eq(s:run{ steps = 1, dt = 1.5 * ts.limit, force = true, progress = false }.steps, 1, "force = true accepted")
end

-- ---- a dt above the stability limit is refused, with the limit in the message ---------------
-- (The message is formatted with %g, which lua_pushfstring does not know: it once raised
-- "invalid option '%g'" instead.)
do
  local s = pile()
  local ts = s:timestep()
  local msg = check.errors(function() s:run{ steps = 10, dt = 2 * ts.limit } end,
    "exceeds the stability limit", "dt above the limit refused")
  check.contains(msg, string.format("stability limit %g s", ts.limit), "refusal gives the limit")
  check.contains(msg, string.format("dt = %g s", 2 * ts.limit), "refusal gives the dt")
  check.contains(msg, "force = true", "refusal says how to override")
  check.eq(s:info().steps, 0, "refused run took no step")
  -- Two timescales: the large step n dt is the one that must stay under the limit.
  msg = check.errors(function() s:run{ steps = 10, dt = 0.5 * ts.limit, integrator = "two_timescales", n = 5, q = 5, m = 1 } end,
    "exceeds the stability limit", "two timescales: n dt above the limit refused")
  check.contains(msg, string.format("dt = %g s", 2.5 * ts.limit), "two timescales: refusal gives n dt")
end



-- Regressions for problems found while writing these tests.
do -- position Verlet keeps its velocity when dt changes between runs
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } }
  s:add_disk{ pos = { 0.5, 0.5 }, radius = 1e-3, vel = { 0.1, 0 } }
  s:run{ steps = 10, dt = 1e-6, integrator = "position_verlet" }
  s:run{ steps = 10, dt = 2e-6, force = true, integrator = "position_verlet" }
  -- velocity = (x - x_prev)/dt: rounding of x ~ 0.5 against steps ~ 1e-7 leaves ~1e-9
  check.near(s:particles().vx[1], 0.1, 1e-8, "position Verlet: velocity survives a change of dt")
end
do -- position Verlet in summed form does not accumulate rounding (2e-6 m in the plain form)
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 9.81, 0 } }
  s:add_disk{ pos = { 0.1, 0.5 }, radius = 1e-3 }
  s:run{ steps = 200000, dt = 0.15 / 200000, integrator = "position_verlet", force = true }
  check.near_abs(s:particles().x[1], 0.1 + 0.5 * 9.81 * 0.15 ^ 2, 1e-10, "position Verlet: free fall over 2e5 steps")
end
do -- two timescales with dt = "auto": the large step n dt is the automatic step
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_disk{ pos = { 0.005, 0.0006 }, radius = 0.5e-3, vel = { 0, -1 } }
  local auto = s:timestep().dt_auto -- from the state the run starts with
  local r = s:run{ steps = 5500, integrator = "two_timescales", n = 50, q = 5, m = 1 }
  check.near(r.dt * 50, auto, 1e-12, "two timescales: n dt = dt_auto")
  check.le(math.abs(s:particles().vy[1]), 1.01, "two timescales: the bounce does not gain energy")
end
do -- leaving the domain through a side without a wall stops the run
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, 0 } }
  s:add_disk{ pos = { 0.005, 0.005 }, radius = 0.5e-3, vel = { 10, 0 } }
  local msg = check.errors(function() s:run{ steps = 100000 } end, "run: particle 1 left the domain", "leaving the box")
  check.contains(msg, "at step ", "leaving the box: names the step")
  check.errors(function() s:run{ steps = 1 } end, "left the domain", "the next run does not go on from stale forces")
end
do -- coincident centres are refused when the run starts, naming both particles
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } } }
  s:add_disk{ pos = { 0.005, 0.005 }, radius = 0.5e-3 }
  s:add_disk{ pos = { 0.005, 0.005 }, radius = 0.5e-3 }
  check.errors(function() s:run{ steps = 1 } end, "run: particles 1 and 2 are at the same position", "coincident particles")
end
do -- the Cundall-Strack spring with the default (overlap-dependent) stiffness creates no energy
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
  local mat = grainlab.material{ density = 2650, young = 30e9, poisson = 0.3, friction = 10 }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:contact{ normal = "hertz", tangential = "spring" }
  local id = s:add_disk{ pos = { 0.005, 1e-3 + 1e-12 }, radius = 1e-3, material = mat }
  s:drag(3e5); s:run{ steps = 20000, dt = 1e-8 }; s:drag(0)
  s:set_velocity(id, { 1e-4, 1e-4 })
  local e0 = s:measure("energy").total
  local k0 = 0.5 * s:particles().mass[1] * 2e-8
  local worst = -math.huge
  for _ = 1, 20 do
    s:run{ steps = 5000, dt = 1e-8 }
    worst = math.max(worst, (s:measure("energy").total - e0) / k0)
  end
  check.le(worst, 1e-6, "spring law: energy never rises (it rose 34x the kinetic energy before the fix)")
end
-- ---- energy watch: a run going unstable without a word ------------------------------------
-- 60 undamped, frictionless disks at ~1 m/s in a closed box, no gravity, no driver: the energy
-- must stay (Hertz is conservative). At the stable limit velocity Verlet makes it fluctuate by
-- ~0.3%; forced to 3x the limit it grows without bound (it ran 20,000 steps to 1.33x unnoticed
-- before the watch). The run stops when the energy rises more than 10% of the mechanical energy
-- above its lowest value, giving both energies with their steps and times, the growth, the
-- limit, the cause and the remedy.
local function gas(seed)
  local L = 0.02
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { L, L } } }
  local q = grainlab.material{ density = 2650, young = 30e9, poisson = 0.3 }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { L, 0 }, normal = { -1, 0 } }
  s:add_wall{ point = { 0, L }, normal = { 0, -1 } }
  s:contact{ normal = "hertz" }
  local rng = grainlab.rng{ seed = seed }
  for i = 0, 59 do
    s:add_disk{ pos = { (i % 8 + 0.5) * L / 8, (i // 8 + 0.5) * L / 8 }, radius = 1e-3, material = q,
                vel = { rng:normal(0, 1), rng:normal(0, 1) } }
  end
  return s, s:timestep().limit
end
do
  local s, limit = gas(1)
  local e0 = s:measure("energy").total
  local msg = check.errors(function() s:run{ steps = 20000, dt = 3 * limit, force = true, progress = false } end,
                           "run: energy grew in a scene without drivers: ", "3x the limit: the energy watch stops the run")
  check.contains(msg, "limit 0.1); likely cause: the time step ", "3x: says the threshold and the cause")
  check.contains(msg, "too large for the contact stiffness", "3x: the cause")
  check.contains(msg, 'use dt = "auto" or a smaller dt', "3x: the remedy")
  local steps = s:info().steps
  check.lt(steps, 20000, "3x: stopped early")
  local a, sa, b, sb = msg:match("energy grew in a scene without drivers: (%S+) J at step (%d+) %(t = %S+ s%), (%S+) J at step (%d+)")
  check.is_true(a and b, "3x: both energies and steps in the message")
  check.eq(tonumber(sb), steps, "3x: the step named is the one it stopped at")
  check.lt(tonumber(sa), tonumber(sb), "3x: the low point came first")
  check.near(tonumber(b), s:measure("energy").total, 1e-5, "3x: the energy named is the scene's")
  check.gt((tonumber(b) - tonumber(a)) / tonumber(b), 0.1, "3x: it grew by more than 10%")
  check.gt(tonumber(b), e0, "3x: above the initial energy")
end
do -- the same gas at the stable limit, 10,000 steps, never trips
  local s, limit = gas(1)
  local e0 = s:measure("energy").total
  local r = s:run{ steps = 10000, dt = limit, progress = false }
  check.eq(r.steps, 10000, "at the limit: ran to the end")
  check.near(s:measure("energy").total, e0, 0.01, "at the limit: energy within 1%")
  -- and in chunks with a callback (the watch keeps its reference across chunks)
  local s2 = gas(2)
  local n = 0
  s2:run{ steps = 6000, dt = limit, every = 500, progress = false, on_step = function() n = n + 1 end }
  check.eq(n, 12, "at the limit, in chunks: ran to the end")
end
do -- in chunks at 3x: the watch keeps its reference across chunks and still stops it
  local s, limit = gas(1)
  check.errors(function() s:run{ steps = 20000, dt = 3 * limit, force = true, every = 100, progress = false,
                                 on_step = function(sc) sc:measure("energy") end } end,
               "energy grew in a scene without drivers", "3x in chunks of 100 steps")
end
do -- drivers are not watched: gravity along a periodic axis (a chute) gains energy legitimately
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, periodic = { true, false }, gravity = { 9.81, 0 } }
  s:add_disk{ pos = { 0.005, 0.005 }, radius = 0.5e-3 }
  check.eq(s:run{ steps = 5000, dt = 1e-4, force = true, progress = false }.steps, 5000, "periodic chute: not stopped")
  check.gt(s:particles().vx[1], 4.8, "periodic chute: it fell through ~120 periods")
  -- nor a moving wall pushing the gas
  local g, limit = gas(3)
  g:add_wall{ point = { 0.0198, 0 }, normal = { -1, 0 }, velocity = { -0.5, 0 } }
  check.eq(g:run{ steps = 4000, dt = limit, progress = false }.steps, 4000, "moving wall: not stopped")
end
-- ---- the likely cause comes from the scene, and the error from the user's line -------------
-- dt was "auto" in each of these: the message must not blame it.
do -- the README's pile without its side walls: a grain rolls off the floor's end
  local sand = grainlab.material{ density = 2650, young = 5e6, poisson = 0.3, friction = 0.5 }
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.03, 0.04 } }, gravity = { 0, -9.81 } }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  local line = debug.getinfo(1, "l").currentline + 1
  local msg = check.errors(function() grainlab.pack.deposit(s, { n = 100, radius = { 0.5e-3, 1e-3 }, seed = 7, material = sand }) end,
    "left the domain", "no side walls: the pile spreads out of the box")
  check.contains(msg, "test_dem_stability.lua:" .. line .. ": run: particle ", "no side walls: at the user's line")
  check.is_true(not msg:find("lua/grainlab/", 1, true), "no side walls: no library position: " .. msg)
  local sign = msg:match("likely cause: no wall on the ([+-])x side of the box %(x = ")
  check.is_true(sign ~= nil, "no side walls: names the open side: " .. msg)
  check.contains(msg, sign == "+" and "s:add_wall{ point = {0.03, 0}, normal = {-1, 0} }"
                                   or "s:add_wall{ point = {0, 0}, normal = {1, 0} }", "no side walls: the wall to add")
  check.contains(msg, "or make the x axis periodic", "no side walls: the other remedy")
  check.is_true(not msg:find("time step", 1, true), "no side walls: dt not blamed")
end
do -- a modulus in the wrong units: gravity alone squeezes a grain by 11 radii
  local soft = grainlab.material{ density = 2650, young = 5, poisson = 0.3, friction = 0.5 }
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.03, 0.04 } }, gravity = { 0, -9.81 } }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.03, 0 }, normal = { -1, 0 } }
  for i = 1, 10 do s:add_disk{ pos = { i * 2.5e-3, 0.02 }, radius = 1e-3, material = soft } end
  local msg = check.errors(function() s:run{ time = 0.1 } end, "run: particle ", "E = 5 Pa: stops")
  check.contains(msg, "likely cause: the contact stiffness is too small for the load: E = 5 Pa gives overlaps of ",
                 "E = 5 Pa: the cause")
  check.contains(msg, "under gravity alone; check the units (Pa)", "E = 5 Pa: the remedy")
  -- the overlap named is the static one of a grain's weight on a grain like it: m g = K d^1.5,
  -- K = 4/3 E* sqrt(r/2), E* = E / (2 (1 - nu^2))
  local id = tonumber(msg:match("run: particle (%d+) "))
  local p = s:particles()
  local K = 4 / 3 * 5 / (2 * (1 - 0.09)) * math.sqrt(p.radius[id] / 2)
  check.near(tonumber(msg:match("gives overlaps of (%S+) times")), (p.mass[id] * 9.81 / K) ^ (2 / 3) / p.radius[id], 1e-3,
             "E = 5 Pa: the overlap named")
end
do -- soft for the impacts (no gravity): 10 m/s against a wall with E = 1 Pa
  local soft = grainlab.material{ density = 2650, young = 1, poisson = 0.3 }
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_disk{ pos = { 0.005, 0.005 }, radius = 0.5e-3, vel = { -10, 0 }, material = soft }
  local msg = check.errors(function() s:run{ time = 0.01 } end, "run: particle 1 went through a wall", "E = 1 Pa impact")
  check.contains(msg, "likely cause: the contact stiffness is too small for the impacts: E = 1 Pa gives overlaps of ",
                 "E = 1 Pa impact: the cause")
  check.contains(msg, " at 10 m/s; check the units (Pa)", "E = 1 Pa impact: the speed")
end
do -- a driver faster than dt = "auto" was chosen for: named as such, dt not called too large
  local q = grainlab.material{ density = 2650, young = 30e9, poisson = 0.3 }
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  local w = s:add_wall{ point = { 0.01, 0 }, normal = { -1, 0 } }
  s:add_disk{ pos = { 0.005, 0.005 }, radius = 0.5e-3, material = q }
  s:wall_velocity(w, { -20, 0 })
  local msg = check.errors(function() s:run{ time = 0.001 } end, "run: particle 1 went through a wall", "driver")
  check.contains(msg, 'likely cause: a contact faster or stiffer than the time step was chosen for (dt = ', "driver: the cause")
  check.contains(msg, ', "auto", for impacts up to 0.1 m/s', "driver: the speed dt was chosen for")
  check.contains(msg, "give run{ impact_velocity = ... } the fastest impact", "driver: the remedy")
end
do -- forced above the limit: dt is blamed, with the factor
  local s = pile()
  local limit = s:timestep().limit
  local msg = check.errors(function() s:run{ steps = 1000, dt = 30 * limit, force = true } end, "run: particle ", "forced")
  check.contains(msg, string.format("likely cause: the time step is too large: dt = %.3g s is 30 times the stability limit %.3g s (forced)",
                                    30 * limit, limit), "forced: dt, the factor and the limit")
end
check.done()
