-- grainlab DEM validation: a solid disk released from rest on an incline, against the rigid body.
--
-- Rigid solution (shared/VALIDATION.md "Rigid disk on an incline", mpm-granular-contact Eq. 25),
-- re-derived here. Axes: x down the slope, y along the plane's outward normal, so gravity is
-- g (sin th, -cos th); z = x cross y, omega is its z component (rolling in +x gives omega < 0).
-- Normal force N = m g cos th; friction F acts on the disk along -x at the contact point -R y.
--   translation:  m x'' = m g sin th - F
--   rotation:     I w'  = (-R y) cross (-F x) = -R F,      I = m R^2 / 2 (solid disk)
--   contact-point velocity  u = x' + w R   (velocity of the material point at -R y)
-- Rolling (u = 0 for all t): x'' = -R w' = R^2 F / I = 2 F / m, so F = m g sin th / 3,
--   x = x0 + g t^2 sin th / 3, w = -x'/R; possible while F <= mu N, i.e. tan th <= 3 mu.
-- Slipping (F = mu N): x = x0 + g t^2 (sin th - mu cos th) / 2, w' = -2 mu g cos th / R, and
--   u = g t (sin th - 3 mu cos th) grows from 0, which is consistent exactly when tan th > 3 mu.
-- Only the spin tells the two apart, so every case checks omega as well as the travel.
--
-- Set-up: a quartz-density cylinder (R = 1 cm, thickness 1 mm: m = rho pi R^2 t, I = m R^2 / 2)
-- on a wall of the same material (E = 1 GPa, nu = 0.3), Hertz normal law without damping, and
-- either the Cundall-Strack spring (kt = 2/7 of the normal tangent stiffness, Coulomb cap) or
-- the regularised Coulomb law (v_r = 1 mm/s, exponent c = 10; |f_t| = mu f_n min(1, (s/v_r)^(1/c))).
-- Close to rigid: the static Hertz overlap delta0 = (m g cos th / K)^(2/3), K = 4/3 E* sqrt(R),
-- E* = E / (2 (1 - nu^2)), is about 2e-5 R. dt = "auto" (1/50 of the fastest pair contact time
-- at sqrt(2 g H) for this box: ~1.7 us, about 470 steps per period of the disk's normal
-- oscillation on the plane).
--
-- Release from rest at the static overlap. add_disk and add_wall both refuse a disk that
-- overlaps a wall, so the disk is placed touching the plane and the plane is then translated by
-- delta0 into it in ONE step of 1e-12 s (the disk moves ~1e-24 m meanwhile); the plane then stops,
-- the normal force equals m g cos th to ~1e-12, and x0, t0 are taken there. (Dropping the disk at
-- y = R instead makes f_n oscillate, undamped, between 0 and 2.5 m g cos th: the friction cap
-- mu f_n vanishes once per period, the rolling disk micro-slips, and the spin error grows to ~1e-3.)
--
-- Checks, all relative, tolerance 1% (params.tol): travel x(T) - x0 against the rigid distance;
-- omega(T) against the rigid spin; for rolling |x' + w R| / |x'| (omega = -v/R); for slipping the
-- slip velocity x' + w R against g T (sin th - 3 mu cos th); and the final classification
-- (rolling when |x' + w R| < tol |x'|) equal to the prediction. Expected deviations are far
-- below 1%: the spring must stretch by mu N / kt (~1e-7 m) before it carries full friction
-- (slip onset lag), and, loaded suddenly and undamped, it oscillates between 0 and twice the
-- rolling friction m g sin th / 3 (for th = 60 deg, mu = 0.9 that peak exceeds mu N, a brief
-- slip at the start); the regularised law rolls with a creep slip v_r (tan th / 3 mu)^c, whose
-- slope d f_t / d s = f_t / (c s) is too stiff for dt = "auto" at c = 10: the slip chatters
-- (period ~5 steps, up to ~1.5e-5 m/s instead of ~7e-8 m/s) while the mean force stays right.
--
--   grainlab scripts/dem_incline.lua [T=0.3] [young=1e9] [v_r=1e-3] [exponent=10] [tol=0.01]

local T = params.T or 0.3                -- s of motion after the release
local young = params.young or 1e9        -- Pa
local v_r = params.v_r or 1e-3           -- m/s, regularised Coulomb
local exponent = params.exponent or 10   -- regularised Coulomb c
local tol = params.tol or 0.01
for name, v in pairs { T = T, young = young, v_r = v_r, exponent = exponent, tol = tol } do
  assert(type(v) == "number" and v > 0, name .. " must be a positive number")
end
assert(exponent >= 1, "exponent must be >= 1")

-- One particle: worker threads would only add synchronisation to every step.
grainlab.threads(1)

local g, R, thick, rho, nu = 9.81, 0.01, 1e-3, 2650, 0.3

-- Rigid-disk prediction for (th, mu) at time t after release from rest.
local function rigid(th, mu, t)
  local rolls = math.tan(th) <= 3 * mu
  local a = rolls and g * math.sin(th) * 2 / 3 or g * (math.sin(th) - mu * math.cos(th))
  local wdot = rolls and -a / R or -2 * mu * g * math.cos(th) / R
  local u = rolls and 0 or g * t * (math.sin(th) - 3 * mu * math.cos(th))
  return { rolls = rolls, dist = 0.5 * a * t * t, v = a * t, omega = wdot * t, slip = u }
end

-- Runs one case; returns the measured errors and the classification.
local function run_case(th, mu, law)
  local mat = grainlab.material{ density = rho, young = young, poisson = nu, friction = mu }
  local s = dem.scene{ dim = 2, box = { { -0.05, 0 }, { 1.0, 0.05 } },
                       gravity = { g * math.sin(th), -g * math.cos(th) }, thickness = thick }
  if law == "spring" then
    s:contact{ normal = "hertz", tangential = "spring" }
  else
    s:contact{ normal = "hertz", tangential = "coulomb_regularized", v_r = v_r, exponent = exponent }
  end
  s:add_disk{ pos = { 0, R }, radius = R, material = mat }
  local wall = s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  local m = s:particles().mass[1]
  local K = 4 / 3 * young / (2 * (1 - nu * nu)) * math.sqrt(R)
  local delta0 = (m * g * math.cos(th) / K) ^ (2 / 3)
  local tiny = 1e-12
  s:wall_velocity(wall, { 0, delta0 / tiny })
  s:run{ steps = 1, dt = tiny }
  s:wall_velocity(wall, { 0, 0 })
  local C = s:measure("contacts")
  assert(C.count == 1, "the disk should touch the plane after the placement step")
  local fn0_err = math.abs(C.fn[1] / (m * g * math.cos(th)) - 1)
  local P0 = s:particles()
  local x0, y0, t0 = P0.x[1], P0.y[1], s:info().time

  -- Sample the normal position on the way: the contact must stay at its static overlap.
  local dy_max = 0
  local c0 = grainlab.clock()
  local res = s:run{ time = T, every = 1000, on_step = function(sc)
    local P = sc:particles()
    dy_max = math.max(dy_max, math.abs(P.y[1] - y0))
  end }
  local wall_s = grainlab.clock() - c0
  local P = s:particles()
  local t = s:info().time - t0
  local th_ = rigid(th, mu, t)
  local v, w = P.vx[1], P.omega[1]
  local u = v + w * R
  local r = {
    rolls_theory = th_.rolls,
    rolls = math.abs(u) < tol * math.abs(v),
    x_err = math.abs((P.x[1] - x0) - th_.dist) / th_.dist,
    omega_err = math.abs(w - th_.omega) / math.abs(th_.omega),
    fn0_err = fn0_err,
    dy_over_delta0 = dy_max / delta0,
    delta0 = delta0,
    steps = res.steps,
    dt = res.dt,
    wall_s = wall_s,
    t = t,
  }
  if th_.rolls then
    r.spin_err = math.abs(u) / math.abs(v)                      -- omega = -v/R
  else
    r.spin_err = math.abs(u - th_.slip) / math.abs(th_.slip)   -- slip velocity g t (sin - 3 mu cos)
  end
  return r
end

local cases = {
  { name = "th60_mu030", th = math.pi / 3, mu = 0.3 },
  { name = "th60_mu090", th = math.pi / 3, mu = 0.9 },
  { name = "th60_mu050", th = math.pi / 3, mu = 0.5 },
  { name = "th30_mu050", th = math.pi / 6, mu = 0.5 },
}
local laws = { { key = "spring", label = "spring" }, { key = "coulomb_regularized", label = "regc" } }

local metrics, checks = {}, {}
local progress = grainlab.progress{ label = "dem_incline", total = #cases * #laws, unit = "runs" }
local rows, done = {}, 0
for _, c in ipairs(cases) do
  for _, law in ipairs(laws) do
    local r = run_case(c.th, c.mu, law.key)
    local id = c.name .. "_" .. law.label
    local spin_name = r.rolls_theory and "rolling_slip_ratio" or "slip_velocity_rel_err"
    metrics[id .. "_x_rel_err"] = r.x_err
    metrics[id .. "_omega_rel_err"] = r.omega_err
    metrics[id .. "_" .. spin_name] = r.spin_err
    metrics[id .. "_normal_drift_over_delta0"] = r.dy_over_delta0
    metrics[id .. "_regime"] = r.rolls and "rolling" or "slipping"
    metrics[id .. "_wall_s"] = r.wall_s
    checks[#checks + 1] = { name = id .. "_x", value = r.x_err, limit = tol }
    checks[#checks + 1] = { name = id .. "_omega", value = r.omega_err, limit = tol }
    checks[#checks + 1] = { name = id .. "_spin", value = r.spin_err, limit = tol }
    checks[#checks + 1] = { name = id .. "_regime", pass = r.rolls == r.rolls_theory }
    checks[#checks + 1] = { name = id .. "_static_start", value = r.fn0_err, limit = 1e-6 }
    rows[#rows + 1] = string.format("%-28s %-9s %-9s %11.3e %11.3e %11.3e %9.2e %8.2f",
      id, r.rolls_theory and "rolling" or "slipping", r.rolls and "rolling" or "slipping",
      r.x_err, r.omega_err, r.spin_err, r.dy_over_delta0, r.wall_s)
    metrics.dt_s, metrics.steps_per_case, metrics.travel_time_s = r.dt, r.steps, r.t
    done = done + 1
    progress:update(done)
  end
end
progress:finish()
print(string.format("%-28s %-9s %-9s %11s %11s %11s %9s %8s", "case", "theory", "measured",
  "x err", "omega err", "spin err", "dy/d0", "wall s"))
for _, line in ipairs(rows) do print(line) end

grainlab.report{
  scenario = "dem_incline",
  params = { T_s = T, young_pa = young, poisson = nu, density_kg_per_m3 = rho, radius_m = R,
             thickness_m = thick, v_r_m_per_s = v_r, exponent = exponent, tol = tol },
  metrics = metrics,
  checks = checks,
}
