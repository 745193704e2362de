-- The biaxial laboratory of Padbidri Ch. 3 (dem-network-cell-framework): sample preparation and
-- the three boundary conditions over dem.scene:boundary (src/dem/boundary.c) and the Delaunay
-- continuum (analysis.delaunay).
--   biax.defaults            Table 3.1 (E 30 GPa, nu 0.3, p 100 kPa, density x 1e5, mu 0.45,
--                            rate 5e-3/s, dt 1e-5 s, membrane 10 N/mm) and App. A/B laws
--   biax.prepare{…}          a confined sample: Jodrey-Tory deposition (grainlab.pack.deposit) or
--                            random addition, copied into a gravity-free, mass-scaled scene, the
--                            pressure ramped on the Delaunay boundary (all sides) with frictionless
--                            contacts and drag, then friction on and a drag-free rest
--   biax.scene(state, cfg)   a scene from a saved state (positions, radii)
--   biax.setup(state, bc, cfg) a scene with one boundary condition: "pressure" (plates + direct
--                            pressure on the lateral Delaunay edges), "membrane" (plates + chains
--                            of frictionless membrane disks on springs carrying the pressure),
--                            "mbc" (pressure on all sides + minimal-boundary penalty)
local biax = {}

biax.defaults = {
  young = 30e9, poisson = 0.3, pressure = 1e5, density = 2650, mass_scale = 1e5,
  friction = 0.45, rate = 5e-3, dt = 1e-5, rmin = 0.5e-3, rmax = 1e-3, thickness = 1.5e-3,
  damping_time = 0.002, exponent = 10, membrane_k = 1e4, membrane_radius = 1.2e-3,
  every = 250, alpha = 1.5, kappa = 20,
}

-- Every configuration key, checked at the entry of each public function (grainlab.args): a typo
-- or a negative modulus names the call and the field instead of failing deep inside a run.
local args = require("grainlab.args")
local STEPS = { "integer", min = 0, max = 1e12 }
local CONFIG = {
  young = { "positive" }, poisson = { "range", lo = 0, hi = 0.5, open_hi = true },
  pressure = { "positive" }, density = { "positive" }, mass_scale = { "positive" },
  friction = { "nonneg" }, rate = { "positive" }, dt = { "positive" }, rmin = { "positive" },
  rmax = { "positive" }, thickness = { "nonneg" }, damping_time = { "nonneg" },
  exponent = { "positive" }, membrane_k = { "positive" }, membrane_radius = { "positive" },
  every = { "integer", min = 1, max = 1e9 }, alpha = { "positive" }, kappa = { "nonneg" },
  v_r = { "positive" },
  -- biax.prepare / biax.prepared
  n = { "integer", min = 3, max = 1000000 }, seed = { "integer", min = 0 },
  method = { "option", values = { "deposit", "random" } },
  shape = { "option", values = { "square", "circle" } }, width = { "positive" },
  ramp_steps = STEPS, hold_steps = STEPS, friction_steps = STEPS, rest_steps = STEPS,
  ramp_stages = { "integer", min = 1, max = 1e6 }, prep_drag = { "nonneg" },
  settle_tol = { "positive" }, settle_rounds = { "integer", min = 1, max = 1e6 },
  cache = { check = function(v) return v == false or args.is_path(v), "false or a file name (no NUL byte)" end },
}
biax.fields = args.fields(CONFIG)

local function cfg_of(opts, call, argn)
  args.check(call or "grainlab.biax.config", argn or 1, opts, CONFIG, true)
  if opts and opts.rmin and opts.rmax and not (opts.rmax >= opts.rmin) then
    args.fail(call or "grainlab.biax.config", argn or 1, "rmax", "radius >= rmin", opts.rmax)
  end
  local c = {}
  for k, v in pairs(biax.defaults) do c[k] = v end
  for k, v in pairs(opts or {}) do c[k] = v end
  c.v_r = (opts and opts.v_r) or (c.rmin + c.rmax) * c.rate -- Eq. 3.A2: v_R = d eps_rate
  return c
end
function biax.config(opts) return cfg_of(opts, "grainlab.biax.config", 1) end

-- A state {x = {...}, y = {...}, r = {...}} (from biax.prepare or biax.save) at argument argn.
local function check_state(call, argn, st)
  local ok = type(st) == "table" and type(st.x) == "table" and type(st.y) == "table"
    and type(st.r) == "table" and #st.x > 0 and #st.y == #st.x and #st.r == #st.x
  for i = 1, ok and #st.x or 0 do
    ok = ok and type(st.x[i]) == "number" and type(st.y[i]) == "number" and type(st.r[i]) == "number"
  end
  if not ok then
    args.arg_fail(call, argn, "state {x = {...}, y = {...}, r = {...}} of equal lengths", st)
  end
end

-- A lab table from biax.setup at argument #1.
local function check_lab(call, lab)
  local mt = type(lab) == "table" and getmetatable(lab.scene)
  if not (type(mt) == "table" and mt.__name == "dem.scene" and type(lab.cfg) == "table") then
    args.arg_fail(call, 1, "lab table from grainlab.biax.setup", lab)
  end
end

local function materials(c)
  local grain = grainlab.material{ density = c.density, young = c.young, poisson = c.poisson,
                                   friction = c.friction }
  local membrane = grainlab.material{ density = c.density, young = c.young, poisson = c.poisson,
                                      friction = 0 }
  return grain, membrane
end

-- A gravity-free, mass-scaled scene holding the state's disks (and nothing else).
function biax.scene(state, c)
  check_state("grainlab.biax.scene", 1, state)
  c = cfg_of(c, "grainlab.biax.scene", 2)
  local xlo, xhi, ylo, yhi = math.huge, -math.huge, math.huge, -math.huge
  for i = 1, #state.x do
    xlo, xhi = math.min(xlo, state.x[i]), math.max(xhi, state.x[i])
    ylo, yhi = math.min(ylo, state.y[i]), math.max(yhi, state.y[i])
  end
  -- room to bulge sideways (and for MBC to shorten), small enough for readable images
  local px, py = 0.35 * (xhi - xlo) + 0.01, 0.12 * (yhi - ylo) + 0.005
  local s = dem.scene{ box = { { xlo - px, ylo - py }, { xhi + px, yhi + py } },
                       gravity = { 0, 0 }, thickness = c.thickness }
  local grain, membrane = materials(c)
  for i = 1, #state.x do
    s:add_disk{ pos = { state.x[i], state.y[i] }, radius = state.r[i],
                material = (state.membrane and state.membrane[i]) and membrane or grain }
  end
  s:scale_mass(c.mass_scale)
  return s, grain, membrane
end

-- Contact laws: App. A (Hertz, Brilliantov damping, regularised Coulomb with v_R = d rate).
function biax.contact(s, c, frictionless)
  args.object("grainlab.biax.contact", 1, s, "dem.scene")
  c = cfg_of(c, "grainlab.biax.contact", 2)
  if frictionless ~= nil and type(frictionless) ~= "boolean" then
    args.arg_fail("grainlab.biax.contact", 3, "boolean", frictionless)
  end
  if frictionless then
    s:contact{ normal = "hertz", damping = "brilliantov", damping_time = c.damping_time }
  else
    s:contact{ normal = "hertz", damping = "brilliantov", damping_time = c.damping_time,
               tangential = "coulomb_regularized", v_r = c.v_r, exponent = c.exponent }
  end
end

local function save(s)
  local P = s:particles()
  local st = { x = {}, y = {}, r = {} }
  for i = 1, P.count do st.x[i], st.y[i], st.r[i] = P.x[i], P.y[i], P.radius[i] end
  return st
end
function biax.save(s)
  args.object("grainlab.biax.save", 1, s, "dem.scene")
  return save(s)
end

-- Runs `steps` steps at dt in chunks (the boundary is rebuilt inside the engine every c.every).
local function run(s, steps, c)
  return s:run{ steps = steps, dt = c.dt, impact_velocity = 1e-3, progress = false }
end

-- Deposited (or randomly placed) disks, consolidated under the confining pressure.
--   n, seed, method = "deposit"|"random", shape = "square"|"circle", width (m), ramp_steps,
--   hold_steps, friction_steps, rest_steps, settle_tol (0.02), settle_rounds (6), and any of
--   biax.defaults. Returns the state {x, y, r} and a report table.
function biax.prepare(opts)
  local c = cfg_of(opts, "grainlab.biax.prepare", 1)
  local n, seed = c.n or 400, c.seed or 1
  local t0 = grainlab.clock()
  local rm = 0.5 * (c.rmin + c.rmax)
  local circle = c.shape == "circle"
  -- a circle of n is cut from the middle of a square deposit of 1.6 n
  local n_dep = circle and math.ceil(1.6 * n) or math.ceil(1.08 * n)
  local W = c.width or math.sqrt((circle and n_dep or n) * math.pi * rm * rm / 0.82) -- about square
  local st
  if (c.method or "deposit") == "deposit" then
    local H = 2.5 * W
    local g = dem.scene{ box = { { -0.01, -0.01 }, { W + 0.01, H } }, gravity = { 0, -9.81 },
                         thickness = c.thickness }
    g:contact{ normal = "hertz" }
    g:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
    g:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
    g:add_wall{ point = { W, 0 }, normal = { -1, 0 } }
    local grain = materials(c)
    -- Jodrey-Tory drops, 8% extra kept off the top (a flat top), no relaxation: the
    -- consolidation below does it.
    grainlab.pack.deposit(g, { n = n_dep, radius = { c.rmin, c.rmax }, seed = seed,
                               material = grain, region = { { 0, 0 }, { W, H } }, relax_steps = 0 })
    local P = g:particles()
    local order = {}
    for i = 1, P.count do order[i] = i end
    if circle then -- the n nearest to the centre of the deposit
      local cx, cy = 0, 0
      for i = 1, P.count do cx, cy = cx + P.x[i] / P.count, cy + P.y[i] / P.count end
      local d2 = {}
      for i = 1, P.count do d2[i] = (P.x[i] - cx) ^ 2 + (P.y[i] - cy) ^ 2 end
      table.sort(order, function(a, b) return d2[a] < d2[b] end)
    else
      table.sort(order, function(a, b) return P.y[a] < P.y[b] end)
    end
    st = { x = {}, y = {}, r = {} }
    for k = 1, n do
      local i = order[k]
      st.x[k], st.y[k], st.r[k] = P.x[i], P.y[i], P.radius[i]
    end
  else
    local g = dem.scene{ box = { { 0, 0 }, { W * 1.5, W * 1.5 } }, gravity = { 0, 0 },
                         thickness = c.thickness }
    grainlab.pack.random(g, { n = n, radius = { c.rmin, c.rmax }, seed = seed })
    st = save(g)
  end
  local s = biax.scene(st, c)
  biax.contact(s, c, true)
  -- Pressure ramp on the Delaunay boundary (all sides), frictionless, with drag.
  s:drag(c.prep_drag or 30)
  local stages = c.ramp_stages or 10
  local per = (c.ramp_steps or 20000) // stages
  for k = 1, stages do
    s:boundary{ pressure = c.pressure * k / stages, every = c.every, alpha = c.alpha }
    run(s, per, c)
  end
  run(s, c.hold_steps or 10000, c)
  biax.contact(s, c, false)
  run(s, c.friction_steps or 5000, c)
  s:drag(0)
  run(s, c.rest_steps or 5000, c)
  -- Settled means the mean Christoffersen pressure within settle_tol (2%) of the confining
  -- pressure. Samples that are not (large circles keep a slow breathing mode after the friction
  -- switch) get rounds of drag (15000 steps) and drag-free rest until they are, at most
  -- settle_rounds (6); the report gives the rounds taken, and a warning if it never settles.
  local tol, rounds = c.settle_tol or 0.02, 0
  local function mean_pressure()
    return analysis.delaunay(s, { alpha = c.alpha }):stress(s).mean_pressure
  end
  local p = mean_pressure()
  while math.abs(p / c.pressure - 1) > tol and rounds < (c.settle_rounds or 6) do
    s:drag(c.prep_drag or 30)
    run(s, 15000, c)
    s:drag(0)
    run(s, c.rest_steps or 5000, c)
    rounds = rounds + 1
    p = mean_pressure()
  end
  if math.abs(p / c.pressure - 1) > tol then
    io.stderr:write(string.format("biax.prepare: warning: mean pressure %.0f Pa is not within %g%% of %g Pa after %d settling rounds\n",
                                  p, 100 * tol, c.pressure, rounds))
  end
  local out = save(s)
  local ke = s:measure("energy").kinetic
  local qs = s:quasistatic{ pressure = c.pressure, strain_rate = c.rate }
  return out, { seconds = grainlab.clock() - t0, kinetic = ke, pressure = p,
                phi = qs.phi, psi = qs.psi, n = n, width = W, settle_rounds = rounds,
                coordination = s:measure("coordination").z }
end

-- biax.prepare, cached in a file: the same n, seed and preparation give the same sample, so
-- scripts share it (out/biax_<n>_<seed>.lua by default; cache = false to always prepare).
function biax.prepared(opts)
  local c = cfg_of(opts, "grainlab.biax.prepared", 1)
  local path = c.cache
  if path == nil then
    path = string.format("out/biax_%s%d_%d.lua", c.shape == "circle" and "circle_" or "", c.n or 400, c.seed or 1)
  end
  if path then
    local f = io.open(path, "r")
    if f then
      f:close()
      local ok, st = pcall(dofile, path)
      if ok and type(st) == "table" and st.x and #st.x == (c.n or 400) then
        return st, st.report or {}, true
      end
    end
  end
  local st, rep = biax.prepare(opts)
  if path then
    local parts = { "return {\n" }
    for _, k in ipairs{ "x", "y", "r" } do
      local v = {}
      for i = 1, #st[k] do v[i] = string.format("%.17g", st[k][i]) end
      parts[#parts + 1] = k .. " = {" .. table.concat(v, ",") .. "},\n"
    end
    parts[#parts + 1] = "report = {"
    for k, v in pairs(rep) do parts[#parts + 1] = string.format("%s = %.17g, ", k, v) end
    parts[#parts + 1] = "} }\n"
    local dir = path:match("^(.*)/[^/]*$")
    if dir then os.execute("mkdir -p '" .. dir .. "'") end
    grainlab.write_file(path, table.concat(parts))
  end
  st.report = rep
  return st, rep, false
end

local function bounds(st, ids)
  local ylo, yhi, xlo, xhi = math.huge, -math.huge, math.huge, -math.huge
  for _, i in ipairs(ids) do
    ylo, yhi = math.min(ylo, st.y[i] - st.r[i]), math.max(yhi, st.y[i] + st.r[i])
    xlo, xhi = math.min(xlo, st.x[i] - st.r[i]), math.max(xhi, st.x[i] + st.r[i])
  end
  return xlo, xhi, ylo, yhi
end

-- Membrane chains left and right, touching the sample, from plate to plate: returns the
-- extended state and the membrane particle ids (left chain top to bottom, right bottom to top).
local function add_membrane(st, c, ylo, yhi)
  local n0, rm = #st.x, c.membrane_radius
  local new = { x = {}, y = {}, r = {}, membrane = {} }
  for i = 1, n0 do new.x[i], new.y[i], new.r[i] = st.x[i], st.y[i], st.r[i] end
  -- touching neighbours at most: the gap between centres is >= 2 rm
  local count = math.max(2, math.floor((yhi - ylo - 2 * rm) / (2 * rm)) + 1)
  local gap = (yhi - ylo - 2 * rm) / (count - 1)
  local left, right = {}, {}
  for side = 1, 2 do
    for k = 1, count do
      local y = side == 1 and (yhi - rm - (k - 1) * gap) or (ylo + rm + (k - 1) * gap)
      local best = side == 1 and math.huge or -math.huge
      for i = 1, n0 do
        local dy, R = y - st.y[i], st.r[i] + rm
        if math.abs(dy) < R then
          local dx = math.sqrt(R * R - dy * dy) + 1e-9
          if side == 1 then best = math.min(best, st.x[i] - dx) else best = math.max(best, st.x[i] + dx) end
        end
      end
      local id = #new.x + 1
      new.x[id], new.y[id], new.r[id], new.membrane[id] = best, y, rm, true
      if side == 1 then left[#left + 1] = id else right[#right + 1] = id end
    end
  end
  return new, left, right
end

-- A scene from the prepared state with boundary condition bc. Returns the scene and a table
-- with: ids (sample particles), plates (wall ids or nil), membrane ids, H0 (plate gap), info.
function biax.setup(st, bc, opts)
  check_state("grainlab.biax.setup", 1, st)
  if bc ~= "pressure" and bc ~= "membrane" and bc ~= "mbc" then
    args.arg_fail("grainlab.biax.setup", 2, "one of 'pressure', 'membrane', 'mbc'", bc)
  end
  local c = cfg_of(opts, "grainlab.biax.setup", 3)
  if not (c.thickness > 0) then -- the boundary pressure acts on edges of this depth
    args.fail("grainlab.biax.setup", 3, "thickness", "positive number (the pressure needs a depth)", c.thickness)
  end
  local n0 = #st.x
  local ids = {}
  for i = 1, n0 do ids[i] = i end
  local xlo, xhi, ylo, yhi = bounds(st, ids)
  local lab = { ids = ids, bc = bc, cfg = c }
  local s
  if bc == "membrane" then
    local left, right
    st, left, right = add_membrane(st, c, ylo, yhi)
    s = biax.scene(st, c)
    lab.membrane = {}
    for _, i in ipairs(left) do lab.membrane[#lab.membrane + 1] = i end
    for _, i in ipairs(right) do lab.membrane[#lab.membrane + 1] = i end
    lab.left, lab.right = left, right
  else
    s = biax.scene(st, c)
  end
  biax.contact(s, c, false)
  lab.scene = s
  if bc == "pressure" or bc == "membrane" then
    local yl, yh = ylo, yhi
    if bc == "membrane" then -- the membrane disks reach the plates too
      for _, i in ipairs(lab.membrane) do
        yl, yh = math.min(yl, st.y[i] - st.r[i]), math.max(yh, st.y[i] + st.r[i])
      end
    end
    lab.plates = { s:add_wall{ point = { 0, yl }, normal = { 0, 1 } },
                   s:add_wall{ point = { 0, yh }, normal = { 0, -1 } } }
    lab.H0 = yh - yl
  end
  if bc == "pressure" then
    lab.info = s:boundary{ pressure = c.pressure, every = c.every, alpha = c.alpha, sides = "lateral" }
  elseif bc == "membrane" then
    local a, b = {}, {}
    local si, sj = {}, {}
    for _, chain in ipairs{ lab.left, lab.right } do
      for k = 1, #chain - 1 do
        a[#a + 1], b[#b + 1] = chain[k], chain[k + 1]
        si[#si + 1], sj[#sj + 1] = chain[k], chain[k + 1]
      end
    end
    lab.info = s:boundary{ mode = "edges", pressure = c.pressure, edges = { a = a, b = b } }
    s:springs{ i = si, j = sj, k = c.membrane_k }
    local bottom, top = {}, {}
    for _, chain in ipairs{ lab.left, lab.right } do
      local first, last = chain[1], chain[#chain]
      if st.y[first] < st.y[last] then first, last = last, first end
      top[#top + 1], bottom[#bottom + 1] = first, last
    end
    s:tie{ ids = bottom, wall = lab.plates[1], axis = 2 }
    s:tie{ ids = top, wall = lab.plates[2], axis = 2 }
  elseif bc == "mbc" then
    lab.info = s:boundary{ pressure = c.pressure, every = c.every, alpha = c.alpha,
                           mbc = { strain_rate = { { 0, 0 }, { 0, -c.rate } },
                                   mask = { { 0, 1 }, { 1, 1 } }, kappa = c.kappa,
                                   dt = c.dt } }
    lab.H0 = yhi - ylo
  else
    error("biax.setup: bc must be 'pressure', 'membrane' or 'mbc', got " .. tostring(bc), 2)
  end
  return s, lab
end

-- Plate forces (bottom, top): the normal force each plate exerts on the sample, contacts and the
-- tied membrane ends (s:wall_force).
function biax.plate_forces(lab)
  check_lab("grainlab.biax.plate_forces", lab)
  if not lab.plates then
    args.arg_fail("grainlab.biax.plate_forces", 1, "lab with plates (bc 'pressure' or 'membrane')", lab)
  end
  return lab.scene:wall_force(lab.plates[1]), lab.scene:wall_force(lab.plates[2])
end

-- Width of the sample particles (lateral extent) now.
local function sample_width(lab)
  local P = lab.scene:particles()
  local xlo, xhi = math.huge, -math.huge
  for _, i in ipairs(lab.ids) do
    xlo, xhi = math.min(xlo, P.x[i] - P.radius[i]), math.max(xhi, P.x[i] + P.radius[i])
  end
  return xhi - xlo
end

-- Plates: force-controlled onto the sample until each carries p W t within `tol` (default 5%),
-- then the plates move at the imposed strain rate. Replacing the all-round pressure by plates
-- placed at the highest and lowest particle would otherwise let the sample unload vertically and
-- spend the first percent of strain taking up the slack. Each plate is a damped body
-- (s:wall_servo: M dv/dt = p W t - F_contact - M rate v, every step, in C): a velocity servo
-- updated every 250 steps went unstable at 3300 disks (the plate stiffness of a big sample times
-- the gain times 250 dt is past 2; plate stress / p still 2.2 / 0.47 after 30000 steps). The
-- plate mass is set so that the terminal approach speed F / (M rate) is `vmax` (0.05/s times
-- the plate gap, 4 mm/s at 3300 disks): M = F / (rate vmax), with rate = 200/s (at 3300 disks
-- 1 mm/s and 100/s took over 60000 steps, the loose top of the deposit compacting slowly; at
-- 300 disks 4 mm/s left the plates oscillating).
-- Stages, all under the servo and with friction (frictionless, as in the consolidation, the
-- plates chased a sample that flowed sideways; `servo_frictionless` keeps that option): with
-- drag until converged, 2000 steps more, drag off (1000 steps), then until converged again,
-- judged on the plate force averaged over 250
-- steps, three times in a row. No-op for MBC (its penalty drives the strain). Returns the plate
-- stress / p (bottom, top) averaged over the last 250 steps before the compression starts.
function biax.start(lab, max_steps, tol)
  check_lab("grainlab.biax.start", lab)
  if max_steps ~= nil and not (math.type(max_steps) == "integer" and max_steps >= 1 and max_steps <= 1e12) then
    args.arg_fail("grainlab.biax.start", 2, "positive integer (at most 1e12)", max_steps)
  end
  if tol ~= nil and not (type(tol) == "number" and tol > 0 and tol <= 1e100) then
    args.arg_fail("grainlab.biax.start", 3, "positive number", tol)
  end
  local s, c = lab.scene, lab.cfg
  local ratio_b, ratio_t = 1, 1
  if lab.plates then
    tol = tol or 0.05
    max_steps = max_steps or 30000
    local pb, pt = lab.plates[1], lab.plates[2]
    local rate, vmax = lab.servo_rate or 200, lab.servo_vmax or 0.05 * lab.H0
    local function servo(on)
      local target = c.pressure * sample_width(lab) * c.thickness
      for _, w in ipairs { pb, pt } do
        if on then
          s:wall_servo(w, { force = target, mass = target / (rate * vmax), rate = rate })
        else
          s:wall_servo(w)
        end
      end
      return target
    end
    -- `steps` in blocks of 250 (the target follows the width), the plate forces averaged over
    -- each block's ten sub-blocks; stops early once converged twice in a row when `until_ok`.
    local done = 0
    local function servo_run(steps, until_ok)
      local ok_count, k = 0, 0
      while k < steps do
        local target = servo(true)
        local fb, ft = 0, 0
        for _ = 1, 10 do
          run(s, 25, c)
          fb, ft = fb + s:wall_force(pb) / 10, ft + s:wall_force(pt) / 10
        end
        k, done = k + 250, done + 250
        ratio_b, ratio_t = fb / target, ft / target
        if lab.verbose then print(done, ratio_b, ratio_t) end
        if math.abs(ratio_b - 1) < tol and math.abs(ratio_t - 1) < tol then
          ok_count = ok_count + 1
          if until_ok and ok_count >= 3 then return true end
        else
          ok_count = 0
        end
      end
      return ok_count > 0
    end
    biax.contact(s, c, lab.servo_frictionless)
    s:drag(lab.servo_drag or 5)
    servo_run(max_steps, true)
    local steps1 = done
    biax.contact(s, c, false)
    servo_run(2000)
    s:drag(0)
    servo_run(1000)
    local ok = servo_run(max_steps, true)
    servo(false)
    lab.servo_converged = ok
    lab.servo_steps, lab.servo_steps_frictionless = done, steps1
    local H = s:wall_point(pt)[2] - s:wall_point(pb)[2]
    lab.H0 = H
    local v = 0.5 * c.rate * H
    s:wall_velocity(pb, { 0, v })
    s:wall_velocity(pt, { 0, -v })
  end
  lab.t0 = s:info().time
  return ratio_b, ratio_t
end

-- Imposed axial strain now (plate gap, or rate x time for MBC), compression positive.
function biax.axial(lab)
  check_lab("grainlab.biax.axial", lab)
  local s = lab.scene
  if lab.plates then
    local H = s:wall_point(lab.plates[2])[2] - s:wall_point(lab.plates[1])[2]
    return 1 - H / lab.H0
  end
  return lab.cfg.rate * (s:info().time - lab.t0)
end

-- Errors below these entries are reported at the user's line (grainlab.entry).
require("grainlab.entry").wrap_all(biax, "grainlab.biax")

-- Each function answers help() itself; those taking a configuration list its fields.
for name, usage in pairs{
  config = "grainlab.biax.config{ ... }", prepare = "grainlab.biax.prepare{ n = 400, seed = 1, ... }",
  prepared = "grainlab.biax.prepared{ n = 400, seed = 1, cache = path|false, ... }",
  scene = "grainlab.biax.scene(state, cfg)", contact = "grainlab.biax.contact(s, cfg, frictionless)",
  setup = "grainlab.biax.setup(state, 'pressure'|'membrane'|'mbc', cfg)",
} do
  grainlab.doc(biax[name], { name = "grainlab.biax." .. name, usage = usage,
    doc = "See help(grainlab.biax). Configuration fields: " .. table.concat(biax.fields, ", ") .. ".",
    fields = biax.fields })
end
for name, usage in pairs{ save = "grainlab.biax.save(s)", plate_forces = "grainlab.biax.plate_forces(lab)",
                          start = "grainlab.biax.start(lab, max_steps, tol)", axial = "grainlab.biax.axial(lab)" } do
  grainlab.doc(biax[name], { name = "grainlab.biax." .. name, usage = usage, doc = "See help(grainlab.biax)." })
end

return biax
