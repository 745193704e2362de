-- grainlab: one granular column at two scales. The column of scripts/demo.lua (1500 disks, DEM)
-- collapses once grain by grain and twice as a continuum in MPM (drucker_prager and mu_i), and
-- the three are compared: final profile, runout, the front against time, CPU time.
--
-- DEM (scripts/lib/dem_column.lua, the demo's set-up and reasons): 1500 disks, radii uniform in
-- [0.5, 1] mm (mean diameter 1.5 mm), density 2650 kg/m^3, Coulomb friction mu = 0.5 between
-- grains and with the floor of fixed disks, Hertz + Brilliantov damping (restitution 0.5), no
-- rolling resistance; a column W0 = 41 mm wide filled to H0 = 2 W0 against the wall at x = 0,
-- the gate removed at t = 0, run until the fastest grain is below 5 mm/s.
--
-- Continuum (scripts/lib/mpm_column.lua): the same width W0 and settled height H0 (the DEM's, at
-- the gate's removal), the same wall at x = 0 (slip: the disks roll and slide along a plain
-- wall), a friction floor with the grains' mu = 0.5, and the DEM packing's density: rho_c = phi
-- rho_s with phi the area fraction the disks fill in W0 x H0. The friction is the DEM packing's
-- macroscopic one: mu_s = tan theta_r with theta_r = 20.8 deg, within the scatter of the angle
-- of repose these disks form at mu = 0.5 (19.1 +- 1.5 deg, scripts/repose.lua); mu(I)'s mu_2 - mu_s = 0.26 and I_0 =
-- 0.279 are Jop et al.'s glass beads' (no measurement of them from grainlab's DEM), d = 1.5 mm
-- the disks' mean diameter; Drucker-Prager takes sin phi = mu_s, psi = 0 (phi = 22.3 deg). G =
-- 0.25 MPa, K = 0.5 MPa (elastic strain under the column 0.4 %). `cells` cells across W0 (2.7
-- grain diameters each at 10), 2 x 2 points per cell, B-splines; the run ends when the front
-- has advanced less than 0.005 W0 over a t_c = sqrt(H0 / g) (or the kinetic energy is below
-- 1e-3 of the energy released).
--
-- Measured as in the demo: the front, the 99th percentile of the grains' (points') right edges
-- (points: x plus half a point spacing); the height over the column's footprint (DEM: the top of
-- the highest grain with x < W0; MPM: the top of the points within one cell of the wall); the
-- final profiles, DEM: the top of the highest grain whose centre lies in each bin of one cell
-- width, MPM: the mass in each cell column over (rho_c h), both averaged over bins of W0 / 4;
-- the time the front takes to 90 % of its final runout (t90); CPU time by os.clock (DEM: the
-- preparation and the collapse apart).
--
-- Fields, cell by cell (docs/coarse-graining.md): each final deposit is coarse-grained with one
-- kernel onto one grid, analysis.coarse_grain on the DEM scene and on both MPM scenes: a Gaussian
-- of width w = 3 mm (2 mean diameters) cut at 3 w, cells of 1.5 mm from x = -3 w to L + 3 w and
-- from under the floor disks' kernels to 3 w over the highest top. Depth: the disks are spheres
-- moving in the plane (no thickness: m = rho_s 4/3 pi r^3) and the continuum holds rho_c = phi
-- rho_s per metre of depth, so the DEM's fields are divided by t_eff = sum 4/3 pi r^3 / sum pi r^2
-- (1.07 mm by default), the depth that gives the disks' area the continuum's mass: both in kg/m^3 and Pa,
-- DEM density / rho_s the local area fraction. DEM stress = contact + kinetic; MPM: the points'
-- stress + kinetic. The base row is the first row whose centre clears the floor disks' kernels
-- (y_b = rf + 3 w above their centres). Reported against the DEM, for each continuum: over the
-- interior (x >= w, y from y_b to 2 w under both local surfaces, the surface being y_b plus the
-- mass above it over rho_c), the rms, max and mean of the relative difference of sigma_yy, the
-- rms of that of the pressure, the mean volume fraction of both, and sigma_yy over the weight
-- above each cell (per unit area) in both; the fraction of the cells filled (rho >= rho_c / 2)
-- by either that both fill; under the column (0 < x < W0) on the base row, sigma_yy and the
-- pressure over the weight above per unit area. Figure: sigma_yy of the three deposits stacked
-- on one colour scale (OUT_fields.png).
--
-- Checks: each continuum's runout within 35 % of the DEM's (the friction is the DEM's; 35 % is
-- the spread of the quasi-2D experiments' prefactors, 1.2 to 1.8 at a = 2, between materials of
-- similar friction); the three runs end at rest; the continuum runs cost less CPU than the DEM's
-- collapse. The coarse-grained mass of each deposit (on cells of w / 2 holding every support,
-- the Gaussian cut at 8 w, whose grid sums are 1 to round-off) equals its mass within 1e-12 (DEM:
-- the grains and the floor disks over t_eff). The floor carries the deposit: sigma_yy integrated
-- over x on the base row, plus the weight of the layer below it, equals the weight per unit
-- width less the vertical force of the wall at x = 0 above that row (DEM: 0.02 % by friction; the
-- continuum's wall slips), which is the x-integrated momentum balance of a static deposit; DEM
-- within 1 % (the grains' residual motion below 5 mm/s and the cut kernel's 1e-4 leave 0.1 %),
-- MPM within 5 % (the continuum balances its stresses on its grid of W0 / cells, coarser than
-- w, so the kernel's average of the points' stresses scatters about the balance: +-2 % from row
-- to row, 0.3-0.7 % on the base row at the default size).
-- Reported, not checked: the final heights and their ratio to the DEM's, and the slope
-- of each deposit's surface over its first 2 W0 (a least-squares line through the bins of W0 / 4
-- whose centres lie there), where the continua and the disks differ most (docs/mpm.md).
--
-- params: cells (across W0, default 10), n (disks, default 1500), out (figure prefix; the
-- default run writes images/column_two_scales_*.png, any other out/).
--   grainlab scripts/column_two_scales.lua [cells=10] [n=1500] [out=out/column_two_scales]
local cells = math.tointeger(tonumber(params.cells or 10))
local n = math.tointeger(tonumber(params.n or 1500))
assert(cells and cells >= 2, "cells must be an integer >= 2")
assert(n and n >= 100, "n must be an integer >= 100")
local figures = require("grainlab.figures")
local out = params.out or figures.path("column_two_scales", {
  published = figures.published({ cells = cells, n = n }, { cells = 10, n = 1500 }) })
local here = (arg[0]:match("^(.*)/") or ".")
local dem_column = dofile(here .. "/lib/dem_column.lua")
local mpm_column = dofile(here .. "/lib/mpm_column.lua")
local g = dem_column.gravity

-- DEM
local cpu0 = os.clock()
local col = dem_column.new{ n = n, seed = 1, aspect = 2, young = 5e6, mu = 0.5 }
local st0 = col:prepare()
local cpu_prep = os.clock() - cpu0
local W0, H0 = col.W0, st0.height
local area = 0
do
  local P = col.s:particles()
  for i = col.nf + 1, col.nf + n do area = area + math.pi * P.radius[i] ^ 2 end
end
local phi = area / (W0 * H0)
col:release()
local dem_t, dem_front = { 0 }, { st0.front }
cpu0 = os.clock()
local t_dem, st_dem = col:collapse(function(t, st)
  dem_t[#dem_t + 1], dem_front[#dem_front + 1] = t, st.front
end)
local cpu_dem = os.clock() - cpu0
local dem = { runout = (st_dem.front - W0) / W0, height = st_dem.height / H0, t = t_dem, cpu = cpu_dem,
              rest = st_dem.vmax < dem_column.v_rest }
print(string.format("DEM:            runout %.3f W0, height %.3f H0, at rest after %.3f s, CPU %.1f s (+ %.1f s preparation), %d grains, %d steps",
                    dem.runout, dem.height, t_dem, cpu_dem, cpu_prep, n, col.steps))

-- Continuum
local rho_s, d = dem_column.density, 1.5e-3
local mu_s = math.tan(math.rad(20.8))
local mat_o = { density = phi * rho_s, grain_density = rho_s, grain_diameter = d, i0 = 0.279, mu_s = mu_s,
                mu_2 = mu_s + math.tan(math.rad(32.76)) - math.tan(math.rad(20.9)), shear = 2.5e5, bulk = 5e5 }
local bin = W0 / 4
local nb = math.ceil(col.L / bin)
local function binned(xs, hs, h)
  local sum, cnt = {}, {}
  for b = 1, nb do sum[b], cnt[b] = 0, 0 end
  for i = 1, #xs do
    local b = math.floor(xs[i] / bin) + 1
    if b >= 1 and b <= nb then sum[b], cnt[b] = sum[b] + hs[i], cnt[b] + 1 end
  end
  local bx, by = {}, {}
  for b = 1, nb do
    bx[b], by[b] = (b - 0.5) * bin, cnt[b] > 0 and sum[b] / cnt[b] or 0
  end
  return bx, by
end
local runs = {}
for _, model in ipairs({ "drucker_prager", "mu_i" }) do
  local c = mpm_column.new{ material = mpm_column.material(model, mat_o), L0 = W0, H0 = H0, cells = cells, ppc = 2,
                            shape = "bspline", floor_mu = 0.5, length = col.L }
  local r = c:collapse{ t_max = 10, slice = 0.1, rest = 1e-3, stall = 0.005 }
  r.runout, r.height = (r.state.front - W0) / W0, r.state.height / H0
  r.xs, r.hs = c:surface()
  r.bx, r.by = binned(r.xs, r.hs)
  r.tc, r.model, r.m, r.h = c.tc, model, c.m, c.h
  runs[#runs + 1] = r
  print(string.format("MPM %-14s runout %.3f W0, height %.3f H0, %s at %.2f s (%.1f t_c), CPU %.1f s, %d points, %d steps",
                      model, r.runout, r.height, r.reason, r.t * c.tc, r.t, r.cpu, r.points, r.steps))
end

-- DEM profile: the top of the highest grain per cell-wide bin, averaged over the bins of W0 / 4
local hcell = W0 / cells
local k = math.ceil(col.L / hcell)
local tops = col:surface(0, hcell, k)
local dxs = {}
for i = 1, k do dxs[i] = (i - 0.5) * hcell end
local dbx, dby = binned(dxs, tops)

-- the time the front takes to 90 % of its final runout
local function t90(ts, fronts, scale)
  local final = fronts[#fronts] - W0
  for i, f in ipairs(fronts) do
    if f - W0 >= 0.9 * final then return ts[i] * scale end
  end
end

-- the surface's slope (degrees) over x in [0, 2 W0]: a least-squares line through the bins there
local function slope(bx, by)
  local n, sx, sy, sxx, sxy = 0, 0, 0, 0, 0
  for i = 1, #bx do
    if bx[i] <= 2 * W0 then
      n, sx, sy, sxx, sxy = n + 1, sx + bx[i], sy + by[i], sxx + bx[i] ^ 2, sxy + bx[i] * by[i]
    end
  end
  return math.deg(math.atan(-(n * sxy - sx * sy) / (n * sxx - sx * sx)))
end

local metrics = { column_width_m = W0, column_height_m = H0, aspect = H0 / W0, area_fraction = phi,
                  mu_s = mu_s, mu_2 = mat_o.mu_2, dp_friction_deg = math.deg(math.asin(mu_s)),
                  runout_over_w0_dem = dem.runout, height_over_h0_dem = dem.height, t_rest_s_dem = t_dem,
                  cpu_s_dem = cpu_dem, cpu_s_dem_preparation = cpu_prep, steps_dem = col.steps, grains = n,
                  surface_slope_deg_dem = slope(dbx, dby), t90_s_dem = t90(dem_t, dem_front, 1) }
local checks = { { name = "dem_at_rest", pass = dem.rest } }
local names = { drucker_prager = "dp", mu_i = "mu_i" }
for _, r in ipairs(runs) do
  local key = names[r.model]
  metrics["runout_over_w0_" .. key] = r.runout
  metrics["height_over_h0_" .. key] = r.height
  metrics["t_end_s_" .. key] = r.t * r.tc
  metrics["cpu_s_" .. key] = r.cpu
  metrics["points_" .. key] = r.points
  metrics["steps_" .. key] = r.steps
  metrics["end_" .. key] = r.reason
  metrics["ke_over_released_" .. key] = r.state.ke / r.state.drop
  metrics["cpu_ratio_dem_over_" .. key] = cpu_dem / r.cpu
  checks[#checks + 1] = { name = "runout_vs_dem_" .. key, value = math.abs(r.runout / dem.runout - 1), limit = 0.35 }
  metrics["height_over_dem_" .. key] = r.height / dem.height
  metrics["surface_slope_deg_" .. key] = slope(r.bx, r.by)
  metrics["t90_s_" .. key] = t90(r.series.t, r.series.front, r.tc)
  checks[#checks + 1] = { name = "at_rest_" .. key, pass = r.reason ~= "cap" }
  checks[#checks + 1] = { name = "cheaper_than_dem_" .. key, value = r.cpu, limit = cpu_dem, op = "<" }
end

-- Figures
local mm = function(v) return v * 1e3 end
local function scaled(xs, f)
  local o = {}
  for i, v in ipairs(xs) do o[i] = f(v) end
  return o
end
local label = { drucker_prager = "Drucker-Prager (MPM)", mu_i = "mu(I) (MPM)" }
local prof = { { x = { 0, mm(W0), mm(W0) }, y = { mm(H0), mm(H0), 0 }, label = "the column at t = 0" },
               { x = scaled(dbx, mm), y = scaled(dby, mm), style = "both", label = "DEM (1500 disks)" } }
for _, r in ipairs(runs) do
  prof[#prof + 1] = { x = scaled(r.bx, mm), y = scaled(r.by, mm), style = "both", label = label[r.model] }
end
render.plot{ file = out .. "_profiles.png", width = 1000, height = 560,
             title = string.format("One column at two scales: final deposits (bins of W0/4; %d cells across W0)", cells),
             xlabel = "x (mm)", ylabel = "height (mm)", series = prof }
local fronts = { { x = dem_t, y = scaled(dem_front, function(f) return mm(f - W0) end), label = "DEM (1500 disks)" } }
for _, r in ipairs(runs) do
  fronts[#fronts + 1] = { x = scaled(r.series.t, function(t) return t * r.tc end),
                          y = scaled(r.series.front, function(f) return mm(f - W0) end), label = label[r.model] }
end
render.plot{ file = out .. "_front.png", width = 1000, height = 560,
             title = "One column at two scales: the front (99th percentile) against time",
             xlabel = "t (s)", ylabel = "runout L(t) - W0 (mm)", series = fronts }

-- The three deposits coarse-grained with one kernel onto one grid, cell by cell. The DEM's disks
-- are spheres moving in the plane (m = rho_s 4/3 pi r^3, no thickness set); the continuum holds,
-- per metre of depth, rho_c = phi rho_s. The DEM fields are divided by the depth t_eff = sum 4/3
-- pi r^3 / sum pi r^2 that gives the disks that density: kg/m^3 and Pa, as the MPM's.
local rf = dem_column.floor_radius
local cg_w, cg_h = 2 * d, d   -- Gaussian of width 2 mean diameters, cut at 3 w; cells of one diameter
local cg_c = 3 * cg_w
local rho_c = mat_o.density
local deposit = {}             -- key -> { scene, depth, mass (kg per m of depth), top }
do
  local P = col.s:particles()
  local vol, ar, m, top = 0, 0, 0, 0
  for i = col.nf + 1, col.nf + n do
    local r = P.radius[i]
    vol, ar, m = vol + 4 / 3 * math.pi * r ^ 3, ar + math.pi * r ^ 2, m + P.mass[i]
    top = math.max(top, P.y[i] + r)
  end
  local m_all = 0
  for i = 1, P.count do m_all = m_all + P.mass[i] end
  deposit.dem = { scene = col.s, depth = vol / ar, top = top, label = "DEM" }
  deposit.dem.mass, deposit.dem.mass_all = m / deposit.dem.depth, m_all / deposit.dem.depth
end
for _, r in ipairs(runs) do
  local p = r.m:points()
  local m, top = 0, 0
  for i = 1, p.count do m, top = m + p.mass[i], math.max(top, p.y[i] + r.h) end
  deposit[names[r.model]] = { scene = r.m, mass = m, mass_all = m, top = top, label = label[r.model] }
end
local keys = { "dem", "dp", "mu_i" }
local FLOOR_TOL = { dem = 0.01, dp = 0.05, mu_i = 0.05 }  -- why: the header

-- One grid for the three: x from -w (the kernels of the wall's grains) to L + w, y from below
-- the floor disks' kernels (centres at -rf) to w over the highest top.
local top = 0
for _, k in ipairs(keys) do top = math.max(top, deposit[k].top) end
local x0, y0 = -cg_c, -cg_h * math.ceil((rf + cg_c) / cg_h + 1e-9)
local nx, ny = math.ceil((col.L + 2 * cg_c) / cg_h - 1e-9), math.ceil((top + cg_c - y0) / cg_h - 1e-9)
local grid = { kernel = "gauss", width = cg_w, cells = { nx, ny },
               region = { { x0, y0 }, { x0 + nx * cg_h, y0 + ny * cg_h } } }
-- the first row whose centre clears the floor disks' kernels: the base of the balance
local jb = math.floor((rf + cg_c - y0) / cg_h) + 1
local yb = y0 + (jb - 0.5) * cg_h
local function opts(k, extra)
  local o = {}
  for a, v in pairs(extra or grid) do o[a] = v end
  o.depth = deposit[k].depth
  return o
end
local F, cg_cpu = {}, os.clock()
for _, k in ipairs(keys) do F[k] = analysis.coarse_grain(deposit[k].scene, opts(k)) end
cg_cpu = os.clock() - cg_cpu

-- Mass: the Gaussian cut at 8 w is smooth to round-off, so on cells of w / 2 holding every
-- support the grid sum of each kernel is 1 to round-off (docs/coarse-graining.md, exactness).
local function cg_mass(k)
  local c = 9 * cg_w
  local mx0, my0 = -c, -rf - c
  local mnx = math.ceil((col.L + 2 * c) / cg_h)
  local mny = math.ceil((deposit[k].top + c - my0) / cg_h)
  local o = opts(k, { width = cg_w, cutoff = 8 * cg_w, cells = { mnx, mny },
                     region = { { mx0, my0 }, { mx0 + mnx * cg_h, my0 + mny * cg_h } } })
  if k == "dem" then o.contacts = false end
  local G = analysis.coarse_grain(deposit[k].scene, o)
  local sum = 0
  for q = 1, G.n do sum = sum + G.density[q] end
  return sum * G.cell_volume
end

local function at(t, i, j) return t[(j - 1) * nx + i] end
local function xc(i) return x0 + (i - 0.5) * cg_h end
local function yc(j) return y0 + (j - 0.5) * cg_h end

-- The floor's balance of field k: the x-integrated sigma_yy on the base row against the weight
-- above it (the rows above and half the base row) less the walls' vertical force there (DEM: the
-- wall at x = 0 carries part of the deposit by friction; the continuum's wall slips).
local function balance(k)
  local f, S, M, T = F[k], 0, 0, 0
  for i = 1, nx do
    S = S + at(f.stress.yy, i, jb)
    for j = jb, ny do
      local wgt = j == jb and 0.5 or 1
      M = M + wgt * at(f.density, i, j)
      if f.traction then T = T + wgt * at(f.traction.y, i, j) end
    end
  end
  S, M, T = S * cg_h, M * cg_h * cg_h, T * cg_h * cg_h
  local W = deposit[k].mass * g
  -- the floor's load: sigma_yy on the base row plus the weight of the layer below it
  return { syy_base = S, weight_above = g * M, wall_support = T, weight = W,
           floor_load = S + W - g * M, balance = S / (g * M - T) - 1 }
end

-- The local surface from the density: per cell column, the base row's height plus the mass above
-- it over rho_c.
local function surface(f)
  local hs = {}
  for i = 1, nx do
    local sum = 0
    for j = jb, ny do sum = sum + at(f.density, i, j) * (j == jb and 0.5 or 1) end
    hs[i] = yb + sum * cg_h / rho_c
  end
  return hs
end

-- The weight above each cell per unit area (the column's density integrated from the cell's
-- centre up): sigma_yy over it is 1 where a column carries its own weight.
local function overburden(f)
  local ob = {}
  for i = 1, nx do
    local acc = 0
    for j = ny, 1, -1 do
      local r = at(f.density, i, j)
      ob[(j - 1) * nx + i] = g * cg_h * (acc + 0.5 * r)
      acc = acc + r
    end
  end
  return ob
end

-- DEM (A) against a continuum (B), cell by cell: the interior (x >= w, from the base row to 2 w
-- under both surfaces) for the stresses, their ratio to the weight above and the volume
-- fraction; the cells filled (rho >= rho_c / 2) by either.
local function compare(A, B)
  local hA, hB, oA, oB = surface(A), surface(B), overburden(A), overburden(B)
  local o = { cells = 0 }
  local s2, smax, sm, p2, dphi, dphi2, phiA, phiB, either, both = 0, 0, 0, 0, 0, 0, 0, 0, 0, 0
  local kA, kB, dk2 = 0, 0, 0
  for j = 1, ny do
    local y = yc(j)
    for i = 1, nx do
      local x = xc(i)
      local fa, fb = at(A.density, i, j) >= 0.5 * rho_c, at(B.density, i, j) >= 0.5 * rho_c
      if x > 0 and y > 0 and (fa or fb) then
        either = either + 1
        if fa and fb then both = both + 1 end
      end
      if x >= cg_w and j >= jb and y <= hA[i] - 2 * cg_w and y <= hB[i] - 2 * cg_w then
        local sa, sb = at(A.stress.yy, i, j), at(B.stress.yy, i, j)
        local rel = (sb - sa) / sa
        local rp = at(B.stress.pressure, i, j) / at(A.stress.pressure, i, j) - 1
        local pa, pb = at(A.density, i, j) / rho_s, at(B.density, i, j) / rho_s
        o.cells = o.cells + 1
        s2, smax, sm, p2 = s2 + rel * rel, math.max(smax, math.abs(rel)), sm + rel, p2 + rp * rp
        dphi, dphi2, phiA, phiB = dphi + (pb - pa), dphi2 + (pb - pa) ^ 2, phiA + pa, phiB + pb
        local ra, rb = sa / at(oA, i, j), sb / at(oB, i, j)
        kA, kB, dk2 = kA + ra, kB + rb, dk2 + (rb - ra) ^ 2
      end
    end
  end
  local c = math.max(o.cells, 1)
  o.syy_rel_rms, o.syy_rel_max, o.syy_rel_mean = math.sqrt(s2 / c), smax, sm / c
  o.pressure_rel_rms = math.sqrt(p2 / c)
  o.phi_dem, o.phi_mpm, o.phi_diff_rms = phiA / c, phiB / c, math.sqrt(dphi2 / c)
  o.filled_both_over_either = both / math.max(either, 1)
  o.syy_over_weight_above_dem, o.syy_over_weight_above_mpm = kA / c, kB / c
  o.syy_over_weight_above_diff_rms = math.sqrt(dk2 / c)
  return o
end

-- Under the column (0 < x < W0), on the base row: sigma_yy and the pressure averaged over the
-- strip against the weight above it per unit area.
local function base(f)
  local syy, p, M, cnt = 0, 0, 0, 0
  for i = 1, nx do
    local x = xc(i)
    if x > 0 and x < W0 then
      cnt = cnt + 1
      syy, p = syy + at(f.stress.yy, i, jb), p + at(f.stress.pressure, i, jb)
      for j = jb, ny do M = M + at(f.density, i, j) * (j == jb and 0.5 or 1) end
    end
  end
  local wpa = g * M * cg_h / cnt
  return { syy = syy / cnt, pressure = p / cnt, weight_per_area = wpa }
end


metrics.cg_kernel, metrics.cg_width_m, metrics.cg_cutoff_m, metrics.cg_cell_m = "gauss", cg_w, cg_c, cg_h
metrics.cg_cells_x, metrics.cg_cells_y, metrics.cg_base_row_y_m = nx, ny, yb
metrics.cg_dem_depth_m, metrics.cg_cpu_s = deposit.dem.depth, cg_cpu
for _, k in ipairs(keys) do
  local b, bs = balance(k), base(F[k])
  local mrel = cg_mass(k) / deposit[k].mass_all - 1
  metrics["cg_mass_rel_err_" .. k] = mrel
  metrics["mass_per_depth_kg_m_" .. k] = deposit[k].mass
  metrics["floor_load_over_weight_" .. k] = b.floor_load / b.weight
  metrics["wall_support_over_weight_" .. k] = b.wall_support / b.weight
  metrics["floor_balance_rel_" .. k] = b.balance
  metrics["base_syy_pa_" .. k], metrics["base_pressure_pa_" .. k] = bs.syy, bs.pressure
  metrics["base_weight_per_area_pa_" .. k] = bs.weight_per_area
  metrics["base_syy_over_weight_" .. k] = bs.syy / bs.weight_per_area
  metrics["base_pressure_over_weight_" .. k] = bs.pressure / bs.weight_per_area
  checks[#checks + 1] = { name = "cg_mass_" .. k, value = math.abs(mrel), limit = 1e-12 }
  checks[#checks + 1] = { name = "floor_load_is_weight_" .. k, value = math.abs(b.floor_load / (b.weight - b.wall_support) - 1),
                          limit = FLOOR_TOL[k] }
  if k ~= "dem" then
    metrics["mass_per_depth_over_dem_" .. k] = deposit[k].mass / deposit.dem.mass
    for name, v in pairs(compare(F.dem, F[k])) do metrics["cg_" .. name .. "_" .. k] = v end
  end
end

-- Figure: sigma_yy of the three deposits stacked (DEM, Drucker-Prager, mu(I) from the top), on one
-- colour scale, cells holding less than 0.3 rho_c left blank.
do
  local fx = math.min(nx, math.ceil((math.max(st_dem.front, runs[1].state.front, runs[2].state.front) + cg_c - x0) / cg_h))
  local j0 = math.floor(-y0 / cg_h) + 1          -- the first row above the floor
  local rows = math.ceil((top - yc(j0)) / cg_h) + 1
  local gap = 3
  local vals, hi = {}, 0
  local tot = 3 * rows + 2 * gap
  for q = 1, fx * tot do vals[q] = 0 / 0 end
  for p, k in ipairs(keys) do
    local r0 = (3 - p) * (rows + gap)           -- DEM on top
    for j = 1, rows do
      for i = 1, fx do
        local jj = j0 + j - 1
        if jj <= ny and at(F[k].density, i, jj) >= 0.3 * rho_c then
          local v = at(F[k].stress.yy, i, jj)
          vals[(r0 + j - 1) * fx + i] = v
          hi = math.max(hi, v)
        end
      end
    end
  end
  local fig = { dim = 2, cells = { fx, tot }, region = { { x0 * 1e3, 0 }, { (x0 + fx * cg_h) * 1e3, tot * cg_h * 1e3 } },
                stress = { yy = vals } }
  render.coarse_grain(fig, { file = out .. "_fields.png", show = "yy", range = { 0, hi }, width = 1000,
                             label = "sigma_yy (Pa)",
                             title = string.format("sigma_yy, Gaussian w = %g mm, 0 < x < %.0f mm: DEM (top), Drucker-Prager, mu(I) (bottom)",
                                                   cg_w * 1e3, (x0 + fx * cg_h) * 1e3) })
end

grainlab.report{
  scenario = "column_two_scales",
  params = { cells = cells, n = n, floor_mu = 0.5, grain_diameter = d, grain_density = rho_s,
             shear = mat_o.shear, bulk = mat_o.bulk, i0 = mat_o.i0 },
  metrics = metrics,
  checks = checks,
}
