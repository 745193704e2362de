-- Two-particle head-on collisions (the fast subset of scripts/dem_collision.lua, which has the
-- derivations): the linear spring-dashpot against its closed form in 2D and 3D, the elastic Hertz
-- contact time, Brilliantov restitution falling with speed and matching an RK4 integration of
-- m_eff d'' = -max(0, K d^{3/2} + T K d^{1/2} d'), and the automatic dt resolving the contact.
-- Contact start/end: first and last steps with a contact, interpolated to zero overlap.
local check = grainlab.check
grainlab.threads(1) -- two grains: threads would only add synchronisation

local pi = math.pi
local r1, r2 = 0.5e-3, 0.7e-3
local quartz = { density = 2650, young = 30e9, poisson = 0.3 }
local glass = { density = 2500, young = 63e9, poisson = 0.22 }
local function with(m, extra)
  local t = {}
  for key, v in pairs(m) do t[key] = v end
  for key, v in pairs(extra or {}) do t[key] = v end
  return t
end
local function mass(m, r) return m.density * 4 / 3 * pi * r ^ 3 end
local function m_eff_of(a, b) local m1, m2 = mass(a, r1), mass(b, r2); return m1 * m2 / (m1 + m2) end
local function hertz_K(a, b)
  local es = 1 / ((1 - a.poisson ^ 2) / a.young + (1 - b.poisson ^ 2) / b.young)
  return 4 / 3 * es * math.sqrt(r1 * r2 / (r1 + r2))
end
local DIRS = { [2] = { 0.6, 0.8 }, [3] = { 1 / 3, 2 / 3, 2 / 3 } }

-- One collision along DIRS[dim], centre of mass at rest (or grain 1 at rest with o.target),
-- touching 0.3 into the third step. Returns t_c, e, steps in contact, dt.
local function build(o, gap)
  local D, n = o.dim, DIRS[o.dim]
  local m1, m2 = mass(o.mat1, r1), mass(o.mat2, r2)
  local f1 = o.target and 0 or m2 / (m1 + m2)
  local lo, hi, p1, p2, v1, v2 = {}, {}, {}, {}, {}, {}
  for d = 1, D do
    lo[d], hi[d] = -0.01, 0.01
    p1[d], p2[d] = -n[d] * (r1 + gap / 2), n[d] * (r2 + gap / 2)
    v1[d], v2[d] = n[d] * o.v * f1, -n[d] * o.v * (1 - f1)
  end
  local s = dem.scene{ dim = D, box = { lo, hi } }
  local add = D == 2 and s.add_disk or s.add_sphere
  add(s, { pos = p1, radius = r1, material = grainlab.material(o.mat1), vel = v1 })
  add(s, { pos = p2, radius = r2, material = grainlab.material(o.mat2), vel = v2 })
  s:contact(o.contact)
  return s
end

local function collide(o)
  local D, n = o.dim, DIRS[o.dim]
  local dt = o.dt or build(o, 1e-4):timestep().dt_auto
  local s = build(o, o.v * dt * 2.3)
  local X, V = { "x", "y", "z" }, { "vx", "vy", "vz" }
  local function overlap(p)
    local d2 = 0
    for d = 1, D do d2 = d2 + (p[X[d]][2] - p[X[d]][1]) ^ 2 end
    return r1 + r2 - math.sqrt(d2)
  end
  local prev_delta, prev_t = overlap(s:particles()), 0
  local t_start, t_end, in_contact, after, disagree = nil, nil, nil, nil, 0
  local r = s:run{ steps = math.ceil(20 * o.t_est / dt), dt = o.dt or "auto", every = 1, on_step = function(sc)
    local p, t = sc:particles(), sc:info().time
    local delta = overlap(p)
    local listed = sc:measure("contacts").count > 0
    if listed ~= (delta > 0) then disagree = disagree + 1 end
    if listed then
      in_contact = (in_contact or 0) + 1
      t_start = t_start or prev_t + (t - prev_t) * (-prev_delta) / (delta - prev_delta)
    elseif t_start then
      t_end = prev_t + (t - prev_t) * prev_delta / (prev_delta - delta)
      after = p
      return false
    end
    prev_delta, prev_t = delta, t
  end }
  check.is_true(t_end, "the collision ended")
  check.eq(disagree, 0, "steps where the contact list disagrees with the overlap")
  check.eq(r.dt, dt, "run used the expected dt")
  local vn = 0
  for d = 1, D do vn = vn + (after[V[d]][2] - after[V[d]][1]) * n[d] end
  return t_end - t_start, vn / o.v, in_contact, dt
end

-- RK4 of d'' = accel(d, d'), d(0) = 0, d'(0) = v, n steps per t_est; crossing interpolated.
local function rk4(accel, v, t_est, n)
  local h, d, u, t = t_est / n, 0.0, v, 0.0
  local function a(dd, uu) return accel(dd > 0 and dd or 0, uu) end
  for _ = 1, 10 * n do
    local k1d, k1u = u, a(d, u)
    local k2d, k2u = u + 0.5 * h * k1u, a(d + 0.5 * h * k1d, u + 0.5 * h * k1u)
    local k3d, k3u = u + 0.5 * h * k2u, a(d + 0.5 * h * k2d, u + 0.5 * h * k2u)
    local k4d, k4u = u + h * k3u, a(d + h * k3d, u + h * k3u)
    local dn = d + h / 6 * (k1d + 2 * k2d + 2 * k3d + k4d)
    local un = u + h / 6 * (k1u + 2 * k2u + 2 * k3u + k4u)
    if dn <= 0 then
      local frac = d / (d - dn)
      return t + h * frac, -(u + frac * (un - u)) / v
    end
    d, u, t = dn, un, t + h
  end
  error("rk4: the contact did not end")
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
local hz_K, hz_m = hertz_K(quartz, glass), m_eff_of(quartz, glass)
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
local function bri_accel(d, u)
  local sd = math.sqrt(d)
  local f = hz_K * d * sd + T * hz_K * sd * u
  return f > 0 and -f / hz_m or 0
end
local prev = math.huge
for i, v in ipairs{ 0.01, 0.1, 1, 10 } do
  local tc = hertz_tc(v)
  local _, e = collide{ dim = 2 + i % 2, mat1 = quartz, mat2 = glass, v = v, dt = tc / 500, t_est = tc, contact = bri }
  check.lt(e, prev, ("brilliantov: e falls with v0 (v0=%g)"):format(v))
  check.gt(e, 0.5, ("brilliantov: e stays plausible (v0=%g)"):format(v))
  prev = e
end
do
  local rtc, re = rk4(bri_accel, 1, hertz_tc(1), 100000)
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
