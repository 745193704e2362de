-- grainlab demo: the accuracy-for-speed trade on the smallest granular event there is.
--
-- Two quartz grains (radius 0.5 mm) meet head-on at v0 under the linear spring-dashpot law
-- (Herrmann & Mueller Eq. 1a with beta = 1, and 1b):  m_eff d2(delta)/dt2 = -k delta - gamma d(delta)/dt.
-- The contact is integrated with velocity Verlet at several steps per contact time, and each run
-- is compared with the closed form (shared/VALIDATION.md):
--   w0 = sqrt(k/m_eff),  b = gamma/(2 m_eff),  t_c = pi/sqrt(w0^2 - b^2),  e = exp(-b t_c).
-- The force is not clipped at zero, so the closed form holds exactly (the same convention the
-- analytic result assumes). The damping coefficient gamma is chosen to give the requested e.
--
--   grainlab scripts/demo.lua [e=0.8] [v0=1.0] [k=1e5]
-- The DEM module (issue 3) will run this collision in C; this script already shows the shape of a
-- grainlab study: knobs, a measured error against cost, checks with stated tolerances, one report.

local e_target = params.e or 0.8
local v0 = params.v0 or 1.0          -- approach speed, m/s
local k = params.k or 1e5            -- normal stiffness, N/m
local radius, density = 0.5e-3, 2650 -- quartz grain
assert(type(e_target) == "number" and e_target > 0 and e_target <= 1, "e must be in (0, 1]")
assert(type(v0) == "number" and v0 > 0, "v0 must be a positive number")
assert(type(k) == "number" and k > 0, "k must be a positive number")

local mass = density * 4 / 3 * math.pi * radius ^ 3
local m_eff = mass / 2
local w0 = math.sqrt(k / m_eff)
-- From e = exp(-b t_c) and t_c = pi / sqrt(w0^2 - b^2):  b = -ln(e) w0 / sqrt(pi^2 + ln(e)^2).
local lne = math.log(e_target)
local b = -lne * w0 / math.sqrt(math.pi ^ 2 + lne ^ 2)
local gamma = 2 * m_eff * b
local tc_theory = math.pi / math.sqrt(w0 ^ 2 - b ^ 2)
local e_theory = math.exp(-b * tc_theory)

-- One collision with n steps per contact time: returns restitution, contact time, steps taken.
local function collide(n)
  local dt = tc_theory / n
  local x1, x2 = 0.0, 2 * radius           -- touching at t = 0
  local v1, v2 = v0 / 2, -v0 / 2
  local function force(x1_, x2_, v1_, v2_)  -- force on grain 1 (grain 2 gets the opposite)
    local delta = 2 * radius - (x2_ - x1_)
    if delta <= 0 then return 0, delta end
    return -(k * delta + gamma * (v1_ - v2_)), delta
  end
  local f, delta = force(x1, x2, v1, v2)
  local t, steps, t_end = 0.0, 0, nil
  while not t_end do
    -- velocity Verlet; the dashpot sees the half-step velocities
    v1 = v1 + 0.5 * dt * f / mass
    v2 = v2 - 0.5 * dt * f / mass
    x1, x2 = x1 + dt * v1, x2 + dt * v2
    local delta_old = delta
    f, delta = force(x1, x2, v1, v2)
    v1 = v1 + 0.5 * dt * f / mass
    v2 = v2 - 0.5 * dt * f / mass
    t, steps = t + dt, steps + 1
    if delta <= 0 then -- separated during this step: interpolate the crossing of delta = 0
      t_end = t - dt * delta / (delta - delta_old)
    end
    if steps > 100 * n then error("collision did not end after 100 contact times") end
  end
  return (v2 - v1) / v0, t_end, steps
end

local sweep = { 10, 20, 40, 80, 160, 320, 640 }
local rows, t0 = {}, grainlab.clock()
local progress = grainlab.progress{ label = "demo", total = #sweep, unit = "runs" }
print(string.format("%16s %14s %14s %12s", "steps/contact", "e error", "t_c error", "wall (s)"))
local total_steps = 0
for i, n in ipairs(sweep) do
  local reps = math.max(1, 20000 // n) -- repeat short runs so the timing means something
  local c0 = grainlab.clock()
  local e, tc, steps
  for _ = 1, reps do e, tc, steps = collide(n) end
  local wall = (grainlab.clock() - c0) / reps
  total_steps = total_steps + reps * steps
  rows[i] = { n = n, e_err = math.abs(e - e_theory) / e_theory, tc_err = math.abs(tc - tc_theory) / tc_theory, wall = wall }
  print(string.format("%16d %14.3e %14.3e %12.3e", n, rows[i].e_err, rows[i].tc_err, wall))
  progress:update(i)
end
progress:finish()
local wall = grainlab.clock() - t0

-- Observed order of convergence of e between the two finest runs.
local last, prev = rows[#rows], rows[#rows - 1]
local order = math.log(prev.e_err / last.e_err) / math.log(last.n / prev.n)
local finest = rows[#rows]
local at80 = rows[4]

grainlab.report{
  scenario = "demo_two_grain_collision",
  params = { e = e_target, v0_m_per_s = v0, k_n_per_m = k, radius_m = radius, density_kg_per_m3 = density },
  metrics = {
    contact_time_theory_s = tc_theory,
    restitution_theory = e_theory,
    restitution_rel_err_at_80_steps = at80.e_err,
    restitution_rel_err_at_640_steps = finest.e_err,
    contact_time_rel_err_at_640_steps = finest.tc_err,
    restitution_convergence_order = order,
    particle_steps_per_s = 2 * total_steps / wall,
    wall_s = wall,
  },
  checks = {
    -- Tolerances: velocity Verlet with a half-step dashpot is first order in the damping term,
    -- so the error in e halves with each doubling; at 640 steps per contact it is below 1e-3.
    { name = "restitution_rel_err_640", value = finest.e_err, limit = 1e-3 },
    { name = "contact_time_rel_err_640", value = finest.tc_err, limit = 1e-3 },
    { name = "restitution_converges", value = order, limit = 0.8, op = ">=" },
  },
}
