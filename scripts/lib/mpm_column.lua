-- A granular column released on a floor, as an MPM continuum (drucker_prager or mu_i), shared by
-- scripts/column_collapse.lua, scripts/column_two_scales.lua, scripts/study_column.lua and
-- scripts/bench/continuum.lua. Not a scenario; load it with
--   local mpm_column = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/mpm_column.lua")
--
-- mpm_column.new{ material, L0, H0, cells, ppc, shape, floor_mu, length, strips } builds the
-- scene: a column L0 wide and H0 high against a slip wall at x = 0 (the plane of symmetry of a
-- column 2 L0 wide, as in the quasi-2D experiments' half columns), on a friction floor
-- (floor_mu) at y = 0, `cells` cells across L0 (square cells), ppc x ppc points per cell, linear
-- or B-spline shapes, the grid `length` long (default 3 L0) with a no-slip wall at its end, two
-- cells of headroom over the column and no wall on top. With strips = k (default 1) the column
-- is k grains side by side, so that the step's threads, which split the points by grains, share
-- it (with the default noslip contact the grains move in one velocity field: one continuum).
-- The column starts at rest under the hydrostatic pressure (sigma_xx = sigma_yy = -rho g (H0 -
-- y): a state inside both models' yield surfaces) as if held by a gate that is removed at t = 0.
-- Returns the column c with c.m (the scene), c.L0, c.H0, c.h (the cell size), c.tc = sqrt(H0 /
-- g), c.nx, c.ny, and:
--   c:state()           front: the 99th percentile of the points' x plus half a point spacing
--                       (so a column at rest has front L0, and a few points ahead of the deposit
--                       do not count); height: the top of the points within the first cell column
--                       (x < h) plus half a point spacing; ke: kinetic energy; drop: the fall of
--                       the potential energy since the start (J/m)
--   c:collapse{ t_max, slice, rest, stall, on_slice }
--                       runs slices of `slice` t_c until the kinetic energy is below rest times
--                       the potential energy released ("rest"), or the front has advanced less
--                       than stall L0 over the last t_c after at least 2 t_c ("stalled": the
--                       front at rest while points near the surface keep a residual agitation),
--                       or t_max t_c ("cap"); on_slice(t, state) after each slice. Returns
--                       { t, reason, state, series = { t, front, height, ke }, cpu, steps,
--                       points, creep } with creep the height lost over the last t_c (over L0).
--   c:surface()         the deposit's surface from the mass field: per cell column, the column's
--                       mass over (density h), the height the material would fill at its
--                       reference density; returns the cell centres' x and these heights
local mpm_column = {}
mpm_column.__index = mpm_column
local g = 9.81
mpm_column.gravity = g

-- The two continua of a comparison: mu_i with grains of diameter d and density rho_s packed to
-- rho_c = phi rho_s, and drucker_prager with the same density and moduli and its friction angle
-- matched to mu_s (sin phi = mu_s: isochoric Drucker-Prager, psi = 0, shears at tan phi* =
-- sin phi, Davis 1968) unless o.phi (degrees) is given.
function mpm_column.material(model, o)
  if model == "mu_i" then
    return mpm.material{ model = "mu_i", density = o.density, shear = o.shear, bulk = o.bulk,
                         mu_s = o.mu_s, mu_2 = o.mu_2, i0 = o.i0, grain_diameter = o.grain_diameter,
                         grain_density = o.grain_density }
  end
  return mpm.material{ model = "drucker_prager", density = o.density, shear = o.shear, bulk = o.bulk,
                       friction = o.phi or math.deg(math.asin(o.mu_s)), dilatancy = 0 }
end

function mpm_column.new(o)
  local L0, H0 = o.L0, o.H0
  local h = L0 / o.cells
  local nx = math.ceil((o.length or 3 * L0) / h - 1e-9)
  local ny = math.ceil(H0 / h - 1e-9) + 2
  local m = mpm.scene{ cells = { nx, ny }, size = { nx * h, ny * h }, gravity = { 0, -g },
                       shape = o.shape or "bspline", wall_gap = 0,
                       walls = { left = "slip", right = "noslip", top = "none",
                                 bottom = { kind = "friction", mu = o.floor_mu } } }
  -- strips > 1: the column as that many side-by-side grains of whole cells (the step's threads
  -- split the points by grains; with the default noslip contact the grains share one velocity
  -- field, one continuum), each with the hydrostatic state of the whole column's height
  local strips = o.strips or 1
  for k = 1, strips do
    local x0, x1 = h * math.floor(o.cells * (k - 1) / strips), h * math.floor(o.cells * k / strips)
    if k == strips then x1 = L0 end
    m:add_rect{ lo = { x0, 0 }, hi = { x1, H0 }, material = o.material, points_per_cell = o.ppc,
                hydrostatic = true }
  end
  local c = setmetatable({ m = m, L0 = L0, H0 = H0, h = h, nx = nx, ny = ny, ppc = o.ppc,
                           density = o.material.density, tc = math.sqrt(H0 / g) }, mpm_column)
  c.pe0 = c:potential()
  return c
end

function mpm_column:potential()
  local p = self.m:points()
  local pe = 0
  for i = 1, p.count do pe = pe + p.mass[i] * g * p.y[i] end
  return pe
end

function mpm_column:state()
  local p = self.m:points()
  local half = 0.5 * self.h / self.ppc
  local xs, ke, pe, top = {}, 0, 0, 0
  for i = 1, p.count do
    xs[i] = p.x[i]
    ke = ke + 0.5 * p.mass[i] * (p.vx[i] ^ 2 + p.vy[i] ^ 2)
    pe = pe + p.mass[i] * g * p.y[i]
    if p.x[i] < self.h then top = math.max(top, p.y[i]) end
  end
  table.sort(xs)
  return { front = xs[math.max(1, math.ceil(0.99 * #xs))] + half, xmax = xs[#xs] + half,
           height = top + half, ke = ke, drop = self.pe0 - pe }
end

function mpm_column:collapse(o)
  local tc, L0 = self.tc, self.L0
  local slice, t_max = o.slice or 0.1, o.t_max or 8
  local per_tc = math.floor(1 / slice + 0.5)
  local st = self:state()
  local series = { t = { 0 }, front = { st.front }, height = { st.height }, ke = { st.ke } }
  local cpu0, steps0 = os.clock(), self.m:info().steps
  local k, reason = 0, "cap"
  while k * slice < t_max - 1e-9 do
    self.m:run{ time = slice * tc, progress = false }
    k = k + 1
    st = self:state()
    local n = #series.t + 1
    series.t[n], series.front[n], series.height[n], series.ke[n] = k * slice, st.front, st.height, st.ke
    if o.on_slice then o.on_slice(k * slice, st) end
    if st.drop > 0 and st.ke < o.rest * st.drop then
      reason = "rest"
      break
    end
    if k * slice >= 2 - 1e-9 and n > per_tc and st.front - series.front[n - per_tc] < o.stall * L0 then
      reason = "stalled"
      break
    end
  end
  local n = #series.t
  local back = math.max(1, n - per_tc)
  return { t = k * slice, reason = reason, state = st, series = series, cpu = os.clock() - cpu0,
           steps = self.m:info().steps - steps0, points = self.m:info().points,
           creep = (series.height[back] - st.height) / L0 / ((series.t[n] - series.t[back]) > 0 and
                   (series.t[n] - series.t[back]) or 1) }
end

function mpm_column:surface()
  local mass = self.m:field("mass").values
  local xs, hs = {}, {}
  for i = 1, self.nx do
    local sum = 0
    for j = 1, self.ny do
      local v = mass[(j - 1) * self.nx + i]
      if v == v then sum = sum + v end
    end
    xs[i] = (i - 0.5) * self.h
    hs[i] = sum / (self.density * self.h)
  end
  return xs, hs
end

return mpm_column
