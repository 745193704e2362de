-- grainlab MPM validation: granular continua at rest, and a slope that fails or stands.
--
-- 1. A layer at rest. A layer of height h on a frictional floor between slip walls, stress-free
--    at the start, loaded by gravity and brought to rest by dynamic relaxation (every few steps
--    the point velocities are damped at the rate of the layer's fundamental mode, omega = 2 pi c
--    / 4h). At rest the vertical stress carries the weight above: in the reference configuration
--    (Lagrangian height Y), sigma_yy = -rho g (h - Y), whatever the constitutive law, the
--    lateral stress and the compression. Checked on the cell means of sigma_yy (m:field('syy'))
--    of every cell at least two cells from a side wall and two below the surface, within 1 %,
--    for model = 'drucker_prager' (phi = 30 deg) and 'mu_i'. The ratio sigma_xx / sigma_yy at
--    mid-depth is reported (an elastic layer's K0 = nu / (1 - nu), here where Drucker-Prager
--    yields under the loading).
--
-- 2. The infinite slope: a layer of thickness h on a rough floor (friction wall, mu = 1),
--    periodic along it, under gravity tilted by beta. Mohr-Coulomb in plane strain: with
--    associated flow (psi = phi) steady shear parallel to the floor carries tau / sigma_n = tan
--    phi on it, so the layer flows for beta > phi and stands for beta < phi; with psi < phi the
--    shear plane carries tan phi* = sin phi cos psi / (1 - sin phi sin psi) (Davis 1968), so
--    psi = 0 flows above phi* = atan(sin phi) = 26.57 deg for phi = 30 deg. Drucker-Prager
--    matched to Mohr-Coulomb in plane strain must show both. Each layer is settled by the same
--    dynamic relaxation for `settle` seconds (a failing layer creeps then), then released for
--    `release` seconds. Fails: the surface speed at the end is at least half of a rigid block's
--    g (sin beta - cos beta tan phi*) release; stands: no point faster than 1 mm/s. Cases
--    beta = phi +- 2 deg (psi = phi) and phi* +- 2 deg (psi = 0).
--
-- params: cells (cells over the layer heights; default 20, the tests use 10), settle, release
-- (s), out (image prefix; the default run writes images/continuum_rest_*.png, any other out/).
local cells = math.tointeger(tonumber(params.cells or 20))
local settle = tonumber(params.settle or 0.1)
local release = tonumber(params.release or 0.4)
local figures = require("grainlab.figures")
local out = params.out or figures.path("continuum_rest", {
  published = figures.published({ cells = cells, settle = settle, release = release },
                                { cells = 20, settle = 0.1, release = 0.4 }) })

local g, rho = 9.81, 1500
local shear, bulk = 1e6, 2e6
local metrics, checks = {}, {}

local function material(model, phi, psi)
  if model == "mu_i" then
    return mpm.material{ model = "mu_i", density = rho, shear = shear, bulk = bulk, mu_s = 0.38,
                         mu_2 = 0.64, grain_diameter = 5e-4, grain_density = 2500 }
  end
  return mpm.material{ model = "drucker_prager", density = rho, shear = shear, bulk = bulk,
                       friction = phi or 30, dilatancy = psi or 0 }
end

-- Dynamic relaxation: every `every` steps the point velocities lose exp(-omega dt every).
local function damper(omega, every)
  return function(m)
    local p = m:points()
    local f = math.exp(-omega * m:timestep{}.dt_auto * every)
    for i = 1, p.count do
      p.vx[i] = p.vx[i] * f
      p.vy[i] = p.vy[i] * f
    end
    m:set_velocities{ vx = p.vx, vy = p.vy }
  end
end

-- ---- 1. the layer at rest ---------------------------------------------------------------------
-- The friction floor's gap test is off (wall_gap = 0): with 2 points per cell the centroid of a
-- resting layer's first cell (3/8 cell) sits 0.04 cell above a continuum's (1/3 cell), beyond
-- the default 0.02, and the floor would let the layer sink.
local stress_series = {}
local W, h = 0.2, 0.1
local hx = h / cells
for _, model in ipairs { "drucker_prager", "mu_i" } do
  local mat = material(model)
  local m = mpm.scene{ cells = { math.floor(W / hx + 0.5), cells + 4 }, size = { W, h + 4 * hx },
                       gravity = { 0, -g }, wall_gap = 0,
                       walls = { left = "slip", right = "slip",
                                 bottom = { kind = "friction", mu = 0.5 }, top = "none" } }
  m:add_rect{ lo = { 0, 0 }, hi = { W, h }, material = mat, points_per_cell = 2 }
  m:run{ time = settle / 2, every = 5, on_step = damper(2 * math.pi * mat.wave_speed / (4 * h), 5) }
  local f = m:field("syy")
  local fx = m:field("sxx")
  local worst, n, ratio, nr = 0, 0, 0, 0
  local ys, sim, ref = {}, {}, {}
  for j = 1, f.ny do
    local yc = (j - 0.5) * hx
    local row, rn = 0, 0
    for i = 1, f.nx do
      local k = (j - 1) * f.nx + i
      local xc = (i - 0.5) * hx
      local v = f.values[k]
      if v == v and xc > 2 * hx and xc < W - 2 * hx and yc < h - 2 * hx then
        local r = rho * g * (h - yc)
        worst = math.max(worst, math.abs(-v - r) / r)
        n = n + 1
        row, rn = row + v, rn + 1
        if math.abs(yc - h / 2) < hx then ratio, nr = ratio + fx.values[k] / v, nr + 1 end
      end
    end
    if rn > 0 then
      ys[#ys + 1] = yc
      sim[#sim + 1] = -row / rn
      ref[#ref + 1] = rho * g * (h - yc)
    end
  end
  metrics["rest_" .. model .. "_worst_syy_err"] = worst
  metrics["rest_" .. model .. "_cells"] = n
  metrics["rest_" .. model .. "_sxx_over_syy_mid"] = ratio / nr
  metrics["rest_" .. model .. "_kinetic_j_per_m"] = m:measure("energy").kinetic
  checks[#checks + 1] = { name = "rest_syy_" .. model, value = worst, limit = 0.01 }
  stress_series[#stress_series + 1] = { x = sim, y = ys, label = model .. " (row means)", style = "points" }
  if model == "mu_i" then
    stress_series[#stress_series + 1] = { x = ref, y = ys, label = "rho g (h - y)" }
  end
end
render.plot{ file = out .. "_stress.png", width = 800, height = 600,
             title = string.format("Layer at rest (h = %g m, %d cells high)", h, cells),
             xlabel = "-sigma_yy (Pa)", ylabel = "y (m)", series = stress_series }

-- ---- 2. the infinite slope --------------------------------------------------------------------
local phi = 30
local phistar = math.deg(math.atan(math.sin(math.rad(phi))))
local cases = {
  { psi = phi, beta = phi + 2, fails = true }, { psi = phi, beta = phi - 2, fails = false },
  { psi = 0, beta = phistar + 2, fails = true }, { psi = 0, beta = phistar - 2, fails = false },
}
local slope_series = {}
local hs = 0.05
local hy = hs / cells
for _, c in ipairs(cases) do
  local b = math.rad(c.beta)
  local mat = material("drucker_prager", phi, c.psi)
  local ncx = 4
  local m = mpm.scene{ cells = { ncx, 2 * cells }, size = { ncx * hy, 2 * cells * hy },
                       periodic = { true, false }, gravity = { g * math.sin(b), -g * math.cos(b) },
                       wall_gap = 0, walls = { bottom = { kind = "friction", mu = 1 }, top = "none" } }
  -- a periodic shape must span less than the period: the last sub-cell centres are inside
  m:add_rect{ lo = { 0, 0 }, hi = { ncx * hy * (1 - 1e-9), hs }, material = mat, points_per_cell = 2 }
  m:run{ time = settle, every = 5, on_step = damper(2 * math.pi * mat.wave_speed / (4 * hs), 5) }
  local function surface()
    local p = m:points()
    local top, v, n, vmax = -1, 0, 0, 0
    for i = 1, p.count do top = math.max(top, p.y[i]) end
    for i = 1, p.count do
      if p.y[i] > top - 0.5 * hy then v, n = v + p.vx[i], n + 1 end
      vmax = math.max(vmax, math.sqrt(p.vx[i] ^ 2 + p.vy[i] ^ 2))
    end
    return v / n, vmax
  end
  local ts, vs = { 0 }, { (surface()) }
  local steps = 8
  for k = 1, steps do
    m:run{ time = release / steps }
    ts[#ts + 1] = k * release / steps
    vs[#vs + 1] = (surface())
  end
  local vsurf, vmax = surface()
  local tanstar = math.sin(math.rad(phi)) * math.cos(math.rad(c.psi)) /
                  (1 - math.sin(math.rad(phi)) * math.sin(math.rad(c.psi)))
  local a = g * (math.sin(b) - math.cos(b) * tanstar)
  local id = string.format("psi%02d_beta%.2f", c.psi, c.beta):gsub("%.", "_")
  metrics["slope_" .. id .. "_v_surface"] = vsurf
  metrics["slope_" .. id .. "_v_max"] = vmax
  if c.fails then
    metrics["slope_" .. id .. "_rigid_v"] = a * release
    checks[#checks + 1] = { name = "slope_fails_" .. id, value = vsurf, limit = 0.5 * a * release, op = ">=" }
  else
    checks[#checks + 1] = { name = "slope_stands_" .. id, value = vmax, limit = 1e-3 }
  end
  slope_series[#slope_series + 1] = {
    x = ts, y = vs, style = "points",
    label = string.format("psi = %g, beta = %.2f (%s)", c.psi, c.beta, c.fails and "beyond" or "below") }
end
render.plot{ file = out .. "_slope.png", width = 800, height = 600,
             title = string.format("Infinite slope, Drucker-Prager phi = %g deg: released after settling", phi),
             xlabel = "t after release (s)", ylabel = "surface velocity along the slope (m/s)",
             series = slope_series }

grainlab.report{
  scenario = "continuum_rest",
  params = { cells = cells, settle = settle, release = release, density = rho, shear = shear,
             bulk = bulk, friction = phi },
  metrics = metrics,
  checks = checks,
}
