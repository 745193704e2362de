-- Coarse-grained stress against the Delaunay cells' Christoffersen stress in the biaxial test
-- (Padbidri Sec. 2.5 and 3.2; analysis.delaunay, mesh:stress).
--
-- Both are averages of the same sums over contacts, branch (x) force. Christoffersen's particle
-- stress splits each contact's b (x) f between its two particles at their centres (the half
-- branches to the contact point) and divides by a third of the particle's cells' area; a cell
-- takes the mean of its three particles: sum_cells A_c sigma_c = sum_c b (x) f / depth exactly,
-- as the coarse-grained field's integral is. Cell by cell the two spread a contact differently:
-- the cell stress keeps a contact with the particles that share it (up to about a diameter
-- away), the kernel spreads it along its branch over a width w. So the comparison is made on
-- (1) the interior's area-weighted mean, where only the contacts that cross the interior's
-- outline are shared differently (a fraction about d / L of them), (2) cell by cell (the
-- correlation, and the rms difference relative to the mean pressure, which is the scale of the
-- fluctuations both resolve), and (3) patches of cells within R of a cell's centroid, where the
-- difference falls as the patch holds more contacts (about as 1 / R: only the contacts on the
-- patch's outline are shared differently). The cell average of the field is a 7-point Gauss
-- rule on the triangle (degree 5). Interior: cells whose centroid is farther than the kernel's
-- reach plus a mean diameter from every boundary particle (the boundary's pressure forces enter
-- neither stress: they act on particles, not at contacts).
-- Sample: grainlab.biax.prepared (n disks, r in [0.5, 1] mm, p = 100 kPa; cached in out/),
-- the pressure boundary condition with plates (biax.setup, biax.start), then `strain` of axial
-- compression at 0.5 %/s (dt 1e-5 s). Kernel: the Gaussian (cut at 3 w), w = `w` mean diameters.
--   grainlab scripts/cg_delaunay.lua [n=400] [seed=1] [strain=0.01] [w=0.5]
-- Figures (images/ from the default run only): cell pressures, coarse-grained against
-- Christoffersen; the rms difference of patch means against the patch radius.
local biax = grainlab.biax
local n, seed = params.n or 400, params.seed or 1
local strain, wrel = params.strain or 0.01, params.w or 0.5
local figures = require("grainlab.figures")
local fig = { published = figures.published({ n = n, seed = seed, strain = strain, w = wrel },
                                            { n = 400, seed = 1, strain = 0.01, w = 0.5 }) }
local png_cells = params.png or figures.path("cg_delaunay_cells.png", fig)
local png_patch = params.png_patch or figures.path("cg_delaunay_patches.png", fig)

local t0 = grainlab.clock()
local c = biax.config{}
local st = biax.prepared{ n = n, seed = seed }
local s, lab = biax.setup(st, "pressure", c)
biax.start(lab)
local steps = math.floor(strain / (c.rate * c.dt) + 0.5)
s:run{ steps = steps, dt = c.dt, impact_velocity = 1e-3, progress = false }
local t_run = grainlab.clock() - t0

local d = c.rmin + c.rmax -- mean diameter
local w = wrel * d
local mesh = analysis.delaunay(s, { ids = lab.ids, alpha = c.alpha })
local C = mesh:stress(s)
local cells = mesh:cells(s)
local P = s:particles()
local loop = mesh:boundary()
local reach = 3 * w
-- interior cells
local interior = {}
for q = 1, #cells.cx do
  local far = true
  for _, id in ipairs(loop) do
    if (cells.cx[q] - P.x[id]) ^ 2 + (cells.cy[q] - P.y[id]) ^ 2 < (reach + d) ^ 2 then far = false; break end
  end
  if far then interior[#interior + 1] = q end
end
-- 7-point rule (Dunavant, degree 5): barycentric points and weights
local a1, b1 = 0.059715871789770, 0.470142064105115
local a2, b2 = 0.797426985353087, 0.101286507323456
local rule = { { 1 / 3, 1 / 3, 1 / 3, 0.225 },
               { a1, b1, b1, 0.132394152788506 }, { b1, a1, b1, 0.132394152788506 }, { b1, b1, a1, 0.132394152788506 },
               { a2, b2, b2, 0.125939180544827 }, { b2, a2, b2, 0.125939180544827 }, { b2, b2, a2, 0.125939180544827 } }
local qx, qy = {}, {}
for _, q in ipairs(interior) do
  local A, B, Cc = cells.a[q], cells.b[q], cells.c[q]
  for _, r in ipairs(rule) do
    qx[#qx + 1] = r[1] * P.x[A] + r[2] * P.x[B] + r[3] * P.x[Cc]
    qy[#qy + 1] = r[1] * P.y[A] + r[2] * P.y[B] + r[3] * P.y[Cc]
  end
end
local F = analysis.coarse_grain(s, { width = w, points = { x = qx, y = qy } })
local cg = {} -- per interior cell: xx, yy, xy (contact stress, as Christoffersen's)
for k = 1, #interior do
  local t = { xx = 0, yy = 0, xy = 0 }
  for j, r in ipairs(rule) do
    local i = (k - 1) * #rule + j
    t.xx = t.xx + r[4] * F.contact.xx[i]
    t.yy = t.yy + r[4] * F.contact.yy[i]
    t.xy = t.xy + r[4] * 0.5 * (F.contact.xy[i] + F.contact.yx[i])
  end
  cg[k] = t
end
local function pres(t) return 0.5 * (t.xx + t.yy) end
local chr = {}
for k, q in ipairs(interior) do chr[k] = { xx = C.xx[q], yy = C.yy[q], xy = 0.5 * (C.xy[q] + C.yx[q]) } end
-- (1) area-weighted means over the interior
local area, mc, mk = 0, { xx = 0, yy = 0, xy = 0 }, { xx = 0, yy = 0, xy = 0 }
for k, q in ipairs(interior) do
  local a = cells.area[q]
  area = area + a
  for _, comp in ipairs{ "xx", "yy", "xy" } do
    mc[comp] = mc[comp] + a * cg[k][comp]
    mk[comp] = mk[comp] + a * chr[k][comp]
  end
end
for _, comp in ipairs{ "xx", "yy", "xy" } do mc[comp], mk[comp] = mc[comp] / area, mk[comp] / area end
local p_mean = pres(mk)
local mean_diff = math.max(math.abs(mc.xx - mk.xx), math.abs(mc.yy - mk.yy), math.abs(mc.xy - mk.xy)) / p_mean
-- (2) cell by cell: pressure correlation, rms difference of every component over the mean pressure
local sx, sy, sxx, syy, sxy, rms = 0, 0, 0, 0, 0, 0
local N = #interior
for k = 1, N do
  local u, v = pres(cg[k]), pres(chr[k])
  sx, sy, sxx, syy, sxy = sx + u, sy + v, sxx + u * u, syy + v * v, sxy + u * v
  rms = rms + ((cg[k].xx - chr[k].xx) ^ 2 + (cg[k].yy - chr[k].yy) ^ 2 + 2 * (cg[k].xy - chr[k].xy) ^ 2) / 4
end
local corr = (sxy - sx * sy / N) / math.sqrt((sxx - sx * sx / N) * (syy - sy * sy / N))
local cell_rms = math.sqrt(rms / N) / p_mean
-- (3) patches: every interior cell's centroid a centre, the cells within R averaged (area)
local radii, patch_rms = { 1, 2, 3, 4 }, {}
for _, R in ipairs(radii) do
  local acc, count = 0, 0
  for k, q in ipairs(interior) do
    local ac, a0 = { xx = 0, yy = 0, xy = 0 }, 0
    local ak = { xx = 0, yy = 0, xy = 0 }
    for k2, q2 in ipairs(interior) do
      if (cells.cx[q] - cells.cx[q2]) ^ 2 + (cells.cy[q] - cells.cy[q2]) ^ 2 <= (R * d) ^ 2 then
        local a = cells.area[q2]
        a0 = a0 + a
        for _, comp in ipairs{ "xx", "yy", "xy" } do
          ac[comp] = ac[comp] + a * cg[k2][comp]
          ak[comp] = ak[comp] + a * chr[k2][comp]
        end
      end
    end
    acc = acc + ((ac.xx - ak.xx) ^ 2 + (ac.yy - ak.yy) ^ 2 + 2 * (ac.xy - ak.xy) ^ 2) / (4 * a0 * a0)
    count = count + 1
  end
  patch_rms[#patch_rms + 1] = math.sqrt(acc / count) / p_mean
end

local metrics = {
  particles = n, axial_strain = strain, width_m = w, mean_diameter_m = d, run_seconds = t_run,
  interior_cells = N, cells = #cells.cx, mean_pressure_pa = p_mean,
  mean_cg = { xx = mc.xx, yy = mc.yy, xy = mc.xy }, mean_christoffersen = { xx = mk.xx, yy = mk.yy, xy = mk.xy },
  mean_difference = mean_diff, cell_pressure_correlation = corr, cell_rms_difference = cell_rms,
  deviator_over_pressure = 0.5 * math.abs(mk.yy - mk.xx) / p_mean,
}
for i, R in ipairs(radii) do metrics[string.format("patch_rms_r%d", R)] = patch_rms[i] end
local checks = {
  { name = "interior_mean", value = mean_diff, limit = 0.05 },
  { name = "cell_pressure_correlation", value = corr, limit = 0.7, op = ">=" },
  { name = "patch_rms_falls", value = patch_rms[#patch_rms] / patch_rms[1], limit = 0.6 },
  { name = "patch_rms_at_4d", value = patch_rms[#patch_rms], limit = 0.15 },
}

os.execute("mkdir -p '" .. png_cells:match("^(.*)/[^/]*$") .. "'")
local xs, ys, lx, ly = {}, {}, {}, {}
local lo, hi = math.huge, -math.huge
for k = 1, N do
  xs[k], ys[k] = pres(chr[k]) / 1e3, pres(cg[k]) / 1e3
  lo, hi = math.min(lo, xs[k], ys[k]), math.max(hi, xs[k], ys[k])
end
lx, ly = { lo, hi }, { lo, hi }
render.plot{ file = png_cells, title = string.format("Cell pressure, %d interior cells: coarse-grained (w = %g d) against Christoffersen", N, wrel),
             xlabel = "Christoffersen cell pressure (kPa)", ylabel = "coarse-grained, averaged over the cell (kPa)",
             series = { { x = lx, y = ly, label = "equal", style = "line" },
                        { x = xs, y = ys, label = string.format("cells (correlation %.2f)", corr), style = "points" } } }
render.plot{ file = png_patch, title = "rms difference of patch-averaged stresses / mean pressure",
             xlabel = "patch radius R / d", ylabel = "rms difference / pressure", xlog = true, ylog = true,
             series = { { x = radii, y = patch_rms, label = "patches of cells within R", style = "both" } } }
print("wrote " .. png_cells .. ", " .. png_patch)

grainlab.report{
  scenario = "cg_delaunay",
  params = { n = n, seed = seed, strain = strain, w_d = wrel, kernel = "gauss", cutoff_w = 3, bc = "pressure" },
  metrics = metrics,
  checks = checks,
}
