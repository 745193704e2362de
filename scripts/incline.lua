-- grainlab MPM validation: a deformable disk rolling down an incline with frictional contact
-- (Bardenhagen, Brackbill & Sulsky 1998, Sec. 4, Figs. 2-4, Eq. 25).
--
-- Rigid-disk reference (shared/VALIDATION.md, re-derived): x along the slope, plane angle th,
-- Coulomb mu, solid disk I = m R^2 / 2, released from rest. Friction F on the contact point:
--   m x'' = m g sin th - F,   I w' = -R F  (w < 0 when rolling in +x)
-- rolling (x'' = -R w'):  F = m g sin th / 3, x = x0 + g t^2 sin th / 3, |w'| = x''/R,
--   possible while F <= mu m g cos th, i.e. tan th <= 3 mu;
-- slipping (F = mu m g cos th): x = x0 + g t^2 (sin th - mu cos th) / 2, |w'| = 2 mu g cos th / R.
-- Only the spin tells the two apart: every case reports the angular acceleration |w(T)| / T
-- against both and checks that it is nearer the predicted one.
--
-- The paper's set-up: R = 0.5 m, G = 2.5 MPa, K = 10 MPa, rho = 3000 kg/m^3, |g| = 9.8, 9 points
-- per cell (points_per_cell = 3), initial pressure from grad p = rho g (hydrostatic = true), the
-- plane is the grid's bottom edge (a friction wall) and gravity is tilted by th. As an extra, the
-- same disk on a plane rotated against the grid under vertical gravity (m:plane, a staircase of
-- nodes with the exact normal). Cases (th, mu) = (pi/3, 0.3) slip, (pi/3, 0.9) roll,
-- (pi/3, 0.5) slip, (pi/6, 0.5) roll at h = 0.5 R, and the refinement h = 0.5, 0.25, 0.125 R for
-- (pi/6, 0.5), the paper's hardest case. Metric err_<case>: the relative error of the travelled
-- distance at T against Eq. 25 (negative: slower than the rigid disk, as the paper finds).
-- The other three cases run at 0.125 R as well. Checks: the error shrinks with refinement and is
-- within 2% at 0.125 R (both set-ups); the spin classifies every case right at 0.125 R.
--
-- params: T (run time, s; default 1), shape ('linear' | 'bspline'), wall_gap (the friction
-- wall's gap test, cells; default the scene's), quick=true (skip the rotated-plane runs),
-- out (image prefix, default images/incline for the default run, out/incline for any other).
--   grainlab scripts/incline.lua [T=1] [shape=linear|bspline] [wall_gap=0.02] [quick=true]
--       [out=out/incline]
local T = tonumber(params.T or 1)
local shape = params.shape or "linear"
local wall_gap = params.wall_gap and tonumber(params.wall_gap) or nil
local quick = params.quick == true
-- The default run publishes into images/ (docs/mpm.md shows it); quick, shorter or other-shape
-- runs write to out/ (grainlab.figures).
local figures = require("grainlab.figures")
local out = params.out or figures.path("incline", {
  published = figures.published({ T = T, shape = shape, wall_gap = wall_gap, quick = quick },
                                { T = 1, shape = "linear", quick = false }) and wall_gap == nil })
local R, g = 0.5, 9.8
local mat = mpm.material{ density = 3000, shear = 2.5e6, bulk = 10e6 }

local function theory(th, mu, t)
  if math.tan(th) > 3 * mu then
    return 0.5 * g * t * t * (math.sin(th) - mu * math.cos(th)), 2 * mu * g * math.cos(th) / R, "slip"
  end
  return g * t * t * math.sin(th) / 3, 2 / 3 * g * math.sin(th) / R, "roll"
end

-- One run; returns the travel history along the plane and the final spin.
local function run_case(th, mu, hR, rotated)
  local h = hR * R
  local xt = theory(th, mu, T)
  local D = 1.15 * xt + 0.5 -- room along the plane
  local m, dir, c0
  if not rotated then
    local Lx, Ly = math.ceil((D + 3 * R) / h) * h, math.ceil(3 * R / h) * h
    m = mpm.scene{ cells = { math.floor(Lx / h + 0.5), math.floor(Ly / h + 0.5) }, size = { Lx, Ly },
                   gravity = { g * math.sin(th), -g * math.cos(th) }, shape = shape, wall_gap = wall_gap,
                   walls = { bottom = { kind = "friction", mu = mu }, left = "none", right = "none", top = "none" } }
    m:add_disk{ center = { 1.2 * R, R }, radius = R, material = mat, points_per_cell = 3, hydrostatic = true }
    dir = { 1, 0 }
  else
    -- plane through P, descending to the right: tangent t = (cos, -sin), outward n = (sin, cos)
    local t, n = { math.cos(th), -math.sin(th) }, { math.sin(th), math.cos(th) }
    local span_x, span_y = (D + 3 * R) * t[1] + 3 * R, (D + 3 * R) * -t[2] + 4 * R
    local Lx, Ly = math.ceil(span_x / h) * h, math.ceil(span_y / h) * h
    local P = { 0.5 * R, Ly - 3 * R }
    m = mpm.scene{ cells = { math.floor(Lx / h + 0.5), math.floor(Ly / h + 0.5) }, size = { Lx, Ly },
                   gravity = { 0, -g }, shape = shape, wall_gap = wall_gap, walls = "none" }
    m:plane{ point = P, normal = n, kind = "friction", mu = mu }
    local c = { P[1] + 1.5 * R * t[1] + R * n[1], P[2] + 1.5 * R * t[2] + R * n[2] }
    m:add_disk{ center = c, radius = R, material = mat, points_per_cell = 3, hydrostatic = true }
    dir = t
  end
  c0 = m:grain(1).center
  local ts, xs = { 0 }, { 0 }
  local t0 = os.clock()
  local dt = m:timestep().dt_auto
  m:run{ time = T, every = math.max(1, math.floor(T / 40 / dt)), on_step = function(s)
    local c = s:grain(1).center
    ts[#ts + 1] = s:info().time
    xs[#xs + 1] = (c[1] - c0[1]) * dir[1] + (c[2] - c0[2]) * dir[2]
  end }
  local gi = m:grain(1)
  local x = (gi.center[1] - c0[1]) * dir[1] + (gi.center[2] - c0[2]) * dir[2]
  if ts[#ts] < T then ts[#ts + 1], xs[#xs + 1] = T, x end
  return { x = x, alpha = math.abs(gi.omega) / T, t = ts, xs = xs, cpu = os.clock() - t0,
           points = gi.points, cells = m:info().cells }
end

local cases = {
  { id = "th60_mu03", th = math.pi / 3, mu = 0.3 },
  { id = "th60_mu09", th = math.pi / 3, mu = 0.9 },
  { id = "th60_mu05", th = math.pi / 3, mu = 0.5 },
  { id = "th30_mu05", th = math.pi / 6, mu = 0.5 },
}
local refine = { 0.5, 0.25, 0.125 }
local metrics, checks = {}, {}
local rows = {}

local function record(setup, c, hR, r)
  local xt, at, kind = theory(c.th, c.mu, T)
  local at_other
  if kind == "slip" then at_other = 2 / 3 * g * math.sin(c.th) / R else at_other = 2 * c.mu * g * math.cos(c.th) / R end
  local err = (r.x - xt) / xt
  local key = string.format("%s_%s_h%03d", setup, c.id, math.floor(1000 * hR + 0.5))
  metrics["err_" .. key] = err
  metrics["alpha_err_" .. key] = (r.alpha - at) / at
  rows[#rows + 1] = string.format("%-8s %-11s h=%-6g R  %4dx%-4d %6d pts  x %8.4f m (rigid %8.4f, %s)  err %+7.2f%%   |w'| %7.3f (%s %7.3f, other %7.3f)  %.2fs",
    setup, c.id, hR, r.cells[1], r.cells[2], r.points, r.x, xt, kind, 100 * err, r.alpha, kind, at, at_other, r.cpu)
  return err, math.abs(r.alpha - at) < math.abs(r.alpha - at_other)
end

local series_cases, series_refine, series_rot = {}, {}, {}
local function analytic_series(c, label)
  local tt, xx = {}, {}
  for k = 0, 50 do
    local t = T * k / 50
    tt[#tt + 1], xx[#xx + 1] = t, (theory(c.th, c.mu, t))
  end
  return { x = tt, y = xx, label = label, style = "line" }
end

local setups = quick and { "tilted" } or { "tilted", "rotated" }
for _, setup in ipairs(setups) do
  local rotated = setup == "rotated"
  for _, c in ipairs(cases) do
    local hs = c.id == "th30_mu05" and refine or { 0.5, 0.125 }
    local errs = {}
    for _, hR in ipairs(hs) do
      local r = run_case(c.th, c.mu, hR, rotated)
      local err, spin_ok = record(setup, c, hR, r)
      errs[#errs + 1] = err
      local lbl = string.format("%s h=%gR", c.id, hR)
      if not rotated and hR == 0.5 then
        series_cases[#series_cases + 1] = { x = r.t, y = r.xs, label = lbl .. " MPM", style = "points" }
      end
      if c.id == "th30_mu05" then
        local target = rotated and series_rot or series_refine
        target[#target + 1] = { x = r.t, y = r.xs, label = lbl .. " MPM", style = "points" }
      end
      if hR == hs[#hs] then
        checks[#checks + 1] = { name = string.format("spin_classifies_%s_%s_h%03d", setup, c.id, math.floor(1000 * hR + 0.5)), pass = spin_ok }
      end
    end
    if #errs == 3 then
      checks[#checks + 1] = { name = "err_shrinks_with_refinement_" .. setup,
                              pass = math.abs(errs[3]) < math.abs(errs[2]) and math.abs(errs[2]) < math.abs(errs[1]) }
      checks[#checks + 1] = { name = "abs_err_at_h125_" .. setup, value = math.abs(errs[3]), limit = 0.02, op = "<=" }
    end
  end
end

print(table.concat(rows, "\n"))
for _, c in ipairs(cases) do series_cases[#series_cases + 1] = analytic_series(c, c.id .. " rigid (Eq. 25)") end
series_refine[#series_refine + 1] = analytic_series(cases[4], "rigid (Eq. 25)")
render.plot{ file = out .. "_cases.png", width = 900, height = 600,
             title = string.format("Disk on an incline, h = 0.5 R, tilted gravity (Figs. 2-3)"),
             xlabel = "t (s)", ylabel = "x_cm - x_0 along the plane (m)", series = series_cases }
render.plot{ file = out .. "_refinement.png", width = 900, height = 600,
             title = "th = pi/6, mu = 0.5: refinement 0.5R, 0.25R, 0.125R (Fig. 4)",
             xlabel = "t (s)", ylabel = "x_cm - x_0 along the plane (m)", series = series_refine }
if not quick then
  series_rot[#series_rot + 1] = analytic_series(cases[4], "rigid (Eq. 25)")
  render.plot{ file = out .. "_rotated.png", width = 900, height = 600,
               title = "th = pi/6, mu = 0.5 on a plane rotated against the grid (staircase nodes)",
               xlabel = "t (s)", ylabel = "x_cm - x_0 along the plane (m)", series = series_rot }
end

grainlab.report{
  scenario = "incline",
  params = { T = T, shape = shape, wall_gap = wall_gap or 0.02, R = R, shear = 2.5e6, bulk = 10e6,
             density = 3000, g = g, points_per_cell = 3, quick = quick },
  metrics = metrics,
  checks = checks,
}
