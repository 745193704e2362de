-- Coarse-grained fields of a static pile: momentum balance and the floor's load (Weinhart,
-- Thornton, Luding & Bokhove 2012; docs/coarse-graining.md).
--
-- In a packing at rest every grain's contact forces balance its weight, F_i + m_i g = 0. The
-- contact stress sigma_ab = sum_c b_a f_b psi_c (compression positive, b from the partner or the
-- wall's contact point to the grain) has the divergence d_a sigma_ab = -sum_i F_ib phi(r - x_i) +
-- t_b, t the walls' force density at their contact points, so that away from the floor
-- d_a sigma_ab = rho g_b (the kinetic stress of grains at rest is nil): the residual
-- |div sigma - rho g| / (rho |g|) measures how static the bed is and how exactly the stress field
-- was computed. Here the divergence is taken from the grid by fourth-order central differences
-- (spacing w / 8: their error is ~1e-4 of rho g for the Gaussian's smoothness), on the cells at
-- least cutoff + d above the floor and cutoff + 2 d below the top of the bed. Averaged over the
-- periodic x, the balance gives sigma_yy(y) = integral from y up of rho |g|: the vertical stress is
-- the weight above per unit area, and at the floor the whole weight per unit width, which the
-- floor's force density t integrates to (and the DEM's own wall force).
-- Bed: scripts/cg_bed.lua (n disks, d = 1 mm, periodic width W, settled to rest).
-- The Gaussian is cut at 5 w here (cutoff=, in widths): the default cut at 3 w leaves a jump of
-- 1.1 % of the peak at the edge of every grain's and contact's support, which a derivative taken
-- from the grid turns into errors of 10-30 % of rho g (measured); at 5 w the jump is 4e-6 of the
-- peak. Lucy (C2: its third derivative jumps) leaves 3-9 % at w = 2-3 d, h = w / 8.
-- The floor's force density integrates to the wall force to the grid's quadrature error (1e-4
-- with the cut at 3 w, 1e-6 at 5 w).
--   grainlab scripts/cg_pile.lua [n=1200] [width=30] [seed=1] [w=1] (w in diameters)
--                                [kernel=gauss|lucy] [cutoff=5] [cache=out/cg_bed_...ckpt]
-- Figures: the vertical and horizontal stress against height with the weight above, and the
-- map of the principal stress difference with its directions (images/ from the default run only).
local cg_bed = dofile((arg[0]:match("^(.*)/") or ".") .. "/cg_bed.lua")
local n, wd, seed = params.n or 1200, params.width or 30, params.seed or 1
local wrel, kernel = params.w or 1, params.kernel or "gauss"
local cutrel = kernel == "gauss" and (params.cutoff or 5) or nil -- in widths
local figures = require("grainlab.figures")
local fig = { published = figures.published({ n = n, width = wd, seed = seed, w = wrel, kernel = kernel, cutoff = cutrel },
                                            { n = 1200, width = 30, seed = 1, w = 1, kernel = "gauss", cutoff = 5 }) }
local png_profile = params.png or figures.path("cg_pile_profile.png", fig)
local png_map = params.png_map or figures.path("cg_pile_psd.png", fig)

local s, bed = cg_bed.get{ n = n, width = wd, seed = seed, cache = params.cache }
local d, g, depth = cg_bed.d, cg_bed.g, cg_bed.depth
local W = bed.W
local worst, top = cg_bed.state(s)
local w = wrel * d
local cg = { width = w, kernel = kernel, cutoff = cutrel and cutrel * w }
local function opts(t) for k, v in pairs(cg) do t[k] = v end return t end
local F0 = analysis.coarse_grain(s, opts{ points = { x = { 0 }, y = { 0 } } })
local cut = F0.cutoff
local h = w / 8
local nx = math.floor(W / h + 0.5)
local y0, y1 = -cut - 2 * h, top + cut + 2 * h
local ny = math.floor((y1 - y0) / h + 0.5)
y1 = y0 + ny * (W / nx)
local t0 = grainlab.clock()
local F = analysis.coarse_grain(s, opts{ cells = { nx, ny }, region = { { 0, y0 }, { W, y1 } } })
local t_cg = grainlab.clock() - t0
local hx, hy = W / nx, (y1 - y0) / ny
local S, rho = F.stress, F.density
local function at(t, i, j) -- periodic in x
  i = (i - 1) % nx + 1
  return t[(j - 1) * nx + i]
end
-- fourth-order central differences
local function dx(t, i, j) return (-at(t, i + 2, j) + 8 * at(t, i + 1, j) - 8 * at(t, i - 1, j) + at(t, i - 2, j)) / (12 * hx) end
local function dy(t, i, j) return (-at(t, i, j + 2) + 8 * at(t, i, j + 1) - 8 * at(t, i, j - 1) + at(t, i, j - 2)) / (12 * hy) end

local ylo, yhi = cut + d, top - cut - 2 * d
local worst_res, sum2, count, worst_at = 0, 0, 0, nil
for j = 3, ny - 2 do
  local y = y0 + (j - 0.5) * hy
  if y >= ylo and y <= yhi then
    for i = 1, nx do
      local r = at(rho, i, j)
      local rx = dx(S.xx, i, j) + dy(S.yx, i, j)        -- d_a sigma_ax - rho g_x (g_x = 0)
      local ry = dx(S.xy, i, j) + dy(S.yy, i, j) + r * g -- d_a sigma_ay - rho g_y
      local rel = math.sqrt(rx * rx + ry * ry) / (r * g)
      sum2, count = sum2 + rel * rel, count + 1
      if rel > worst_res then worst_res, worst_at = rel, { i = i, j = j, x = (i - 0.5) * hx, y = y } end
    end
  end
end
local rms_res = math.sqrt(sum2 / count)

-- x-averaged profiles: sigma_yy, sigma_xx, and the weight above per unit area (from the CG density)
local syy, sxx, wt, ys = {}, {}, {}, {}
for j = 1, ny do
  local a, b, r = 0, 0, 0
  for i = 1, nx do a, b, r = a + at(S.yy, i, j), b + at(S.xx, i, j), r + at(rho, i, j) end
  syy[j], sxx[j], ys[j], wt[j] = a / nx, b / nx, y0 + (j - 0.5) * hy, r / nx
end
local above = {} -- integral of rho g from the row's centre to the top (midpoint sums)
local acc = 0
for j = ny, 1, -1 do
  above[j] = acc + 0.5 * wt[j] * g * hy
  acc = acc + wt[j] * g * hy
end
local worst_prof = 0
for j = 1, ny do
  if ys[j] >= ylo and ys[j] <= yhi then
    worst_prof = math.max(worst_prof, math.abs(syy[j] - above[j]) / above[j])
  end
end
-- the floor: the whole weight per unit width, the floor's force density, the DEM's wall force
local P = s:particles()
local weight = 0
for i = 1, P.count do weight = weight + P.mass[i] * g end
local weight_pa = weight / (W * depth)
local trac = 0
for k = 1, F.n do trac = trac + F.traction.y[k] end
trac = trac * F.cell_volume / W -- N per m^2 of floor (the fields are per depth)
local wall = s:wall_force(1)
local wall_pa = wall / (W * depth)
-- sigma_yy of the lowest bulk row plus the weight below it (per area)
local jb
for j = 1, ny do if ys[j] >= ylo then jb = j; break end end
local floor_from_bulk = syy[jb] + (above[1] - above[jb])

local metrics = {
  particles = P.count, bed_width_m = W, bed_top_m = top, width_m = w, cutoff_m = cut,
  grid = { nx, ny }, grid_spacing_m = hx, cg_seconds = t_cg, prep_seconds = bed.prep_s,
  largest_net_force_over_weight = worst, coordination = s:measure("coordination").z,
  balance_residual_max = worst_res, balance_residual_rms = rms_res, balance_cells = count,
  balance_worst_x_m = worst_at.x, balance_worst_y_m = worst_at.y,
  profile_syy_vs_weight_max = worst_prof,
  weight_per_area_pa = weight_pa, floor_traction_pa = trac, floor_wall_force_pa = wall_pa,
  floor_from_bulk_pa = floor_from_bulk,
  k0_mid = sxx[math.floor((jb + ny) / 2)] / syy[math.floor((jb + ny) / 2)],
}
local checks = {
  { name = "static_bed", value = worst, limit = 0.05 },
  { name = "momentum_balance_max", value = worst_res, limit = 0.01 },
  { name = "syy_is_weight_above", value = worst_prof, limit = 0.01 },
  { name = "floor_traction_is_weight", value = math.abs(trac / weight_pa - 1), limit = 0.01 },
  { name = "floor_traction_is_wall_force", value = math.abs(trac / wall_pa - 1), limit = 1e-3 },
  { name = "floor_from_bulk_is_weight", value = math.abs(floor_from_bulk / weight_pa - 1), limit = 0.01 },
}

-- figures
os.execute("mkdir -p '" .. png_profile:match("^(.*)/[^/]*$") .. "'")
local py, pyy, pxx, pw = {}, {}, {}, {}
for j = 1, ny, 2 do
  py[#py + 1] = ys[j] / d
  pyy[#pyy + 1] = syy[j]
  pxx[#pxx + 1] = sxx[j]
  pw[#pw + 1] = above[j]
end
render.plot{ file = png_profile, title = string.format("Static bed, %d disks: stresses averaged over x (%s, w = %g d)", P.count, kernel, wrel),
             xlabel = "height y / d", ylabel = "stress (Pa)",
             series = { { x = py, y = pw, label = "weight above per area (integral of rho g)", style = "line" },
                        { x = py, y = pyy, label = "sigma_yy", style = "points" },
                        { x = py, y = pxx, label = "sigma_xx", style = "points" } } }
local Fm = analysis.coarse_grain(s, opts{ cells = { math.floor(W / (w / 3)), math.floor((top + d) / (w / 3)) },
                                         region = { { 0, 0 }, { W, top + d } } })
render.coarse_grain(Fm, { file = png_map, show = "psd", glyph_every = 3, interpolation = "bilinear",
                          title = string.format("Principal stress difference and major direction (%s, w = %g d)", kernel, wrel) })
print("wrote " .. png_profile .. ", " .. png_map)

grainlab.report{
  scenario = "cg_pile",
  params = { n = n, width_d = wd, seed = seed, w_d = wrel, kernel = kernel, cutoff_w = cutrel or 1,
             diameter_m = d },
  metrics = metrics,
  checks = checks,
}
