-- Disks under a confining pressure applied as forces on the outermost particles, between two rigid
-- plates: the sample, the boundary and the preparation of scripts/two_timescales.lua (whose header
-- gives the procedure and its reasons), shared with its test. Not a scenario: the file is a chunk
-- of its configuration,
--   local confined = assert(loadfile((arg[0]:match("^(.*)/") or ".") .. "/lib/confined_disks.lua")){
--     n = 1000, rmin = 0.5e-3, rmax = 1e-3, thickness = 1.5e-3, material = quartz, seed = 1,
--     mass_scale = 1e5, damping_time = 0.002, v_r = 1.5e-5, exponent = 10, impact_velocity = 1e-3 }
-- and returns deposit, build, save, confine, strips, strip_gap, plate_forces and prepare(p).
local cfg = ...
local n_disks, rmin, rmax, thick = cfg.n, cfg.rmin, cfg.rmax, cfg.thickness
local quartz, seed, mass_scale, T_damp = cfg.material, cfg.seed, cfg.mass_scale, cfg.damping_time
local v_R, exponent, v_imp = cfg.v_r, cfg.exponent, cfg.impact_velocity

-- ---- sample: deposition under gravity, copied into a gravity-free scene ----------------------
local W0 = 0.046 * math.sqrt(n_disks / 1000)
local function deposit()
  local Hbin = 2.5 * W0
  local g = dem.scene{ box = { { -0.01, -0.01 }, { W0 + 0.01, Hbin } }, gravity = { 0, -9.81 },
                       thickness = thick }
  g:contact{ normal = "hertz" }
  g:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  g:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  g:add_wall{ point = { W0, 0 }, normal = { -1, 0 } }
  -- 8% more disks than needed; the n lowest are kept, so that the top of the sample is flat to
  -- within a grain (the free surface of a deposit is not).
  grainlab.pack.deposit(g, { n = math.ceil(1.08 * n_disks), radius = { rmin, rmax }, seed = seed,
                             material = quartz, region = { { 0, 0 }, { W0, Hbin } } })
  local P = g:particles()
  local order = {}
  for i = 1, P.count do order[i] = i end
  table.sort(order, function(a, b) return P.y[a] < P.y[b] end)
  local st = { x = {}, y = {}, r = {}, vx = {}, vy = {}, w = {} }
  for k = 1, n_disks do
    local i = order[k]
    st.x[k], st.y[k], st.r[k] = P.x[i], P.y[i], P.radius[i]
    st.vx[k], st.vy[k], st.w[k] = 0, 0, 0
  end
  return st
end

-- A gravity-free scene from a state {x, y, r, vx, vy, w[, ybot, ytop]}, friction on or off. With
-- ybot, ytop (a saved compression state) it gets the plates there: walls 1 (bottom), 2 (top).
local function build(st, friction)
  local ylo, yhi = math.huge, -math.huge
  for i = 1, #st.x do
    ylo, yhi = math.min(ylo, st.y[i] - st.r[i]), math.max(yhi, st.y[i] + st.r[i])
  end
  local H = yhi - ylo
  local s = dem.scene{ box = { { -0.5 * W0, ylo - 0.2 * H }, { 1.5 * W0, yhi + 0.2 * H } },
                       gravity = { 0, 0 }, thickness = thick }
  for i = 1, #st.x do
    s:add_disk{ pos = { st.x[i], st.y[i] }, radius = st.r[i], material = quartz,
                vel = { st.vx[i], st.vy[i] }, omega = st.w[i] }
  end
  s:scale_mass(mass_scale)
  if friction then
    s:contact{ normal = "hertz", damping = "brilliantov", damping_time = T_damp,
               tangential = "coulomb_regularized", v_r = v_R, exponent = exponent }
  else
    s:contact{ normal = "hertz", damping = "brilliantov", damping_time = T_damp }
  end
  if not st.ybot then return s end
  -- add_wall refuses a plate that overlaps a disk: add the plates touching the extreme disks,
  -- then move them to their saved places (into the loaded disks) in one step of 1e-12 s; the
  -- disks move by ~1e-16 m meanwhile, and their velocities (kicked by the damping of that
  -- fast plate) are restored.
  ylo, yhi = ylo - 1e-9, yhi + 1e-9
  local ybot, ytop = st.ybot, st.ytop
  s:add_wall{ point = { 0, math.min(ybot, ylo) }, normal = { 0, 1 } }
  s:add_wall{ point = { 0, math.max(ytop, yhi) }, normal = { 0, -1 } }
  if ybot > ylo or ytop < yhi then
    local tiny = 1e-12
    s:wall_velocity(1, { 0, (ybot - math.min(ybot, ylo)) / tiny })
    s:wall_velocity(2, { 0, (ytop - math.max(ytop, yhi)) / tiny })
    s:run{ steps = 1, dt = tiny, progress = false }
    s:wall_velocity(1, { 0, 0 })
    s:wall_velocity(2, { 0, 0 })
    for i = 1, #st.x do s:set_velocity(i, { st.vx[i], st.vy[i] }) end
  end
  return s
end

local function save(s)
  local P = s:particles()
  local st = { x = {}, y = {}, r = {}, vx = {}, vy = {}, w = {} }
  for i = 1, P.count do
    st.x[i], st.y[i], st.r[i] = P.x[i], P.y[i], P.radius[i]
    st.vx[i], st.vy[i], st.w[i] = P.vx[i], P.vy[i], P.omega and P.omega[i] or 0
  end
  st.ybot, st.ytop = s:wall_point(1)[2], s:wall_point(2)[2]
  return st
end

-- The boundary seen from outside: thin bands (height ~r_min/2) across axis `a` (1: bands along
-- x, 2: along y) between lo and hi; at each band's mid-line, the particle whose surface reaches
-- farthest out on either side (the chord, not the centre: a disk covering several bands is the
-- outermost one in each band where its surface is), and how far it reaches.
local function bands(P, a, lo, hi)
  local c = a == 1 and P.x or P.y
  local o = a == 1 and P.y or P.x
  local r = P.radius
  local nb = math.max(1, math.floor((hi - lo) / (0.5 * rmin) + 0.5))
  local h = (hi - lo) / nb
  local low, high, lreach, hreach = {}, {}, {}, {}
  for i = 1, P.count do
    local b0 = math.max(1, math.ceil((c[i] - r[i] - lo) / h + 0.5))
    local b1 = math.min(nb, math.floor((c[i] + r[i] - lo) / h + 0.5))
    for b = b0, b1 do
      local dy = lo + (b - 0.5) * h - c[i]
      local half = math.sqrt(math.max(0, r[i] * r[i] - dy * dy))
      if not low[b] or o[i] - half < lreach[b] then low[b], lreach[b] = i, o[i] - half end
      if not high[b] or o[i] + half > hreach[b] then high[b], hreach[b] = i, o[i] + half end
    end
  end
  return { P = P, low = low, high = high, lreach = lreach, hreach = hreach, h = h, lo = lo,
           nb = nb, a = a }
end

-- Confining pressure pp as forces p * h * t on the outermost particle of each band of height h
-- (a particle collects one share per band it is outermost in: the pressure on its exposed
-- projected height), pointing inwards along the axis; applied at the centres (no moment).
-- plates = true: left and right only, bands between the plates (walls 1, 2); otherwise all four
-- sides, bands over the extent of the particles. Returns the mean lateral extent W (mean over
-- bands of the right reach minus the left reach) and the lateral band data.
local function confine(s, pp, plates)
  local P = s:particles()
  local xlo, xhi, ylo, yhi = math.huge, -math.huge, math.huge, -math.huge
  for i = 1, P.count do
    xlo, xhi = math.min(xlo, P.x[i] - P.radius[i]), math.max(xhi, P.x[i] + P.radius[i])
    ylo, yhi = math.min(ylo, P.y[i] - P.radius[i]), math.max(yhi, P.y[i] + P.radius[i])
  end
  if plates then ylo, yhi = s:wall_point(1)[2], s:wall_point(2)[2] end
  local fx, fy, order = {}, {}, {}
  local function add(i, ax, ay)
    if not fx[i] then fx[i], fy[i] = 0, 0; order[#order + 1] = i end
    fx[i], fy[i] = fx[i] + ax, fy[i] + ay
  end
  local lat = bands(P, 2, ylo, yhi)
  local f, wsum, k = pp * lat.h * thick, 0, 0
  for b = 1, lat.nb do
    if lat.low[b] then
      k = k + 1
      add(lat.low[b], f, 0)
      add(lat.high[b], -f, 0)
      wsum = wsum + lat.hreach[b] - lat.lreach[b]
    end
  end
  if not plates then
    local ver = bands(P, 1, xlo, xhi)
    local fv = pp * ver.h * thick
    for b = 1, ver.nb do
      if ver.low[b] then
        add(ver.low[b], 0, fv)
        add(ver.high[b], 0, -fv)
      end
    end
  end
  local ids, ax, ay = {}, {}, {}
  for n, i in ipairs(order) do ids[n], ax[n], ay[n] = i, fx[i], fy[i] end
  s:clear_forces()
  s:set_forces{ ids = ids, fx = ax, fy = ay }
  return wsum / k, lat
end

-- The lateral strips: the particles whose surface comes within 2 r_max of the boundary reach at
-- some band (from confine's band data). Their mean abscissae move smoothly, unlike the reaches.
local function strips(B)
  local P, left, right = B.P, {}, {}
  for i = 1, P.count do
    local b0 = math.max(1, math.ceil((P.y[i] - P.radius[i] - B.lo) / B.h + 0.5))
    local b1 = math.min(B.nb, math.floor((P.y[i] + P.radius[i] - B.lo) / B.h + 0.5))
    local l, r = false, false
    for b = b0, b1 do
      if B.low[b] then
        l = l or (P.x[i] - P.radius[i]) - B.lreach[b] < 2 * rmax
        r = r or B.hreach[b] - (P.x[i] + P.radius[i]) < 2 * rmax
      end
    end
    if l then left[#left + 1] = i end
    if r then right[#right + 1] = i end
  end
  return left, right
end

local function strip_gap(x, left, right)
  local sl, sr = 0, 0
  for _, i in ipairs(left) do sl = sl + x[i] end
  for _, i in ipairs(right) do sr = sr + x[i] end
  return sr / #right - sl / #left
end

-- Normal forces on the plates (walls 1 and 2).
local function plate_forces(s)
  local C = s:measure("contacts")
  local fb, ft = 0, 0
  for k = 1, C.count or #C.i do
    if C.j[k] == -1 then fb = fb + C.fn[k] elseif C.j[k] == -2 then ft = ft + C.fn[k] end
  end
  return fb, ft
end

-- ---- preparation -----------------------------------------------------------------------------
-- Frictionless isotropic consolidation: the pressure on all four sides as forces on the outermost
-- particles, ramped to p, with a background drag. Then friction is switched on, the plates are
-- put touching the top and bottom particles, the vertical forces removed and the plates
-- servo-controlled to carry p W t (first with the drag, then without); the state is saved with
-- the plates at rest.
-- prepare(p) returns the saved state, the prepared scene (plates at rest) and the stress of the
-- bottom and top plates over p.
local function prepare(p)
  local prep = build(deposit(), false)
  local prep_dt = 2e-5
  local function run_prep(steps, pp, plates)
    local done = 0
    while done < steps do
      confine(prep, pp, plates)
      prep:run{ steps = 250, dt = prep_dt, impact_velocity = v_imp, progress = false }
      done = done + 250
    end
  end
  prep:drag(50)
  local ramp_stages = 20
  for k = 1, ramp_stages do run_prep(1000, p * k / ramp_stages, false) end
  run_prep(20000, p, false)
  -- Friction on (the paper's law), then the plates replace the vertical forces.
  prep:contact{ normal = "hertz", damping = "brilliantov", damping_time = T_damp,
                tangential = "coulomb_regularized", v_r = v_R, exponent = exponent }
  run_prep(5000, p, false)
  do
    local P = prep:particles()
    local ylo, yhi = math.huge, -math.huge
    for i = 1, P.count do
      ylo, yhi = math.min(ylo, P.y[i] - P.radius[i]), math.max(yhi, P.y[i] + P.radius[i])
    end
    prep:add_wall{ point = { 0, ylo - 1e-9 }, normal = { 0, 1 } }
    prep:add_wall{ point = { 0, yhi + 1e-9 }, normal = { 0, -1 } }
  end
  -- Plate servo: each plate moves at gain * (p W t - its force), at most vmax; with the drag on,
  -- the sample's slowest mode relaxes at ~ k/(drag M) ~ 20/s for its plate stiffness k ~ 7e5 N/m
  -- and mass M ~ 720 kg, so the servo rate gain * k must stay below that.
  local function servo_run(steps, gain, vmax)
    local done = 0
    while done < steps do
      local W = confine(prep, p, true)
      local target = p * W * thick
      local fb, ft = plate_forces(prep)
      local vb = math.max(-vmax, math.min(vmax, gain * (target - fb)))
      local vt = math.max(-vmax, math.min(vmax, gain * (target - ft)))
      prep:wall_velocity(1, { 0, vb })
      prep:wall_velocity(2, { 0, -vt })
      prep:run{ steps = 250, dt = prep_dt, impact_velocity = v_imp, progress = false }
      done = done + 250
    end
    prep:wall_velocity(1, { 0, 0 })
    prep:wall_velocity(2, { 0, 0 })
    local W = confine(prep, p, true)
    local fb, ft = plate_forces(prep)
    return fb / (p * W * thick), ft / (p * W * thick)
  end
  -- Approach: the plates close in at 0.5 mm/s until each carries half of p W t (the top of the
  -- sample is rough by a fraction of a grain), then the servo takes over.
  for _ = 1, 400 do
    local sb, st = servo_run(0, 0, 0)
    if sb > 0.5 and st > 0.5 then break end
    prep:wall_velocity(1, { 0, sb > 0.5 and 0 or 5e-4 })
    prep:wall_velocity(2, { 0, st > 0.5 and 0 or -5e-4 })
    prep:run{ steps = 250, dt = prep_dt, impact_velocity = v_imp, progress = false }
  end
  servo_run(20000, 1e-5, 5e-4)
  prep:drag(0)
  servo_run(30000, 5e-6, 5e-4)
  local prepared = save(prep)
  local sb, stp = servo_run(0, 0, 0)
  return prepared, prep, sb, stp
end

return { W0 = W0, deposit = deposit, build = build, save = save, confine = confine, strips = strips,
         strip_gap = strip_gap, plate_forces = plate_forces, prepare = prepare }
