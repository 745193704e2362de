-- Smoke version of scripts/study_dem.lua (which has the derivations): head-on collisions of a quartz
-- and a glass grain in 2D, linear spring-dashpot (e = 0.5, clip = false) against its closed form and
-- elastic Hertz against t_c = 2.9432751843 d_max/v0, at dt/t_c = 1/20 and 1/200 with velocity
-- Verlet and Gear. Measured as in the study, from the end state alone: the touch is at gap/v0 (free
-- flight is exact), the end where the outgoing straight line meets zero overlap, e = u/v0.
-- Checks: every error falls from t_c/20 to t_c/200, velocity Verlet at least like dt (its dashpot
-- sees half-step velocities: first order), Gear at least like dt^2 on the linear law, and the
-- known sizes at t_c/200 (velocity Verlet's e error ~0.7 dt/t_c).
local check = grainlab.check
grainlab.threads(1) -- two grains: threads would only add synchronisation

local pi, v0, k, e_lin = math.pi, 1.0, 1e5, 0.5
local r1, r2 = 0.5e-3, 0.7e-3
local ma = { density = 2650, young = 30e9, poisson = 0.3 }
local mb = { density = 2500, young = 63e9, poisson = 0.22 }
local DIR = { 0.6, 0.8 }
local function mass(m, r) return m.density * 4 / 3 * pi * r ^ 3 end
local m1, m2 = mass(ma, r1), mass(mb, r2)
local m_eff = m1 * m2 / (m1 + m2)

local cases = {}
do
  local w0, lne = math.sqrt(k / m_eff), math.log(e_lin)
  local b = -lne * w0 / math.sqrt(pi ^ 2 + lne ^ 2)
  local w = math.sqrt(w0 ^ 2 - b ^ 2)
  cases[1] = { name = "linear", tc = pi / w, e = math.exp(-b * pi / w), rest1 = e_lin, rest2 = 1,
               contact = { normal = "linear", stiffness = k, damping = "viscous", clip = false } }
  local es = 1 / ((1 - ma.poisson ^ 2) / ma.young + (1 - mb.poisson ^ 2) / mb.young)
  local K = 4 / 3 * es * math.sqrt(r1 * r2 / (r1 + r2))
  cases[2] = { name = "hertz", tc = 2.9432751843247047 * (5 * m_eff * v0 ^ 2 / (4 * K)) ^ 0.4 / v0, e = 1,
               contact = { normal = "hertz" } }
end

local function collide(c, integ, dt, ph)
  local gap = v0 * dt * (2 + ph)
  local f1 = m2 / (m1 + m2)
  local s = dem.scene{ dim = 2, box = { { -0.01, -0.01 }, { 0.01, 0.01 } } }
  local mat1 = grainlab.material{ density = ma.density, young = ma.young, poisson = ma.poisson, restitution = c.rest1 }
  local mat2 = grainlab.material{ density = mb.density, young = mb.young, poisson = mb.poisson, restitution = c.rest2 }
  s:add_disk{ pos = { -DIR[1] * (r1 + gap / 2), -DIR[2] * (r1 + gap / 2) }, radius = r1, material = mat1,
              vel = { DIR[1] * v0 * f1, DIR[2] * v0 * f1 } }
  s:add_disk{ pos = { DIR[1] * (r2 + gap / 2), DIR[2] * (r2 + gap / 2) }, radius = r2, material = mat2,
              vel = { -DIR[1] * v0 * (1 - f1), -DIR[2] * v0 * (1 - f1) } }
  s:contact(c.contact)
  s:run{ steps = math.ceil((gap / v0 + 1.5 * c.tc) / dt) + 10, dt = dt, integrator = integ, force = true,
         progress = false }
  local p = s:particles()
  local dx, dy = p.x[2] - p.x[1], p.y[2] - p.y[1]
  local delta = r1 + r2 - math.sqrt(dx * dx + dy * dy)
  local u = (p.vx[2] - p.vx[1]) * DIR[1] + (p.vy[2] - p.vy[1]) * DIR[2]
  check.is_true(delta < 0 and u > 0 and s:measure("contacts").count == 0, c.name .. " " .. integ .. ": separated")
  return s:info().time + delta / u - gap / v0, u / v0
end

-- worst relative errors over two touch phases
local function errors(c, integ, frac)
  local e_err, tc_err = 0, 0
  for _, ph in ipairs{ 0.25, 0.75 } do
    local tc, e = collide(c, integ, frac * c.tc, ph)
    e_err = math.max(e_err, math.abs(e - c.e) / c.e)
    tc_err = math.max(tc_err, math.abs(tc - c.tc) / c.tc)
  end
  return { e = e_err, tc = tc_err }
end

local t0 = grainlab.clock()
local err = {}
for _, c in ipairs(cases) do
  for _, integ in ipairs{ "velocity_verlet", "gear" } do
    local coarse, fine = errors(c, integ, 1 / 20), errors(c, integ, 1 / 200)
    err[c.name .. " " .. integ] = fine
    for _, name in ipairs{ "e", "tc" } do
      local what = string.format("%s %s %s", c.name, integ, name)
      check.lt(fine[name], coarse[name], what .. ": error falls from t_c/20 to t_c/200")
      -- the order over the decade: >= 0.8 (velocity Verlet, first order) or >= 1.8 (Gear, linear)
      local order = math.log(coarse[name] / fine[name]) / math.log(10)
      check.le(integ == "gear" and c.name == "linear" and 1.8 or 0.8, order, what .. ": observed order")
    end
  end
end
-- velocity Verlet's restitution error at t_c/200: ~0.7 dt/t_c = 3.6e-3 (first order)
check.near(err["linear velocity_verlet"].e, 0.7 / 200, 0.3, "velocity Verlet e error at t_c/200")
check.lt(err["linear gear"].e, 1e-4, "Gear e error at t_c/200")
check.lt(err["hertz velocity_verlet"].tc, 1e-4, "velocity Verlet Hertz t_c error at t_c/200")
-- Wall time is reported, never checked (it depends on the machine's load).
print(string.format("smoke study: %.2f s wall", grainlab.clock() - t0))
