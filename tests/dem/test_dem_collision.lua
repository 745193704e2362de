-- Two-particle head-on collisions (the fast subset of scripts/dem_collision.lua, which has the
-- derivations): the linear spring-dashpot against its closed form in 2D and 3D, the elastic Hertz
-- contact time, Brilliantov restitution falling with speed and matching an RK4 integration of
-- m_eff d'' = -max(0, K d^{3/2} + T K d^{1/2} d'), and the automatic dt resolving the contact.
-- The grains, the measured collision and the RK4 reference are the script's own
-- (scripts/lib/collision.lua).
local check = grainlab.check
grainlab.threads(1) -- two grains: threads would only add synchronisation

local collision = dofile("../../scripts/lib/collision.lua")
local pi = math.pi
local quartz, glass, m_eff_of = collision.quartz, collision.glass, collision.m_eff_of
local function with(m, extra)
  local t = {}
  for _, src in ipairs{ m, extra } do for key, v in pairs(src) do t[key] = v end end
  return t
end

-- One collision (scripts/lib/collision.lua: centre of mass at rest, or grain 1 at rest with
-- o.target), touching 0.3 into the third step, at o.dt or (without) the automatic dt. Returns
-- t_c, e, steps in contact, dt.
local function collide(o)
  o.phase, o.auto = 0.3, not o.dt
  local r = collision.collide(o)
  return r.tc, r.e, r.steps, r.dt
end

-- Linear law, clip = false: t_c = pi/w, e = exp(-b t_c), w = sqrt(w0^2 - b^2), w0 = sqrt(k/m_eff),
-- b = -ln(e) w0/sqrt(pi^2 + ln(e)^2) from the pair's (smaller) material restitution. The damping
-- error is first order in dt (~0.7/steps at e = 0.5, ~6.5/steps at e = 0.1).
local k = 1e5
for _, c in ipairs{ { 0.9, 2000 }, { 0.5, 2000 }, { 0.1, 10000 } } do
  local e_mat, steps = c[1], c[2]
  local ma, mb = with(quartz, { restitution = e_mat }), with(glass, { restitution = 1 })
  local w0 = math.sqrt(k / m_eff_of(ma, mb))
  local lne = math.log(e_mat)
  local b = -lne * w0 / math.sqrt(pi ^ 2 + lne ^ 2)
  local tc = pi / math.sqrt(w0 ^ 2 - b ^ 2)
  for D = 2, 3 do
    local t, e = collide{ dim = D, mat1 = ma, mat2 = mb, v = 1, dt = tc / steps, t_est = tc,
                          contact = { normal = "linear", stiffness = k, damping = "viscous", clip = false } }
    check.near(t, tc, 1e-3, ("linear %dD e=%g: contact time"):format(D, e_mat))
    check.near(e, e_mat, 1e-3, ("linear %dD e=%g: restitution"):format(D, e_mat))
  end
end

-- Hertz, elastic: t_c = 2.94328 d_max/v0, d_max = (5 m_eff v0^2/(4K))^{2/5}, e = 1.
local hz_K, hz_m = collision.hertz_K(quartz, glass), m_eff_of(quartz, glass)
local function hertz_tc(v) return 2.94328 * (5 * hz_m * v ^ 2 / (4 * hz_K)) ^ 0.4 / v end
for D = 2, 3 do
  for _, v in ipairs{ 0.1, 10 } do
    local tc = hertz_tc(v)
    local t, e = collide{ dim = D, mat1 = quartz, mat2 = glass, v = v, dt = tc / 1000, t_est = tc,
                          contact = { normal = "hertz" } }
    check.near(t, tc, 1e-3, ("hertz %dD v0=%g: contact time"):format(D, v))
    check.near(e, 1, 1e-5, ("hertz %dD v0=%g: restitution"):format(D, v))
  end
end

-- Hertz + Brilliantov (T = 1e-7 s): e falls with v0, and matches RK4 (1e5 steps) at 1 m/s.
local T = 1e-7
local bri = { normal = "hertz", damping = "brilliantov", damping_time = T }
local prev = math.huge
for i, v in ipairs{ 0.01, 0.1, 1, 10 } do
  local tc = hertz_tc(v)
  local _, e = collide{ dim = 2 + i % 2, mat1 = quartz, mat2 = glass, v = v, dt = tc / 500, t_est = tc, contact = bri }
  check.lt(e, prev, ("brilliantov: e falls with v0 (v0=%g)"):format(v))
  check.gt(e, 0.5, ("brilliantov: e stays plausible (v0=%g)"):format(v))
  prev = e
end
do
  local rtc, re = collision.rk4(collision.hertz_accel(hz_K, hz_m, T), 1, hertz_tc(1), 100000)
  local t, e = collide{ dim = 3, mat1 = quartz, mat2 = glass, v = 1, dt = rtc / 2000, t_est = rtc, contact = bri }
  check.near(t, rtc, 1e-3, "brilliantov 3D v0=1: contact time vs RK4")
  check.near(e, re, 1e-3, "brilliantov 3D v0=1: restitution vs RK4")
  check.lt(re, 0.95, "brilliantov: RK4 restitution is clearly below 1")
end

-- The automatic dt resolves the contact with >= 20 steps, whichever grain is moving, for each law.
local mr = with(quartz, { restitution = 0.5 })
for _, c in ipairs{
  { { normal = "linear", stiffness = k, damping = "viscous" }, 1, pi * math.sqrt(m_eff_of(mr, glass) / k) },
  { { normal = "hertz" }, 10, hertz_tc(10) }, { { normal = "hertz" }, 0.01, hertz_tc(0.01) },
  { bri, 10, hertz_tc(10) },
} do
  for _, target in ipairs{ false, true } do
    local D = target and 3 or 2
    local t, _, n, dt = collide{ dim = D, mat1 = mr, mat2 = glass, v = c[2], t_est = c[3], contact = c[1], target = target }
    local what = ("auto dt, %s%s, v0=%g"):format(c[1].normal, c[1].damping and ("+" .. c[1].damping) or "", c[2])
    check.ge(n, 20, what .. ": steps in contact")
    check.near(t, n * dt, 1.5 / n, what .. ": contact time ~ steps x dt")
  end
end

check.done()
