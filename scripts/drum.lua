-- grainlab DEM: a rotating drum in 2D, the dynamic angle of repose against the Froude number
-- (Herrmann & Mueller Sec. 3 lists rotating drums among what soft-sphere codes are used for).
--
-- A drum of radius R turning at omega carries a bed of grains up its rising side; in the
-- rolling regime (Froude number Fr = omega^2 R / g from ~1e-4 to ~1e-2) a thin layer flows
-- down a flat surface steadily, at a dynamic angle theta_d that rises with Fr; at lower Fr the
-- surface slumps in intermittent avalanches, at higher it bends into an S (cascading).
--
-- Procedure:
--  * The drum: a circle wall (a cylinder, particles inside) of radius `radius` mean diameters,
--    Coulomb friction mu = 0.5 with the grains as between them; N disks (radii uniform in
--    [0.5, 1] mm) filling `fill` of its area, poured in by an inserter and settled at rest.
--  * One run through every Froude number of `frs`, in increasing order: the drum's angular
--    velocity follows a piecewise-linear table (the wall's motion, sampled by the step itself),
--    held at each Fr for `settle` + `measure` s of scene time (ramped in 0.1 s between levels).
--    During `measure` the surface is sampled every `sample` s: the top of the highest grain in
--    bins of 2 mean diameters across the middle 60 % of the drum's width, a least-squares line,
--    theta_d its angle to the horizontal; theta_d is the mean over the samples, with their
--    standard deviation (the fluctuation) and the mean of each half of the window (steadiness).
--  * The flow field at the Fr nearest 1e-3: the grains' velocities averaged over the window in a
--    grid of cells 2 mean diameters wide, drawn as the speed with arrows.
--  * Law: Hertz, Brilliantov damping (restitution 0.5 at 1 m/s), Cundall-Strack spring, E = 1e6
--    Pa, dt = the stability limit at 2 m/s.
-- Checks: theta_d rises with Fr over the range; in (5, 60) deg; each window steady (the halves'
-- means within `steady` deg); the bed is carried by the drum (its mean angular velocity about the
-- centre during the window is more than 0.2 omega).
--
--   grainlab scripts/drum.lua [radius=30] [fill=0.4] [frs=3e-4,1e-3,3e-3,1e-2,3e-2] [settle=2]
--       [measure=3] [sample=0.05] [steady=2] [seed=1] [csv=out/drum.csv] [verbose=false]
local figures = require("grainlab.figures")

local radius_d = params.radius or 30
local fillf = params.fill or 0.4
local settle = params.settle or 2
local measure = params.measure or 3
local sample = params.sample or 0.05
local steady = params.steady or 2 -- deg: the halves' means may differ by this much
local seed = math.tointeger(params.seed or 1)
local csv = params.csv or "out/drum.csv"
local verbose = params.verbose == true
assert(type(radius_d) == "number" and radius_d >= 8, "radius must be a number >= 8 (mean diameters)")
assert(type(fillf) == "number" and fillf > 0.1 and fillf < 0.7, "fill must be in (0.1, 0.7)")
for k, v in pairs({ settle = settle, measure = measure, sample = sample }) do
  assert(type(v) == "number" and v > 0, k .. " must be a positive number (s)")
end
assert(seed and seed >= 0, "seed must be a non-negative integer")
local frs = {}
for v in tostring(params.frs or "3e-4,1e-3,3e-3,1e-2,3e-2"):gmatch("[^,]+") do
  local f = tonumber(v)
  assert(f and f > 0 and f < 1, "frs: Froude numbers in (0, 1)")
  frs[#frs + 1] = f
end
table.sort(frs)
local published = figures.published({ radius = radius_d, fill = fillf, frs = table.concat(frs, ","),
                                      settle = settle, measure = measure, sample = sample, seed = seed,
                                      steady = steady },
                                    { radius = 30, fill = 0.4, frs = table.concat({ 3e-4, 1e-3, 3e-3, 1e-2, 3e-2 }, ","), settle = 2,
                                      measure = 3, sample = 0.05, seed = 1, steady = 2 })
local png = params.png or figures.path("drum.png", { published = published })
local png_field = figures.path("drum_flow.png", { published = published })
local function say(fmt, ...) if verbose then io.stderr:write(string.format(fmt, ...) .. "\n") end end

local g, rho, rmin, rmax = 9.81, 2650, 0.5e-3, 1e-3
local d = rmin + rmax
local R = radius_d * d
local area = math.pi * (rmax ^ 3 - rmin ^ 3) / (3 * (rmax - rmin)) / 0.82
local n = math.floor(fillf * math.pi * R * R / area)
local mat = grainlab.material{ density = rho, young = 1e6, poisson = 0.3, friction = 0.5 }
local bw = 2 * d

-- The schedule of omega: at rest while the grains are poured and settle (t_fill), then level k
-- from T[k] to T[k + 1], the first 0.1 s a ramp from the last.
local t_fill = 0.9
local T, omegas, rows = {}, {}, { { 0, 0, 0, 0 }, { t_fill, 0, 0, 0 } }
local t = t_fill
for k, fr in ipairs(frs) do
  omegas[k] = math.sqrt(fr * g / R)
  T[k] = t
  rows[#rows + 1] = { t + 0.1, 0, 0, omegas[k] }
  t = t + settle + measure
  rows[#rows + 1] = { t, 0, 0, omegas[k] }
end

local s = dem.scene{ dim = 2, box = { { -R, -R }, { R, R } }, gravity = { 0, -g } }
s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
           tangential = "spring" }
local drum = s:add_cylinder{ center = { 0, 0 }, radius = R, inside = true, material = mat,
                             motion = rows }
s:inserter{ box = { { -0.95 * R, -0.95 * R }, { 0.95 * R, 0.95 * R } }, count = n, rate = 5 * n,
            radius = { rmin, rmax }, material = mat, seed = seed, attempts = 500 }
local dt = s:timestep{ impact_velocity = 2 }.limit
local function advance(T_) s:run{ time = T_, dt = dt, impact_velocity = 2, progress = false } end
local c0 = grainlab.clock()
advance(0.3)
s:drag(20)
advance(0.4)
s:drag(0)
advance(0.2)
local n_in = s:info().count
say("drum: R %.1f mm, %d grains (of %d), dt %.3g s, filled in %.1f s", R * 1e3, n_in, n, dt,
    grainlab.clock() - c0)
assert(math.abs(s:info().time - t_fill) < 1e-3, "drum: the fill took " .. s:info().time .. " s, not the " .. t_fill .. " s the schedule gives it")

-- the surface: highest grain top per bin across the middle 60 %, least-squares line
local function surface_angle(P)
  local tops, nb = {}, math.floor(1.2 * R / bw)
  for i = 1, P.count do
    local k = math.floor((P.x[i] + 0.6 * R) / bw)
    if k >= 0 and k < nb then tops[k] = math.max(tops[k] or -math.huge, P.y[i] + P.radius[i]) end
  end
  local sx, sy, sxx, sxy, m = 0, 0, 0, 0, 0
  for k = 0, nb - 1 do
    if tops[k] then
      local x = -0.6 * R + (k + 0.5) * bw
      m, sx, sy, sxx, sxy = m + 1, sx + x, sy + tops[k], sxx + x * x, sxy + x * tops[k]
    end
  end
  local slope = (m * sxy - sx * sy) / (m * sxx - sx * sx)
  return math.deg(math.atan(math.abs(slope)))
end

local ng = math.floor(2 * R / bw)
local results = {}
local field_k = 1
for k, fr in ipairs(frs) do
  if math.abs(math.log(fr / 1e-3)) < math.abs(math.log(frs[field_k] / 1e-3)) then field_k = k end
end
local progress = grainlab.progress{ label = "drum", total = #frs, unit = "Froude numbers" }
for k, fr in ipairs(frs) do
  local c1 = grainlab.clock()
  advance(settle)
  local angles, spin = {}, {}
  local su, sv, cnt = {}, {}, {}
  local steps = math.floor(measure / sample + 0.5)
  for q = 1, steps do
    advance(sample)
    local P = s:particles()
    angles[q] = surface_angle(P)
    local L, I = 0, 0 -- the bed's mean angular velocity about the centre
    for i = 1, P.count do
      L = L + P.mass[i] * (P.x[i] * P.vy[i] - P.y[i] * P.vx[i])
      I = I + P.mass[i] * (P.x[i] ^ 2 + P.y[i] ^ 2)
    end
    spin[q] = L / I
    if k == field_k then
      for i = 1, P.count do
        local ci = math.floor((P.x[i] + R) / bw)
        local cj = math.floor((P.y[i] + R) / bw)
        if ci >= 0 and ci < ng and cj >= 0 and cj < ng then
          local c = cj * ng + ci + 1
          su[c], sv[c], cnt[c] = (su[c] or 0) + P.vx[i], (sv[c] or 0) + P.vy[i], (cnt[c] or 0) + 1
        end
      end
    end
  end
  local mean, h1, h2, sd, w = 0, 0, 0, 0, 0
  for q, a in ipairs(angles) do
    mean = mean + a / steps
    if q <= steps // 2 then h1 = h1 + a / (steps // 2) else h2 = h2 + a / (steps - steps // 2) end
    w = w + spin[q] / steps
  end
  for _, a in ipairs(angles) do sd = sd + (a - mean) ^ 2 / math.max(steps - 1, 1) end
  sd = math.sqrt(sd)
  results[k] = { fr = fr, omega = omegas[k], theta = mean, sd = sd, h1 = h1, h2 = h2, spin = w,
                 wall_s = grainlab.clock() - c1 }
  if k == field_k then
    local speed, u, v = {}, {}, {}
    for c = 1, ng * ng do
      local x = -R + ((c - 1) % ng + 0.5) * bw
      local y = -R + ((c - 1) // ng + 0.5) * bw
      if cnt[c] and cnt[c] >= steps and x * x + y * y < R * R then -- a grain there half the time
        u[c], v[c] = su[c] / cnt[c], sv[c] / cnt[c]
        speed[c] = math.sqrt(u[c] ^ 2 + v[c] ^ 2) * 1e3
      else
        u[c], v[c], speed[c] = 0, 0, 0 / 0
      end
    end
    render.field{ file = png_field, values = speed, nx = ng, ny = ng,
                  extent = { { -R * 1e3, -R * 1e3 }, { R * 1e3, R * 1e3 } }, label = "mm/s",
                  title = string.format("drum, Fr = %g: time-averaged grain velocity", fr),
                  arrows = { u = u, v = v, unit = "m/s" } }
    print("wrote " .. png_field)
  end
  say("Fr %g (omega %.3f rad/s): theta_d %.2f deg (sd %.2f; halves %.2f, %.2f), bed spin %.3f rad/s, %.1f s",
      fr, omegas[k], mean, sd, h1, h2, w, grainlab.clock() - c1)
  progress:update(k)
end
progress:finish()

local metrics, checks, rows_csv = { grains = n_in, dt_s = dt, drum_radius_m = R }, {}, { "froude,omega_rad_per_s,theta_d_deg,theta_sd_deg,first_half_deg,second_half_deg,bed_spin_rad_per_s" }
print(string.format("%9s %9s %9s %7s %9s %9s %9s", "Fr", "omega", "theta_d", "sd", "1st half", "2nd half", "bed spin"))
for _, r in ipairs(results) do
  local id = ("fr" .. string.format("%.0e", r.fr)):gsub("e%-0*", "em"):gsub("[^%w_]", "")
  print(string.format("%9.1e %9.3f %9.2f %7.2f %9.2f %9.2f %9.3f", r.fr, r.omega, r.theta, r.sd, r.h1,
                      r.h2, r.spin))
  rows_csv[#rows_csv + 1] = string.format("%g,%.5f,%.4f,%.4f,%.4f,%.4f,%.5f", r.fr, r.omega, r.theta,
                                          r.sd, r.h1, r.h2, r.spin)
  metrics["theta_d_deg_" .. id] = r.theta
  metrics["theta_sd_deg_" .. id] = r.sd
  metrics["wall_s_" .. id] = r.wall_s
  checks[#checks + 1] = { name = "theta_d_in_5_60_deg_" .. id, pass = r.theta > 5 and r.theta < 60 }
  checks[#checks + 1] = { name = "steady_halves_deg_" .. id, value = math.abs(r.h2 - r.h1), limit = steady }
  checks[#checks + 1] = { name = "bed_carried_spin_over_omega_" .. id, value = r.spin / r.omega,
                          limit = 0.2, op = ">" }
end
if #results > 1 then
  checks[#checks + 1] = { name = "theta_d_rise_over_fr_range_deg",
                          value = results[#results].theta - results[1].theta, limit = 0, op = ">" }
end
os.execute("mkdir -p out")
assert(grainlab.write_file(csv, table.concat(rows_csv, "\n") .. "\n"))
print("wrote " .. csv)
do
  local x, y = {}, {}
  for _, r in ipairs(results) do x[#x + 1], y[#y + 1] = math.log(r.fr, 10), r.theta end
  render.plot{ file = png, width = 900, height = 560,
               title = string.format("rotating drum, %d disks, R = %g d: dynamic angle of repose", n_in, radius_d),
               xlabel = "log10 Froude number (omega^2 R / g)", ylabel = "dynamic angle (degrees)",
               series = { { x = x, y = y, label = "theta_d (mean over the window)", style = "both" } } }
  print("wrote " .. png)
end

grainlab.report{
  scenario = "drum",
  params = { radius_d = radius_d, fill = fillf, frs = frs, settle_s = settle, measure_s = measure,
             sample_s = sample, seed = seed, friction = 0.5, young_pa = 1e6, csv = csv },
  metrics = metrics,
  checks = checks,
}
