-- grainlab DEM: biaxial compression under three boundary conditions (Padbidri Ch. 3,
-- dem-network-cell-framework.txt Sec. 3.2-3.4, Table 3.1), on the Delaunay-cell continuum.
--
-- Sample (Sec. 3.3, grainlab.biax.prepared, cached in out/biax_<n>_<seed>.lua): Jodrey-Tory
-- deposition of n disks, r uniform in [0.5, 1] mm (8% extra dropped, the n lowest kept), copied
-- into a gravity-free scene, quartz E = 30 GPa, nu = 0.3, density 2650 x 1e5 (mass scaling),
-- cylinders 1.5 mm thick (a pressure p on an edge of length L is the force p L t); Hertz +
-- Brilliantov damping (T = 2 ms, App. B) + regularised Coulomb mu = 0.45, v_R = d eps_rate
-- (Eq. 3.A2), c = 10; the confining pressure (100 kPa) ramped on the Delaunay boundary (all
-- sides, frictionless, with drag), then friction on and a drag-free rest. The quasistatic
-- coefficient (Eq. 2.13/2.B1) is reported.
-- The same sample then goes to each boundary condition (biax.setup):
--   pressure  rigid plates top and bottom + the pressure on the lateral edges of the Delaunay
--             boundary (alpha rule 1.5), rebuilt every 250 steps (Fig. 2.2)
--   membrane  rigid plates + a chain of frictionless membrane disks (r = 1.2 mm) each side, on
--             10 N/mm springs, carrying the pressure; the chain ends move vertically with the plates
--   mbc       pressure on the whole Delaunay boundary + the penalty of Eqs. 3.2-3.5 driving the
--             coarse strain rate to E_yy = -rate, E_xy = 0 (E_xx free: the pressure sets it);
--             K = 20 p t V / rate capped at half the explicit limit for dt (s:boundary doc)
-- Plates are force-controlled onto the sample until each carries p W t within 5% (biax.start),
-- then move at +-rate H/2; dt = 1e-5 s
-- (Table 3.1), velocity Verlet, one thread.
-- Measured every 0.1% of axial strain (`sample`): the coarse (Bagi-Satake) strain increment of
-- the sample particles from the Delaunay mesh built at the previous sample (Eq. 3.1, exact for
-- the piecewise-linear field), summed: volumetric strain eps_v = sum tr(dE) (dilation positive)
-- and eps_yy; the stress ratio sigma_yy / sigma_xx of the area-weighted Christoffersen stress;
-- the ratio of actual to imposed axial strain rate dE_yy / (-rate dt) (Fig. 3.3).
-- Figures (images/biaxial_*.png): Fig. 3.6 eps_v against axial strain, three curves; stress
-- ratio; MBC rate ratio; per BC: displacements relative to the affine field of the window's
-- coarse strain (Figs. 3.7-3.9; the paper subtracts the eps_yy part only, affine=yy; by
-- default the whole coarse strain is subtracted, leaving the non-affine part), L_II maps
-- shading cells with L_II > 2 <L_II> (Fig. 3.10), pressure maps shading cells with p > 1.75 <p>
-- (Fig. 3.11), and the cluster-averaged pressure against circle diameter at top, centre and
-- bottom (Fig. 3.12).
--
--   grainlab scripts/biaxial.lua [bc=all|pressure|membrane|mbc|plot] [scale=1] [n=3300]
--       [strain=0.20] [rate=0.005] [seed=1] [sample=0.001] [png=images/biaxial] [csv=out/biaxial]
--       [affine=full|yy] [out=out]
-- Figures go to images/ only from the full-size run (all of n, strain, rate, seed, sample,
-- affine at their defaults); any other run writes them to out/ (or out=DIR), its CSVs to
-- out/biaxial_reduced_<bc>.csv (grainlab.figures).
-- bc = one condition writes out/biaxial_<bc>.csv and its maps (run the three in parallel), then
-- bc = plot draws the comparison figures from the CSVs present and reports; bc = all does both.
-- Map and window strains are the paper's (L_II/p at 7%, 7.5%, 8.5%; windows 10-12-14%,
-- 10-11.5-13.5%, 12-14-15.5%), scaled by strain/0.20 for shorter runs.
local biax = grainlab.biax
local scale = params.scale or 1
local n = params.n or math.floor(3300 * scale + 0.5)
local strain = params.strain or 0.20
local rate = params.rate or 5e-3
local seed = params.seed or 1
local sample = params.sample or 0.001
local which = params.bc or "all"
local affine = params.affine or "full"
-- Only the full-size run (the defaults) publishes into images/; any other run writes its figures
-- and CSVs into out/ (or out=DIR) under other names, so neither a figure in images/ nor the CSVs
-- that bc=plot draws them from are overwritten by a reduced run.
local figures = require("grainlab.figures")
local published = figures.published({ n = n, strain = strain, rate = rate, seed = seed, sample = sample,
                                      affine = affine },
                                    { n = 3300, strain = 0.20, rate = 5e-3, seed = 1, sample = 0.001,
                                      affine = "full" })
local png = params.png or figures.path("biaxial", { published = published, out = params.out })
local csv = params.csv or (published and "out/biaxial" or figures.path("biaxial_reduced", { published = false, out = params.out }))
assert(affine == "full" or affine == "yy", "affine must be 'full' or 'yy', got " .. tostring(affine))
grainlab.threads(1)
for name, v in pairs { n = n, strain = strain, rate = rate, sample = sample } do
  assert(type(v) == "number" and v > 0, name .. " must be a positive number")
end
os.execute("mkdir -p out")
local c = biax.config{ rate = rate }
local f = strain / 0.20 -- paper strains are for a run to 20%
local plan = {
  pressure = { maps = 0.070 * f, windows = { 0.10 * f, 0.12 * f, 0.14 * f } },
  membrane = { maps = 0.075 * f, windows = { 0.10 * f, 0.115 * f, 0.135 * f } },
  mbc = { maps = 0.085 * f, windows = { 0.12 * f, 0.14 * f, 0.155 * f } },
}
local names = { pressure = "direct pressure", membrane = "membrane", mbc = "minimal BC" }

local function read_csv(path)
  local fh = io.open(path, "r")
  if not fh then return nil end
  local rows, head = {}, nil
  for line in fh:lines() do
    local v = {}
    for x in line:gmatch("[^,]+") do v[#v + 1] = x end
    if not head then head = v else
      local r = {}
      for k, h in ipairs(head) do r[h] = tonumber(v[k]) end
      rows[#rows + 1] = r
    end
  end
  fh:close()
  return rows
end

-- ---- cell maps (Figs. 3.10, 3.11) and cluster pressure (Fig. 3.12) -------------------------
local function cell_map(s, lab, mesh, values, threshold_factor, file, title)
  local cells = mesh:cells(s)
  local mean, area = 0, 0
  for k = 1, #values do mean, area = mean + values[k] * cells.area[k], area + cells.area[k] end
  mean = mean / area
  local shade, count = {}, 0
  for k = 1, #values do
    shade[k] = values[k] > threshold_factor * mean and 0 or 0.88
    if shade[k] == 0 then count = count + 1 end
  end
  -- the sample's extent, padded by 4%
  local xlo, xhi, ylo, yhi = math.huge, -math.huge, math.huge, -math.huge
  for k = 1, #cells.cx do
    xlo, xhi = math.min(xlo, cells.cx[k]), math.max(xhi, cells.cx[k])
    ylo, yhi = math.min(ylo, cells.cy[k]), math.max(yhi, cells.cy[k])
  end
  local padx, pady = 0.04 * (xhi - xlo) + 2 * c.rmax, 0.04 * (yhi - ylo) + 2 * c.rmax
  local lo, hi = { xlo - padx, ylo - pady }, { xhi + padx, yhi + pady }
  local W, H = hi[1] - lo[1], hi[2] - lo[2]
  local nx = 900
  local ny = math.floor(nx * H / W + 0.5)
  local grid = mesh:raster(shade, { nx = nx, ny = ny, extent = { lo, hi }, state = s })
  render.field{ file = file, values = grid, nx = nx, ny = ny, extent = { lo, hi }, colormap = "gray",
                range = { 0, 1 }, colorbar = false, width = 700, title = title }
  return mean, count / #values
end

local function cluster_pressure(s, mesh, stress)
  local cells = mesh:cells(s)
  local ylo, yhi, xsum, area, psum = math.huge, -math.huge, 0, 0, 0
  for k = 1, #cells.cy do
    ylo, yhi = math.min(ylo, cells.cy[k]), math.max(yhi, cells.cy[k])
    xsum = xsum + cells.cx[k] * cells.area[k]
    psum = psum + stress.pressure[k] * cells.area[k]
    area = area + cells.area[k]
  end
  local xc, pmean, H = xsum / area, psum / area, yhi - ylo
  local d_mean = c.rmin + c.rmax -- mean diameter
  local out = {}
  for _, where in ipairs { { "top", ylo + 0.8 * H }, { "centre", ylo + 0.5 * H }, { "bottom", ylo + 0.2 * H } } do
    local xs, ys = {}, {}
    for m = 2, 40 do
      local D = m * d_mean
      if D > 0.4 * H then break end
      local a, ps = 0, 0
      for k = 1, #cells.cx do
        local dx, dy = cells.cx[k] - xc, cells.cy[k] - where[2]
        if dx * dx + dy * dy <= 0.25 * D * D then
          a, ps = a + cells.area[k], ps + stress.pressure[k] * cells.area[k]
        end
      end
      if a > 0 then xs[#xs + 1], ys[#ys + 1] = m, ps / a / pmean end
    end
    out[#out + 1] = { x = xs, y = ys, label = where[1], style = "both" }
  end
  return out, pmean
end

-- ---- one boundary condition ------------------------------------------------------------------
local function run_bc(bc, st)
  local t_start = grainlab.clock()
  local s, lab = biax.setup(st, bc, c)
  local sb, stp = biax.start(lab)
  local p = plan[bc]
  local ev, eyy, exx = 0, 0, 0
  -- rewritten during the run (grainlab.recorder's flush), so a run stopped early keeps its curve
  local rows = grainlab.recorder{ file = string.format("%s_%s.csv", csv, bc), columns = { "axial", "eps_v",
                                  "eps_yy_coarse", "eps_xx_coarse", "stress_ratio", "rate_ratio", "pressure" } }
  local mesh = analysis.delaunay(s, { ids = lab.ids })
  local t_prev = s:info().time
  local per = math.max(1, math.floor(sample / (rate * c.dt) + 0.5)) -- steps per sample
  local total = math.floor(strain / (rate * c.dt) + 0.5)
  local done, peak, peak_at = 0, -math.huge, 0
  local maps_done, win = false, 1
  local win_ref = nil
  local metrics = {}
  local mbc_ratios = {}
  local progress = grainlab.progress{ label = "biaxial " .. bc, total = total, unit = "steps" }
  local function window_start(k)
    s:set_reference()
    local m = analysis.delaunay(s, { ids = lab.ids })
    local cells = m:cells(s)
    local xc, yc, a = 0, 0, 0
    for q = 1, #cells.cx do
      xc, yc, a = xc + cells.cx[q] * cells.area[q], yc + cells.cy[q] * cells.area[q], a + cells.area[q]
    end
    win_ref = { k = k, mesh = m, center = { xc / a, yc / a }, ea = biax.axial(lab) }
  end
  local function window_end(k)
    local e = win_ref.mesh:strain(s).coarse_gradient
    local ea = biax.axial(lab)
    local file = string.format("%s_%s_displacement_%d.png", png, bc, k - 1)
    -- colour: |displacement - affine| per disk (arrows alone vanish among thousands of disks)
    local G = affine == "yy" and { { 0, 0 }, { 0, e.yy } } or { { e.xx, e.xy }, { e.yx, e.yy } }
    local d = s:measure("displacement", { affine = G, center = win_ref.center })
    local mag, sorted = {}, {}
    for i = 1, #d.x do
      mag[i] = 1e3 * math.sqrt(d.x[i] ^ 2 + d.y[i] ^ 2)
      sorted[i] = mag[i]
    end
    table.sort(sorted)
    local hi = math.max(sorted[math.floor(0.98 * #sorted)], 1e-9)
    render.png(s, file, { width = 900, color = mag, colormap = "viridis", range = { 0, hi },
                          show = { "displacement", "walls", "box", "colorbar" },
                          displacement = { affine = G, center = win_ref.center },
                          label = "|displacement - affine| (mm)",
                          title = string.format("%s: displacement less the affine part (%s), axial strain %.1f-%.1f%%",
                                                names[bc], affine == "yy" and "uniform eps_yy" or "coarse strain",
                                                100 * win_ref.ea, 100 * ea) })
    metrics["displacement_png_" .. (k - 1)] = file
  end
  while done < total do
    local steps = math.min(per, total - done)
    s:run{ steps = steps, dt = c.dt, impact_velocity = 1e-3, progress = false }
    done = done + steps
    progress:update(done)
    local now = s:info().time
    local e = mesh:strain(s).coarse
    local dt = now - t_prev
    ev, eyy, exx = ev + e.xx + e.yy, eyy + e.yy, exx + e.xx
    local ratio = e.yy / (-rate * dt)
    local stress = nil
    local ea = biax.axial(lab)
    -- maps (Figs. 3.10-3.12) once the axial strain passes the plan's
    if not maps_done and ea >= p.maps then
      maps_done = true
      stress = mesh:stress(s)
      local cur = analysis.delaunay(s, { ids = lab.ids })
      local rf = cur:strain_rate(s)
      local lmean, lfrac = cell_map(s, lab, cur, rf.lii, 2,
        string.format("%s_%s_lii.png", png, bc),
        string.format("%s at %.1f%%: cells with L_II > 2 <L_II>", names[bc], 100 * ea))
      local cs = cur:stress(s)
      local pmean, pfrac = cell_map(s, lab, cur, cs.pressure, 1.75,
        string.format("%s_%s_pressure.png", png, bc),
        string.format("%s at %.1f%%: cells with p > 1.75 <p>", names[bc], 100 * ea))
      local series = cluster_pressure(s, cur, cs)
      local xmax = 2
      for _, sr in ipairs(series) do xmax = math.max(xmax, sr.x[#sr.x] or 2) end
      series[#series + 1] = { x = { 2, xmax }, y = { 1, 1 }, label = "assembly mean", style = "line" }
      render.plot{ file = string.format("%s_%s_cluster_pressure.png", png, bc), width = 800, height = 520,
                   title = string.format("%s at %.1f%% axial strain: pressure in circles (Fig. 3.12)", names[bc], 100 * ea),
                   xlabel = "circle diameter / mean particle diameter", ylabel = "p_circle / <p>", series = series }
      for _, sr in ipairs(series) do
        if sr.label ~= "assembly mean" and #sr.y > 0 then
          local dev = 0
          for q = 1, #sr.y do dev = math.max(dev, math.abs(sr.y[q] - 1)) end
          metrics["cluster_pressure_maxdev_" .. sr.label] = dev
        end
      end
      metrics.map_strain = ea
      metrics.map_mean_lii = lmean
      metrics.map_lii_shaded_fraction = lfrac
      metrics.map_mean_pressure = pmean
      metrics.map_pressure_shaded_fraction = pfrac
    end
    if win <= 2 and not win_ref and ea >= p.windows[win] then window_start(win) end
    if win_ref and ea >= p.windows[win + 1] then
      window_end(win + 1)
      win = win + 1
      win_ref = nil
      if win <= 2 then window_start(win) end
    end
    stress = stress or mesh:stress(s)
    local sr = stress.mean.yy / stress.mean.xx
    rows:add{ axial = ea, eps_v = ev, eps_yy_coarse = -eyy, eps_xx_coarse = exx, stress_ratio = sr,
              rate_ratio = ratio, pressure = stress.mean_pressure }
    if ev > peak then peak, peak_at = ev, ea end
    if ea > 0.01 * f then mbc_ratios[#mbc_ratios + 1] = ratio end
    mesh, t_prev = analysis.delaunay(s, { ids = lab.ids }), now
  end
  progress:finish()
  rows:write()
  local bi = s:boundary_info()
  local mean, dev = 0, 0
  for _, r in ipairs(mbc_ratios) do mean = mean + r end
  mean = mean / math.max(1, #mbc_ratios)
  for _, r in ipairs(mbc_ratios) do dev = dev + (r - mean) ^ 2 end
  metrics.peak_dilation = peak
  metrics.peak_dilation_at = peak_at
  metrics.final_eps_v = ev
  metrics.rate_ratio_mean = mean
  metrics.rate_ratio_std = math.sqrt(dev / math.max(1, #mbc_ratios))
  metrics.wall_s = grainlab.clock() - t_start
  metrics.steps = total
  metrics.boundary_updates = bi.updates
  metrics.triangulation_s = bi.update_seconds
  metrics.penalty_k = lab.info and lab.info.K or 0
  metrics.plate_stress_ratio_start_bottom = sb
  metrics.plate_stress_ratio_start_top = stp
  metrics.servo_steps = lab.servo_steps or 0
  return metrics
end

-- ---- main ---------------------------------------------------------------------------------------
local metrics, checks = {}, {}
local run_list = {}
if which == "all" then run_list = { "pressure", "membrane", "mbc" }
elseif which ~= "plot" then run_list = { which } end
if #run_list > 0 then
  local t0 = grainlab.clock()
  local st, rep, cached = biax.prepared{ n = n, seed = seed, rate = rate }
  io.stderr:write(string.format("sample of %d disks %s in %.1f s: <p> = %.0f Pa, phi = %.3g\n", n,
                                cached and "loaded" or "prepared", grainlab.clock() - t0, rep.pressure or 0, rep.phi or 0))
  metrics.prep_pressure_pa = rep.pressure
  metrics.prep_phi = rep.phi
  metrics.prep_psi = rep.psi
  metrics.prep_coordination = rep.coordination
  for _, bc in ipairs(run_list) do
    local m = run_bc(bc, st)
    for k, v in pairs(m) do metrics[bc .. "_" .. k] = v end
    if bc == "mbc" then
      checks[#checks + 1] = { name = "mbc_rate_ratio_within_5pct", value = math.abs(m.rate_ratio_mean - 1), limit = 0.05 }
    end
    collectgarbage()
  end
end
if which == "plot" or which == "all" then
  local ev, sr, rr = {}, {}, {}
  for _, bc in ipairs { "pressure", "membrane", "mbc" } do
    local rows = read_csv(string.format("%s_%s.csv", csv, bc))
    if rows and #rows > 0 then -- (a run still going has written its header and the rows so far)
      local x, y, z, w = {}, {}, {}, {}
      local peak, at = -math.huge, 0
      for _, r in ipairs(rows) do
        x[#x + 1], y[#y + 1], z[#z + 1], w[#w + 1] = 100 * r.axial, 100 * r.eps_v, r.stress_ratio, r.rate_ratio
        if r.eps_v > peak then peak, at = r.eps_v, r.axial end
      end
      ev[#ev + 1] = { x = x, y = y, label = names[bc], style = "line" }
      sr[#sr + 1] = { x = x, y = z, label = names[bc], style = "line" }
      if bc == "mbc" then rr[#rr + 1] = { x = x, y = w, label = "minimal BC: dE_yy / (-rate dt)", style = "line" } end
      metrics[bc .. "_peak_dilation"] = peak
      metrics[bc .. "_peak_dilation_at"] = at
      metrics[bc .. "_final_eps_v"] = rows[#rows].eps_v
    end
  end
  if #ev > 0 then
    render.plot{ file = png .. "_volumetric.png", width = 900, height = 560,
                 title = string.format("Fig. 3.6: volumetric strain (dilation > 0), %d disks", n),
                 xlabel = "axial strain (%)", ylabel = "volumetric strain (%)", series = ev }
    render.plot{ file = png .. "_stress_ratio.png", width = 900, height = 560,
                 title = "stress ratio (Christoffersen, cell-area mean)",
                 xlabel = "axial strain (%)", ylabel = "sigma_yy / sigma_xx", series = sr }
  end
  if #rr > 0 then
    rr[#rr + 1] = { x = { rr[1].x[1], rr[1].x[#rr[1].x] }, y = { 1, 1 }, label = "imposed", style = "line" }
    render.plot{ file = png .. "_mbc_rate_ratio.png", width = 900, height = 520,
                 title = "Fig. 3.3: actual / imposed axial strain rate under the minimal BC",
                 xlabel = "axial strain (%)", ylabel = "rate ratio", series = rr }
  end
end
grainlab.report{
  scenario = "biaxial",
  params = { n = n, strain = strain, rate = rate, seed = seed, bc = which, dt = c.dt, sample = sample,
             pressure_pa = c.pressure },
  metrics = metrics,
  checks = checks,
}
