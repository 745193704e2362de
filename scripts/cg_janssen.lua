-- Janssen's silo by coarse-graining: the vertical stress in a filled 2D silo saturates with depth
-- because the walls carry the weight by friction (Janssen 1895; Sperl 2006).
--
-- A slice of a slab silo of width D (two walls) at depth z below the surface balances its weight
-- against the friction of the walls: d(D sigma_v)/dz = rho_b g D - 2 tau_w, tau_w = mu sigma_h,
-- sigma_h = K sigma_v. Hence sigma_v(z) = sigma_inf (1 - exp(-z / lambda)) with
-- lambda = D / (2 K mu) and sigma_inf = rho_b g lambda. The coarse-grained fields give every term
-- of this balance exactly: d_a sigma_ab = rho g_b + t_b, t the walls' force density at their
-- contact points, so integrating over x across the whole silo (the walls' boundary layers
-- included) turns it into the slice balance with sigma_v = (1/D) integral of sigma_yy dx, and
-- the walls' normal and tangential loads per unit height are the integrals of t_x and t_y over
-- each wall's layer. The mobilised wall friction mu_m = tau_w / sigma_h is measured (a settled
-- fill does not slide on its walls everywhere), and K is reported two ways: from the fitted
-- lambda, K_fit = D / (2 mu_m lambda), and directly, K_dir = sigma_h / sigma_v over the depths
-- where both are resolved (below 2 D).
-- Silo: walls at x = 0 and D (mu 0.5, the grains' own), floor at y = 0; n disks, radius uniform
-- in [0.4, 0.6] mm, cylinders 1 mm thick (Pa), density 2650, Hertz (E = 1e7 Pa: soft, a long
-- step), Brilliantov damping (restitution 0.5), Cundall-Strack spring. Jodrey-Tory deposition between the walls, settled under a fifth of
-- gravity, then gravity raised to g in `stages` steps of `stage_s` seconds (with a drag of
-- 20/s) and settled: every layer is loaded more and more and sinks monotonically past the walls,
-- so that their friction points up at every height, as when a silo is filled from above
-- (Janssen's assumption). A fill settled at g at once keeps pockets near its top where the walls
-- pull it down (it overshoots and rebounds as it sags): sigma_v then grows faster than
-- hydrostatic there and Janssen's law fits poorly (measured: R^2 0.86 for 2400 disks); sliding the
-- walls up or lowering the floor after the fact did not remove them.
-- Fields: the Gaussian, w = 1 d, cut at 3 w, on a grid of w / 4 spanning the walls' layers.
-- Fit: sigma_inf, lambda and the surface height by least squares over the depths from 1 d below
-- the surface to 1.5 D above the floor (the floor's layer excluded).
--   grainlab scripts/cg_janssen.lua [n=2400] [width=20] [seed=1] [mu_wall=0.5] [stages=10]
--                                   [stage_s=0.02] [cache=...]
-- Figures (images/ from the default run only): sigma_v against depth with the fit and the
-- hydrostatic line; the map of the principal stress difference with its directions.
local n, wd, seed = params.n or 2400, params.width or 20, params.seed or 1
local mu_w = params.mu_wall or 0.5
local stages, stage_s = params.stages or 10, params.stage_s or 0.02
local figures = require("grainlab.figures")
local fig = { published = figures.published({ n = n, width = wd, seed = seed, mu_wall = mu_w, stages = stages,
                                              stage_s = stage_s },
                                            { n = 2400, width = 20, seed = 1, mu_wall = 0.5, stages = 10,
                                              stage_s = 0.02 }) }
local d, rho_s, g, depth = 1e-3, 2650, 9.81, 1e-3
local D = wd * d
local png_profile = params.png or figures.path("cg_janssen.png", fig)
local png_map = params.png_map or figures.path("cg_janssen_psd.png", fig)

local path = params.cache
if path == nil then
  path = string.format("out/cg_silo_%d_%d_%d_%g_%d_%g.ckpt", n, wd, seed, mu_w, stages, stage_s)
end
local s, prep_s
local f = path and io.open(path, "rb")
if f then
  f:close()
  s, prep_s = dem.load(path), 0
else
  local t0 = grainlab.clock()
  local H = 2.5 * n * math.pi * 0.25 * d * d / D
  s = dem.scene{ dim = 2, box = { { -0.002, -0.002 }, { D + 0.002, H } }, gravity = { 0, -g }, thickness = depth }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 }, friction = mu_w }
  s:add_wall{ point = { D, 0 }, normal = { -1, 0 }, friction = mu_w }
  local m = grainlab.material{ density = rho_s, young = 1e7, poisson = 0.3, friction = 0.5, restitution = 0.5 }
  grainlab.pack.deposit(s, { n = n, radius = { 0.4e-3, 0.6e-3 }, seed = seed, material = m,
                             region = { { 0, 0 }, { D, H } }, relax_steps = 0 })
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1, tangential = "spring" }
  -- settled under a fifth of gravity, then gravity raised to g in `stages` steps, each run for
  -- `stage_s` seconds with a drag: every layer is loaded more and more and sinks monotonically
  -- past the walls, whose friction then points up at every height (Janssen's assumption), as
  -- when a silo is filled from above; then settled at g
  s:gravity{ 0, -0.2 * g }
  grainlab.pack.settle(s, { quiet = 1e-5, final_steps = 0 })
  s:drag(20)
  for k = 1, stages do
    s:gravity{ 0, -(0.2 + 0.8 * k / stages) * g }
    s:run{ time = stage_s, progress = false }
  end
  s:drag(0)
  grainlab.pack.settle(s, { quiet = 1e-5 })
  prep_s = grainlab.clock() - t0
  if path then
    os.execute("mkdir -p '" .. (path:match("^(.*)/[^/]*$") or ".") .. "'")
    s:save(path)
  end
end
local P = s:particles()
local top = 0
for i = 1, P.count do top = math.max(top, P.y[i] + P.radius[i]) end

local w = d
local cut = 3 * w
local h = w / 4
local x0, x1 = -cut, D + cut
local nx = math.ceil((x1 - x0) / h)
local y0 = -cut
local ny = math.ceil((top + cut - y0) / h)
local F = analysis.coarse_grain(s, { width = w, cells = { nx, ny },
                                     region = { { x0, y0 }, { x0 + nx * h, y0 + ny * h } } })
local function at(t, i, j) return t[(j - 1) * nx + i] end
-- per row: sigma_v = (1/D) integral of sigma_yy dx; the walls' loads per unit height (normal from
-- t_x, shear from t_y, each wall's layer: x < D/2 and x > D/2); the density over the silo's width
local rows = {}
for j = 1, ny do
  local syy, tx_l, tx_r, ty, rho = 0, 0, 0, 0, 0
  for i = 1, nx do
    local x = x0 + (i - 0.5) * h
    syy = syy + at(F.stress.yy, i, j)
    rho = rho + at(F.density, i, j)
    if x < 0.5 * D then
      tx_l = tx_l + at(F.traction.x, i, j)
    else
      tx_r = tx_r - at(F.traction.x, i, j)
    end
    if x < 0.25 * D or x > 0.75 * D then ty = ty + at(F.traction.y, i, j) end
  end
  rows[j] = { y = y0 + (j - 0.5) * h, sv = syy * h / D, sh = 0.5 * (tx_l + tx_r) * h,
              tau = 0.5 * ty * h, rho_b = rho * h / D }
end
-- the fit range: from 1 d below the surface down to 1.5 D above the floor
local fit = {}
for _, r in ipairs(rows) do
  if r.y <= top - d and r.y >= 1.5 * D then fit[#fit + 1] = r end
end
-- bulk density: the fill between 1.5 D above the floor and 3 d below its top
local rb, nb = 0, 0
for _, r in ipairs(rows) do if r.y >= 1.5 * D and r.y <= top - 3 * d then rb, nb = rb + r.rho_b, nb + 1 end end
rb = rb / nb
-- least squares for sigma_inf at each (lambda, surface): a grid then a refinement
local function sse(lam, ys)
  local a, b = 0, 0
  for _, r in ipairs(fit) do
    local z = math.max(0, ys - r.y)
    local e = 1 - math.exp(-z / lam)
    a, b = a + e * e, b + e * r.sv
  end
  local sinf = b / a
  local err = 0
  for _, r in ipairs(fit) do
    local z = math.max(0, ys - r.y)
    err = err + (r.sv - sinf * (1 - math.exp(-z / lam))) ^ 2
  end
  return err, sinf
end
local best = { err = math.huge }
local function search(l0, l1, s0, s1, steps)
  for a = 0, steps do
    local lam = l0 * (l1 / l0) ^ (a / steps)
    for b = 0, steps do
      local ys = s0 + (s1 - s0) * b / steps
      local err, sinf = sse(lam, ys)
      if err < best.err then best = { err = err, lam = lam, ys = ys, sinf = sinf } end
    end
  end
end
search(0.2 * D, 50 * D, top - 3 * d, top + 1 * d, 60)
for _ = 1, 3 do
  search(best.lam / 1.3, best.lam * 1.3, best.ys - 0.5 * d, best.ys + 0.5 * d, 30)
end
local var, mean = 0, 0
for _, r in ipairs(fit) do mean = mean + r.sv / #fit end
for _, r in ipairs(fit) do var = var + (r.sv - mean) ^ 2 end
local r2 = 1 - best.err / var
-- the mobilised friction and K directly, below 2 D (where sigma_v is well resolved) and above
-- 1.5 D from the floor
local th, tn, kd, nk = 0, 0, 0, 0
for _, r in ipairs(fit) do
  if best.ys - r.y >= 2 * D then
    th, tn = th + r.tau, tn + r.sh
    kd, nk = kd + r.sh / r.sv, nk + 1
  end
end
local mu_m = th / tn
local K_dir = kd / nk
local K_fit = D / (2 * mu_m * best.lam)
local zmax = best.ys - fit[1].y
-- the fill's vertical balance: the walls' force density integrates to the weight (the floor's
-- normal force and the side walls' friction, which carries most of it: a wall force without its
-- friction, or with the wrong sign, would miss by twice that). Within 5e-3: the grains' residual
-- net forces (static_fill) and the grid sums' 1e-4 with the cut at 3 w.
local weight, up = 0, 0
for i = 1, P.count do weight = weight + P.mass[i] * g end
for k = 1, F.n do up = up + F.traction.y[k] end
up = up * F.cell_volume * depth
local floor_share = s:wall_force(1) / weight
local fnet = 0 -- the largest net force on a grain over its weight
for i = 1, P.count do fnet = math.max(fnet, math.sqrt(P.fx[i] ^ 2 + P.fy[i] ^ 2) / (P.mass[i] * g)) end
local metrics = {
  largest_net_force_over_weight = fnet, weight_n = weight, walls_up_over_weight = up / weight,
  floor_share_of_weight = floor_share,
  particles = P.count, silo_width_m = D, fill_height_m = top, prep_seconds = prep_s,
  bulk_density = rb, lambda_m = best.lam, lambda_over_width = best.lam / D, sigma_inf_pa = best.sinf,
  surface_m = best.ys, fit_r2 = r2, mu_mobilised = mu_m, k_fit = K_fit, k_direct = K_dir,
  sigma_inf_over_rho_g_lambda = best.sinf / (rb * g * best.lam), depth_over_lambda = zmax / best.lam,
  saturation_at_bottom = 1 - math.exp(-zmax / best.lam),
}
local checks = {
  { name = "janssen_fit_r2", value = r2, limit = 0.98, op = ">=" },
  { name = "saturates", value = zmax / best.lam, limit = 1.5, op = ">=" },
  { name = "static_fill", value = fnet, limit = 0.05 },
  { name = "walls_carry_the_weight", value = math.abs(up / weight - 1), limit = 5e-3 },
  -- Janssen's law takes K mu constant; in the fill the mobilised friction varies with depth
  -- (0.3-0.4), so sigma_inf and rho_b g lambda, and K from the fit and directly, agree to 15-20 %
  { name = "sigma_inf_is_rho_g_lambda", value = math.abs(best.sinf / (rb * g * best.lam) - 1), limit = 0.2 },
  { name = "k_fit_vs_direct", value = math.abs(K_fit / K_dir - 1), limit = 0.25 },
}

os.execute("mkdir -p '" .. png_profile:match("^(.*)/[^/]*$") .. "'")
local zs, sv, zf, sf, zh, sh_ = {}, {}, {}, {}, {}, {}
for k = 1, #rows, 2 do
  local r = rows[k]
  local z = best.ys - r.y
  if z >= 0 and r.y >= 0 then
    zs[#zs + 1], sv[#sv + 1] = z / D, r.sv
    zh[#zh + 1], sh_[#sh_ + 1] = z / D, rb * g * z
  end
end
for k = 0, 100 do
  local z = zmax * k / 100
  zf[#zf + 1], sf[#sf + 1] = z / D, best.sinf * (1 - math.exp(-z / best.lam))
end
render.plot{ file = png_profile,
             title = string.format("Janssen: 2D silo, %d disks, D = %g d: K = %.2f (fit), %.2f (direct), mu_m = %.2f",
                                   P.count, wd, K_fit, K_dir, mu_m),
             xlabel = "depth z / D", ylabel = "sigma_v (Pa)",
             series = { { x = zh, y = sh_, label = "hydrostatic rho_b g z", style = "line" },
                        { x = zs, y = sv, label = "coarse-grained sigma_v (width average)", style = "points" },
                        { x = zf, y = sf, label = string.format("Janssen fit, lambda = %.2f D", best.lam / D), style = "line" } } }
local Fm = analysis.coarse_grain(s, { width = w, cells = { math.ceil(D / (w / 3)), math.ceil(top / (w / 3)) },
                                      region = { { 0, 0 }, { D, math.ceil(top / (w / 3)) * w / 3 } } })
render.coarse_grain(Fm, { file = png_map, show = "psd", glyph_every = 3, interpolation = "bilinear",
                          width = 560, title = "Silo: principal stress difference, major direction" })
print("wrote " .. png_profile .. ", " .. png_map)

grainlab.report{
  scenario = "cg_janssen",
  params = { n = n, width_d = wd, seed = seed, mu_wall = mu_w, w_d = 1, kernel = "gauss",
             gravity_stages = stages, stage_s = stage_s },
  metrics = metrics,
  checks = checks,
}
