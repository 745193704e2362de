-- Two grains in a head-on collision, shared by scripts/dem_collision.lua (which has the closed
-- forms and their derivations) and its test: the grains and their materials, the reference (RK4
-- of the contact ODE m_eff d'' = -max(0, f(d, d'))), and the kernel's collision measured step by
-- step. Not a scenario; load it with
--   local collision = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/collision.lua")
local M = {}

local pi = math.pi
local r1, r2 = 0.5e-3, 0.7e-3
M.r1, M.r2 = r1, r2
M.quartz = { density = 2650, young = 30e9, poisson = 0.3 }
M.glass = { density = 2500, young = 63e9, poisson = 0.22 }
local function mass(m, r) return m.density * 4 / 3 * pi * r ^ 3 end
local function e_star(a, b) return 1 / ((1 - a.poisson ^ 2) / a.young + (1 - b.poisson ^ 2) / b.young) end
M.mass, M.e_star = mass, e_star
function M.hertz_K(a, b) return 4 / 3 * e_star(a, b) * math.sqrt(r1 * r2 / (r1 + r2)) end
function M.m_eff_of(a, b) local m1, m2 = mass(a, r1), mass(b, r2); return m1 * m2 / (m1 + m2) end
local DIRS = { [2] = { 0.6, 0.8 }, [3] = { 1 / 3, 2 / 3, 2 / 3 } }
M.DIRS = DIRS

-- ---- reference: RK4 of m_eff d'' = -max(0, f(d, d')) ----------------------------------------
-- accel(d, u) is -f/m_eff (d >= 0). Starts at d = 0, d' = v; h = t_est/n. Returns t_c, e.
-- The crossing of d = 0 inside the last step is interpolated linearly in d and d' (exact in free
-- flight, which is how clipped contacts end; O(h^2) for the unclipped linear law).
function M.rk4(accel, v, t_est, n)
  local h = t_est / n
  local d, u, t = 0.0, v, 0.0
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

-- The linear law f = k d + gamma d' (w0sq = k/m_eff, b = gamma/(2 m_eff)), clipped at f >= 0
-- or not; the Hertz law with Brilliantov damping time Tb (0: elastic), always clipped.
function M.linear_accel(w0sq, b, clip)
  return function(d, u)
    local f = w0sq * d + 2 * b * u
    if clip and f < 0 then f = 0 end
    return -f
  end
end
function M.hertz_accel(K, m_eff, Tb)
  return function(d, u)
    local sd = math.sqrt(d)
    local f = K * d * sd + Tb * K * sd * u
    if f < 0 then f = 0 end
    return -f / m_eff
  end
end

-- ---- the kernel's collision ---------------------------------------------------------------
-- o: dim, contact (table for s:contact), mat1, mat2 (tables for grainlab.material), v (approach
-- speed), dt, t_est (expected contact time); o.target: grain 1 at rest, grain 2 moving (else the
-- centre of mass at rest). The grains start gap apart along DIRS[dim]. Returns the scene and
-- what s:contact returned.
local function build(o, gap)
  local D, n = o.dim, DIRS[o.dim]
  local m1, m2 = mass(o.mat1, r1), mass(o.mat2, r2)
  local lo, hi = {}, {}
  for d = 1, D do lo[d], hi[d] = -0.01, 0.01 end
  local s = dem.scene{ dim = D, box = { lo, hi } }
  local p1, p2, v1, v2 = {}, {}, {}, {}
  for d = 1, D do
    p1[d] = -n[d] * (r1 + gap / 2)
    p2[d] = n[d] * (r2 + gap / 2)
    v1[d] = o.target and 0 or n[d] * o.v * m2 / (m1 + m2)
    v2[d] = o.target and -n[d] * o.v or -n[d] * o.v * m1 / (m1 + m2)
  end
  local add = D == 2 and s.add_disk or s.add_sphere
  add(s, { pos = p1, radius = r1, material = grainlab.material(o.mat1), vel = v1 })
  add(s, { pos = p2, radius = r2, material = grainlab.material(o.mat2), vel = v2 })
  return s, s:contact(o.contact)
end
M.build = build

-- One collision, the grains touching at fraction o.phase into the third step. The start and end
-- of the contact are the first and last steps with a contact, each refined by linear
-- interpolation of the overlap to zero across the step boundary. Returns { tc = contact time,
-- e = restitution, steps = steps with a contact, transverse = transverse velocity left / v,
-- damping_time = what s:contact returned, dt }. o.auto: run with the default dt = "auto" (o.dt
-- ignored). An error if the contact list disagrees with the overlap or the collision never ends.
function M.collide(o)
  local D, n = o.dim, DIRS[o.dim]
  local dt = o.auto and build(o, 1e-4):timestep().dt_auto or o.dt
  local gap = o.v * dt * (2 + o.phase) -- touch inside the third step, at fraction phase of it
  local s, T_out = build(o, gap)
  local X = { "x", "y", "z" }
  local function overlap(p)
    local d2 = 0
    for d = 1, D do d2 = d2 + (p[X[d]][2] - p[X[d]][1]) ^ 2 end
    return r1 + r2 - math.sqrt(d2)
  end
  local prev_delta, prev_t = overlap(s:particles()), 0
  local t_start, t_end, in_contact, after = nil, nil, 0, nil
  local run = s:run{ steps = math.ceil(20 * o.t_est / dt) + 10, dt = o.auto and "auto" or dt, every = 1, on_step = function(sc)
    local p, t = sc:particles(), sc:info().time
    local delta = overlap(p)
    local nc = sc:measure("contacts").count
    assert((nc > 0) == (delta > 0), "contact list disagrees with the overlap")
    if nc > 0 then
      in_contact = in_contact + 1
      if not t_start then t_start = prev_t + (t - prev_t) * (-prev_delta) / (delta - prev_delta) end
    elseif t_start and not t_end then
      t_end = prev_t + (t - prev_t) * prev_delta / (prev_delta - delta)
      after = p
      return false
    end
    prev_delta, prev_t = delta, t
  end }
  assert(t_end, "the collision did not end")
  assert(run.dt == dt, "run used another dt")
  local vn, vt = 0, 0
  local V = { "vx", "vy", "vz" }
  for d = 1, D do vn = vn + (after[V[d]][2] - after[V[d]][1]) * n[d] end
  for d = 1, D do
    local rel = after[V[d]][2] - after[V[d]][1]
    vt = math.max(vt, math.abs(rel - vn * n[d]))
  end
  return { tc = t_end - t_start, e = vn / o.v, steps = in_contact, transverse = vt / o.v,
           damping_time = T_out, dt = dt }
end

return M
