-- A solid disk (I = m R^2 / 2) released from rest at its static Hertz overlap on an incline,
-- against the rigid body (shared/VALIDATION.md, mpm-granular-contact Eq. 25): it rolls when
-- tan th <= 3 mu (x - x0 = g t^2 sin th / 3, omega = -v/R) and slips otherwise
-- (x - x0 = g t^2 (sin th - mu cos th) / 2, omega' = -2 mu g cos th / R, slip velocity
-- v + omega R = g t (sin th - 3 mu cos th)). One rolling (pi/6, 0.5) and one slipping (pi/3, 0.3)
-- case with the Cundall-Strack spring and with regularised Coulomb (defaults v_r = 1e-3 m/s,
-- exponent 10); dt = "auto"; 1% on travel and spin.
-- The full set and the derivation are in scripts/dem_incline.lua.
local check = grainlab.check
grainlab.threads(1) -- one particle: threads only add synchronisation

local g, R, thick, young, nu, tol, T = 9.81, 0.01, 1e-3, 1e9, 0.3, 0.01, 0.2

local function incline(th, mu, law)
  local what = string.format("th=%.4f mu=%.2f %s: ", th, mu, law)
  local mat = grainlab.material{ density = 2650, young = young, poisson = nu, friction = mu }
  local s = dem.scene{ dim = 2, box = { { -0.05, 0 }, { 1.0, 0.05 } },
                       gravity = { g * math.sin(th), -g * math.cos(th) }, thickness = thick }
  s:contact{ normal = "hertz", tangential = law }
  s:add_disk{ pos = { 0, R }, radius = R, material = mat }
  local wall = s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  -- Static overlap under N = m g cos th: delta0 = (N / K)^(2/3), K = 4/3 E* sqrt(R). Overlapping
  -- placements are refused, so the plane is moved by delta0 into the touching disk in one 1e-12 s step.
  local m = s:particles().mass[1]
  check.near(m, 2650 * math.pi * R * R * thick, 1e-12, what .. "cylinder mass")
  local K = 4 / 3 * young / (2 * (1 - nu * nu)) * math.sqrt(R)
  local delta0 = (m * g * math.cos(th) / K) ^ (2 / 3)
  s:wall_velocity(wall, { 0, delta0 / 1e-12 })
  s:run{ steps = 1, dt = 1e-12 }
  s:wall_velocity(wall, { 0, 0 })
  local C = s:measure("contacts")
  check.eq(C.count, 1, what .. "in contact at release")
  check.near(C.fn[1], m * g * math.cos(th), 1e-6, what .. "normal force at release")
  local P = s:particles()
  local x0, y0, t0 = P.x[1], P.y[1], s:info().time

  s:run{ time = T }
  P = s:particles()
  local t = s:info().time - t0
  local v, w = P.vx[1], P.omega[1]
  check.near_abs(P.y[1] - y0, 0, 1e-3 * delta0, what .. "stays at the static overlap")
  if math.tan(th) <= 3 * mu then
    local a = 2 / 3 * g * math.sin(th)
    check.near(P.x[1] - x0, 0.5 * a * t * t, tol, what .. "rolling travel")
    check.near(w, -a * t / R, tol, what .. "rolling omega")
    check.near(w, -v / R, tol, what .. "omega = -v/R")
  else
    local a = g * (math.sin(th) - mu * math.cos(th))
    check.near(P.x[1] - x0, 0.5 * a * t * t, tol, what .. "slipping travel")
    check.near(w, -2 * mu * g * math.cos(th) * t / R, tol, what .. "slipping omega")
    check.near(v + w * R, g * t * (math.sin(th) - 3 * mu * math.cos(th)), tol, what .. "slip velocity")
    check.gt(math.abs(v + w * R), tol * math.abs(v), what .. "classified as slipping")
  end
end

for _, law in ipairs { "spring", "coulomb_regularized" } do
  incline(math.pi / 6, 0.5, law) -- tan th = 0.577 <= 1.5: rolls
  incline(math.pi / 3, 0.3, law) -- tan th = 1.732 > 0.9: slips
end
check.done()
