-- Packing generators for DEM scenes, reproducible from a seed:
--   pack.random(s, {…})   random sequential addition: no overlaps, uniform in a region;
--   pack.deposit(s, {…})  gravity deposition, Jodrey-Tory style (Padbidri Sec. 2.5): each disk is
--                         dropped at a random abscissa and followed as it falls and rolls over the
--                         pile until it rests on two supports (2D); then pack.settle relaxes it
--                         at the scene's real stiffness. In 3D, spheres are placed by random
--                         addition and settled dynamically with softened contacts and drag, then
--                         the stiffness is ramped back;
--   pack.settle(s, {…})   damps a packing into a quiescent state (critical background drag);
--   pack.slab{…}          a dense polydisperse disk packing of a square periodic in y, for MPM
--                         grains (the shear test of Bardenhagen et al., Fig. 5); returns tables.
local args = require("grainlab.args")
local pack = {}

-- Every public function checks its arguments at entry against these specs (grainlab.args), so
-- an error names grainlab.pack.* and the field, never add_disk, rng or uniform; the same specs
-- give the field lists that help() and the generated binding test read.
local function fail(call, field, expected, got) args.fail(call, call:find("slab") and 1 or 2, field, expected, got) end

-- Counts are capped: a Lua-side packer placing more than ten million grains would run for hours
-- (and an integer like 2^62 would never end).
local MAX_COUNT = 10000000
local RADIUS = { check = function(v)
  local expected = "positive number or {min, max} with 0 < min <= max (at most 1e+100)"
  if type(v) == "number" then return v > 0 and v <= 1e100, expected end
  return type(v) == "table" and #v == 2 and type(v[1]) == "number" and type(v[2]) == "number"
    and v[1] > 0 and v[2] >= v[1] and v[2] <= 1e100, expected
end }
local DRAG = { check = function(v)
  return v == "auto" or (type(v) == "number" and v >= 0 and v <= 1e100),
    "non-negative number or 'auto'"
end }
local SPECS = {
  random = { n = { "integer", min = 1, max = MAX_COUNT, required = true }, radius = RADIUS,
             region = { "table" }, seed = { "integer", min = 0 }, material = { check = args.material },
             max_tries = { "integer", min = 1, max = 1e12 }, speed = { "nonneg" } },
  clumps = { n = { "integer", min = 1, max = MAX_COUNT, required = true }, template = { required = true, check = function(v)
               return type(v) == "userdata" or (type(v) == "table" and #v > 0),
                 "dem.clump_template or a non-empty array of them"
             end },
             region = { "table" }, seed = { "integer", min = 0 }, material = { check = args.material },
             max_tries = { "integer", min = 1, max = 1e12 }, speed = { "nonneg" } },
  deposit = { n = { "integer", min = 1, max = MAX_COUNT, required = true }, radius = RADIUS,
              region = { "table" }, seed = { "integer", min = 0 }, material = { check = args.material },
              relax_steps = { "integer", min = 0, max = 1e12 }, drag = DRAG },
  settle = { soften = { "range", lo = 0, hi = 1, open_lo = true }, drag = DRAG, quiet = { "positive" },
             min_steps = { "integer", min = 0, max = 1e12 }, max_steps = { "integer", min = 1, max = 1e12 },
             ramp_stages = { "integer", min = 1, max = 1e6 }, ramp_steps = { "integer", min = 1, max = 1e12 },
             final_steps = { "integer", min = 0, max = 1e12 }, dt_final = { "positive" },
             verbose = { "boolean" }, dt = { "positive" }, v_floor = { "positive" },
             check_steps = { "integer", min = 1, max = 1e12 }, collapse = { "nonneg" },
             collapse_drag = { "nonneg" }, collapse_quiet = { "positive" } },
  slab = { size = { "positive", required = true }, n = { "integer", min = 1, max = 100000 },
           diameter = { check = function(v)
             return type(v) == "table" and #v == 3 and type(v[1]) == "number" and type(v[2]) == "number"
               and type(v[3]) == "number" and v[1] > 0 and v[1] < v[2] and v[2] < v[3] and v[3] <= 1e100,
               "{d_min, d_mean, d_max} with 0 < d_min < d_mean < d_max"
           end },
           seed = { "integer", min = 0 }, width = { "range", lo = 1, hi = 1e6, open_lo = true },
           margin = { "nonneg" } },
}

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
  local ok, expected = args.box(dim)(region)
  for d = 1, dim do -- inside the box: a region outside it would fail inside add_disk
    ok = ok and region[1][d] >= info.box[1][d] and region[2][d] <= info.box[2][d]
  end
  if not ok then fail(call, "region", expected .. ", inside the scene's box", region) end
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

-- The options both packers share: n, the seeded stream, the radius sampler, the region.
local function common(call, s, opts, spec)
  args.object(call, 1, s, "dem.scene")
  args.check(call, 2, opts, spec)
  local info = s:info()
  local n = opts.n
  local rng = grainlab.rng{ seed = opts.seed or 0 }
  local sample, rmax_new = radius_sampler(call, opts.radius, rng)
  local lo, hi = region_of(call, s, opts.region, info.dim)
  for d = 1, info.dim do
    if 2 * rmax_new > hi[d] - lo[d] then
      fail(call, "radius", string.format("radius at most half the region's smallest extent (%g)",
                                         0.5 * (hi[d] - lo[d])), opts.radius)
    end
  end
  return info, n, rng, sample, rmax_new, lo, hi
end

-- The packing fraction random sequential addition reaches when no particle fits any more (its
-- saturation, equal radii): 0.547 for disks (Hinrichsen, Feder & Jossang 1986), 0.384 for
-- spheres (Torquato, Uche & Stillinger 2006). With a range of radii the process stops sooner, as
-- a large radius drawn late finds no room (measured: 0.46 for radii 1:2 and 1:4 in 2D after 300
-- tries per particle, where equal radii reach 0.52), and a finite region loses a layer along its
-- sides; what is asked beyond saturation can never be placed.
local RSA_LIMIT = { [2] = 0.547, [3] = 0.384 }

-- The mean area (2D) or volume (3D) of a particle of the radius spec (a number, or uniform in
-- {a, b}): pi <r^2> = pi (a^2 + ab + b^2) / 3, 4/3 pi <r^3> = pi (a + b)(a^2 + b^2) / 3.
local function mean_size(radius, dim)
  if radius == nil then radius = { 0.5e-3, 1e-3 } end
  local a, b = radius, radius
  if type(radius) == "table" then a, b = radius[1], radius[2] end
  if dim == 2 then return math.pi * (a * a + a * b + b * b) / 3 end
  return math.pi * (a + b) * (a * a + b * b) / 3
end

function pack.random(s, opts)
  local call = "grainlab.pack.random"
  local info, n, rng, sample, rmax_new, lo, hi = common(call, s, opts, SPECS.random)
  local dim = info.dim
  local max_tries = positive_int(call, opts, "max_tries", 1000 * n)
  local speed = opts.speed or 0
  if type(speed) ~= "number" or not (speed >= 0) then fail(call, "speed", "non-negative number", speed) end
  local placed, rmax = existing(s, dim)
  rmax = math.max(rmax, rmax_new)
  -- Refused at entry what random addition cannot reach, rather than found out after max_tries.
  local vol, there = 1, 0
  for d = 1, dim do vol = vol * (hi[d] - lo[d]) end
  for _, p in ipairs(placed) do
    local inside = true
    for d = 1, dim do inside = inside and p[d] >= lo[d] and p[d] <= hi[d] end
    if inside then there = there + (dim == 2 and math.pi * p.r ^ 2 or 4 / 3 * math.pi * p.r ^ 3) end
  end
  local each, limit = mean_size(opts.radius, dim), RSA_LIMIT[dim]
  local asked = (there + n * each) / vol
  if asked > limit then
    local fits = math.max(0, math.floor((limit * vol - there) / each))
    fail(call, "n", string.format("at most %d particles (random addition saturates at a packing fraction of %.3g " ..
                                  "of the region; %d of mean %s %.3g m^%d%s ask for %.3g; use pack.deposit, a larger region or fewer particles)",
                                  fits, limit, n, dim == 2 and "area" or "volume", each, dim,
                                  there > 0 and string.format(" with the %.3g already there", there / vol) or "", asked), n)
  end
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
  return ids, { placed = #ids, tries = tries, fraction = area / vol }
end

-- Random sequential addition of clumps: n copies of the template (or of templates drawn at
-- random from a list), each at a uniformly random centre and orientation (2D: an angle; 3D: a
-- uniform quaternion, Shoemake's normalised Gaussian 4-vector) such that no member overlaps a
-- particle already there and every member lies inside the region. Returns the clumps' ids and
-- { placed, tries, fraction } (the unions' area in 2D, volume in 3D, over the region's).
local function is_template(v) return type(v) == "userdata" and tostring(v):find("^dem.clump_template") end

local function rotate(dim, q, v)
  if dim == 2 then
    local c, sn = math.cos(q), math.sin(q)
    return { c * v[1] - sn * v[2], sn * v[1] + c * v[2] }
  end
  local w, x, y, z = q[1], q[2], q[3], q[4]
  return { (1 - 2 * (y * y + z * z)) * v[1] + 2 * (x * y - w * z) * v[2] + 2 * (x * z + w * y) * v[3],
           2 * (x * y + w * z) * v[1] + (1 - 2 * (x * x + z * z)) * v[2] + 2 * (y * z - w * x) * v[3],
           2 * (x * z - w * y) * v[1] + 2 * (y * z + w * x) * v[2] + (1 - 2 * (x * x + y * y)) * v[3] }
end

function pack.clumps(s, opts)
  local call = "grainlab.pack.clumps"
  args.object(call, 1, s, "dem.scene")
  args.check(call, 2, opts, SPECS.clumps)
  local info = s:info()
  local dim = info.dim
  local list = is_template(opts.template) and { opts.template } or opts.template
  if type(list) ~= "table" or #list == 0 then
    fail(call, "template", "dem.clump_template or a non-empty array of them", opts.template)
  end
  local planar = dim == 2 and (info.thickness or 0) > 0
  local shapes = {}
  for k, T in ipairs(list) do
    if not is_template(T) then fail(call, "template", "dem.clump_template or a non-empty array of them", T) end
    local ti = T:info()
    if ti.dim ~= dim then
      fail(call, "template", string.format("%dD templates (the scene's), not a %dD one (entry %d)", dim, ti.dim, k), T)
    end
    local sh = planar and ti.disks or ti
    local centre, members, bound, rbig = sh.centre, T:members(), 0, 0
    for _, m in ipairs(members) do
      local o = {}
      for d = 1, dim do o[d] = m.offset[d] - centre[d] end
      m.rel = o
      local l = 0
      for d = 1, dim do l = l + o[d] ^ 2 end
      bound, rbig = math.max(bound, math.sqrt(l) + m.radius), math.max(rbig, m.radius)
    end
    shapes[k] = { T = T, members = members, bound = bound, rbig = rbig,
                  size = dim == 2 and ti.disks.area or ti.volume }
  end
  local rng = grainlab.rng{ seed = opts.seed or 0 }
  local lo, hi = region_of(call, s, opts.region, dim)
  local n = opts.n
  local max_tries = positive_int(call, opts, "max_tries", 1000 * n)
  local speed = opts.speed or 0
  local placed, rmax = existing(s, dim)
  for _, sh in ipairs(shapes) do
    for d = 1, dim do
      if 2 * sh.bound > hi[d] - lo[d] then
        fail(call, "region", string.format("a region wider than the clumps' bounding diameter %g", 2 * sh.bound), opts.region)
      end
    end
    rmax = math.max(rmax, sh.rbig)
  end
  local grid = new_grid(lo, hi, 2 * rmax, dim)
  for _, p in ipairs(placed) do grid.add(p) end
  local vol = 1
  for d = 1, dim do vol = vol * (hi[d] - lo[d]) end
  local ids, tries, filled = {}, 0, 0
  for _ = 1, n do
    local sh = shapes[#shapes == 1 and 1 or rng:integer(1, #shapes)]
    while true do
      tries = tries + 1
      if tries > max_tries then
        error(string.format("%s: placed %d of %d clumps in %d tries; the region is too full for random addition " ..
                            "(a larger region, fewer clumps, or pour them in layers)", call, #ids, n, max_tries), 2)
      end
      local x, q = {}, nil
      for d = 1, dim do x[d] = rng:uniform(lo[d] + sh.bound, hi[d] - sh.bound) end
      if dim == 2 then
        q = rng:uniform(0, 2 * math.pi)
      else
        local g, l = {}, 0
        repeat
          for a = 1, 4 do g[a] = rng:normal() end
          l = math.sqrt(g[1] ^ 2 + g[2] ^ 2 + g[3] ^ 2 + g[4] ^ 2)
        until l > 1e-6
        q = { g[1] / l, g[2] / l, g[3] / l, g[4] / l }
      end
      local world, clash = {}, false
      for k, m in ipairs(sh.members) do
        local r = rotate(dim, q, m.rel)
        local p = { r = m.radius }
        for d = 1, dim do p[d] = x[d] + r[d] end
        world[k] = p
        clash = clash or grid.near(p, m.radius + rmax, function(o)
          local d2 = 0
          for d = 1, dim do d2 = d2 + (p[d] - o[d]) ^ 2 end
          return d2 < (m.radius + o.r) ^ 2
        end)
        if clash then break end
      end
      if not clash then
        local vel
        if speed > 0 then
          local v, norm = {}, 0
          for d = 1, dim do v[d] = rng:normal(); norm = norm + v[d] ^ 2 end
          for d = 1, dim do v[d] = speed * v[d] / math.sqrt(norm) end
          vel = v
        end
        ids[#ids + 1] = s:add_clump{ template = sh.T, material = opts.material, position = x,
                                     orientation = q, velocity = vel }
        for _, p in ipairs(world) do grid.add(p) end
        filled = filled + sh.size
        break
      end
    end
  end
  return ids, { placed = #ids, tries = tries, fraction = filled / vol }
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
  local call = "grainlab.pack.deposit"
  local info, n, rng, sample, rmax_new, lo, hi = common(call, s, opts, SPECS.deposit)
  local dim = info.dim
  local g = info.gravity
  if dim == 3 then
    -- 3D: random addition in the region, a fall with softened contacts and a mild drag (grains
    -- land at ~ g/drag), the stiffness restored in small steps under the drag (a sudden
    -- stiffening would release the stored elastic energy at once), then pack.settle at full
    -- stiffness.
    local ids = pack.random(s, { n = n, radius = opts.radius, region = { lo, hi }, seed = opts.seed,
                                 material = opts.material })
    local old_drag, soften, stages = s:drag(), 1e-3, 30
    s:scale_stiffness(soften)
    s:drag(opts.drag or 30)
    local function v_rms()
      local P, s2 = s:particles(), 0
      for i = 1, P.count do s2 = s2 + P.vx[i] ^ 2 + P.vy[i] ^ 2 + P.vz[i] ^ 2 end
      return math.sqrt(s2 / P.count)
    end
    local steps = 0
    repeat
      steps = steps + s:run{ steps = 2000, impact_velocity = 0.5, progress = false }.steps
    until (steps >= 10000 and v_rms() < 1e-3) or steps >= 400000
    local f = (1 / soften) ^ (1 / stages)
    for k = 1, stages do
      s:scale_stiffness(k < stages and f or (1 / soften) / f ^ (stages - 1))
      s:run{ steps = 500, impact_velocity = 0.1, progress = false }
    end
    s:drag(old_drag)
    if (opts.relax_steps or 20000) > 0 then pack.settle(s, { max_steps = opts.relax_steps or 20000 }) end
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
  -- Relax under gravity at the real stiffness (pack.settle: critical drag, quasi-static dt): the
  -- pile only has to sag by its elastic compression.
  local relax = opts.relax_steps or 20000
  if math.type(relax) ~= "integer" or relax < 0 then fail(call, "relax_steps", "non-negative integer", relax) end
  local settled
  if relax > 0 then settled = pack.settle(s, { drag = opts.drag, max_steps = relax, final_steps = 0 }) end
  return ids, { placed = #ids, settle = settled }
end

-- Speeds of the particles: the largest, the rms, and the particle table.
local function speeds(s)
  local P = s:particles()
  local vx, vy, vz = P.vx, P.vy, P.vz
  local vmax2, sum = 0, 0
  for i = 1, P.count do
    local v2 = vx[i] * vx[i] + vy[i] * vy[i] + (vz and vz[i] * vz[i] or 0)
    sum = sum + v2
    if v2 > vmax2 then vmax2 = v2 end
  end
  return math.sqrt(vmax2), math.sqrt(sum / math.max(1, P.count)), P
end

-- A bound on the highest frequency of the loaded packing (Gershgorin, from the tangent stiffness
-- a f_n / overlap of every contact, a = the law's exponent): velocity Verlet is stable for
-- dt < 2 / omega_max. 0 when nothing touches.
local function contact_omega(s, P)
  local c = s:measure("contacts")
  local law = s:info().normal
  local a = law == "linear" and 1 or law == "hertz" and 1.5 or 2
  local m, w2, best = P.mass, {}, 0
  local ci, cj, fn, ov = c.i, c.j, c.fn, c.overlap
  for q = 1, #ci do
    local d = ov[q]
    if d > 0 then
      local k, i, j = a * math.abs(fn[q]) / d, ci[q], cj[q]
      local wi = (w2[i] or 0) + (j > 0 and 2 or 1) * k / m[i]
      w2[i] = wi
      if wi > best then best = wi end
      if j > 0 then
        local wj = (w2[j] or 0) + 2 * k / m[j]
        w2[j] = wj
        if wj > best then best = wj end
      end
    end
  end
  return math.sqrt(best)
end

-- The relaxation step: the stability limit (1/10 of the contact time) of a collision at the
-- current top speed (at least v_floor), and at most 1/omega_max of the loaded contacts (half the
-- Verlet limit). Returns dt and the impact velocity to pass to run.
local function relax_dt(s, vmax, P, v_floor, with_contacts)
  local v = math.max(v_floor, vmax)
  local dt = s:timestep{ impact_velocity = v }.limit
  if with_contacts then
    local w = contact_omega(s, P)
    if w > 0 then dt = math.min(dt, 1 / w) end
  end
  return dt, v
end

-- Settles a scene into a quiescent state (see the doc string at the bottom).
--
-- Why this way (measured on the 2D benchmark pile, Hertz + Brilliantov + Cundall-Strack, from
-- pack.deposit): the contact damping T k d^(1/2) d' is stiffness-proportional, so a mode of
-- frequency w is damped at a ratio of about w T / 3: ~1e-3 for the whole-pile vertical mode
-- (w ~ 1.4e3 rad/s for 20,000 disks, ~9e3 for 2,000), i.e. not at all. Only the background drag
-- damps that mode, best near critical, drag = 2 w (20,000 disks: v_rms < 1e-4 m/s after ~4500
-- steps with drag 2000-3000/s, 8000 with 1000/s, > 9000 with 10000/s); 20/s leaves it ringing.
-- Softening does not pay for Hertz: under a fixed load the tangent stiffness goes like k^(2/3),
-- the pile's frequencies like k^(1/3), so longer steps are eaten by longer periods, the soft pile
-- creeps more, and every re-stiffening stage releases stored elastic energy (20,000 disks, soften
-- 1e-3: still v_rms ~1e-3 m/s after 200,000 soft steps, 214 s). A geometric deposition is already
-- close to equilibrium: at full stiffness it only has to sag by its elastic compression, about a
-- period of the fundamental with critical drag. Near rest the contacts are soft too (small
-- overlaps): dt ~1e-6 s is stable here (4e-6 s is not), 10x the dt of an impact at 1 m/s.
function pack.settle(s, opts)
  local call = "grainlab.pack.settle"
  args.object(call, 1, s, "dem.scene")
  opts = args.check(call, 2, opts, SPECS.settle, true)
  local soften = opts.soften or 1
  if type(soften) ~= "number" or not (soften > 0 and soften <= 1) then fail(call, "soften", "number in (0, 1]", soften) end
  local quiet = opts.quiet or 1e-5
  if type(quiet) ~= "number" or not (quiet > 0) then fail(call, "quiet", "positive number", quiet) end
  local drag = opts.drag or "auto"
  if drag ~= "auto" and (type(drag) ~= "number" or not (drag >= 0)) then
    fail(call, "drag", "non-negative number or 'auto'", drag)
  end
  local v_floor = opts.v_floor or 0.01
  if type(v_floor) ~= "number" or not (v_floor > 0) then fail(call, "v_floor", "positive number", v_floor) end
  if opts.dt ~= nil and (type(opts.dt) ~= "number" or not (opts.dt > 0)) then fail(call, "dt", "positive number", opts.dt) end
  if opts.dt_final ~= nil and (type(opts.dt_final) ~= "number" or not (opts.dt_final > 0)) then
    fail(call, "dt_final", "positive number", opts.dt_final)
  end
  local stages = positive_int(call, opts, "ramp_stages", 10)
  local ramp_steps = positive_int(call, opts, "ramp_steps", nil)
  local min_steps = opts.min_steps or 0
  if math.type(min_steps) ~= "integer" or min_steps < 0 then fail(call, "min_steps", "non-negative integer", min_steps) end
  local max_steps = positive_int(call, opts, "max_steps", 200000)
  local check_steps = positive_int(call, opts, "check_steps", nil)
  local final_steps = opts.final_steps or 2000
  if math.type(final_steps) ~= "integer" or final_steps < 0 then fail(call, "final_steps", "non-negative integer", final_steps) end
  local collapse = opts.collapse or 0
  if type(collapse) ~= "number" or not (collapse >= 0) then fail(call, "collapse", "non-negative number (s)", collapse) end
  local collapse_drag = opts.collapse_drag or 20
  if type(collapse_drag) ~= "number" or not (collapse_drag >= 0) then
    fail(call, "collapse_drag", "non-negative number", collapse_drag)
  end
  local collapse_quiet = opts.collapse_quiet or 1e-4
  if type(collapse_quiet) ~= "number" or not (collapse_quiet > 0) then
    fail(call, "collapse_quiet", "positive number", collapse_quiet)
  end
  -- Under a fixed load the pile's frequencies scale like k^(1/3) for Hertz (overlap ~ k^(-2/3)),
  -- k^(1/2) for a linear spring: the drag follows them through a stiffness ramp.
  local w_exp = s:info().normal == "linear" and 0.5 or 1 / 3
  local function log(fmt, ...)
    if opts.verbose then io.stderr:write(string.format("settle: " .. fmt .. "\n", ...)) end
  end

  local old_drag = s:drag()
  local steps, t_start = 0, s:info().time
  local vmax, vrms, P = speeds(s)
  local dt, vimp = 0, 0
  local function pick_dt(with_contacts)
    if opts.dt then dt, vimp = opts.dt, nil else dt, vimp = relax_dt(s, vmax, P, v_floor, with_contacts) end
  end
  local function run(n)
    local r = s:run{ steps = n, dt = dt, impact_velocity = vimp, force = opts.dt ~= nil, progress = false }
    steps = steps + r.steps
    vmax, vrms, P = speeds(s)
  end

  if soften < 1 then s:scale_stiffness(soften) end

  -- Drag: critical for the slowest mode. From rest, a packing falls into its contacts and the
  -- kinetic energy peaks a quarter period t_p = pi / (2 w) later: drag = 2 w = pi / t_p.
  local t_peak
  if drag == "auto" then
    s:drag(0)
    local e0 = s:measure("energy").kinetic
    local emax, t_max, t0 = e0, 0, s:info().time
    pick_dt(true)
    local cap = math.min(max_steps, math.max(2000, max_steps // 4))
    while steps < cap do
      run(math.min(cap - steps, math.max(10, steps // 10)))
      local e, t = s:measure("energy").kinetic, s:info().time - t0
      if e > emax then emax, t_max = e, t end
      if e < 0.7 * emax then break end
      pick_dt(false)
    end
    if t_max > 0 and emax > 10 * e0 then -- a peak the fall made, not motion already there
      t_peak = t_max
      drag = math.pi / t_peak
    else
      drag = 1000 -- moving at the start (not from rest): no peak to read the frequency from
    end
    log("kinetic energy peaked at %.3g s: drag %.4g /s (%d steps, dt %.3g s)", t_max, drag, steps, dt)
  end
  s:drag(drag)
  local check = check_steps or
                math.max(100, math.min(2000, math.floor((t_peak or math.pi / math.max(drag, 1)) / math.max(dt, 1e-300) + 0.5)))

  -- Relax until the rms speed is below `quiet`, or below 10 quiet and no longer falling (by 10%
  -- over 3 checks, ~1 period of the slowest mode): what is left then is a few grains creeping at
  -- their terminal speed under the drag, which more steps would not stop.
  local function relax(label)
    local hist, start = {}, steps
    while steps - start < max_steps do
      if steps >= min_steps and (vrms <= quiet or (vrms < 10 * quiet and #hist >= 3 and vrms > 0.9 * hist[#hist - 2])) then
        break
      end
      hist[#hist + 1] = vrms
      pick_dt(true)
      run(check)
      log("%s: %d steps (dt %.3g s, drag %.4g /s): v_max %.3g, v_rms %.3g m/s", label, steps, dt, s:drag(), vmax, vrms)
    end
  end
  relax(soften < 1 and "soft" or "relax")

  -- Collapse: a packing built geometrically (pack.deposit) has a few grains in frictionally
  -- unstable spots; the critical drag holds them at a creeping speed (~1e-3 m/s), and without
  -- drag they fail and trigger small cascades for a few tenths of a second. With collapse = t,
  -- the packing may do so under a weak drag (fast: a stronger drag slows the cascades) until the
  -- fastest grain is below collapse_quiet, for at most t seconds; then it is relaxed again.
  local function collapse_phase()
    if collapse <= 0 then return end
    local t_end = s:info().time + collapse
    s:drag(collapse_drag)
    while s:info().time < t_end do
      pick_dt(true)
      run(math.max(1, math.min(2000, math.ceil((t_end - s:info().time) / dt))))
      log("collapse: %d steps (dt %.3g s, drag %.4g /s): v_max %.3g, v_rms %.3g m/s", steps, dt, collapse_drag, vmax, vrms)
      if vmax < collapse_quiet then break end
    end
    s:drag(drag)
    relax("relax")
  end
  if soften == 1 then collapse_phase() end

  if soften < 1 then
    -- Ramp the stiffness back in `stages` factors; each stage lasts about one period of the
    -- slowest mode (or ramp_steps), with the drag kept critical as the frequencies rise.
    local factor = (1 / soften) ^ (1 / stages)
    local period = 4 * (t_peak or math.pi / math.max(drag, 1))
    for k = 1, stages do
      local f = k < stages and factor or (1 / soften) / factor ^ (stages - 1)
      s:scale_stiffness(f)
      drag = drag * f ^ w_exp
      period = period / f ^ w_exp
      s:drag(drag)
      pick_dt(true)
      run(ramp_steps or math.max(100, math.floor(period / dt + 0.5)))
      log("ramp %d/%d: %d steps (dt %.3g s, drag %.4g /s): v_max %.3g, v_rms %.3g m/s", k, stages, steps, dt, drag, vmax, vrms)
    end
    relax("relax")
    collapse_phase()
  end
  local settled = s:measure("coordination")
  local res = { steps = steps, time = s:info().time - t_start, drag = drag, dt = dt, t_peak = t_peak,
                v_rms_settled = vrms, v_max_settled = vmax, z_settled = settled.z }

  s:drag(old_drag)
  if final_steps > 0 then
    if not opts.dt_final then pick_dt(true) end
    local r = s:run{ steps = final_steps, dt = opts.dt_final or dt, impact_velocity = math.max(v_floor, vmax),
                     force = opts.dt_final == nil and opts.dt ~= nil, progress = false }
    steps = steps + r.steps
    vmax, vrms = speeds(s)
    log("final: %d steps without drag (dt %.3g s): v_max %.3g, v_rms %.3g m/s", final_steps, r.dt, vmax, vrms)
  end
  local z = s:measure("coordination")
  res.steps, res.v_rms, res.v_max, res.z, res.z_no_rattlers = steps, vrms, vmax, z.z, z.z_no_rattlers
  return res
end

grainlab.doc(pack, { name = "grainlab.pack", doc = [[Packing generators (reproducible from seed):
  pack.random(s, { n =, radius = r | {min, max}, region = {{lo},{hi}}, seed =, material =, speed = })
    random sequential addition without overlaps; returns ids, {placed, tries, fraction}. More
    than it can ever place is refused at entry: a packing fraction of the region (with the
    particles already in it) above its saturation, 0.547 in 2D and 0.384 in 3D; else it stops
    after max_tries (default 1000 n) with the count it placed.
  pack.deposit(s, { n =, radius = {0.5e-3, 1e-3}, region =, seed =, material =, relax_steps = 20000, drag = 'auto' })
    gravity deposition: 2D drop-and-roll (Jodrey-Tory style) onto the floor of the region, then
    pack.settle at the scene's stiffness with at most relax_steps steps (0: none; set the contact
    law first); returns ids, {placed, settle = pack.settle's result}. 3D: random addition and
    dynamic settling (softened contacts, drag 50, relax_steps = 2000 per decade of stiffness).
  pack.settle(s, { drag = 'auto', quiet = 1e-5, min_steps = 0, max_steps = 200000, dt = nil,
                   v_floor = 0.01, check_steps = nil, collapse = 0, collapse_drag = 20,
                   collapse_quiet = 1e-4, final_steps = 2000, dt_final = nil,
                   soften = 1, ramp_stages = 10, ramp_steps = nil, verbose = false })
    relaxes a packing at rest (e.g. from pack.deposit) into a quiescent one at full stiffness: a
    background drag, critical for the slowest mode (drag = 'auto': pi / t_p, t_p the time the
    kinetic energy takes to peak when the packing falls into its contacts from rest; 1000/s if
    it was moving at the start), in chunks of check_steps (default t_p / dt, 100..2000) until
    the rms speed is below quiet, or below 10 quiet and no longer falling (grains creeping at
    their terminal speed), or max_steps. dt: the stability limit of an impact at max(v_floor,
    fastest speed), at most 1 / (highest frequency of the loaded contacts).
    collapse = t (s): then lets the grains that the drag only holds (frictionally unstable spots
    of a geometric packing) fail under the weak collapse_drag until the fastest grain is below
    collapse_quiet m/s (at most t seconds of simulated time), and relaxes again: a static pile
    (2D, mu 0.45: ~0.2-0.3 s, 1.2e5-3e5 steps). Then the old drag is restored and final_steps
    steps are run at dt_final (default: the relaxation dt).
    soften < 1 first relaxes with the stiffness scaled by soften, then ramps it back in
    ramp_stages factors of ramp_steps steps (default: a period of the slowest mode) with the drag
    kept critical (slower and less robust for Hertz piles; kept for comparison).
    Returns {steps, time, drag, dt, t_peak, v_rms, v_max, z, z_no_rattlers (after the final
    steps), v_rms_settled, v_max_settled, z_settled (before them)}.
  pack.slab{ size = L, n = 369, diameter = {31e-6, 57e-6, 250e-6}, seed = 5, width = 1.8, margin = 0 }
    a dense polydisperse disk packing of an L x L square periodic in y, for MPM grains (the
    shear test of Bardenhagen et al., Fig. 5): random placement in a wider slab, compacted with
    the DEM module by a wall; with margin > 0 the disks overlapping [0, L] of a packing of
    [-margin, L + margin], cut by the edges. Returns {x, y, r, area_fraction, shrink,
    mean_radius}. Refused at entry: L below 4 d_min, disks covering more of the initial slab
    than random placement reaches (0.547), less than 0.2 of the square, or an initial slab
    they fill below 0.05 (the compaction's steps grow with its width).]] })
-- pack.slab{ size = L, n = 369, diameter = {d_min, d_mean, d_max}, seed = 5, width = 1.8, margin = 0 }
-- Diameters d_min + an exponential of mean 26/57 d_mean (the shape of the paper's HMX sizes),
-- truncated at min(d_max, L / 4) (the DEM periodic axis needs 3 neighbour cut-offs) and
-- rescaled so the mean is exactly d_mean; placed at random, largest first, in a slab width x L wide (periodic in y); compacted with the DEM module
-- (frictionless soft Hertz disks with drag, the right wall pushed in to x = L); then every radius
-- shrinks by the largest relative overlap left, so no two disks overlap, and x is stretched so
-- the outermost disks touch x = 0 and x = L. With margin > 0 the packing spans [-margin,
-- L + margin] and only the disks overlapping [0, L] are returned (those across an edge are cut by
-- it, as in the paper's Fig. 5). Returns {x, y, r,
-- area_fraction (of the L x L square), shrink, mean_radius}.
function pack.slab(opts)
  args.check("grainlab.pack.slab", 1, opts, SPECS.slab)
  local L = opts.size
  if type(L) ~= "number" or not (L > 0) then fail("grainlab.pack.slab", "size", "positive number", L) end
  local n = positive_int("slab", opts, "n", 369)
  local dd = opts.diameter or { 31e-6, 57e-6, 250e-6 }
  if type(dd) ~= "table" or #dd ~= 3 or not (dd[1] > 0 and dd[1] < dd[2] and dd[2] < dd[3]) then
    fail("grainlab.pack.slab", "diameter", "{d_min, d_mean, d_max} with 0 < d_min < d_mean < d_max", dd)
  end
  local d_min, d_mean, d_max = dd[1], dd[2], math.min(dd[3], 0.25 * L)
  local W0 = opts.width or 1.8
  if type(W0) ~= "number" or not (W0 > 1) then fail("grainlab.pack.slab", "width", "number > 1", W0) end
  local margin = opts.margin or 0
  if type(margin) ~= "number" or not (margin >= 0) then fail("grainlab.pack.slab", "margin", "non-negative number", margin) end
  local Lp = L + 2 * margin -- packed width; the disks are shifted by -margin at the end
  W0 = W0 * Lp
  if d_max <= d_min then -- no diameter to draw (the sampler below would never end)
    fail("grainlab.pack.slab", "size", string.format("size above 4 d_min = %g (no disk is wider than size/4)", 4 * d_min), L)
  end
  local rng = grainlab.rng{ seed = opts.seed or 5 }
  local d = {}
  local scale, span = d_mean - d_min, d_max - d_min
  for i = 1, n do
    local v, tries = nil, 0
    repeat v = d_min - scale * math.log(1 - rng:uniform()); tries = tries + 1 until v <= d_max or tries == 64
    if v > d_max then -- a truncation far in the head: the same law, by its inverse distribution
      v = d_min - scale * math.log(1 - rng:uniform() * -math.expm1(-span / scale))
      v = math.min(v, d_max)
    end
    d[i] = v
  end
  local mean = 0
  for i = 1, n do mean = mean + d[i] / n end
  local k = (d_mean - d_min) / (mean - d_min)
  for i = 1, n do d[i] = math.min(d_min + k * (d[i] - d_min), d_max) end
  table.sort(d, function(a, b) return a > b end)
  -- Refused at entry: more disk area than random placement can put in the initial slab, or a
  -- slab too sparse to be a packing (the compaction's steps grow as size / diameter).
  local area0 = 0
  for i = 1, n do area0 = area0 + math.pi / 4 * d[i] ^ 2 end
  local each, f0, f = area0 / n, area0 / (W0 * L), area0 / (Lp * L)
  if f0 > RSA_LIMIT[2] then
    fail("grainlab.pack.slab", "n", string.format("at most %d disks (their random placement in the initial slab, width x size wide, " ..
         "saturates at a packing fraction of %.3g; %d disks of field 'diameter' (mean area %.3g m^2) ask for %.3g there, " ..
         "%.3g of the size^2 square)",
         math.floor(RSA_LIMIT[2] * W0 * L / each), RSA_LIMIT[2], n, each, f0, f), n)
  end
  if f < 0.2 then
    fail("grainlab.pack.slab", "n", string.format("at least %d disks (a slab is a packing: the disks must cover 0.2 of the " ..
         "size^2 square at least; %d disks of field 'diameter' (mean area %.3g m^2) cover %.3g)", math.ceil(0.2 * Lp * L / each), n, each, f), n)
  end
  if f0 < 0.05 then -- the wall travels (width - 1) size: the compaction's steps grow with it
    fail("grainlab.pack.slab", "width", string.format("width at most %.3g (the initial slab must hold the disks at a packing " ..
         "fraction of 0.05 at least; they cover %.3g of the size^2 square, %.3g of the slab)", f / 0.05, f, f0), opts.width)
  end
  local function dy_min(a, b) local t = a - b; return t - L * math.floor(t / L + 0.5) end
  -- Buckets of side >= the largest diameter, periodic in y: the disks a disk can overlap lie in
  -- its bucket and the 8 around it, so a try costs the same for any n.
  local cell = d[1]
  local ny = math.max(1, math.floor(L / cell))
  local function buckets()
    local b = {}
    local function key(cx, cy) return cx * ny + cy end
    local function cy_of(yv) return math.min(ny - 1, math.max(0, math.floor(yv / L * ny))) end
    function b.add(i, xv, yv)
      local kk = key(math.floor(xv / cell), cy_of(yv))
      local t = b[kk]
      if not t then t = {}; b[kk] = t end
      t[#t + 1] = i
    end
    -- fn(j) for every disk near (xv, yv); stops at the first true
    function b.near(xv, yv, fn)
      local cx, cy = math.floor(xv / cell), cy_of(yv)
      local rows = ny >= 3 and { (cy - 1) % ny, cy, (cy + 1) % ny } or (ny == 2 and { 0, 1 } or { 0 })
      for ix = cx - 1, cx + 1 do
        for _, iy in ipairs(rows) do
          local t = b[key(ix, iy)]
          if t then for _, j in ipairs(t) do if fn(j) then return true end end end
        end
      end
      return false
    end
    return b
  end
  local x, y, r = {}, {}, {}
  local grid, tries, max_tries = buckets(), 0, 1000 * n
  for i = 1, n do
    r[i] = 0.5 * d[i]
    local ok
    repeat
      tries = tries + 1
      x[i], y[i] = r[i] + (W0 - 2 * r[i]) * rng:uniform(), L * rng:uniform()
      ok = not grid.near(x[i], y[i], function(j)
        local ex, ey = x[i] - x[j], dy_min(y[i], y[j])
        return ex * ex + ey * ey < (r[i] + r[j]) ^ 2
      end)
    until ok or tries >= max_tries
    if not ok then
      error(string.format("grainlab.pack.slab: placed %d of %d disks in the initial slab in %d tries; use fewer or smaller disks, or a larger width",
                          i - 1, n, max_tries), 2)
    end
    grid.add(i, x[i], y[i])
  end
  local soft = grainlab.material{ density = 1900, young = 2e8, poisson = 0.3, friction = 0, restitution = 0.3 }
  local ds = dem.scene{ box = { { -0.1 * Lp, 0 }, { W0 + 0.1 * Lp, L } }, gravity = { 0, 0 }, periodic = { false, true } }
  ds:contact{ normal = "hertz", damping = "viscous" }
  ds:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  local right = ds:add_wall{ point = { W0, 0 }, normal = { -1, 0 } }
  for i = 1, n do ds:add_disk{ pos = { x[i], y[i] }, radius = r[i], material = soft } end
  local v_wall = 2
  ds:wall_velocity(right, { -v_wall, 0 })
  ds:drag(2e4)
  ds:run{ time = (W0 - Lp) / v_wall }
  ds:wall_velocity(right, { 0, 0 })
  ds:run{ time = 2e-4 }
  local P = ds:particles()
  for i = 1, n do x[i], y[i] = P.x[i], P.y[i] - L * math.floor(P.y[i] / L) end
  local worst = 0
  grid = buckets()
  for i = 1, n do
    grid.near(x[i], y[i], function(j)
      local ex, ey = x[i] - x[j], dy_min(y[i], y[j])
      local ov = (r[i] + r[j]) - math.sqrt(ex * ex + ey * ey)
      if ov > 0 then worst = math.max(worst, ov / (r[i] + r[j])) end
    end)
    grid.add(i, x[i], y[i])
  end
  -- stretch x so the outermost disks touch x = 0 and x = L (the soft wall contacts and the
  -- shrink leave a small gap; a stretch >= 1 only moves disks apart)
  local lo, hi = math.huge, -math.huge
  for i = 1, n do
    r[i] = r[i] * (1 - worst - 1e-3)
    lo, hi = math.min(lo, x[i] - r[i]), math.max(hi, x[i] + r[i])
  end
  local k = Lp / (hi - lo)
  if k < 1 then -- the walls were overrun: scale the whole packing (radii too) into [0, Lp]
    for i = 1, n do r[i] = r[i] * k end
  end
  -- keep the disks overlapping [0, L] (with a margin, those across the edges are cut there)
  local ox, oy, or_, area, rsum = {}, {}, {}, 0, 0
  for i = 1, n do
    local xi = (x[i] - lo) * k - margin
    if xi + r[i] > 0 and xi - r[i] < L then
      ox[#ox + 1], oy[#oy + 1], or_[#or_ + 1] = xi, y[i], r[i]
      local a, b = math.max(0, xi - r[i]) - xi, math.min(L, xi + r[i]) - xi -- chord limits
      local function F(u) u = math.max(-r[i], math.min(r[i], u)); return u * math.sqrt(r[i] ^ 2 - u * u) + r[i] ^ 2 * math.asin(u / r[i]) end
      area = area + (F(b) - F(a)) -- area of the disk between the edges
      rsum = rsum + r[i]
    end
  end
  return { x = ox, y = oy, r = or_, area_fraction = area / (L * L), shrink = worst + 1e-3, mean_radius = rsum / #ox }
end

-- Errors below these entries are reported at the user's line (grainlab.entry).
require("grainlab.entry").wrap_all(pack, "grainlab.pack")

-- Each function answers help() itself, with the fields its entry check accepts.
for name, usage in pairs{
  random = "grainlab.pack.random(s, { n =, radius = r | {min, max}, region = {{lo},{hi}}, seed =, material =, max_tries =, speed = })",
  clumps = "grainlab.pack.clumps(s, { n =, template = T | {T1, T2, ...}, region = {{lo},{hi}}, seed =, material =, max_tries =, speed = })",
  deposit = "grainlab.pack.deposit(s, { n =, radius = {0.5e-3, 1e-3}, region =, seed =, material =, relax_steps = 20000, drag = 'auto' })",
  settle = "grainlab.pack.settle(s, { drag = 'auto', quiet = 1e-5, max_steps = 200000, ... })",
  slab = "grainlab.pack.slab{ size = L, n = 369, diameter = {d_min, d_mean, d_max}, seed = 5, width = 1.8, margin = 0 }",
} do
  grainlab.doc(pack[name], { name = "grainlab.pack." .. name, usage = usage,
    doc = "See help(grainlab.pack) for what it does and returns.", fields = args.fields(SPECS[name]) })
end

return pack
