-- grainlab DEM: Brazil-nut segregation, 2D: a large intruder at the bottom of a vertically
-- vibrated bed of small disks rises to the top; its rise time against the shaking strength
-- Gamma = A omega^2 / g.
--
-- Known physics: Rosato et al., PRL 58, 1038 (1987) (the large grain rises, by small grains
-- filling the void under it); Knight, Jaeger & Nagel, PRL 70, 3728 (1993) (in a deep bed the
-- rise is carried by convection rolls, down the side walls, driven by the walls' friction, up
-- the middle; the intruder rises with the upflow at the convection speed, and the rise time
-- falls as Gamma grows above ~1.2); Moebius et al., Nature 414, 270 (2001) (the rise time
-- also depends on the intruder's density and the interstitial air; here: same density, no air).
-- Below Gamma = 1 the bed never leaves the floor and nothing moves.
--
-- Procedure:
--  * The box: two planar side walls `width` small diameters apart and a floor (a polyline
--    segment), no lid (a lid changes the picture); Coulomb friction mu = 0.5 between grains and
--    with the walls (the side walls' friction drives the convection).
--  * A packing: the intruder (diameter `ratio` small diameters, the small grains' density) at
--    rest on the floor in the middle, then small disks (radii uniform in [0.8, 1.2] r, which
--    keeps a 2D bed from crystallising) poured in over it by an inserter to a bed `depth`
--    intruder diameters deep, settled (drag, then without) and saved to a checkpoint. `packings`
--    packings, seeds seed, seed + 1, ...
--  * A run: the checkpoint is loaded, the floor replaced by one that moves vertically, its
--    height A (1 - cos omega t), A = Gamma g / omega^2, omega = 2 pi f (at rest at t = 0, so the
--    start is smooth; the table of its velocity is sampled by the step itself; the new floor sits
--    below the old one by the deepest overlap, ~1 % of a small radius, as a wall may not be
--    added into a grain). Once per cycle, with the floor at its lowest, the intruder's height
--    above the floor (its bottom, normalised by the bed height h at rest) and the rank count: the
--    small grains whose centre is above the intruder's (a rank does not change when the bed
--    dilates or flies). The intruder has reached the top when that count is at most the number
--    of grains in a layer one intruder diameter thick, N 2 r_b / h (its centre within one
--    diameter of the surface: a stricter N r_b / h is seldom met, the intruder near the top is
--    carried about by the rolls); the rise time is the first cycle it is, in cycles, and the run
--    stops there. A run that has not risen by `t_max` cycles is reported as not risen (and a
--    Gamma where one did has no median: the median is over every packing).
--  * Law: Hertz, Brilliantov damping (restitution 0.5 at 1 m/s), Cundall-Strack spring, E = 1e7
--    Pa, dt = the stability limit at 2 m/s. Not softer: the bed is a spring under its own
--    weight; at E = 1e6 it sinks by ~1 mm, which puts its bounce (sqrt(g / x) / 2 pi ~ 16 Hz)
--    at the drive's 20 Hz, and surface grains left at 9 A omega (and the domain); at 1e7 they
--    stay below 3 A omega and the overlaps below a few % of a radius.
-- Checks: every packing rises for Gamma >= `rise_from`; none rises for Gamma < 1; the median rise
-- time at the largest Gamma is below that at the smallest rising Gamma, and the least-squares
-- slope of log(rise time) against Gamma over the rising Gammas is negative; the largest contact
-- overlap sampled (every 10 cycles, walls included) stays below 10 % of the smaller radius, and
-- no grain moves faster than 5 A omega (sampled once per cycle).
-- Output: a report, a CSV (param csv: one row per run and cycle), and figures (images/ for the
-- default run): the intruder's height against cycles for every Gamma (packing 1, each trace
-- ending where it reached the top), the rise time against Gamma for every packing with the
-- median, and a snapshot of packing 1 at the largest Gamma when its intruder reached the top,
-- the small grains shaded by their starting layer.
--
--   grainlab scripts/brazil_nut.lua [gammas=0.8,2,2.5,3,4,5] [packings=3] [seed=1]
--       [frequency=20] [ratio=4] [width=24] [depth=4] [t_max=200] [rise_from=2]
--       [csv=out/brazil_nut.csv] [verbose=false]
local figures = require("grainlab.figures")
local pour = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/pour.lua")
local heap_box = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/heap_box.lua") -- its least-squares line

local function int(v) return type(v) == "number" and math.tointeger(v) or nil end
local packings = int(params.packings or 3)
local seed = int(params.seed or 1)
local f = params.frequency or 20
local ratio = params.ratio or 4
local width = params.width or 24
local depth = params.depth or 4
local t_max = int(params.t_max or 200)
local rise_from = params.rise_from or 2
local csv = params.csv or "out/brazil_nut.csv"
local verbose = params.verbose == true
assert(packings and packings >= 1, "packings must be an integer >= 1")
assert(seed and seed >= 0, "seed must be a non-negative integer")
assert(type(f) == "number" and f > 0, "frequency must be a positive number (Hz)")
assert(type(ratio) == "number" and ratio >= 2, "ratio must be a number >= 2")
assert(type(width) == "number" and width >= 2 * ratio, "width must be a number >= 2 ratio (small diameters)")
assert(type(depth) == "number" and depth >= 1.5, "depth must be a number >= 1.5 (intruder diameters)")
assert(t_max and t_max >= 5, "t_max must be an integer >= 5 (cycles)")
assert(type(rise_from) == "number", "rise_from must be a number")
local gammas = {}
for v in tostring(params.gammas or "0.8,2,2.5,3,4,5"):gmatch("[^,]+") do
  local G = tonumber(v)
  assert(G and G > 0 and G < 20, "gammas: shaking strengths in (0, 20)")
  gammas[#gammas + 1] = G
end
table.sort(gammas)
local published = figures.published({ gammas = table.concat(gammas, ","), packings = packings,
                                      seed = seed, frequency = f, ratio = ratio, width = width,
                                      depth = depth, t_max = t_max },
                                    { gammas = "0.8,2,2.5,3,4,5", packings = 3, seed = 1,
                                      frequency = 20, ratio = 4, width = 24, depth = 4,
                                      t_max = 200 })
local png = params.png or figures.path("brazil_nut.png", { published = published })
local png_rise = figures.path("brazil_nut_rise.png", { published = published })
local png_snap = figures.path("brazil_nut_snapshot.png", { published = published })
local function say(fmt, ...) if verbose then io.stderr:write(string.format(fmt, ...) .. "\n") end end

local g, rho, r = 9.81, 2650, 1e-3 -- small grains: radii in [0.8, 1.2] r
local d = 2 * r
local rb = ratio * r -- the intruder's radius
local W = width * d
local H0 = depth * 2 * rb -- the bed depth asked for
local area = math.pi * r * r * (1 + 0.2 ^ 2 / 3) / 0.82 -- per small disk, packed
local n_small = math.floor((W * H0 - math.pi * rb * rb / 0.82) / area + 0.5)
local omega = 2 * math.pi * f
local period = 1 / f
local young = 1e7 -- not softer: see the header
local mat = grainlab.material{ density = rho, young = young, poisson = 0.3, friction = 0.5 }
local Amax = gammas[#gammas] * g / omega ^ 2
-- lid-free: the domain's top only bounds the flight; the splash off the bed's surface reaches a
-- few times the floor's speed A omega (up to 3.8 A omega measured at Gamma = 5)
local top = H0 + 2 * rb + (6 * Amax * omega) ^ 2 / (2 * g)
local below = 3 * d

local function new_scene()
  local s = dem.scene{ dim = 2, box = { { 0, -below }, { W, top } }, gravity = { 0, -g } }
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
             tangential = "spring" }
  return s
end

-- A packing: the intruder (id 1) on the floor, the small grains poured over it and settled;
-- saved to `path`. Returns the bed height at rest and the number of small grains.
local function pack(k, path)
  local c0 = grainlab.clock()
  local s = new_scene()
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 }, material = mat }
  s:add_wall{ point = { W, 0 }, normal = { -1, 0 }, material = mat }
  s:add_polyline{ points = { { 0, 0 }, { W, 0 } }, material = mat }
  s:add_disk{ pos = { 0.5 * W, rb }, radius = rb, material = mat }
  s:inserter{ box = { { 0, 2 * rb + 0.2 * d }, { W, 2.5 * H0 } }, rate = 4 * n_small, count = n_small,
              radius = { 0.8 * r, 1.2 * r }, material = mat, seed = seed + k - 1, attempts = 500 }
  local dt = s:timestep{ impact_velocity = 2 }.limit
  local function advance(T) s:run{ time = T, dt = dt, impact_velocity = 2, progress = false } end
  pour(s, n_small, advance, "brazil_nut")
  s:save(path)
  local P = s:particles()
  -- the bed height: the mean over bins of 2 d of the highest small grain's top
  local tops, nb = {}, math.floor(W / (2 * d))
  for i = 2, P.count do
    local b = math.min(nb - 1, math.floor(P.x[i] / (2 * d)))
    tops[b] = math.max(tops[b] or 0, P.y[i] + P.radius[i])
  end
  local h = 0
  for b = 0, nb - 1 do h = h + (tops[b] or 0) / nb end
  say("packing %d: %d small grains, bed %.1f mm (%.2f intruder diameters), intruder at %.2f mm, %.1f s",
      k, P.count - 1, h * 1e3, h / (2 * rb), P.y[1] * 1e3, grainlab.clock() - c0)
  return h, P.count - 1, dt
end

-- The largest contact overlap over the smaller radius (walls: j < 0, the particle's radius).
local function max_overlap(s, P)
  local c = s:measure("contacts")
  local m = 0
  for q = 1, #c.i do
    local j = c.j[q]
    local rr = j > 0 and math.min(P.radius[c.i[q]], P.radius[j]) or P.radius[c.i[q]]
    m = math.max(m, c.overlap[q] / rr)
  end
  return m
end

-- The snapshot: the grains of P (the intruder yellow) in a scene of their own that ends above the
-- bed (the full domain is mostly air), each small grain shaded by its height at the start, in
-- bands of h / 8: the convection shows as bands dragged down along the walls.
local function snapshot(file, P, P0, y_floor, h, G, c)
  local y_top = y_floor + 1.6 * h
  local v = dem.scene{ dim = 2, box = { { 0, y_floor - d }, { W, y_top } } }
  local colour = {}
  for i = 1, P.count do
    if P.y[i] + P.radius[i] < y_top then
      v:add_disk{ pos = { P.x[i], P.y[i] }, radius = P.radius[i], material = mat, fixed = true }
      colour[#colour + 1] = i == 1 and 1 or 0.1 + 0.35 * (math.floor(P0.y[i] / (h / 8)) % 2)
    end
  end
  render.png(v, file, { color = colour, colormap = "viridis", range = { 0, 1 }, width = 700, show = {},
                        walls = { { point = { 0, 0 }, normal = { 1, 0 } }, { point = { W, 0 }, normal = { -1, 0 } },
                                  { point = { 0, y_floor }, normal = { 0, 1 } } },
                        title = string.format("Gamma = %g, cycle %d: the intruder (yellow) at the top; small grains shaded by their starting layer", G, c) })
  print("wrote " .. file)
end

-- One run: packing `path` shaken at Gamma. Returns the record and the rise time (cycles, or nil).
local function shake(path, G, h, n, dt, snap)
  local c0 = grainlab.clock()
  local s = dem.load(path)
  local t0 = s:info().time
  local A = G * g / omega ^ 2
  -- the floor: ids 1, 2 the side walls, 3 the fixed floor, replaced by a moving one; a wall
  -- may not be added into a particle, so the new floor sits just below the deepest overlap
  -- with the old one (a drop of ~1 % of a small radius)
  local P0 = s:particles()
  local y0 = 0
  for i = 1, P0.count do y0 = math.min(y0, P0.y[i] - P0.radius[i]) end
  y0 = y0 - 1e-9
  s:remove_wall(3)
  local floor = s:add_polyline{ points = { { 0, y0 }, { W, y0 } }, material = mat,
                                motion = function(t) return { 0, A * omega * math.sin(omega * (t - t0)) }, 0 end,
                                motion_step = period / 64, motion_until = t0 + (t_max + 1) * period }
  local y_floor0 = s:wall_point(floor)[2]
  local n_top = n * 2 * rb / h
  local rec = { cycle = {}, z = {}, above = {} }
  local rise, worst, vmax = nil, 0, 0
  for c = 1, t_max do
    s:run{ time = period, dt = dt, impact_velocity = 2, progress = false }
    local P = s:particles()
    local yf = s:wall_point(floor)[2] - y_floor0 + y0
    local yb = P.y[1]
    local above = 0
    for i = 2, P.count do
      if P.y[i] > yb then above = above + 1 end
      vmax = math.max(vmax, math.sqrt(P.vx[i] ^ 2 + P.vy[i] ^ 2))
    end
    rec.cycle[c], rec.z[c], rec.above[c] = c, (yb - yf - rb) / h, above
    if c % 20 == 0 then say("  Gamma %g cycle %d: intruder at %.3f h, %d small grains above", G, c, rec.z[c], above) end
    if c % 10 == 1 then worst = math.max(worst, max_overlap(s, P)) end
    if above <= n_top then
      rise = c
      if snap then snapshot(snap, P, P0, yf, h, G, c) end
      break
    end
  end
  say("Gamma %g: %s, %d samples, max overlap %.3f r, vmax %.3f m/s (A omega %.3f), %.1f s", G,
      rise and string.format("risen after %d cycles", rise) or "not risen", #rec.cycle, worst, vmax,
      A * omega, grainlab.clock() - c0)
  return rec, rise, worst, vmax, A, grainlab.clock() - c0
end

print(string.format("brazil_nut: intruder %g small diameters in a %g d wide bed %g intruder diameters deep, f = %g Hz, Gamma = %s, %d packings",
                    ratio, width, depth, f, table.concat(gammas, ", "), packings))
local progress = grainlab.progress{ label = "brazil_nut", total = packings * #gammas, unit = "runs" }
local runs, packs = {}, {}
for k = 1, packings do
  local path = os.tmpname()
  local h, n, dt = pack(k, path)
  packs[k] = { h = h, n = n, dt = dt }
  for j, G in ipairs(gammas) do
    local snap = (k == 1 and j == #gammas) and png_snap or nil
    local rec, rise, worst, vmax, A, wall = shake(path, G, h, n, dt, snap)
    runs[#runs + 1] = { k = k, G = G, rec = rec, rise = rise, overlap = worst, vmax = vmax, A = A,
                        wall_s = wall }
    progress:update((k - 1) * #gammas + j)
  end
  os.remove(path)
end
progress:finish()

local function median(v)
  local t = {}
  for i, x in ipairs(v) do t[i] = x end
  table.sort(t)
  local m = #t
  if m == 0 then return nil end
  return m % 2 == 1 and t[(m + 1) // 2] or 0.5 * (t[m // 2] + t[m // 2 + 1])
end

local metrics = { small_grains = packs[1].n, dt_s = packs[1].dt, intruder_diameter_m = 2 * rb,
                  box_width_m = W }
local checks = {}
local per = {}
local worst, vmax_over = 0, 0
print(string.format("%6s %8s %s %8s %8s", "Gamma", "A (mm)", "rise time per packing (cycles)", "median", "risen"))
for j, G in ipairs(gammas) do
  local times, risen, cells = {}, 0, {}
  local A
  for _, rn in ipairs(runs) do
    if rn.G == G then
      A = rn.A
      cells[#cells + 1] = rn.rise and string.format("%d", rn.rise) or "-"
      if rn.rise then times[#times + 1], risen = rn.rise, risen + 1 end
      worst = math.max(worst, rn.overlap)
      vmax_over = math.max(vmax_over, rn.vmax / (rn.A * omega))
    end
  end
  local med = risen == packings and median(times) or nil -- the median of all packings: all risen
  per[j] = { G = G, times = times, risen = risen, median = med, A = A }
  print(string.format("%6g %8.3f %s %8s %5d/%d", G, A * 1e3, table.concat(cells, " "),
                      med and string.format("%g", med) or "-", risen, packings))
  local id = string.format("g%03d", math.floor(G * 10 + 0.5))
  metrics["risen_" .. id] = risen
  if med then metrics["rise_cycles_median_" .. id] = med end
  if G >= rise_from then
    checks[#checks + 1] = { name = "every_packing_rises_" .. id, value = risen, limit = packings, op = ">=" }
  elseif G < 1 then
    checks[#checks + 1] = { name = "no_rise_below_gamma_1_" .. id, value = risen, limit = 0, op = "<=" }
  end
end
metrics.max_overlap_over_radius = worst
metrics.max_speed_over_a_omega = vmax_over
-- the trend over the Gammas from rise_from on where every packing rose
local xs, ys = {}, {}
for _, p in ipairs(per) do
  if p.G >= rise_from and p.median then
    for _, t in ipairs(p.times) do xs[#xs + 1], ys[#ys + 1] = p.G, math.log(t) end
  end
end
local first, last
for _, p in ipairs(per) do
  if p.G >= rise_from and p.median then
    first = first or p
    last = p
  end
end
if first and last and first ~= last then
  local _, slope = heap_box.line(xs, ys)
  metrics.log_rise_slope_per_gamma = slope
  checks[#checks + 1] = { name = "median_rise_falls_largest_vs_smallest_gamma",
                          value = last.median / first.median, limit = 1, op = "<" }
  checks[#checks + 1] = { name = "log_rise_cycles_slope_per_gamma", value = slope, limit = 0, op = "<" }
end
checks[#checks + 1] = { name = "max_overlap_over_radius", value = worst, limit = 0.1 }
checks[#checks + 1] = { name = "max_speed_over_a_omega", value = vmax_over, limit = 5 }

os.execute("mkdir -p out")
local rows = { "gamma,packing,cycle,height_over_bed,small_above,risen_cycle" }
for _, rn in ipairs(runs) do
  for c = 1, #rn.rec.cycle do
    rows[#rows + 1] = string.format("%g,%d,%d,%.5f,%d,%s", rn.G, rn.k, c, rn.rec.z[c],
                                    rn.rec.above[c], rn.rise and tostring(rn.rise) or "")
  end
end
assert(grainlab.write_file(csv, table.concat(rows, "\n") .. "\n"))
print("wrote " .. csv)

do
  local series = {}
  for _, rn in ipairs(runs) do
    if rn.k == 1 then
      series[#series + 1] = { x = rn.rec.cycle, y = rn.rec.z, style = "line",
                              label = string.format("Gamma = %g%s", rn.G, rn.rise and "" or " (not risen)") }
    end
  end
  render.plot{ file = png, width = 900, height = 560,
               title = string.format("Brazil nut: intruder of %g d in a bed of %d disks, f = %g Hz (packing 1)",
                                     ratio, packs[1].n, f),
               xlabel = "cycles", ylabel = "intruder bottom above the floor / bed height",
               series = series }
  print("wrote " .. png)
  local px, py, mx, my = {}, {}, {}, {}
  for _, p in ipairs(per) do
    for _, t in ipairs(p.times) do px[#px + 1], py[#py + 1] = p.G, t end
    if p.median then mx[#mx + 1], my[#my + 1] = p.G, p.median end
  end
  local rs = {}
  if #px > 0 then rs[#rs + 1] = { x = px, y = py, label = "each packing", style = "points" } end
  if #mx > 0 then rs[#rs + 1] = { x = mx, y = my, label = "median", style = "both" } end
  if #rs > 0 then
    render.plot{ file = png_rise, width = 900, height = 560,
                 title = string.format("Brazil nut: rise time against Gamma (%d packings, f = %g Hz)", packings, f),
                 xlabel = "Gamma = A omega^2 / g", ylabel = "rise time (cycles)", series = rs }
    print("wrote " .. png_rise)
  end
end

grainlab.report{
  scenario = "brazil_nut",
  params = { gammas = gammas, packings = packings, seed = seed, frequency_hz = f, ratio = ratio,
             width_d = width, depth_intruder_d = depth, t_max_cycles = t_max, rise_from = rise_from,
             friction = 0.5, young_pa = young, csv = csv },
  metrics = metrics,
  checks = checks,
}
