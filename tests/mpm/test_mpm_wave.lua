-- Axial vibration of a free-free elastic bar (a classic MPM test): mode 1, v = v0 cos(pi x / L),
-- has period T = 2 L / c with the thin-strip plane-strain bar speed c = sqrt(E / ((1 - nu^2) rho)).
-- Measured at 40 cells along the bar (20 in brackets), 2 x 2 points per cell: MUSL +0.24% (+0.64%),
-- USL +0.26% (+0.67%), USF +0.24% (+0.64%); B-splines +0.17%, +0.39%, +0.17% (+0.73, +1.1, +0.73%).
-- Tolerance 0.5%.
local check = grainlab.check
local G, K, rho = 2.5e6, 10e6, 3000
local mat = mpm.material{ density = rho, shear = G, bulk = K }
local E, nu = mat.young, mat.poisson
check.near(E, 9 * K * G / (3 * K + G), 1e-12, "young from shear and bulk")
local c = math.sqrt(E / ((1 - nu ^ 2) * rho))
-- The same for every update order and both shape functions (USL: the paper's; USF: stress first).
local function period(update, shape)
local Lb, Hb, nc = 1.0, 0.1, 40
local h = Lb / nc
local m = mpm.scene{ cells = { nc + 8, 10 }, size = { (nc + 8) * h, 10 * h }, walls = "none", update = update, shape = shape }
local x0, y0 = 4 * h, 4 * h
m:add_rect{ lo = { x0, y0 }, hi = { x0 + Lb, y0 + Hb }, material = mat }
local p = m:points()
local vx, vy, right = {}, {}, {}
for i = 1, p.count do
  vx[i], vy[i] = 0.01 * math.cos(math.pi * (p.x[i] - x0) / Lb), 0
  if p.x[i] > x0 + 0.9 * Lb then right[#right + 1] = i end
end
m:set_velocities{ vx = vx, vy = vy }
local function v_end()
  local q, s = m:points(), 0
  for _, i in ipairs(right) do s = s + q.vx[i] end
  return s / #right
end
local T = 2 * Lb / c
local prev, t_prev, crossings = v_end(), 0, {}
m:run{ time = 2.2 * T, every = 1, on_step = function(s)
  local v, t = v_end(), s:info().time
  if (prev < 0) ~= (v < 0) then crossings[#crossings + 1] = t_prev + (t - t_prev) * prev / (prev - v) end
  prev, t_prev = v, t
end }
local tag = " (" .. update .. ", " .. shape .. ")"
check.ge(#crossings, 4, "zero crossings of the end velocity" .. tag)
local T_measured = (crossings[#crossings] - crossings[1]) / ((#crossings - 1) / 2)
check.near(T_measured, T, 0.005, "bar period 2 L / c" .. tag)
check.near_abs(m:measure("momentum").linear[1], 0, 1e-12, "no net momentum" .. tag)
end
for _, update in ipairs({ "musl", "usl", "usf" }) do
  for _, shape in ipairs({ "linear", "bspline" }) do period(update, shape) end
end
check.done()
