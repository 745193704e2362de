-- Packing generators for DEM scenes, reproducible from a seed:
--   pack.random(s, {…})   random sequential addition: no overlaps, uniform in a region;
--   pack.deposit(s, {…})  gravity deposition, Jodrey-Tory style (Padbidri Sec. 2.5): each disk is
--                         dropped at a random abscissa and followed as it falls and rolls over the
--                         pile until it rests on two supports (2D); then a short damped relaxation
--                         at the scene's real stiffness. In 3D, spheres are placed by random
--                         addition and settled dynamically with softened contacts and drag, then
--                         the stiffness is ramped back.
local pack = {}

local function fail(call, field, expected, got)
  local g = type(got) == "number" and tostring(got) or type(got) == "string" and ("'" .. got .. "'") or type(got)
  error(string.format("bad field '%s' in argument #2 to '%s' (%s expected, got %s)", field, call, expected, g), 3)
end

local function check_opts(call, opts, allowed)
  if type(opts) ~= "table" then
    error(string.format("bad argument #2 to '%s' (table expected, got %s)", call, type(opts)), 3)
  end
  for k in pairs(opts) do
    if not allowed[k] then
      local names = {}
      for name in pairs(allowed) do names[#names + 1] = name end
      table.sort(names)
      error(string.format("bad argument #2 to '%s' (unknown field '%s'; valid fields: %s)", call,
                          tostring(k), table.concat(names, ", ")), 3)
    end
  end
end

local function positive_int(call, opts, field, default)
  local v = opts[field]
  if v == nil then return default end
  if math.type(v) ~= "integer" or v < 1 then fail(call, field, "positive integer", v) end
  return v
end

-- radius: a number or {lo, hi} (uniform); returns the sampler and the largest radius.
local function radius_sampler(call, radius, rng)
  if radius == nil then radius = { 0.5e-3, 1e-3 } end
  if type(radius) == "number" then
    if not (radius > 0) then fail(call, "radius", "positive number or {min, max}", radius) end
    return function() return radius end, radius
  end
  if type(radius) ~= "table" or type(radius[1]) ~= "number" or type(radius[2]) ~= "number" or
     not (radius[1] > 0 and radius[2] >= radius[1]) then
    fail(call, "radius", "positive number or {min, max} with 0 < min <= max", radius)
  end
  local lo, hi = radius[1], radius[2]
  return function() return rng:uniform(lo, hi) end, hi
end

local function region_of(call, s, region, dim)
  local info = s:info()
  if region == nil then return info.box[1], info.box[2] end
  local ok = type(region) == "table" and type(region[1]) == "table" and type(region[2]) == "table"
  for d = 1, dim do
    ok = ok and type(region[1][d]) == "number" and type(region[2][d]) == "number" and region[2][d] > region[1][d]
  end
  if not ok then fail(call, "region", "{{lower corner}, {upper corner}}", region) end
  return region[1], region[2]
end

-- A uniform grid of buckets over the particles placed so far.
local function new_grid(lo, hi, cell, dim)
  local g = { cell = cell, lo = lo, n = {}, buckets = {} }
  for d = 1, dim do g.n[d] = math.max(1, math.floor((hi[d] - lo[d]) / cell) + 1) end
  local function key(c) return dim == 2 and (c[2] * g.n[1] + c[1]) or ((c[3] * g.n[2] + c[2]) * g.n[1] + c[1]) end
  local function coord(x, d) return math.min(g.n[d] - 1, math.max(0, math.floor((x - lo[d]) / cell))) end
  function g.add(p)
    local c = {}
    for d = 1, dim do c[d] = coord(p[d], d) end
    local k = key(c)
    local b = g.buckets[k]
    if not b then b = {}; g.buckets[k] = b end
    b[#b + 1] = p
  end
  -- Calls fn(p) for every particle in the cells within `reach` of x.
  function g.near(x, reach, fn)
    local lo_c, hi_c = {}, {}
    for d = 1, dim do
      lo_c[d] = coord(x[d] - reach, d)
      hi_c[d] = coord(x[d] + reach, d)
    end
    local c = {}
    for cz = (dim == 3 and lo_c[3] or 0), (dim == 3 and hi_c[3] or 0) do
      for cy = lo_c[2], hi_c[2] do
        for cx = lo_c[1], hi_c[1] do
          c[1], c[2], c[3] = cx, cy, cz
          local b = g.buckets[key(c)]
          if b then for _, p in ipairs(b) do if fn(p) then return true end end end
        end
      end
    end
    return false
  end
  return g
end

local function existing(s, dim)
  local P, list = s:particles(), {}
  local rmax = 0
  for i = 1, P.count do
    list[i] = { P.x[i], P.y[i], dim == 3 and P.z[i] or nil, r = P.radius[i] }
    rmax = math.max(rmax, P.radius[i])
  end
  return list, rmax
end

function pack.random(s, opts)
  local call = "pack.random"
  check_opts(call, opts, { n = true, radius = true, region = true, seed = true, material = true,
                           max_tries = true, speed = true })
  local info = s:info()
  local dim = info.dim
  local n = positive_int(call, opts, "n", nil)
  if not n then fail(call, "n", "positive integer", nil) end
  local rng = grainlab.rng{ seed = opts.seed or 0 }
  local sample, rmax_new = radius_sampler(call, opts.radius, rng)
  local lo, hi = region_of(call, s, opts.region, dim)
  local max_tries = positive_int(call, opts, "max_tries", 1000 * n)
  local speed = opts.speed or 0
  if type(speed) ~= "number" or not (speed >= 0) then fail(call, "speed", "non-negative number", speed) end
  local placed, rmax = existing(s, dim)
  rmax = math.max(rmax, rmax_new)
  local grid = new_grid(lo, hi, 2 * rmax, dim)
  for _, p in ipairs(placed) do grid.add(p) end
  local add = dim == 2 and s.add_disk or s.add_sphere
  local ids, tries, area = {}, 0, 0
  for _ = 1, n do
    local r = sample()
    local ok = false
    while not ok do
      tries = tries + 1
      if tries > max_tries then
        error(string.format("%s: placed %d of %d particles in %d tries; the region is too full for random addition (use pack.deposit, a larger region or fewer particles)",
                            call, #ids, n, max_tries), 2)
      end
      local x = {}
      for d = 1, dim do x[d] = rng:uniform(lo[d] + r, hi[d] - r) end
      local clash = grid.near(x, r + rmax, function(p)
        local d2 = 0
        for d = 1, dim do d2 = d2 + (x[d] - p[d]) ^ 2 end
        return d2 < (r + p.r) ^ 2
      end)
      if not clash then
        local vel
        if speed > 0 then -- random direction, fixed speed
          local v, norm = {}, 0
          for d = 1, dim do v[d] = rng:normal(); norm = norm + v[d] ^ 2 end
          for d = 1, dim do v[d] = speed * v[d] / math.sqrt(norm) end
          vel = v
        end
        local okadd, id = pcall(add, s, { pos = x, radius = r, material = opts.material, vel = vel })
        if okadd then
          ok = true
          x.r = r
          grid.add(x)
          ids[#ids + 1] = id
          area = area + (dim == 2 and math.pi * r * r or 4 / 3 * math.pi * r ^ 3)
        elseif not tostring(id):find("overlaps", 1, true) then
          error(id, 0)
        end
      end
    end
  end
  local vol = 1
  for d = 1, dim do vol = vol * (hi[d] - lo[d]) end
  return ids, { placed = #ids, tries = tries, fraction = area / vol }
end

-- 2D drop-and-roll: the resting place of a disk of radius r dropped at abscissa x0 onto the
-- disks in `grid`, inside [xl, xr] above the floor yf. Returns x, y.
local function drop_and_roll(grid, r, x0, xl, xr, yf, rmax, ytop)
  -- Falling straight down from height y at abscissa px, excluding disk `skip`: the first disk
  -- met (or nil for the floor) and the height of the centre there.
  local function fall(px, y, skip)
    local best, who = yf + r, nil
    local c0 = math.max(0, math.floor((px - r - rmax - grid.lo[1]) / grid.cell))
    local c1 = math.min(grid.n[1] - 1, math.floor((px + r + rmax - grid.lo[1]) / grid.cell))
    local top = math.min(grid.n[2] - 1, math.floor((y - grid.lo[2]) / grid.cell) + 1)
    for cy = top, 0, -1 do
      -- rows below reach at most their top edge + r + rmax: stop when that cannot beat `best`
      if grid.lo[2] + (cy + 1) * grid.cell + r + rmax < best then break end
      for cx = c0, c1 do
        local b = grid.buckets[cy * grid.n[1] + cx]
        if b then
          for _, p in ipairs(b) do
            local dx, R = px - p[1], r + p.r
            if p ~= skip and math.abs(dx) < R then
              local h = p[2] + math.sqrt(R * R - dx * dx)
              if h > best and h <= y + 1e-12 then best, who = h, p end
            end
          end
        end
      end
    end
    return best, who
  end
  local x = x0
  local y, on = fall(x, ytop, nil)
  for _ = 1, 10000 do
    if not on then return x, y end -- on the floor
    -- Roll around `on`, downhill, until another disk, the floor, a side wall or the equator.
    local cx, cy, R = on[1], on[2], r + on.r
    local dir = x >= cx and 1 or -1
    local theta = math.atan(x - cx, y - cy) -- angle from the upward vertical, signed
    local best_t, best_p, kind = dir * math.pi / 2, nil, "equator"
    local function consider(t, k, p)
      if (t - theta) * dir > 1e-12 and (t - best_t) * dir < 0 then best_t, kind, best_p = t, k, p end
    end
    local cf = (yf + r - cy) / R -- floor: cy + R cos(t) = yf + r
    if cf > -1 and cf < 1 then consider(dir * math.acos(cf), "floor") end
    for _, xw in ipairs{ xl + r, xr - r } do -- side walls: cx + R sin(t) = xw
      local sw = (xw - cx) / R
      if sw > -1 and sw < 1 then consider(math.asin(sw), "wall") end
    end
    grid.near({ cx, cy }, R + r + rmax, function(p) -- other disks: circle (c, R) meets (p, r + p.r)
      if p == on then return false end
      local dx, dy = p[1] - cx, p[2] - cy
      local d, R2 = math.sqrt(dx * dx + dy * dy), r + p.r
      if d >= R + R2 or d <= math.abs(R - R2) then return false end
      local a = (R * R - R2 * R2 + d * d) / (2 * d)
      local hh = math.sqrt(math.max(0, R * R - a * a))
      local mx, my = cx + a * dx / d, cy + a * dy / d
      for _, sgn in ipairs{ 1, -1 } do
        local px, py = mx - sgn * hh * dy / d, my + sgn * hh * dx / d
        consider(math.atan(px - cx, py - cy), "disk", p)
      end
      return false
    end)
    x, y = cx + R * math.sin(best_t), cy + R * math.cos(best_t)
    if kind == "floor" or kind == "wall" then return x, y end
    if kind == "disk" then
      if (x - cx) * (x - best_p[1]) <= 0 then return x, y end -- cradled between two supports
      on = best_p -- both supports on one side: roll on around the new one
    else
      y, on = fall(x, y, on) -- past the equator of its support: fall again
    end
  end
  return x, y
end

function pack.deposit(s, opts)
  local call = "pack.deposit"
  check_opts(call, opts, { n = true, radius = true, region = true, seed = true, material = true,
                           relax_steps = true, drag = true })
  local info = s:info()
  local dim = info.dim
  local n = positive_int(call, opts, "n", nil)
  if not n then fail(call, "n", "positive integer", nil) end
  local rng = grainlab.rng{ seed = opts.seed or 0 }
  local sample, rmax_new = radius_sampler(call, opts.radius, rng)
  local lo, hi = region_of(call, s, opts.region, dim)
  local g = info.gravity
  if dim == 3 then
    -- 3D: random addition in the region, then dynamic settling (softened, dragged, re-stiffened).
    local ids = pack.random(s, { n = n, radius = opts.radius, region = { lo, hi }, seed = opts.seed,
                                 material = opts.material })
    local drag = opts.drag or 50
    s:scale_stiffness(1e-4)
    s:drag(drag)
    s:run{ time = 0.3 }
    for _ = 1, 4 do s:scale_stiffness(10); s:run{ steps = opts.relax_steps or 2000 } end
    s:drag(0)
    return ids, { placed = #ids }
  end
  if not (g[1] == 0 and g[2] < 0) then
    error(call .. ": 2D deposition needs gravity along -y (got {" .. g[1] .. ", " .. g[2] .. "})", 2)
  end
  local placed, rmax = existing(s, dim)
  rmax = math.max(rmax, rmax_new)
  local grid = new_grid(lo, hi, 2 * rmax, dim)
  for _, p in ipairs(placed) do grid.add(p) end
  local ids = {}
  local ytop = hi[2]
  for k = 1, n do
    local r = sample()
    local x0 = rng:uniform(lo[1] + r, hi[1] - r)
    local x, y = drop_and_roll(grid, r, x0, lo[1], hi[1], lo[2], rmax, ytop)
    if y + r > hi[2] then
      error(string.format("%s: the region is full after %d of %d disks (the pile reached the top at y = %g)",
                          call, k - 1, n, hi[2]), 2)
    end
    local p = { x, y, r = r }
    grid.add(p)
    -- A hair above contact, so the DEM relaxation starts from touching, not overlapping, disks.
    local id = s:add_disk{ pos = { x, y + 1e-12 }, radius = r, material = opts.material }
    ids[#ids + 1] = id
  end
  -- Relax under gravity at the real stiffness, with drag to kill the elastic ringing.
  local drag = opts.drag or 200
  local old = s:drag()
  s:drag(drag)
  s:run{ steps = opts.relax_steps or 3000 }
  s:drag(old)
  return ids, { placed = #ids }
end

-- Settles a scene into a quiescent state cheaply: contacts softened by `soften` (time steps grow
-- like soften^(-2/5) for Hertz), a background drag, at least min_steps until the rms speed is below
-- `quiet`; then the stiffness is restored gently (ramp_stages factors, each followed by ramp_steps
-- steps with the drag on: a sudden stiffening releases the stored elastic energy at once and
-- blows the pile apart); then drag off and `final_steps` steps at dt_final.
function pack.settle(s, opts)
  local call = "pack.settle"
  opts = opts or {}
  check_opts(call, opts, { soften = true, drag = true, quiet = true, min_steps = true,
                           max_steps = true, ramp_stages = true, ramp_steps = true,
                           final_steps = true, dt_final = true, verbose = true })
  local soften = opts.soften or 1e-3
  if type(soften) ~= "number" or not (soften > 0 and soften <= 1) then fail(call, "soften", "number in (0, 1]", soften) end
  local quiet = opts.quiet or 1e-3
  local drag = opts.drag or 20
  local stages = positive_int(call, opts, "ramp_stages", 30)
  local ramp_steps = positive_int(call, opts, "ramp_steps", 1000)
  local min_steps = positive_int(call, opts, "min_steps", 20000)
  local max_steps = positive_int(call, opts, "max_steps", 200000)
  local final_steps = opts.final_steps or 2000
  local function rms()
    local P, s2 = s:particles(), 0
    for i = 1, P.count do
      s2 = s2 + P.vx[i] ^ 2 + P.vy[i] ^ 2 + (P.vz and P.vz[i] ^ 2 or 0)
    end
    return math.sqrt(s2 / math.max(1, P.count))
  end
  local old_drag = s:drag()
  local steps = 0
  s:scale_stiffness(soften)
  s:drag(drag)
  local v = math.huge
  while (steps < min_steps or v > quiet) and steps < max_steps do
    local r = s:run{ steps = 2000, impact_velocity = 0.1, progress = false }
    steps = steps + r.steps
    v = rms()
    if opts.verbose then io.stderr:write(string.format("settle: %d soft steps, v_rms %.3g m/s\n", steps, v)) end
  end
  local factor = (1 / soften) ^ (1 / stages)
  for k = 1, stages do
    s:scale_stiffness(k < stages and factor or (1 / soften) / factor ^ (stages - 1))
    steps = steps + s:run{ steps = ramp_steps, impact_velocity = 0.1, progress = false }.steps
  end
  s:drag(old_drag)
  if final_steps > 0 then
    steps = steps + s:run{ steps = final_steps, dt = opts.dt_final, progress = false }.steps
  end
  local z = s:measure("coordination")
  return { steps = steps, v_rms = rms(), z = z.z, z_no_rattlers = z.z_no_rattlers }
end

grainlab.doc(pack, { name = "grainlab.pack", doc = [[Packing generators (reproducible from seed):
  pack.random(s, { n =, radius = r | {min, max}, region = {{lo},{hi}}, seed =, material =, speed = })
    random sequential addition without overlaps; returns ids, {placed, tries, fraction}
  pack.deposit(s, { n =, radius = {0.5e-3, 1e-3}, region =, seed =, material =, relax_steps = 3000, drag = 200 })
    gravity deposition: 2D drop-and-roll (Jodrey-Tory style) onto the floor of the region, then a
    damped relaxation at the scene's stiffness; 3D: random addition and dynamic settling.
  pack.settle(s, { soften = 1e-3, drag = 20, quiet = 1e-3, min_steps = 20000, max_steps = 200000,
                   ramp_stages = 30, ramp_steps = 1000, final_steps = 2000, dt_final = nil })
    settles a scene with softened contacts and drag, then restores the stiffness gently;
    returns {steps, v_rms, z, z_no_rattlers}.]] })
return pack
