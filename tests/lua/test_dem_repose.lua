-- Angle of repose (Herrmann Sec. 3), small and fast: the procedure of scripts/repose.lua (see its
-- header for the reasoning) with 250 disks and mu = 0.1 and 0.8. Disks of radius 0.5..1 mm are
-- deposited in a box [0, W] on a rough floor of fixed disks, with a catch basin below and beside
-- it; the gate wall at x = W is removed, the grains that fall out land in the basin, and the
-- surface of the pile left in the box is fitted by a line (top of the highest grain in 2 mm
-- bins, away from the walls, above the first layer and below the initial surface).
-- Hertz + Brilliantov damping (e = 0.5 at 1 m/s) + Cundall-Strack spring, E = 1e6 Pa (the angle
-- does not depend on the stiffness; the step is large), dt = the stability limit at 2 m/s.
-- Checks: the pile is at rest when measured, theta_r(0.8) > theta_r(0.1) + 2 deg, both within
-- (0, 45) deg, a fit to within a mean diameter, and a third to two thirds of the grains left
-- over at mu = 0.8 (fewer at 0.1).
local check = grainlab.check
grainlab.threads(1) -- 250 particles: threads only add synchronisation

local n, seed = 250, 1
local rmin, rmax, young, g = 0.5e-3, 1e-3, 1e6, 9.81
local area = math.pi * (rmax ^ 3 - rmin ^ 3) / (3 * (rmax - rmin)) / 0.82
local W = math.sqrt(n * area / 0.5)
local depth, length, top = 0.6 * W, 3 * W, 0.8 * W + 4 * rmax
local bw = 2 * rmax
local nb = math.floor(W / bw)

local function in_box(P, i) return P.x[i] < W and P.y[i] > 0 end

local function box_state(s, nf)
  local P, vmax, count = s:particles(), 0, 0
  for i = nf + 1, P.count do
    if in_box(P, i) then
      vmax, count = math.max(vmax, math.sqrt(P.vx[i] ^ 2 + P.vy[i] ^ 2)), count + 1
    end
  end
  return vmax, count
end

local function surface(s, nf)
  local P, tops, hmax = s:particles(), {}, 0
  for i = nf + 1, P.count do
    if in_box(P, i) then
      local b, h = math.floor(P.x[i] / bw), P.y[i] + P.radius[i]
      if b >= 0 and b < nb then tops[b] = math.max(tops[b] or 0, h) end
      hmax = math.max(hmax, h)
    end
  end
  return tops, hmax
end

local function repose(mu)
  local what = string.format("mu = %.1f: ", mu)
  local mat = grainlab.material{ density = 2650, young = young, poisson = 0.3, friction = mu }
  local s = dem.scene{ dim = 2, box = { { 0, -depth }, { length, top } }, gravity = { 0, -g } }
  s:contact{ normal = "hertz", tangential = "spring" }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  local gate = s:add_wall{ point = { W, 0 }, normal = { -1, 0 } }
  s:add_wall{ point = { 0, -depth }, normal = { 0, 1 } }
  s:add_wall{ point = { length, 0 }, normal = { -1, 0 } }
  local nf = math.floor(W / (2 * rmin))
  for k = 0, nf - 1 do
    s:add_disk{ pos = { rmin * (2 * k + 1), -rmin }, radius = rmin, material = mat, fixed = true }
  end
  grainlab.pack.deposit(s, { n = n, radius = { rmin, rmax }, seed = seed, material = mat,
                             region = { { 0, -2 * rmin }, { W, top - 2 * rmax } }, relax_steps = 0 })
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
             tangential = "spring" }
  local dt = s:timestep{ impact_velocity = 2 }.limit
  local function advance(T) s:run{ time = T, dt = dt, impact_velocity = 2, progress = false } end
  s:drag(20)
  advance(0.1)
  s:drag(0)
  advance(0.1)
  local _, h_init = surface(s, nf)
  check.near(h_init, 0.5 * W, 0.3, what .. "filled to about W/2 (looser with more friction)")

  s:remove_wall(gate)
  local t, vmax, left = 0, math.huge, n
  while t < 3 and not (t >= 0.3 and vmax < 5e-3) do
    advance(0.05)
    t = t + 0.05
    vmax, left = box_state(s, nf)
  end
  check.lt(vmax, 5e-3, what .. "the pile is at rest")
  local tops = surface(s, nf)
  local sx, sy, sxx, sxy, k = 0, 0, 0, 0, 0
  local pts = {}
  for b = 0, nb - 1 do
    local x, h = (b + 0.5) * bw, tops[b]
    if h and x >= 2 * bw and x <= W - 2 * bw and h > 2 * rmax and h < h_init - 2 * rmax then
      k, sx, sy, sxx, sxy = k + 1, sx + x, sy + h, sxx + x * x, sxy + x * h
      pts[#pts + 1] = { x, h }
    end
  end
  check.ge(k, 6, what .. "points on the slope")
  local slope = (k * sxy - sx * sy) / (k * sxx - sx * sx)
  local a = (sy - slope * sx) / k
  local ss = 0
  for _, p in ipairs(pts) do ss = ss + (p[2] - a - slope * p[1]) ^ 2 end
  check.lt(math.sqrt(ss / k), rmin + rmax, what .. "fit rms below a mean diameter")
  local theta = math.deg(math.atan(-slope))
  check.gt(theta, 0, what .. "theta_r > 0")
  check.lt(theta, 45, what .. "theta_r < 45 deg")
  return theta, left
end

local th_lo, left_lo = repose(0.1)
local th_hi, left_hi = repose(0.8)
print(string.format("theta_r: mu 0.1 -> %.2f deg (%d left), mu 0.8 -> %.2f deg (%d left)",
                    th_lo, left_lo, th_hi, left_hi))
check.gt(th_hi, th_lo + 2, "theta_r(0.8) above theta_r(0.1) + 2 deg")
check.gt(left_hi, left_lo, "more grains stay in the box at mu = 0.8")
check.gt(left_hi, n / 3, "mu = 0.8: a third of the grains stay")
check.lt(left_hi, 2 * n / 3, "mu = 0.8: most of the grains above the slope fall out")
check.done()
