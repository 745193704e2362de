-- Angle of repose (Herrmann Sec. 3), small and fast: the procedure of scripts/repose.lua (its
-- pile in a box, scripts/lib/heap_box.lua; see the script's header for the reasoning) with 250 disks
-- and mu = 0.1 and 0.8. Disks of radius 0.5..1 mm are
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

local heap_box = dofile("../../scripts/lib/heap_box.lua")
local n, seed = 250, 1

local function repose(mu)
  local what = string.format("mu = %.1f: ", mu)
  local b = heap_box.new{ n = n, mu = mu, seed = seed }
  check.near(b.h_init, 0.5 * b.W, 0.3, what .. "filled to about W/2 (looser with more friction)")
  local r = b:collapse(3)
  check.lt(r.vmax, 5e-3, what .. "the pile is at rest")
  check.ge(r.points, 6, what .. "points on the slope")
  check.lt(r.rms, 1, what .. "fit rms below a mean diameter")
  check.gt(r.theta, 0, what .. "theta_r > 0")
  check.lt(r.theta, 45, what .. "theta_r < 45 deg")
  check.lt(r.basin_top, -2 * b.rf, what .. "the basin heap stays below the box floor")
  return r.theta, r.left
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
