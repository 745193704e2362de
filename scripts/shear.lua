-- grainlab MPM reproduction: large shear of a polydisperse granular slab with and without
-- frictional contact (Bardenhagen, Brackbill & Sulsky 1998, Sec. 4, Figs. 5-8).
--
-- The paper's set-up: 369 disks, diameters 31-250 um with mean 57 um, in a 1.2 mm x 1.2 mm domain
-- periodic in y, 150 x 150 cells, 4 points per cell (points_per_cell = 2), HMX as von Mises
-- (G 7.5 GPa, K 11.4 GPa, yield 0.3 GPa, hardening 0.01 GPa, rho 1900 kg/m^3). The grains
-- overlapping the left edge are fixed, those overlapping the right edge move up at 100 m/s
-- (m:prescribe; they are clipped at the edge), and the grid's left and right walls do the same;
-- mu = 0.3. Average shear gamma = v t / L (8e4 /s), run to 80%.
--
-- Packing (Fig. 5): diameters d = 31 um + an exponential of mean 26 um, truncated at 250 um and
-- rescaled to a mean of exactly 57 um; placed largest first at random in a slab 1.8 L wide
-- (periodic in y), then compacted with the DEM module: frictionless soft Hertz disks, the right
-- wall pushed in to L, settled with drag; finally every radius shrinks by the largest relative
-- overlap the soft contacts left, so no two grains overlap. Area fraction and shrink reported.
--
-- Outputs (images/shear_*.png): the initial configuration coloured by grain (Fig. 5); the
-- deformed state at 75% shear for noslip and friction (Fig. 6); the principal stress difference
-- sigma_1 - sigma_2 at 63% and 71% shear with friction (Fig. 7); the column-averaged vertical
-- displacement at 25/50/75% beside the uniform profile (Fig. 8). Metrics: the shear-band width in
-- mean grain diameters (paper: about 7) from the friction run's 75% profile: the width of the
-- band that takes the middle 80% of the total displacement jump (10% to 90% of the right
-- boundary's displacement); the plastic work for noslip and friction at 75% (the paper: far
-- more plastic deformation without slip).
--
-- params: scale (fraction of the domain side, the grains keep their size; default 1), shear
-- (final average shear, default 0.8), mu (0.3), cfl (0.4), seed (5), models ('both' | 'noslip'
-- | 'friction'), out (image prefix, default images/shear for the default run, out/shear for
-- any other).
--   grainlab scripts/shear.lua [scale=1] [shear=0.8] [mu=0.3] [cfl=0.4] [seed=5]
--       [models=both|noslip|friction] [out=out/shear]
local scale = tonumber(params.scale or 1)
local shear_end = tonumber(params.shear or 0.8)
local mu = tonumber(params.mu or 0.3)
local cfl = tonumber(params.cfl or 0.4)
local seed = math.tointeger(tonumber(params.seed or 5))
local models = params.models or "both"
-- The default run publishes into images/ (docs/mpm.md shows it); any other (scale=0.25 is a
-- test) writes to out/ (grainlab.figures).
local figures = require("grainlab.figures")
local out = params.out or figures.path("shear", {
  published = figures.published({ scale = scale, shear = shear_end, mu = mu, cfl = cfl, seed = seed, models = models },
                                { scale = 1, shear = 0.8, mu = 0.3, cfl = 0.4, seed = 5, models = "both" }) })

local L = 1.2e-3 * scale
local cells = math.max(8, math.floor(150 * scale + 0.5))
local v_top = 100
local n_grains = math.max(6, math.floor(369 * scale * scale + 0.5))
local d_mean, d_min, d_max = 57e-6, 31e-6, 250e-6

-- ---- packing -------------------------------------------------------------------------------
local t_pack = os.clock()
-- the packing extends half a mean diameter beyond each edge, so that grains overlap the edges
local margin = 0.5 * d_mean
local pk = grainlab.pack.slab{ size = L, n = math.floor(n_grains * (L + 2 * margin) / L + 0.5), margin = margin,
                               diameter = { d_min, d_mean, d_max }, seed = seed }
n_grains = #pk.x
t_pack = os.clock() - t_pack
local x, y, r, phi, worst = pk.x, pk.y, pk.r, pk.area_fraction, pk.shrink
local d_final = 2 * pk.mean_radius

-- ---- MPM runs --------------------------------------------------------------------------------
local hmx = mpm.material{ model = "vonmises", density = 1900, shear = 7.5e9, bulk = 11.4e9,
                          yield = 0.3e9, hardening = 0.01e9 }
local h = L / cells
local function build(model)
  local m = mpm.scene{ cells = { cells, cells }, size = { L, L }, periodic = { false, true },
                       walls = { left = "noslip", right = { kind = "noslip", velocity = { 0, v_top } } } }
  local left, right = {}, {}
  for i = 1, n_grains do
    -- a disk reaching less than half a cell into the domain would hold no point: left out
    if x[i] + r[i] > 0.5 * h and x[i] - r[i] < L - 0.5 * h then
      local g = m:add_disk{ center = { x[i], y[i] }, radius = r[i], material = hmx, points_per_cell = 2,
                            clip = true }
      if x[i] - r[i] < 0 then left[#left + 1] = g elseif x[i] + r[i] > L then right[#right + 1] = g end
    end
  end
  for _, g in ipairs(left) do m:prescribe(g, { 0, 0 }) end
  for _, g in ipairs(right) do m:prescribe(g, { 0, v_top }) end
  if model == "friction" then m:contact{ model = "friction", mu = mu } end
  return m, #left, #right
end

local function grain_colours(m)
  local p = m:points()
  local v = {}
  for i = 1, p.count do v[i] = ((p.grain[i] * 0.618034) % 1) end
  return p, v
end
local function draw_grains(m, file, title)
  local p, v = grain_colours(m)
  render.points{ file = file, width = 800, height = 800, x = p.x, y = p.y, values = v,
                 size = math.max(1.5, 800 / cells / 2 * 1.1), extent = { { 0, 0 }, { L, L } },
                 colorbar = false, title = title }
end

local m_probe = build("noslip")
n_grains = m_probe:info().grains
m_probe = nil
local metrics, checks = { grains = n_grains, area_fraction = phi, mean_diameter_um = d_final * 1e6,
                          cells = cells, h_m = h, packing_overlap_removed = worst, packing_cpu_s = t_pack }, {}
local profiles, timing = {}, {}
local m0 = build("noslip")
metrics.points = m0:info().points
draw_grains(m0, out .. "_initial.png", string.format("%d grains, area fraction %.2f (Fig. 5)", n_grains, phi))
m0 = nil

local run_models = models == "both" and { "noslip", "friction" } or { models }
for _, model in ipairs(run_models) do
  local m, nl, nr = build(model)
  metrics["prescribed_left_" .. model], metrics["prescribed_right_" .. model] = nl, nr
  local marks = { 0.25, 0.5, 0.63, 0.71, 0.75, shear_end }
  table.sort(marks)
  local t0, w0 = os.clock(), grainlab.clock()
  local steps = 0
  for _, gamma in ipairs(marks) do
    if gamma <= shear_end then
      local t_target = gamma * L / v_top
      local dt_left = t_target - m:info().time
      if dt_left > 0 then
        local res = m:run{ time = dt_left, cfl = cfl }
        steps = steps + res.steps
      end
      local tag = string.format("%02d", math.floor(gamma * 100 + 0.5))
      if gamma == 0.25 or gamma == 0.5 or gamma == 0.75 then
        profiles[model .. tag] = m:measure("columns")
      end
      if gamma == 0.75 then
        draw_grains(m, string.format("%s_%s_75.png", out, model),
                    string.format("%s, 75%% shear (Fig. 6%s)", model == "noslip" and "no slip" or "friction mu = " .. mu, model == "noslip" and "a" or "b"))
        local e = m:measure("energy")
        metrics["plastic_work_75_" .. model] = e.plastic
        metrics["material_shear_75_" .. model] = m:measure("shear")
      end
      if model == "friction" and (gamma == 0.63 or gamma == 0.71) then
        local f = m:field("psd")
        render.field{ file = string.format("%s_psd_%s.png", out, tag), width = 800, height = 800,
                      values = f.values, nx = f.nx, ny = f.ny, extent = { { 0, 0 }, { L, L } },
                      colormap = "gray", background = { 0, 0, 0 }, label = "sigma_1 - sigma_2 (Pa)", interpolation = "bilinear",
                      title = string.format("Principal stress difference, %d%% shear (Fig. 7)", math.floor(gamma * 100 + 0.5)) }
      end
    end
  end
  timing[model] = grainlab.clock() - w0
  metrics["cpu_s_" .. model] = os.clock() - t0
  metrics["wall_s_" .. model] = timing[model]
  metrics["steps_" .. model] = steps
  metrics["point_steps_per_s_" .. model] = metrics.points * steps / timing[model]
end

-- ---- Fig. 8 and the shear band ----------------------------------------------------------------
local series = {}
local ref = models == "noslip" and "noslip" or "friction"
for _, tag in ipairs({ "25", "50", "75" }) do
  local c = profiles[ref .. tag]
  if c then
    local xs, ys = {}, {}
    for i = 1, #c.x do
      if c.uy[i] == c.uy[i] then xs[#xs + 1], ys[#ys + 1] = c.x[i] * 1e3, c.uy[i] * 1e6 end
    end
    series[#series + 1] = { x = xs, y = ys, label = tag .. "% shear (" .. ref .. ")", style = "points" }
    local gamma = tonumber(tag) / 100
    series[#series + 1] = { x = { 0, L * 1e3 }, y = { 0, gamma * L * 1e6 }, label = tag .. "% uniform", style = "line" }
  end
end
if #series > 0 then
  render.plot{ file = out .. "_columns.png", width = 900, height = 600,
               title = "Column-averaged vertical displacement (Fig. 8)", xlabel = "x (mm)",
               ylabel = "mean u_y (um)", series = series }
end
local c75 = profiles[ref .. "75"]
if c75 then
  local U = 0.75 * L
  local x10, x90
  for i = 1, #c75.x do
    local u = c75.uy[i]
    if u == u then
      if not x10 and u >= 0.1 * U then x10 = c75.x[i] end
      if not x90 and u >= 0.9 * U then x90 = c75.x[i] end
    end
  end
  if x10 and x90 then
    metrics.band_width_diameters = (x90 - x10) / d_mean
    metrics.band_width_fraction_of_domain = (x90 - x10) / L
  end
end
if metrics.plastic_work_75_noslip and metrics.plastic_work_75_friction then
  metrics.plastic_work_ratio_noslip_over_friction = metrics.plastic_work_75_noslip / metrics.plastic_work_75_friction
  checks[#checks + 1] = { name = "noslip_deforms_more_plastically", value = metrics.plastic_work_ratio_noslip_over_friction, limit = 1, op = ">" }
end
checks[#checks + 1] = { name = "area_fraction_dense", value = phi, limit = 0.6, op = ">=" }
if metrics.band_width_diameters then
  checks[#checks + 1] = { name = "shear_band_narrower_than_domain", value = metrics.band_width_fraction_of_domain, limit = 1, op = "<" }
end

grainlab.report{
  scenario = "shear",
  params = { scale = scale, shear = shear_end, mu = mu, cfl = cfl, seed = seed, models = models,
             size_m = L, cells = cells, v_m_per_s = v_top },
  metrics = metrics,
  checks = checks,
}
