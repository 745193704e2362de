-- The pile in a box of Herrmann & Mueller Sec. 3, shared by scripts/repose.lua (the angle of
-- repose: the gate removed) and scripts/marginal_stability.lua (the angle of marginal stability:
-- the box tilted), their variants with rolling resistance, with liquid bridges and with clumps
-- (scripts/repose_rolling.lua, scripts/repose_cohesive.lua, scripts/repose_clumps.lua), and
-- their tests. Not a scenario;
-- load it with
--   local heap_box = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/heap_box.lua")
--
-- heap_box.new{ n, mu, seed, young, aspect, ... } builds and settles the packing (the procedure
-- and its reasons are in scripts/repose.lua's header; geometry_only = true: the sizes only):
--   box    x in [0, W]: left wall x = 0, the gate (a removable wall) x = W, a rough floor of
--          fixed disks of radius rmin with their tops at y = 0; N disks, radii uniform in
--          [rmin, rmax], deposited to a height h0 = aspect * W (W = sqrt(N a / aspect)).
--   basin  below and beside the box (floor y = -0.6 W, far wall x = 3 W), for the grains that
--          leave it when the gate is removed; the domain has no open side.
--   law    Hertz + Brilliantov damping (restitution e_rest at 1 m/s, every pair its own time) +
--          Cundall-Strack spring capped at mu f_n; with mu_r, rolling resistance (the EPSD law,
--          rolling friction mu_r, rolling damping 0.3); with bridge = { liquid_volume,
--          surface_tension, contact_angle }, a liquid bridge on every contact, planes included
--          (cohesion "capillary", docs/dem.md "Cohesion"); dt = dt_factor x the stability limit
--          at 2 m/s.
--   settle 0.1 s with a background drag of 20/s, then without, in slices of 0.02 s, until the
--          fastest grain is below v_rest (at most 0.6 s).
-- shape = "dimer" | "trimer" (default "disk": the disks above) fills the box with rigid clumps
-- (docs/dem.md "Clumps") of equal member disks of radius r, r taking `sizes` values evenly over
-- [rmin, rmax] (a template each, drawn at random): a dimer two members r apart (aspect ratio
-- 1.5), a trimer three at the corners of a triangle of side r. As many clumps as hold the N disks'
-- area (the same box W), rounded; poured by random sequential addition (grainlab.pack.clumps)
-- into the box up to a height that they fill at area fraction 0.3, then falling with the drag on
-- until the fastest is below 5 cm/s (at most 1 s), then settled as above. b.grains is then the
-- number of clumps, b.members their members (the scene's particles after the floor).
-- The returned box b has b.s (the scene), b.nf (the floor disks, the scene's first particles),
-- b.W, b.h_init (top of the settled packing), b.dt, b.t_relax, and the methods below.
local heap_box = {}

local g, rho, nu = 9.81, 2650, 0.3
local v_imp = 2.0 -- m/s, the impact velocity the time step is chosen for
heap_box.gravity, heap_box.density, heap_box.poisson = g, rho, nu

-- The clumps' members' offsets in units of the member radius r: centres r apart.
local clump_shapes = {
  dimer = { { -0.5, 0 }, { 0.5, 0 } },
  trimer = { { 0, 1 / math.sqrt(3) }, { -0.5, -0.5 / math.sqrt(3) }, { 0.5, -0.5 / math.sqrt(3) } },
}

-- The friction coefficients of a script's `mus` parameter ("0.1,0.8" or one number), sorted;
-- `default` when it is not given.
function heap_box.mus(text, default)
  if not text then return default end
  local mus = {}
  for v in tostring(text):gmatch("[^,]+") do
    local mu = tonumber(v)
    assert(mu and mu >= 0, "mus must be a comma-separated list of non-negative numbers")
    mus[#mus + 1] = mu
  end
  table.sort(mus)
  return mus
end

-- Runs run(mu, seed) for every mu of o.mus and o.seeds packings (seeds o.seed, o.seed + 1, ...)
-- under a progress line (o.label), and returns one table per mu: mu, runs (run's tables), and
-- for every key of o.mean the mean over the packings (and key_sd, the standard deviation, when
-- seeds > 1), of o.max the largest (NaN, a failed fit, stays visible), of o.sum the sum.
function heap_box.sweep(o)
  local seeds = o.seeds
  local progress = grainlab.progress{ label = o.label, total = #o.mus * seeds, unit = "runs" }
  local results, done = {}, 0
  for i, mu in ipairs(o.mus) do
    local r = { mu = mu, runs = {} } -- (mu: the swept value, whatever it is)
    for k = 1, seeds do
      r.runs[k] = o.run(mu, o.seed + k - 1)
      done = done + 1
      progress:update(done)
    end
    for _, key in ipairs(o.mean or {}) do
      local m, var = 0, 0
      for _, x in ipairs(r.runs) do m = m + x[key] / seeds end
      for _, x in ipairs(r.runs) do var = var + (x[key] - m) ^ 2 end
      r[key] = m
      if seeds > 1 then r[key .. "_sd"] = math.sqrt(var / (seeds - 1)) end
    end
    for _, key in ipairs(o.max or {}) do
      r[key] = -math.huge
      for _, x in ipairs(r.runs) do
        r[key] = math.max(r[key], x[key])
        if x[key] ~= x[key] then r[key] = x[key] break end
      end
    end
    for _, key in ipairs(o.sum or {}) do
      r[key] = 0
      for _, x in ipairs(r.runs) do r[key] = r[key] + x[key] end
    end
    results[i] = r
  end
  progress:finish()
  return results
end

function heap_box.new(o)
  local b = {
    n = o.n, mu = o.mu, seed = o.seed, young = o.young or 1e6, aspect = o.aspect or 0.5,
    dt_factor = o.dt_factor or 1, v_rest = o.v_rest or 5e-3, rmin = o.rmin or 0.5e-3,
    rmax = o.rmax or 1e-3, e_rest = o.e_rest or 0.5,
  }
  setmetatable(b, { __index = heap_box })
  local rmin, rmax = b.rmin, b.rmax
  b.dmean = rmin + rmax
  -- Area per disk in the packing: pi <r^2> / 0.82, <r^2> = (rmax^3 - rmin^3) / (3 (rmax - rmin)).
  local area = math.pi * (rmax ^ 3 - rmin ^ 3) / (3 * (rmax - rmin)) / 0.82
  b.W = math.sqrt(b.n * area / b.aspect)
  b.h0 = b.aspect * b.W
  b.rf = rmin -- floor disks
  b.depth, b.length = 0.6 * b.W, 3 * b.W
  b.top = 1.6 * b.h0 + 4 * rmax
  b.shape = o.shape or "disk"
  b.grains, b.members = b.n, b.n
  if b.shape ~= "disk" then
    local unit = clump_shapes[b.shape]
    assert(unit, "heap_box: shape must be \"disk\", \"dimer\" or \"trimer\"")
    local sizes, a_mean = o.sizes or 6, 0
    b.templates = {}
    for k = 1, sizes do
      local r = rmin + (k - 0.5) * (rmax - rmin) / sizes
      local members = {}
      for q, u in ipairs(unit) do members[q] = { offset = { u[1] * r, u[2] * r }, radius = r } end
      b.templates[k] = dem.clump_template{ members = members }
      a_mean = a_mean + b.templates[k]:info().disks.area / sizes
    end
    -- the N disks' solid area, 0.82 of the packing's
    b.grains = math.floor(b.n * 0.82 * area / a_mean + 0.5)
    b.members = b.grains * #unit
    b.fill_top = 0.82 * b.h0 / 0.3 -- the pouring region's top: area fraction 0.3
    b.top = b.fill_top + 4 * rmax
  end
  b.bw = 2 * rmax -- surface bins
  b.nb = math.floor(b.W / b.bw)
  if o.geometry_only then return b end -- the sizes only, no scene

  b.mu_r = o.mu_r -- rolling friction (EPSD law, docs/dem.md "Rolling resistance"); nil: none
  local mat = grainlab.material{ density = rho, young = b.young, poisson = nu, friction = b.mu,
                                 rolling_friction = b.mu_r }
  local s = dem.scene{ dim = 2, box = { { 0, -b.depth }, { b.length, b.top } }, gravity = { 0, -g } }
  b.s = s
  s:contact{ normal = "hertz", tangential = "spring" } -- for the deposit's own relaxation
  b.left_wall = s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  b.gate = s:add_wall{ point = { b.W, 0 }, normal = { -1, 0 } }
  s:add_wall{ point = { 0, -b.depth }, normal = { 0, 1 } }
  s:add_wall{ point = { b.length, 0 }, normal = { -1, 0 } }
  b.nf = 0
  for k = 0, math.floor(b.W / (2 * b.rf)) - 1 do
    s:add_disk{ pos = { b.rf + 2 * b.rf * k, -b.rf }, radius = b.rf, material = mat, fixed = true }
    b.nf = b.nf + 1
  end
  if b.shape == "disk" then
    grainlab.pack.deposit(s, { n = b.n, radius = { rmin, rmax }, seed = b.seed, material = mat,
                               region = { { 0, -2 * b.rf }, { b.W, b.top - 2 * rmax } },
                               relax_steps = 0 })
  else
    grainlab.pack.clumps(s, { n = b.grains, template = b.templates, seed = b.seed, material = mat,
                              region = { { 0, 0 }, { b.W, b.fill_top } } })
  end
  local bridge = o.bridge or {} -- nil: dry grains, the law above and nothing more
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = b.e_rest, impact_velocity = 1,
             tangential = "spring", rolling_resistance = b.mu_r and "epsd" or nil,
             rolling_damping = b.mu_r and 0.3 or nil, cohesion = o.bridge and "capillary" or nil,
             liquid_volume = bridge.liquid_volume, surface_tension = bridge.surface_tension,
             contact_angle = bridge.contact_angle }
  b.dt = b.dt_factor * s:timestep{ impact_velocity = v_imp }.limit

  s:drag(20)
  b.t_fall = 0
  if b.shape ~= "disk" then -- the poured clumps fall onto the floor first
    repeat
      b:advance(0.02)
      b.t_fall = b.t_fall + 0.02
    until b:state() < 0.05 or b.t_fall >= 1 - 1e-9
  end
  b:advance(0.1)
  s:drag(0)
  b.t_relax = 0.1
  repeat
    b:advance(0.02)
    b.t_relax = b.t_relax + 0.02
  until b:state() < b.v_rest or b.t_relax >= 0.6 - 1e-9
  b.h_init = 0
  for _, h in pairs(b:surface()) do b.h_init = math.max(b.h_init, h) end
  return b
end

function heap_box:advance(T)
  self.s:run{ time = T, dt = self.dt, impact_velocity = v_imp, progress = false }
end

-- In the box (x < W, y > 0 in the box's frame): the fastest grain, the number of grains, and the
-- number faster than v (when v is given).
function heap_box:state(v)
  local P = self.s:particles()
  local vmax, count, fast = 0, 0, 0
  for i = self.nf + 1, P.count do
    if P.x[i] < self.W and P.y[i] > 0 then
      local sp = math.sqrt(P.vx[i] ^ 2 + P.vy[i] ^ 2)
      vmax = math.max(vmax, sp)
      count = count + 1
      if v and sp > v then fast = fast + 1 end
    end
  end
  return vmax, count, fast
end

-- Top of the highest grain in the box (y + r) per bin (0-based; nil where empty).
function heap_box:surface()
  local P, tops = self.s:particles(), {}
  for i = self.nf + 1, P.count do
    if P.x[i] < self.W and P.y[i] > 0 then
      local k = math.floor(P.x[i] / self.bw)
      if k >= 0 and k < self.nb then
        tops[k] = math.max(tops[k] or -math.huge, P.y[i] + P.radius[i])
      end
    end
  end
  return tops
end

-- Least squares y = a + b x through the points (xs[i], ys[i]): a, b.
function heap_box.line(xs, ys)
  local k, sx, sy, sxx, sxy = #xs, 0, 0, 0, 0
  for i = 1, k do
    sx, sy = sx + xs[i], sy + ys[i]
    sxx, sxy = sxx + xs[i] * xs[i], sxy + xs[i] * ys[i]
  end
  local b = (k * sxy - sx * sy) / (k * sxx - sx * sx)
  return (sy - b * sx) / k, b
end

-- The bins' tops at least two largest diameters from the left wall and the gate line (and, when
-- given, keep(h)): lists x, h.
local function inner_tops(self, tops, keep)
  local xs, ys = {}, {}
  for k = 0, self.nb - 1 do
    local x, h = (k + 0.5) * self.bw, tops[k]
    if h and x >= 2 * self.bw and x <= self.W - 2 * self.bw and (not keep or keep(h)) then
      xs[#xs + 1], ys[#ys + 1] = x, h
    end
  end
  return xs, ys
end

-- Least-squares line h = a + s x through the sloping part of the surface: the inner bins above
-- the first layer (> 2 rmax) and below the settled top minus 2 rmax. Returns the angle atan(-s)
-- (deg), the rms residual (mean diameters) and the number of points.
function heap_box:fit(tops)
  local xs, ys = inner_tops(self, tops, function(h)
    return h > 2 * self.rmax and h < self.h_init - 2 * self.rmax
  end)
  local k = #xs
  if k < 5 then return 0 / 0, 0 / 0, k end
  local a, slope = heap_box.line(xs, ys)
  local ss = 0
  for i = 1, k do ss = ss + (ys[i] - a - slope * xs[i]) ^ 2 end
  return math.deg(math.atan(-slope)), math.sqrt(ss / k) / self.dmean, k
end

-- The slope of the whole surface in the box's frame (deg, positive when it rises towards the
-- gate): a line through the tops of the inner bins.
function heap_box:surface_slope()
  local xs, ys = inner_tops(self, self:surface())
  if #xs < 5 then return 0 / 0 end
  local _, slope = heap_box.line(xs, ys)
  return math.deg(math.atan(slope))
end

-- The angle of repose: the gate removed, slices of 0.05 s until, after at least 0.3 s, the
-- fastest grain still in the box is below v_rest (at most T_max). Returns a table: theta (deg),
-- rms, points, left (grains in the box), vmax, t, tops, basin_top (the highest resting grain
-- outside the box region). on_slice(t, vmax, left) is called after each slice when given.
function heap_box:collapse(T_max, on_slice)
  local s = self.s
  s:remove_wall(self.gate)
  local t, vmax, left = 0, math.huge, self.members
  while t < T_max - 1e-9 do
    self:advance(0.05)
    t = t + 0.05
    vmax, left = self:state()
    if on_slice then on_slice(t, vmax, left) end
    if t >= 0.3 - 1e-9 and vmax < self.v_rest then break end
  end
  -- The highest resting grain (< 5 cm/s: not one still falling off the edge) outside the box
  -- region (x >= W or y <= 0): the basin heap must stay below the box floor.
  local P = s:particles()
  local basin_top = -self.depth
  for i = self.nf + 1, P.count do
    if (P.x[i] >= self.W or P.y[i] <= 0) and P.vx[i] ^ 2 + P.vy[i] ^ 2 < 0.05 ^ 2 then
      basin_top = math.max(basin_top, P.y[i] + P.radius[i])
    end
  end
  local tops = self:surface()
  local theta, rms, points = self:fit(tops)
  return { theta = theta, rms = rms, points = points, left = left, vmax = vmax, t = t,
           tops = tops, basin_top = basin_top }
end

-- Gravity tilted by theta (deg) towards the gate (+x): the box tilted the other way.
function heap_box:tilt_to(theta)
  local r = math.rad(theta)
  self.s:gravity({ g * math.sin(r), -g * math.cos(r) })
end

-- The angle of marginal stability: the closed box tilted in steps (gravity rotated towards the
-- gate), each held for `hold` s. An avalanche is a surface that gave way: at least `fraction` of
-- the grains moved by more than a mean diameter during one hold. (Fast grains or a rise of the
-- surface's slope by a fraction of a degree also flag the small slips of a few surface grains
-- that come and go from a few degrees on, long before the surface fails.) The deposit's surface
-- is not level (a few degrees), so the angle is the surface's own: theta_m = the tilt that made
-- it give way minus the slope it had in the box before that tilt (surface_slope), i.e. its angle
-- to the horizontal when it failed. From `start` deg in steps of `step` deg until the first
-- avalanche, then again from the last stable state (restored from a checkpoint: the same state,
-- exactly) in steps of step / refine until the first avalanche (which may come past the coarse
-- step's tilt: a jump of a whole coarse step can set off what smaller steps do not). Returns theta_m (deg), the surface's angle to the
-- horizontal after the failing hold, the tilt that failed, the number of holds, and true when the
-- fine steps found no avalanche within two coarse steps past the coarse one (the pile crept: the
-- coarse result is returned).
-- on_hold(tilt, moved, slope) is called after each hold when given (moved: the grains that
-- moved by more than a mean diameter).
function heap_box:marginal(o)
  local start, step, hold = o.start or 4, o.step or 2, o.hold or 0.2
  local refine, fraction = o.refine or 4, o.fraction or 0.1
  local ckpt, limit = assert(o.checkpoint, "heap_box:marginal needs checkpoint = path"), o.limit or 60
  local need = math.max(3, math.ceil(fraction * self.n))
  local prev, holds = self:surface_slope(), 0
  local function gives_way(theta) -- true, the slope after; or false, and prev moves on
    local P0 = self.s:particles()
    self:tilt_to(theta)
    holds = holds + 1
    self:advance(hold)
    local P, moved, d2 = self.s:particles(), 0, self.dmean ^ 2
    for i = self.nf + 1, P.count do
      if (P.x[i] - P0.x[i]) ^ 2 + (P.y[i] - P0.y[i]) ^ 2 > d2 then moved = moved + 1 end
    end
    local slope = self:surface_slope()
    if o.on_hold then o.on_hold(theta, moved, slope) end
    if moved >= need then return true, slope end
    prev = slope
    return false
  end
  -- coarse: the last stable state saved before each step
  local stable, theta = 0, start
  local stable_slope = prev
  self.s:save(ckpt)
  local failed, coarse_after = false, nil
  while theta <= limit do
    local gave, slope = gives_way(theta)
    if gave then failed, coarse_after = true, slope break end
    stable, stable_slope = theta, prev
    self.s:save(ckpt)
    theta = theta + step
  end
  if not failed then return 0 / 0, 0 / 0, theta, holds end
  local coarse = { theta - stable_slope, theta - coarse_after, theta }
  -- fine: from the last stable state, on past the coarse failure if need be (a jump of the
  -- whole coarse step can set off what smaller steps to the same tilt do not), up to `span`
  -- (two coarse steps) beyond it; a pile that only creeps under the small steps (strong rolling
  -- resistance: each hold moves fewer than `fraction` of the grains a diameter) keeps the coarse
  -- result, and the fifth value says so
  self.s = dem.load(ckpt)
  prev = stable_slope
  local fine = step / refine
  local t, last = stable + fine, math.min(limit, theta + (o.span or 2 * step))
  while t <= last + 1e-9 do
    local before = prev
    local gave, slope = gives_way(t)
    if gave then return t - before, t - slope, t, holds, false end
    t = t + fine
  end
  return coarse[1], coarse[2], coarse[3], holds, true
end

-- The checks every gate-removal pile carries, appended to `checks` for run tag id: the surface
-- fit's rms (in mean diameters) within rms_limit, the pile at rest (fastest grain in the box
-- below v_rest) and the basin heap below the box floor by two floor radii (rf).
function heap_box.pile_checks(checks, id, r, rms_limit, v_rest, rf)
  checks[#checks + 1] = { name = "fit_rms_over_d_" .. id, value = r.rms, limit = rms_limit }
  checks[#checks + 1] = { name = "at_rest_v_max_m_per_s_" .. id, value = r.vmax, limit = v_rest,
                          op = "<" }
  checks[#checks + 1] = { name = "basin_clear_top_m_" .. id, value = r.basin_top, limit = -2 * rf }
end

return heap_box
