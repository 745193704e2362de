-- Rolling resistance on walls that turn (docs/dem.md "Rolling resistance", "Walls"):
--  1. the relative rolling rate at a wall is w_i - w_wall: a grain carried round by a spinning
--     drum at the drum's own spin (no gravity: the drum's push is its centripetal force) has
--     none, so rolling resistance changes nothing: its spin stays Omega and its path is the one
--     without rolling resistance, to the bit, for both laws, 2D and 3D. Against w_i alone, the
--     torque mu_r r F_n would brake the spin by about mu_r Omega^2 rho t / (k r) (k = 2/5).
--  2. the wall's reported torque includes the rolling couple and the force's moment about its
--     centre taken where the grain's torque puts it (x_i - r_i n), so the angular momentum of the
--     grains about the centre, L = sum m (x - c) x v + I w, changes by exactly the impulse of
--     gravity's moment minus the wall's torque. Velocity Verlet updates x x v with the trapezoid
--     of the moments exactly (the dt^2 terms cancel), so the balance holds to round-off (1e-9
--     of the impulse) for grains in a spinning drum with friction and EPSD rolling resistance,
--     2D and 3D. (One grain per drum: a pair's friction moments, -r_i n x f_t and -r_j n x f_t,
--     miss the overlap's share delta n x f_t, which no wall torque can balance.)
local check = grainlab.check

-- 1. -------------------------------------------------------------------------------------------
-- Without a tangential law (the rolling law switches rotations on), the spin changes by the
-- rolling torque alone: it must stay Omega to the bit. The grain starts touching, carried round
-- at Omega; pressing outward, it loads the contact (F_n ~ m Omega^2 rho), so the torque against
-- w_i would not vanish.
local function corotating(dim, law, mu_r)
  local R, r, Omega = 0.02, 0.002, 5.0
  local mat = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3, friction = 0.5,
                                 rolling_friction = mu_r }
  local s, w
  if dim == 2 then
    s = dem.scene{ dim = 2, box = { { -0.025, -0.025 }, { 0.025, 0.025 } } }
  else
    s = dem.scene{ dim = 3, box = { { -0.025, -0.025, -0.01 }, { 0.025, 0.025, 0.01 } } }
  end
  s:contact{ normal = "linear", stiffness = 1e4, rolling_resistance = law }
  local rho = R - r
  if dim == 2 then
    w = s:add_cylinder{ center = { 0, 0 }, radius = R, material = mat, omega = Omega }
    s:add_disk{ pos = { 0, -rho }, radius = r, material = mat, vel = { Omega * rho, 0 }, omega = Omega }
  else
    w = s:add_cylinder{ center = { 0, 0, 0 }, radius = R, axis = { 0, 0, 1 }, material = mat,
                        omega = { 0, 0, Omega } }
    s:add_sphere{ pos = { 0, -rho, 0 }, radius = r, material = mat, vel = { Omega * rho, 0, 0 },
                  omega = { 0, 0, Omega } }
  end
  local fmin = math.huge
  s:run{ time = 0.05, dt = 2e-5, every = 10, on_step = function(sc) fmin = math.min(fmin, sc:wall_force(w)) end }
  return s:particles(), Omega, fmin
end

for _, dim in ipairs{ 2, 3 } do
  for _, law in ipairs{ "epsd", "constant" } do
    local what = string.format("%dD %s, a grain carried round by a drum", dim, law)
    local p, Omega, fmin = corotating(dim, law, 0.3)
    local q = corotating(dim, law, 0)
    check.gt(fmin, 0, what .. ": pressed on the wall all along")
    check.eq(dim == 2 and p.omega[1] or p.wz[1], Omega, what .. ": its spin stays the drum's")
    if dim == 3 then check.eq(p.wx[1], 0, what .. ": no tilt") check.eq(p.wy[1], 0, what .. ": no tilt") end
    check.eq(string.format("%a %a", p.x[1], p.y[1]), string.format("%a %a", q.x[1], q.y[1]),
      what .. ": its path is the one without rolling resistance")
  end
end

-- 2. -------------------------------------------------------------------------------------------
local function balance(dim)
  local g, R, r, Omega = 9.81, 0.02, 0.002, 8.0
  local mat = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3, friction = 0.6,
                                 rolling_friction = 0.2 }
  local s, w
  if dim == 2 then
    s = dem.scene{ dim = 2, box = { { -0.025, -0.025 }, { 0.025, 0.025 } }, gravity = { 0, -g } }
  else
    s = dem.scene{ dim = 3, box = { { -0.025, -0.025, -0.01 }, { 0.025, 0.025, 0.01 } },
                   gravity = { 0, -g, 0 } }
  end
  s:contact{ normal = "linear", stiffness = 1e4, damping = "viscous", tangential = "spring",
             rolling_resistance = "epsd", rolling_damping = 0.3 }
  if dim == 2 then
    w = s:add_cylinder{ center = { 0, 0 }, radius = R, material = mat, omega = Omega }
    local a = 0.15 -- off the bottom: it rolls and slides back and forth
    s:add_disk{ pos = { (R - r) * math.sin(a), -(R - r) * math.cos(a) }, radius = r, material = mat }
  else
    -- the axis tilted out of z: the spin, the gravity and the moments have every component
    w = s:add_cylinder{ center = { 0, 0, 0 }, radius = R, axis = { 0.3, 0, 1 }, material = mat,
                        omega = { 0.3 * Omega, 0, Omega } }
    local a, l = 0.15, math.sqrt(1.09)
    local e1, ax = { 1 / l, 0, -0.3 / l }, { 0.3 / l, 0, 1 / l } -- e1, -y: normal to the axis
    local pos = {}
    for c = 1, 3 do
      pos[c] = (R - r) * (math.sin(a) * e1[c] - (c == 2 and math.cos(a) or 0)) + 0.002 * ax[c]
    end
    s:add_sphere{ pos = pos, radius = r, material = mat }
  end
  local dt = 2e-5
  s:run{ steps = 1, dt = dt }
  local function state()
    local p, f, t = s:particles(), s:wall_load(w)
    local m, I = p.mass[1], 0.4 * p.mass[1] * p.radius[1] ^ 2
    local x = { p.x[1], p.y[1], dim == 3 and p.z[1] or 0 }
    local v = { p.vx[1], p.vy[1], dim == 3 and p.vz[1] or 0 }
    local om = dim == 2 and { 0, 0, p.omega[1] } or { p.wx[1], p.wy[1], p.wz[1] }
    local tw = dim == 2 and { 0, 0, t } or t
    local gv = dim == 2 and { 0, -g, 0 } or { 0, -g, 0 }
    local L, M = {}, {}
    local function cross(a, b, c) return a[(c % 3) + 1] * b[((c + 1) % 3) + 1] - a[((c + 1) % 3) + 1] * b[(c % 3) + 1] end
    for c = 1, 3 do
      L[c] = m * cross(x, v, c) + I * om[c]
      M[c] = m * cross(x, gv, c) - tw[c] -- gravity's moment and the contact's (minus the wall's)
    end
    return L, M, math.abs(tw[3])
  end
  local L0, Mprev = state()
  local imp, scale = { 0, 0, 0 }, 0
  s:run{ steps = 1500, dt = dt, every = 1, on_step = function()
    local _, M, tw = state()
    for c = 1, 3 do imp[c] = imp[c] + 0.5 * dt * (Mprev[c] + M[c]) end
    scale = scale + dt * tw
    Mprev = M
  end }
  local L1 = state()
  check.gt(scale, 0, dim .. "D drum: the wall turned the grain")
  local rolled = s:particles()
  for c = (dim == 2 and 3 or 1), 3 do
    check.near_abs(L1[c] - L0[c], imp[c], 1e-9 * scale,
      string.format("%dD drum: angular momentum %s balances gravity and the wall's torque", dim, ("xyz"):sub(c, c)))
  end
  return rolled
end
balance(2)
balance(3)

check.done()
