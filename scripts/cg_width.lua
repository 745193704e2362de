-- The width study of coarse-graining (Weinhart, Thornton, Luding & Bokhove 2012, Sec. 5): the
-- fields of the static bed (scripts/cg_bed.lua) against the kernel width w from 0.5 d to 4 d.
--
-- Below a grain diameter the fields resolve single grains and force chains: the stress at a
-- point jumps with w, and along a row at mid-depth it fluctuates about its mean by as much as the
-- mean. As w grows the fluctuations shrink (about as 1 / w: a Gaussian of width w averages some
-- (w / d)^2 grains) and the stress at a point settles on the continuum value, the weight above per
-- unit area; but a wide kernel also smears the boundaries: at a height y0 above the floor
-- the x-averaged sigma_yy falls short of the weight above, because part of the kernel reaches
-- below the floor's contact points, where the stress is 0 (the floor's force enters as the
-- boundary force density there); the Gaussian reaches 3 w, so the bias at y0 sets in once 3 w
-- approaches y0. The plateau is the range of w where both are small: the local fluctuation
-- below 20 % and the floor bias at y0 = 6 d below 1 %: the fields there no longer depend on w
-- beyond the grain-scale scatter that remains (force chains: in a static bed nothing averages it
-- but the kernel; a flow would add time averages).
-- Kernel: the Gaussian cut at 3 w (MercuryCG's default).
--   grainlab scripts/cg_width.lua [n=1200] [width=30] [seed=1] [widths=0.5,0.75,1,1.5,2,3,4] [y0=6]
--                                 [cache=out/cg_bed_...ckpt]
-- Figures (images/ from the default run only): the stress at points of the mid-depth row against
-- w, and the fluctuation and the floor bias against w.
local cg_bed = dofile((arg[0]:match("^(.*)/") or ".") .. "/cg_bed.lua")
local n, wd, seed = params.n or 1200, params.width or 30, params.seed or 1
local widths = {}
for v in tostring(params.widths or "0.5,0.75,1,1.5,2,3,4"):gmatch("[^,]+") do widths[#widths + 1] = assert(tonumber(v)) end
local y0 = params.y0 or 6 -- diameters above the floor where the bias is measured
local figures = require("grainlab.figures")
local fig = { published = params.widths == nil and
                          figures.published({ n = n, width = wd, seed = seed, y0 = y0 },
                                            { n = 1200, width = 30, seed = 1, y0 = 6 }) }
local png_points = params.png or figures.path("cg_width_points.png", fig)
local png_study = params.png_study or figures.path("cg_width_study.png", fig)

local s, bed = cg_bed.get{ n = n, width = wd, seed = seed, cache = params.cache }
local d, g, W = cg_bed.d, cg_bed.g, bed.W
local _, top = cg_bed.state(s)
local P = s:particles()

-- the weight above y per unit area, counted by grain centres (the continuum value at y)
local function weight_above(y)
  local m = 0
  for i = 1, P.count do if P.y[i] > y then m = m + P.mass[i] end end
  return m * g / (W * cg_bed.depth)
end

local y_mid, y_floor = 0.5 * top, y0 * d
local nrow = math.floor(W / (0.1 * d))
local xs, ym, yf = {}, {}, {}
for i = 1, nrow do xs[i] = (i - 0.5) * W / nrow; ym[i] = y_mid; yf[i] = y_floor end
local probes = { 0.1, 0.3, 0.5, 0.7, 0.9 } -- fractions of W along the mid row
local px, py = {}, {}
for k, f in ipairs(probes) do px[k], py[k] = f * W, y_mid end
local hyd_mid = weight_above(y_mid)

local rows = {}
for _, wrel in ipairs(widths) do
  local w = wrel * d
  local R = analysis.coarse_grain(s, { width = w, points = { x = xs, y = ym } })
  local Pr = analysis.coarse_grain(s, { width = w, points = { x = px, y = py } })
  local mean, m2 = 0, 0
  for i = 1, nrow do mean = mean + R.stress.yy[i] / nrow end
  for i = 1, nrow do m2 = m2 + (R.stress.yy[i] - mean) ^ 2 / nrow end
  -- the floor bias: sigma_yy averaged over x at y0 against the weight above y0 of the same
  -- fields' density (integral of rho g from y0 up, over a grid of w / 8 rows): equal outside
  -- the floor's boundary layer (the balance), short of it inside
  local cut = R.cutoff
  local hy = w / 8
  local nyb = math.ceil((top + cut - y_floor) / hy)
  local nxb = math.ceil(W / math.min(0.25 * d, w / 3))
  local B = analysis.coarse_grain(s, { width = w, cells = { nxb, nyb },
                                       region = { { 0, y_floor - 0.5 * hy }, { W, y_floor - 0.5 * hy + nyb * hy } } })
  local wt, s0 = 0, 0
  for j = 1, nyb do
    local rr = 0
    for i = 1, nxb do rr = rr + B.density[(j - 1) * nxb + i] end
    wt = wt + rr / nxb * g * hy * (j == 1 and 0.5 or 1) -- from the first row's centre, y0
  end
  for i = 1, nxb do s0 = s0 + B.stress.yy[i] / nxb end
  local r = { w = wrel, mean = mean / hyd_mid, fluct = math.sqrt(m2) / mean, bias = 1 - s0 / wt, points = {} }
  for k = 1, #probes do r.points[k] = Pr.stress.yy[k] / hyd_mid end
  rows[#rows + 1] = r
end

-- the plateau: fluctuation below 20 % and floor bias below 1 %
local plateau = {}
for _, r in ipairs(rows) do
  if r.fluct < 0.20 and math.abs(r.bias) < 0.01 then plateau[#plateau + 1] = r.w end
end

local checks = {}
local metrics = { particles = P.count, y_mid_m = y_mid, hydrostatic_mid_pa = hyd_mid,
                  plateau_w_over_d = plateau }
for _, r in ipairs(rows) do
  local tag = string.format("w%g", r.w):gsub("%.", "_")
  metrics["fluctuation_" .. tag] = r.fluct
  metrics["floor_bias_" .. tag] = r.bias
  metrics["row_mean_over_weight_" .. tag] = r.mean
end
checks[#checks + 1] = { name = "fluctuation_falls", value = rows[#rows].fluct / rows[1].fluct, limit = 1 / 3 }
checks[#checks + 1] = { name = "floor_bias_grows", value = rows[#rows].bias - rows[1].bias, limit = 0, op = ">" }
checks[#checks + 1] = { name = "plateau_exists", value = #plateau, limit = 1, op = ">=" }
-- the row mean is the weight above at every w (the balance, averaged over the period)
local worst_mean = 0
for _, r in ipairs(rows) do worst_mean = math.max(worst_mean, math.abs(r.mean - 1)) end
metrics.row_mean_worst = worst_mean
checks[#checks + 1] = { name = "row_mean_is_weight", value = worst_mean, limit = 0.02 }

os.execute("mkdir -p '" .. png_points:match("^(.*)/[^/]*$") .. "'")
local series = {}
for k, f in ipairs(probes) do
  local x, y = {}, {}
  for _, r in ipairs(rows) do x[#x + 1] = r.w; y[#y + 1] = r.points[k] end
  series[#series + 1] = { x = x, y = y, label = string.format("x = %.1f W", f), style = "both" }
end
render.plot{ file = png_points, title = "sigma_yy at points of the mid-depth row / weight above, against the width",
             xlabel = "w / d", ylabel = "sigma_yy / (weight above per area)", xlog = true, series = series }
local wx, fy, by = {}, {}, {}
for _, r in ipairs(rows) do wx[#wx + 1] = r.w; fy[#fy + 1] = r.fluct; by[#by + 1] = math.max(math.abs(r.bias), 1e-4) end
render.plot{ file = png_study, title = string.format("Width study: fluctuation along the mid row, bias %g d above the floor", y0),
             xlabel = "w / d", ylabel = "relative", xlog = true, ylog = true,
             series = { { x = wx, y = fy, label = "rms of sigma_yy along x / its mean (mid-depth)", style = "both" },
                        { x = wx, y = by, label = string.format("1 - sigma_yy / weight above, %g d above the floor (at least 1e-4)", y0), style = "both" } } }
print("wrote " .. png_points .. ", " .. png_study)

grainlab.report{
  scenario = "cg_width",
  params = { n = n, width_d = wd, seed = seed, widths = widths, kernel = "gauss", cutoff_w = 3, y0_d = y0 },
  metrics = metrics,
  checks = checks,
}
