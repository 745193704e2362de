-- grainlab DEM study: error against wall time over the time step and the integrator, on the two
-- validation tests with exact answers.
--
-- Sweep: dt/t_c in params.fracs (default 1/10 .. 1/1000) x integrator in velocity_verlet,
-- position_verlet, gear and two_timescales (cycles of one large step n dt and q steps dt; dt is the
-- small step, so the largest step is n dt; n = q = 4 by default; m is passed but the kernel does not
-- use it: it only names the macro step m (n + q) dt). Every run uses force = true so the sweep can go
-- past the kernel's stability guard (s:timestep().limit); such runs are marked "forced" in the
-- table, and a run the kernel stops as unstable is listed and left out of the CSV and the fits.
--
-- Test 1, head-on collisions (set-up of scripts/dem_collision.lua, which has the derivations): a
-- quartz grain (r = 0.5 mm) and a glass grain (r = 0.7 mm) in 2D, approaching at v0 along (0.6, 0.8),
-- centre of mass at rest; t_c is the analytic contact time of the case.
--   linear_e0.5: linear law k = 1e5 N/m with viscous damping, clip = false, against the closed form
--     w0 = sqrt(k/m_eff), b = -ln(e) w0/sqrt(pi^2 + ln(e)^2), t_c = pi/sqrt(w0^2 - b^2),
--     e = exp(-b t_c).
--   hertz_v1: elastic Hertz, t_c = 2.9432751843 d_max/v0 (= 2 B(2/5, 1/2)/(5/2)),
--     d_max = (5 m_eff v0^2/(4K))^{2/5}, K = 4/3 E* sqrt(R_eff); e = 1.
-- Measurement, no per-step callback (so the timed run is the measured run): before and after the
-- contact the grains fly freely, and every integrator here is exact in free flight, so the touch is
-- at gap/v0 and the end of the contact is where the outgoing straight line meets zero overlap,
-- t_end = t + delta/u (delta < 0 the final overlap, u the separation speed). The run goes on for
-- ~0.5 t_c + 10 steps after the expected end (Gear's corrector transient dies out) and must end
-- separated. e = u/v0. Each run is made with the touch at params.phases (3) phases within a step
-- and reports its worst error (the force switches on and off at step boundaries). Wall time: the
-- s:run calls only, repeated on fresh scenes until params.min_time (0.02 s) has accumulated.
--
-- Test 3, a solid disk (cylinder R = 1 cm, 1 mm thick, quartz density, E = 1 GPa) released from rest
-- at its static Hertz overlap on an incline, Cundall-Strack spring friction (set-up and rigid
-- solution of scripts/dem_incline.lua): rolling_th30_mu0.5 (x = g t^2 sin th/3, omega = -x'/R) and
-- slipping_th60_mu0.3 (x = g t^2 (sin th - mu cos th)/2, omega' = -2 mu g cos th/R), after
-- params.T = 0.15 s. t_c = s:timestep().contact_time (the kernel's own scale: dt = "auto" is t_c/50).
-- Two errors each: against the rigid disk (what a user wants; it includes the soft-contact model
-- error: slip-onset lag of the spring and its undamped oscillation, which shrink like 1/T and do not
-- depend on dt) and against a fine run of the same model (velocity Verlet at t_c/params.ref_div,
-- 2000), the discretisation error alone, given for dt >= 4 ref_div^-1 t_c only.
--
-- Metrics: the observed order of each integrator (least-squares slope of log error vs log dt over
-- the resolved part: largest step <= t_c/20 and error > 1e-12), per error and for the worst
-- collision error; the cheapest integrator/dt reaching 1e-3 per test (worst error over the test's
-- cases and errors, wall time summed over its cases).
-- Checks (tolerances):
--   collision errors fall with dt for each integrator over the resolved range: every ratio
--     err(dt_next)/err(dt) < 1 for every case and error;
--   velocity Verlet's worst collision error at dt = t_c/1000 <= 1e-3 (its restitution error is first
--     order, ~0.7 dt/t_c at e = 0.5, because the dashpot sees half-step velocities);
--   every integrator at least first order on the collision (worst-error order >= 0.8);
--   incline discretisation error (worst over cases and errors) falls from the coarsest to the finest
--     compared dt for each integrator (finest < coarsest; it need not fall at every step: Gear's
--     numerical damping of the contact oscillation makes its spin error non-monotone);
--   incline error against the rigid disk <= 2e-3 (0.15 s/T) for every stable run (the model floor,
--     ~7e-4 at T = 0.15 s, shrinks like 1/T).
-- The collision checks need two resolved settings; with fewer they are left out.
-- Measured with the defaults (70-90 s on a loaded machine, 35 s of CPU): collision orders 1.0
-- for velocity and position Verlet (they are the same scheme here and give identical errors; Hertz:
-- e 2.5, t_c 2.0), 2.0 for Gear (linear e; its t_c goes like dt^3.2; Hertz 2.5: d^{3/2} is not
-- smooth at the touch) and 1.1 for two timescales (the large step sets the error). Cheapest to 1e-3:
-- collisions, Gear at t_c/20; incline, two timescales at t_c/10 (past the guard, stable): against the
-- rigid disk every run sits on the model floor (~3e-4 travel, ~7e-4 spin when slipping). Against the
-- fine run Gear converges only like dt on the incline and at coarse dt damps the spring's oscillation
-- (rolling spin vs rigid 2e-11 at t_c/10); position Verlet's travel error grows below t_c/100:
-- x_{n+1} = 2 x_n - x_{n-1} + a dt^2 accumulates roundoff (free fall over 1e6 steps: 2e-6 off).
--
--   grainlab scripts/study_dem.lua [csv=out/study_dem.csv] [v0=1.0] [k=1e5] [e=0.5] [T=0.15]
--                                  [phases=3] [min_time=0.02] [ref_div=2000] [n=4] [q=4] [m=1]
--                                  [fracs=10,20,50,100,200,500,1000]

local csv_path = params.csv or "out/study_dem.csv"
local v0 = params.v0 or 1.0                 -- approach speed, m/s
local k = params.k or 1e5                   -- linear stiffness, N/m
local e_lin = params.e or 0.5               -- restitution of the linear case
local T_incl = params.T or 0.15             -- s of motion on the incline
local nphases = params.phases or 3          -- touch phases per collision run
local min_time = params.min_time or 0.02    -- s of accumulated timing per collision setting
local ref_div = params.ref_div or 2000      -- incline reference: velocity Verlet at t_c/ref_div
local tt_n, tt_q, tt_m = params.n or 4, params.q or 4, params.m or 1
local fracs = {}
for f in tostring(params.fracs or "10,20,50,100,200,500,1000"):gmatch("[^,]+") do
  local d = tonumber(f)
  assert(d and d >= 1, "fracs: a comma-separated list of divisors of t_c (>= 1)")
  fracs[#fracs + 1] = 1 / d
end
-- images/ only from the default sweep (docs/dem.md shows it); any other run writes to out/.
local figures = require("grainlab.figures")
local png = params.png or figures.path("study_dem.png", {
  published = figures.published({ v0 = v0, k = k, e = e_lin, T = T_incl, phases = nphases, min_time = min_time,
                                  ref_div = ref_div, n = tt_n, q = tt_q, m = tt_m,
                                  fracs = tostring(params.fracs or "10,20,50,100,200,500,1000") },
                                { v0 = 1.0, k = 1e5, e = 0.5, T = 0.15, phases = 3, min_time = 0.02, ref_div = 2000,
                                  n = 4, q = 4, m = 1, fracs = "10,20,50,100,200,500,1000" }) })
table.sort(fracs, function(a, b) return a > b end)
assert(type(csv_path) == "string", "csv must be a path")
for name, v in pairs { v0 = v0, k = k, T = T_incl, min_time = min_time } do
  assert(type(v) == "number" and v > 0, name .. " must be a positive number")
end
assert(type(e_lin) == "number" and e_lin > 0 and e_lin < 1, "e must be in (0, 1)")
assert(math.type(nphases) == "integer" and nphases >= 1, "phases must be a positive integer")
assert(math.type(ref_div) == "integer" and ref_div >= 100, "ref_div must be an integer >= 100")
for name, v in pairs { n = tt_n, q = tt_q, m = tt_m } do
  assert(math.type(v) == "integer" and v >= (name == "q" and 0 or 1), name .. " must be an integer")
end
grainlab.threads(1) -- one or two grains: threads would only add synchronisation

local INTEGRATORS = { "velocity_verlet", "position_verlet", "gear", "two_timescales" }
local SHORT = { velocity_verlet = "vv", position_verlet = "pv", gear = "gear", two_timescales = "tt" }
local function largest_step(integ) return integ == "two_timescales" and tt_n or 1 end
local function run_opts(integ, dt, extra)
  local o = { dt = dt, integrator = integ, force = true, progress = false }
  if integ == "two_timescales" then o.n, o.q, o.m = tt_n, tt_q, tt_m end
  for key, v in pairs(extra) do o[key] = v end
  return o
end
local function rel(a, b) return math.abs(a - b) / math.abs(b) end
local t_wall0 = grainlab.clock()
local progress = grainlab.progress{ label = "study_dem", total = #fracs * #INTEGRATORS * 4 + 2, unit = "settings" }
local done = 0
local function tick() done = done + 1; progress:update(done) end

-- ---- test 1: head-on collisions ------------------------------------------------------------
local pi = math.pi
local r1, r2 = 0.5e-3, 0.7e-3
local quartz = { density = 2650, young = 30e9, poisson = 0.3 }
local glass = { density = 2500, young = 63e9, poisson = 0.22 }
local function mass(m, r) return m.density * 4 / 3 * pi * r ^ 3 end
local DIR = { 0.6, 0.8 }
local C_HERTZ = 2.9432751843247047 -- 2 Gamma(2/5) Gamma(1/2) / (5/2 Gamma(9/10))

local collision_cases = {}
do
  local ma = { density = quartz.density, young = quartz.young, poisson = quartz.poisson, restitution = e_lin }
  local mb = { density = glass.density, young = glass.young, poisson = glass.poisson, restitution = 1 }
  local m1, m2 = mass(ma, r1), mass(mb, r2)
  local m_eff = m1 * m2 / (m1 + m2)
  local w0, lne = math.sqrt(k / m_eff), math.log(e_lin)
  local b = -lne * w0 / math.sqrt(pi ^ 2 + lne ^ 2)
  local w = math.sqrt(w0 ^ 2 - b ^ 2)
  collision_cases[1] = { name = string.format("linear_e%g", e_lin), mat1 = ma, mat2 = mb, tc = pi / w, e = math.exp(-b * pi / w),
                         contact = { normal = "linear", stiffness = k, damping = "viscous", clip = false } }
  local ha = { density = quartz.density, young = quartz.young, poisson = quartz.poisson }
  local hb = { density = glass.density, young = glass.young, poisson = glass.poisson }
  local es = 1 / ((1 - ha.poisson ^ 2) / ha.young + (1 - hb.poisson ^ 2) / hb.young)
  local K = 4 / 3 * es * math.sqrt(r1 * r2 / (r1 + r2))
  local dmax = (5 * m_eff * v0 ^ 2 / (4 * K)) ^ 0.4
  collision_cases[2] = { name = string.format("hertz_v%g", v0), mat1 = ha, mat2 = hb, tc = C_HERTZ * dmax / v0, e = 1,
                         contact = { normal = "hertz" } }
end

local function build_pair(c, gap)
  local m1, m2 = mass(c.mat1, r1), mass(c.mat2, r2)
  local f1 = m2 / (m1 + m2)
  local s = dem.scene{ dim = 2, box = { { -0.01, -0.01 }, { 0.01, 0.01 } } }
  s:add_disk{ pos = { -DIR[1] * (r1 + gap / 2), -DIR[2] * (r1 + gap / 2) }, radius = r1,
              material = grainlab.material(c.mat1), vel = { DIR[1] * v0 * f1, DIR[2] * v0 * f1 } }
  s:add_disk{ pos = { DIR[1] * (r2 + gap / 2), DIR[2] * (r2 + gap / 2) }, radius = r2,
              material = grainlab.material(c.mat2), vel = { -DIR[1] * v0 * (1 - f1), -DIR[2] * v0 * (1 - f1) } }
  s:contact(c.contact)
  return s
end

-- One collision at touch phase ph; returns t_c, e, steps, seconds in s:run (or nil, message).
local function collide(c, integ, dt, ph)
  local gap = v0 * dt * (2 + ph)
  local s = build_pair(c, gap)
  local steps = math.ceil((gap / v0 + 1.5 * c.tc) / dt) + 10
  local c0 = grainlab.clock()
  local ok, res = pcall(s.run, s, run_opts(integ, dt, { steps = steps }))
  local wall = grainlab.clock() - c0
  if not ok then return nil, tostring(res) end
  local p = s:particles()
  local dx, dy = p.x[2] - p.x[1], p.y[2] - p.y[1]
  local delta = r1 + r2 - math.sqrt(dx * dx + dy * dy)
  local u = (p.vx[2] - p.vx[1]) * DIR[1] + (p.vy[2] - p.vy[1]) * DIR[2]
  if not (delta < 0 and u > 0 and s:measure("contacts").count == 0) then
    return nil, "the contact had not ended"
  end
  return s:info().time + delta / u - gap / v0, u / v0, res.steps, wall
end

local runs = {} -- {test, case, integ, frac, steps, wall, errs = {{name, value}...}, forced, note}
local PHASES = {}
for i = 1, nphases do PHASES[i] = (i - 0.5) / nphases end

for _, c in ipairs(collision_cases) do
  -- the kernel's stability guard for this pair (its own contact time is of the lightest grain)
  local limit = build_pair(c, 1e-4):timestep{ impact_velocity = v0 }.limit
  for _, integ in ipairs(INTEGRATORS) do
    for _, frac in ipairs(fracs) do
      local dt = frac * c.tc
      local r = { test = "collision", case = c.name, integ = integ, frac = frac,
                  forced = largest_step(integ) * dt > limit }
      local tc_err, e_err, steps, wall, reps, fail = 0, 0, nil, 0, 0, nil
      repeat
        for _, ph in ipairs(PHASES) do
          local tc, e, st, w = collide(c, integ, dt, ph)
          if not tc then fail = e break end
          if reps == 0 then
            tc_err, e_err = math.max(tc_err, rel(tc, c.tc)), math.max(e_err, rel(e, c.e))
            steps = math.max(steps or 0, st)
          end
          wall = wall + w
        end
        reps = reps + 1
      until fail or wall >= min_time or reps >= 10000
      if fail then
        r.note = "unstable: " .. fail:gsub("\n.*", ""):sub(1, 60)
      else
        r.steps, r.wall = steps, wall / (reps * nphases)
        r.errs = { { "restitution_rel_err", e_err }, { "contact_time_rel_err", tc_err } }
      end
      runs[#runs + 1] = r
      tick()
    end
  end
end

-- ---- test 3: rigid disk on an incline ------------------------------------------------------
local g, R, thick, rho, nu, young = 9.81, 0.01, 1e-3, 2650, 0.3, 1e9
local incline_cases = {
  { name = "rolling_th30_mu0.5", th = pi / 6, mu = 0.5 },
  { name = "slipping_th60_mu0.3", th = pi / 3, mu = 0.3 },
}
local function rigid(th, mu, t)
  local rolls = math.tan(th) <= 3 * mu
  local a = rolls and g * math.sin(th) * 2 / 3 or g * (math.sin(th) - mu * math.cos(th))
  local wdot = rolls and -a / R or -2 * mu * g * math.cos(th) / R
  return { rolls = rolls, dist = 0.5 * a * t * t, omega = wdot * t }
end

-- Released from rest at the static overlap (the plane moved by delta0 in one 1e-12 s step, as in
-- dem_incline.lua), then T of motion at dt = T/ceil(T/(frac t_c)) (within 1e-4 of frac t_c; every
-- run, the reference included, ends at T exactly). Returns the travel, omega, time, steps, wall
-- and the guard's limit and t_c (or nil, message).
local function incline(c, integ, frac)
  local mat = grainlab.material{ density = rho, young = young, poisson = nu, friction = c.mu }
  local s = dem.scene{ dim = 2, box = { { -0.05, 0 }, { 1.0, 0.05 } },
                       gravity = { g * math.sin(c.th), -g * math.cos(c.th) }, thickness = thick }
  s:contact{ normal = "hertz", tangential = "spring" }
  s:add_disk{ pos = { 0, R }, radius = R, material = mat }
  local wall = s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  local m = s:particles().mass[1]
  local K = 4 / 3 * young / (2 * (1 - nu * nu)) * math.sqrt(R)
  local delta0 = (m * g * math.cos(c.th) / K) ^ (2 / 3)
  s:wall_velocity(wall, { 0, delta0 / 1e-12 })
  s:run{ steps = 1, dt = 1e-12, progress = false }
  s:wall_velocity(wall, { 0, 0 })
  assert(s:measure("contacts").count == 1, "the disk should touch the plane after the placement step")
  local ts = s:timestep()
  local P0 = s:particles()
  local x0, t0 = P0.x[1], s:info().time
  local c0 = grainlab.clock()
  local steps = math.ceil(T_incl / (frac * ts.contact_time) - 1e-9) -- dt = T/steps: all end at T
  local ok, res = pcall(s.run, s, run_opts(integ, T_incl / steps, { steps = steps }))
  local wall_s = grainlab.clock() - c0
  if not ok then return nil, tostring(res) end
  local P = s:particles()
  return { dist = P.x[1] - x0, omega = P.omega[1], t = s:info().time - t0, steps = res.steps,
           wall = wall_s, limit = ts.limit, tc = ts.contact_time }
end

local incline_tc
for _, c in ipairs(incline_cases) do
  local ref = assert(incline(c, "velocity_verlet", 1 / ref_div))
  tick()
  incline_tc = ref.tc
  for _, integ in ipairs(INTEGRATORS) do
    for _, frac in ipairs(fracs) do
      local r = { test = "incline", case = c.name, integ = integ, frac = frac }
      local m, fail = incline(c, integ, frac)
      if not m then
        r.note = "unstable: " .. fail:gsub("\n.*", ""):sub(1, 60)
      else
        local th = rigid(c.th, c.mu, m.t)
        r.forced = largest_step(integ) * frac * m.tc > m.limit
        r.steps, r.wall = m.steps, m.wall
        r.errs = { { "distance_rel_err_vs_rigid", rel(m.dist, th.dist) },
                   { "omega_rel_err_vs_rigid", rel(m.omega, th.omega) } }
        assert(math.abs(ref.t - m.t) < 1e-9 * T_incl, "reference and run end at different times")
        if frac >= 4 / ref_div then
          r.errs[3] = { "distance_rel_err_vs_fine", rel(m.dist, ref.dist) }
          r.errs[4] = { "omega_rel_err_vs_fine", rel(m.omega, ref.omega) }
        end
      end
      runs[#runs + 1] = r
      tick()
    end
  end
end
progress:finish()

-- ---- table and CSV -------------------------------------------------------------------------
local ABBR = { restitution_rel_err = "e err", contact_time_rel_err = "t_c err",
               distance_rel_err_vs_rigid = "x err(rigid)", omega_rel_err_vs_rigid = "w err(rigid)",
               distance_rel_err_vs_fine = "x err(fine)", omega_rel_err_vs_fine = "w err(fine)" }
local last_head
for _, r in ipairs(runs) do
  local head = r.test .. " " .. r.case
  if head ~= last_head then
    local names = r.test == "collision" and { "restitution_rel_err", "contact_time_rel_err" }
                  or { "distance_rel_err_vs_rigid", "omega_rel_err_vs_rigid", "distance_rel_err_vs_fine", "omega_rel_err_vs_fine" }
    local cols = {}
    for i, n in ipairs(names) do cols[i] = string.format("%12s", ABBR[n]) end
    print(string.format("\n%s  (t_c = %.4g s)", head, r.test == "collision" and
      (r.case == collision_cases[1].name and collision_cases[1].tc or collision_cases[2].tc) or incline_tc))
    print(string.format("%-16s %8s %8s %10s %s", "integrator", "dt/t_c", "steps", "wall s", table.concat(cols, " ")))
    last_head = head
  end
  local cols = {}
  for i, e in ipairs(r.errs or {}) do cols[i] = string.format("%12.3e", e[2]) end
  print(string.format("%-16s %8s %8s %10s %s%s", r.integ, string.format("1/%d", math.floor(1 / r.frac + 0.5)),
    r.steps and tostring(r.steps) or "-", r.wall and string.format("%10.3e", r.wall) or "-",
    table.concat(cols, " "), (r.forced and "  forced" or "") .. (r.note and ("  " .. r.note) or "")))
end

local lines = { "test,case,integrator,dt_over_tc,error_name,error,wall_s,steps" }
for _, r in ipairs(runs) do
  for _, e in ipairs(r.errs or {}) do
    lines[#lines + 1] = string.format("%s,%s,%s,%.9g,%s,%.6e,%.6e,%d", r.test, r.case, r.integ, r.frac,
                                      e[1], e[2], r.wall, r.steps)
  end
end
if csv_path:find("/") then os.execute("mkdir -p '" .. csv_path:match("^(.*)/[^/]*$") .. "'") end
assert(grainlab.write_file(csv_path, table.concat(lines, "\n") .. "\n"))
print("\nwrote " .. csv_path .. " (" .. (#lines - 1) .. " rows)")

do -- error against wall time on the damped linear collision, one line per integrator
  local series = {}
  local case = collision_cases[1].name
  for _, integ in ipairs(INTEGRATORS) do
    local pts = {}
    for _, r in ipairs(runs) do
      if r.test == "collision" and r.case == case and r.integ == integ and r.errs and r.wall then
        local worst = 0
        for _, e in ipairs(r.errs) do worst = math.max(worst, e[2]) end
        if worst > 0 then pts[#pts + 1] = { r.wall, worst } end
      end
    end
    table.sort(pts, function(a, b) return a[1] < b[1] end)
    local x, y = {}, {}
    for i, p in ipairs(pts) do x[i], y[i] = p[1], p[2] end
    if #x > 0 then series[#series + 1] = { x = x, y = y, label = integ, style = "both" } end
  end
  render.plot{ file = png, width = 900, height = 560, xlog = true, ylog = true,
               title = "collision (" .. case .. "): error against cost, dt = t_c/10 ... t_c/1000",
               xlabel = "wall time per collision (s)", ylabel = "worst relative error (e, t_c)",
               series = series }
  print("wrote " .. png)
end

-- ---- analysis ------------------------------------------------------------------------------
local metrics, checks = {}, {}
local function series(test, integ, case, name) -- resolved points {frac, err}, coarse to fine
  local pts = {}
  for _, r in ipairs(runs) do
    if r.test == test and r.integ == integ and r.case == case and r.errs
       and largest_step(integ) * r.frac <= 1 / 20 + 1e-12 then
      for _, e in ipairs(r.errs) do
        if e[1] == name and e[2] > 1e-12 then pts[#pts + 1] = { r.frac, e[2] } end
      end
    end
  end
  return pts
end
local function slope(pts)
  if #pts < 2 then return nil end
  local n, sx, sy, sxx, sxy = #pts, 0, 0, 0, 0
  for _, p in ipairs(pts) do
    local x, y = math.log(p[1]), math.log(p[2])
    sx, sy, sxx, sxy = sx + x, sy + y, sxx + x * x, sxy + x * y
  end
  return (n * sxy - sx * sy) / (n * sxx - sx * sx)
end
-- worst error of a test per (integrator, frac), wall summed over its cases; names filter
local function worst_by_setting(test, names)
  local by = {}
  for _, r in ipairs(runs) do
    if r.test == test then
      local key = r.integ .. "@" .. r.frac
      local w = by[key] or { integ = r.integ, frac = r.frac, err = 0, wall = 0, ok = true, n = 0 }
      by[key] = w
      if not r.errs then w.ok = false else
        w.wall = w.wall + r.wall
        for _, e in ipairs(r.errs) do
          if names[e[1]] then w.err = math.max(w.err, e[2]); w.n = w.n + 1 end
        end
      end
    end
  end
  return by
end
local function cheapest(by, tol)
  local best
  for _, w in pairs(by) do
    if w.ok and w.n > 0 and w.err <= tol and (not best or w.wall < best.wall) then best = w end
  end
  if not best then return "none" end
  return { integrator = best.integ, dt_over_tc = best.frac, error = best.err, wall_s = best.wall }
end

print(string.format("\n%-16s %-22s %-22s %8s", "integrator", "case", "error", "order"))
local COLL_NAMES = { restitution_rel_err = true, contact_time_rel_err = true }
local coll_by = worst_by_setting("collision", COLL_NAMES)
local orders = {}
for _, integ in ipairs(INTEGRATORS) do
  orders[integ] = {}
  local max_ratio = 0
  for _, c in ipairs(collision_cases) do
    for _, name in ipairs{ "restitution_rel_err", "contact_time_rel_err" } do
      local pts = series("collision", integ, c.name, name)
      local o = slope(pts)
      orders[integ][c.name .. "_" .. name] = o
      print(string.format("%-16s %-22s %-22s %8s", integ, c.name, name, o and string.format("%.2f", o) or "-"))
      for i = 2, #pts do max_ratio = math.max(max_ratio, pts[i][2] / pts[i - 1][2]) end
    end
  end
  -- order of the worst collision error (over both cases and errors)
  local pts = {}
  for _, frac in ipairs(fracs) do
    local w = coll_by[integ .. "@" .. frac]
    if w and w.ok and largest_step(integ) * frac <= 1 / 20 + 1e-12 and w.err > 1e-12 then pts[#pts + 1] = { frac, w.err } end
  end
  local o = slope(pts)
  metrics["collision_order_" .. integ] = o
  print(string.format("%-16s %-22s %-22s %8s", integ, "worst", "max of the above", o and string.format("%.2f", o) or "-"))
  if o then -- at least two resolved settings
    checks[#checks + 1] = { name = "collision_error_falls_" .. integ, value = max_ratio, limit = 1, op = "<" }
    checks[#checks + 1] = { name = "collision_order_" .. integ, value = o, limit = 0.8, op = ">=" }
  end
end
metrics.collision_orders = orders
do
  local w = coll_by["velocity_verlet@" .. 1 / 1000]
  if w then
    metrics.velocity_verlet_collision_err_at_tc_over_1000 = w.err
    checks[#checks + 1] = { name = "velocity_verlet_collision_err_at_tc_over_1000", value = w.ok and w.err or 1, limit = 1e-3 }
  end
end
metrics.cheapest_collision_1e_3 = cheapest(coll_by, 1e-3)
local rigid_by = worst_by_setting("incline", { distance_rel_err_vs_rigid = true, omega_rel_err_vs_rigid = true })
local fine_by = worst_by_setting("incline", { distance_rel_err_vs_fine = true, omega_rel_err_vs_fine = true })
metrics.cheapest_incline_1e_3_vs_rigid = cheapest(rigid_by, 1e-3)
metrics.cheapest_incline_1e_3_vs_fine = cheapest(fine_by, 1e-3)

local worst_rigid = 0
for _, w in pairs(rigid_by) do if w.ok then worst_rigid = math.max(worst_rigid, w.err) end end
metrics.incline_worst_err_vs_rigid = worst_rigid
checks[#checks + 1] = { name = "incline_err_vs_rigid_within_model_floor", value = worst_rigid, limit = 2e-3 * 0.15 / T_incl }
local incline_orders = {}
for _, integ in ipairs(INTEGRATORS) do
  local pts = {}
  for _, frac in ipairs(fracs) do
    local w = fine_by[integ .. "@" .. frac]
    if w and w.ok and w.n > 0 then pts[#pts + 1] = { frac, w.err } end
  end
  incline_orders[integ] = slope(pts)
  if #pts >= 2 then
    checks[#checks + 1] = { name = "incline_discretisation_err_falls_" .. integ,
                            value = pts[#pts][2] / pts[1][2], limit = 1, op = "<" }
  end
end
metrics.incline_orders_vs_fine = incline_orders

local function describe(c)
  if c == "none" then return "none" end
  return string.format("%s at dt = t_c/%d: error %.2e, %.3e s", c.integrator, math.floor(1 / c.dt_over_tc + 0.5), c.error, c.wall_s)
end
print("\ncheapest to 1e-3 (worst error over the test's cases, wall summed over them):")
print("  collision:          " .. describe(metrics.cheapest_collision_1e_3))
print("  incline vs rigid:   " .. describe(metrics.cheapest_incline_1e_3_vs_rigid))
print("  incline vs fine dt: " .. describe(metrics.cheapest_incline_1e_3_vs_fine))

local unstable = {}
for _, r in ipairs(runs) do
  if not r.errs then unstable[#unstable + 1] = string.format("%s %s %s 1/%d", r.test, r.case, r.integ, math.floor(1 / r.frac + 0.5)) end
end
metrics.unstable_runs = unstable
metrics.incline_contact_time_s = incline_tc
metrics.collision_contact_time_linear_s = collision_cases[1].tc
metrics.collision_contact_time_hertz_s = collision_cases[2].tc
metrics.csv_rows = #lines - 1
metrics.wall_s = grainlab.clock() - t_wall0

grainlab.report{
  scenario = "study_dem",
  params = { csv = csv_path, v0_m_per_s = v0, k_n_per_m = k, restitution = e_lin, incline_time_s = T_incl,
             phases = nphases, min_time_s = min_time, ref_div = ref_div, tt_n = tt_n, tt_q = tt_q, tt_m = tt_m,
             dt_over_tc = fracs },
  metrics = metrics,
  checks = checks,
}
