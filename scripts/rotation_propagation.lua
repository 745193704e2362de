-- grainlab DEM: how far a forced rotation propagates through a confined assembly (Padbidri
-- Ch. 4, dem-network-cell-framework.txt Sec. 4.2-4.4, Table 4.1).
--
-- Sample: a circular assembly of n (2827) disks, r uniform in [0.5, 1] mm, cut from the middle
-- of a Jodrey-Tory deposit of 1.6 n and consolidated like the biaxial sample (grainlab.biax.
-- prepared{ shape = "circle" }: the 100 kPa pressure ramped on the Delaunay boundary, frictionless
-- with drag, then friction on, drag off). Materials as Table 4.1 (E 30 GPa, nu 0.3, density x
-- 1e5, mu 0.45), Hertz + Brilliantov + regularised Coulomb (v_R = d x 0.005/s as in Ch. 3).
-- Boundary: the pressure on the whole Delaunay boundary, rebuilt every 250 steps, and the rigid
-- rotation of the assembly suppressed by the minimal boundary conditions on the velocity gradient
-- (Eqs. 3.2-3.5 with target 0 on the off-diagonal components H_xy, H_yx only, plus the integral
-- term, so the off-diagonal displacement gradient stays ~0: Sec. 4.2).
-- The forced particle (the one nearest the centre) has its angular velocity ramped linearly to
-- omega0 = 0.03 rad/s over 2.5 s and then held (s:spin; its translation is free).
-- Time step: 1e-6 s by default (Table 4.1 uses 1e-7 s; Table 3.1's 1e-5 s is too coarse here).
-- The regularised Coulomb law with c = 10 is nearly a step function of the slip, so explicit
-- steps make the tangential force chatter, and the chatter leaves a slow, spurious spin on every
-- particle even with no forcing: the median time-averaged |omega| of an unforced 990-disk circle
-- over 0.25 s is 4.9e-3, 2.9e-3, 1.1e-3 and 5.5e-4 rad/s at dt = 10, 5, 2 and 1 us, first order
-- in dt (the full-size figures per dt are in the README). The control run's own median |omega| /
-- omega0 is reported as `background_median`; the check fails if it exceeds half the threshold,
-- where a run would measure the integrator rather than the assembly.
-- A control scene from the identical state, never forced, advances in lockstep, and each
-- particle's response is the difference d omega = omega(forced run) - omega(control run),
-- averaged exactly over the hold (the change of the integrated rotation / hold; runs are
-- deterministic: d omega is what the forcing caused).
-- Measured over the hold: each particle's mean d omega; |d omega| / omega0 against the
-- distance from the forced particle in mean diameters <d> (Fig. 4.5; binned maximum and mean
-- drawn over the scatter; the data in out/rotation_propagation.csv); the influence distance =
-- where the binned mean |d omega|/omega0 falls (and stays, 3 bins) below `threshold` (10%), and
-- where the binned largest falls (and stays) below it, and where the mean falls below twice the
-- far-field floor (the two runs also decorrelate far away: free spinners, local rearrangements;
-- the floor is the mean beyond 15 <d>); the map of |omega|/omega0
-- (Fig. 4.4a); the weighted directional tensor T = sum 1/|s| s^ (x) b^ f/<f> over the contact
-- segments with midpoints within 10 <d> (Eq. 4.1; b^ oriented outward, b^.s^ >= 0; T <d> is
-- reported, dimensionless) with the eigenvectors of sym(T); and the rose of W(b, theta) =
-- 1/|s| s^.b^ f/<f> summed in 15-degree sectors of theta (Eq. 4.2, Fig. 4.4b).
--   grainlab scripts/rotation_propagation.lua [n=2827] [seed=1] [omega=0.03] [ramp=2.5]
--       [hold=1] [dt=1e-6] [threshold=0.1] [png=images/rotation]
local biax = grainlab.biax
local n = params.n or 2827
local seed = params.seed or 1
local omega0 = params.omega or 0.03
local ramp = params.ramp or 2.5
local hold = params.hold or 1.0 -- the longer the hold, the higher the decorrelation floor
local dt = params.dt or 1e-6
local threshold = params.threshold or 0.1
-- images/ only from the default run (docs/analysis.md shows it); any other run writes to out/.
local figures = require("grainlab.figures")
local png = params.png or figures.path("rotation", {
  published = figures.published({ n = n, seed = seed, omega = omega0, ramp = ramp, hold = hold, dt = dt,
                                  threshold = threshold },
                                { n = 2827, seed = 1, omega = 0.03, ramp = 2.5, hold = 1.0, dt = 1e-6,
                                  threshold = 0.1 }) })
grainlab.threads(1)
os.execute("mkdir -p out")
local c = biax.config{ dt = dt }

local t0 = grainlab.clock()
local st, rep, cached = biax.prepared{ n = n, seed = seed, shape = "circle" }
io.stderr:write(string.format("circular sample of %d disks %s in %.1f s: <p> = %.0f Pa\n", n,
                              cached and "loaded" or "prepared", grainlab.clock() - t0, rep.pressure or 0))
local function make()
  local sc = biax.scene(st, c)
  biax.contact(sc, c, false)
  local inf = sc:boundary{ pressure = c.pressure, every = c.every, alpha = c.alpha,
                           mbc = { gradient = { { 0, 0 }, { 0, 0 } }, mask = { { 0, 1 }, { 1, 0 } },
                                   rate = omega0, dt = c.dt } }
  return sc, inf
end
local s, info = make()
local control = make() -- the same state, never forced: the reference the forcing is measured against

-- The forced particle: nearest the centroid.
local P = s:particles()
local cx, cy = 0, 0
for i = 1, P.count do cx, cy = cx + P.x[i] / P.count, cy + P.y[i] / P.count end
local forced, best = 1, math.huge
for i = 1, P.count do
  local d2 = (P.x[i] - cx) ^ 2 + (P.y[i] - cy) ^ 2
  if d2 < best then forced, best = i, d2 end
end
local dmean = 0
for i = 1, P.count do dmean = dmean + 2 * P.radius[i] / P.count end

-- Ramp, then hold. The mean angular velocity over the hold is the exact time average: the
-- change of each particle's integrated rotation (s:particles().angle) divided by the hold.
local chunk = 250
local ramp_steps = math.floor(ramp / dt + 0.5)
local hold_steps = math.floor(hold / dt + 0.5)
local progress = grainlab.progress{ label = "rotation", total = ramp_steps + hold_steps, unit = "steps" }
local done = 0
local t_run = grainlab.clock()
while done < ramp_steps do
  local step = math.min(chunk, ramp_steps - done)
  s:spin{ id = forced, omega = omega0 * math.min(1, (done + step) / ramp_steps) }
  s:run{ steps = step, dt = dt, impact_velocity = 1e-3, progress = false }
  control:run{ steps = step, dt = dt, impact_velocity = 1e-3, progress = false }
  done = done + step
  progress:update(done)
end
local A0, B0 = s:particles().angle, control:particles().angle
while done < ramp_steps + hold_steps do
  local step = math.min(100 * chunk, ramp_steps + hold_steps - done)
  s:run{ steps = step, dt = dt, impact_velocity = 1e-3, progress = false }
  control:run{ steps = step, dt = dt, impact_velocity = 1e-3, progress = false }
  done = done + step
  progress:update(done)
end
progress:finish()
local A1, B1 = s:particles().angle, control:particles().angle
local wmean, wctrl = {}, {} -- forced minus control; the control's own background
for i = 1, #A1 do
  wmean[i] = ((A1[i] - A0[i]) - (B1[i] - B0[i])) / (hold_steps * dt)
  wctrl[i] = math.abs(B1[i] - B0[i]) / (hold_steps * dt) / omega0
end
table.sort(wctrl)
local background_median, background_p90 = wctrl[math.floor(0.5 * #wctrl) + 1], wctrl[math.floor(0.9 * #wctrl) + 1]
local run_wall = grainlab.clock() - t_run
local bi = s:boundary_info()

-- ---- |omega| against distance (Fig. 4.5) -----------------------------------------------------
P = s:particles()
local xf, yf = P.x[forced], P.y[forced]
local dist, ratio = {}, {}
local bins_max, bins_sum, bins_n = {}, {}, {}
local infl10, infl5, far_sum, far_n = 0, 0, 0, 0
for i = 1, P.count do
  if i ~= forced then
    local d = math.sqrt((P.x[i] - xf) ^ 2 + (P.y[i] - yf) ^ 2) / dmean
    local r = math.abs(wmean[i]) / omega0
    dist[#dist + 1], ratio[#ratio + 1] = d, math.max(r, 1e-5) -- log axis: floor at 1e-5
    local b = math.floor(d) + 1
    bins_max[b] = math.max(bins_max[b] or 0, r)
    bins_sum[b], bins_n[b] = (bins_sum[b] or 0) + r, (bins_n[b] or 0) + 1
    if r >= threshold then infl10 = math.max(infl10, d) end
    if r >= 0.5 * threshold then infl5 = math.max(infl5, d) end
    if d > 15 then far_sum, far_n = far_sum + r, far_n + 1 end
  end
end
local bx, bmax, bmean = {}, {}, {}
for b = 1, #bins_n do
  if bins_n[b] then
    bx[#bx + 1], bmax[#bmax + 1] = b - 0.5, math.max(1e-5, bins_max[b])
    bmean[#bmean + 1] = math.max(1e-5, bins_sum[b] / bins_n[b])
  end
end
-- Influence distance on the binned mean: the first bin edge from which the mean stays below the
-- level for 3 bins. The two runs also decorrelate far away (free spinners, local
-- rearrangements), a floor measured as the mean beyond 15 <d>; the second definition uses twice
-- that floor as the level (beyond 0.6 of the largest distance in samples smaller than 25 <d>).
local floor_sum, floor_n = 0, 0
local far = math.min(15, 0.6 * bx[#bx]) -- small samples: the outer 40%
for k = 1, #bx do if bx[k] > far then floor_sum, floor_n = floor_sum + bmean[k], floor_n + 1 end end
local floor = floor_sum / math.max(1, floor_n)
local function crossing(level, curve)
  curve = curve or bmean
  for k = 1, #bx do
    local below = true
    for q = k, math.min(#bx, k + 2) do below = below and curve[q] < level end
    if below then return bx[k] - 0.5 end
  end
  return bx[#bx] + 0.5
end
local infl_mean = crossing(threshold)
local infl_floor = crossing(2 * floor)
local infl_max = crossing(threshold, bmax) -- where no particle of 3 successive bins reaches it
local lines = { "distance_d,d_omega_over_omega0" }
for k = 1, #dist do lines[#lines + 1] = string.format("%.4f,%.6e", dist[k], ratio[k]) end
assert(grainlab.write_file(params.csv or "out/rotation_propagation.csv", table.concat(lines, "\n") .. "\n"))
render.plot{ file = png .. "_decay.png", width = 900, height = 560,
             title = string.format("Fig. 4.5: rotation against distance from the forced particle (%d disks)", n),
             xlabel = "distance / mean diameter", ylabel = "|d omega| / omega_0 (forced - control, mean over hold)", ylog = true,
             series = { { x = dist, y = ratio, label = "particles", style = "points" },
                        { x = bx, y = bmax, label = "largest in each 1 <d> bin", style = "line" },
                        { x = bx, y = bmean, label = "mean in each 1 <d> bin", style = "line" },
                        { x = { 0, bx[#bx] }, y = { threshold, threshold }, label = string.format("%g omega_0", threshold), style = "line" },
                        { x = { 0, bx[#bx] }, y = { 2 * floor, 2 * floor }, label = string.format("2 x far-field floor (mean beyond %.0f <d>)", far), style = "line" } } }

-- ---- map (Fig. 4.4a) ----------------------------------------------------------------------------
local values = {}
for i = 1, P.count do values[i] = math.min(1, math.abs(wmean[i]) / omega0) end
values[forced] = 1 -- (its own d omega is omega0 minus the control's)
render.png(s, png .. "_map.png", { width = 900, color = values, colormap = "viridis", range = { 0, 0.3 },
                                   show = { "colorbar" }, label = "|d omega| / omega_0 (forced particle = 1, scale clipped at 0.3)",
                                   title = string.format("Fig. 4.4a: rotation caused by the forced particle (mean over the hold), omega_0 = %g rad/s", omega0) })

-- ---- weighted directional tensor (Eq. 4.1) and rose of W (Eq. 4.2) ---------------------------
local C = s:measure("contacts")
local fmean, fn_n = 0, 0
for k = 1, #C.i do if C.j[k] > 0 then fmean, fn_n = fmean + C.fn[k], fn_n + 1 end end
fmean = fmean / fn_n
local T = { 0, 0, 0, 0 }
local sectors, nsec = {}, 24
for q = 1, nsec do sectors[q] = 0 end
local cutoff = 10 * dmean
local segments = 0
for k = 1, #C.i do
  local i, j = C.i[k], C.j[k]
  if j > 0 then
    local mx, my = 0.5 * (P.x[i] + P.x[j]), 0.5 * (P.y[i] + P.y[j])
    local sx, sy = mx - xf, my - yf
    local sl = math.sqrt(sx * sx + sy * sy)
    if sl > 0 and sl <= cutoff then
      local bxv, byv = P.x[i] - P.x[j], P.y[i] - P.y[j]
      local bl = math.sqrt(bxv * bxv + byv * byv)
      bxv, byv = bxv / bl, byv / bl
      sx, sy = sx / sl, sy / sl
      if bxv * sx + byv * sy < 0 then bxv, byv = -bxv, -byv end
      local wgt = C.fn[k] / fmean / sl
      T[1], T[2], T[3], T[4] = T[1] + wgt * sx * bxv, T[2] + wgt * sx * byv, T[3] + wgt * sy * bxv, T[4] + wgt * sy * byv
      local theta = math.atan(sy, sx) % (2 * math.pi)
      local q = math.floor(theta / (2 * math.pi) * nsec) % nsec + 1
      sectors[q] = sectors[q] + wgt * (sx * bxv + sy * byv)
      segments = segments + 1
    end
  end
end
for q = 1, 4 do T[q] = T[q] * dmean end
for q = 1, nsec do sectors[q] = sectors[q] * dmean end
-- eigenvectors of sym(T)
local a, b2, d = T[1], 0.5 * (T[2] + T[3]), T[4]
local mid, rad = 0.5 * (a + d), math.sqrt(0.25 * (a - d) ^ 2 + b2 * b2)
local l1, l2 = mid + rad, mid - rad
local phi = 0.5 * math.atan(2 * b2, a - d) -- direction of the larger eigenvalue
local rx, ry, rmax = {}, {}, 0
for q = 1, nsec + 1 do
  local qq = (q - 1) % nsec + 1
  local th = (qq - 0.5) / nsec * 2 * math.pi
  rx[q], ry[q] = sectors[qq] * math.cos(th), sectors[qq] * math.sin(th)
  rmax = math.max(rmax, sectors[qq])
end
local e1 = rmax * 1.1
local series = { { x = rx, y = ry, label = "W(b, theta), 15 degree sectors", style = "both" },
                 { x = { -e1 * math.cos(phi), e1 * math.cos(phi) }, y = { -e1 * math.sin(phi), e1 * math.sin(phi) },
                   label = string.format("eigenvector of sym(T), %.3g", l1), style = "line" },
                 { x = { e1 * math.sin(phi), -e1 * math.sin(phi) }, y = { -e1 * math.cos(phi), e1 * math.cos(phi) },
                   label = string.format("eigenvector of sym(T), %.3g", l2), style = "line" },
                 { x = { -1.25 * e1, 1.25 * e1 }, y = { -1.25 * e1, 1.25 * e1 }, style = "none" } } -- equal extents
render.plot{ file = png .. "_rose.png", width = 720, height = 740, -- a square frame
             title = string.format("Fig. 4.4b: rose of W within 10 <d> (%d segments)", segments),
             xlabel = "W cos(theta)", ylabel = "W sin(theta)", series = series }

print(string.format("forced particle %d; influence distance (binned mean < %g omega0) %.1f <d>, (binned largest < %g omega0) %.1f <d>, (mean < 2 x floor %.3g) %.1f <d>; outermost particle >= %g omega0: %.1f <d>",
                    forced, threshold, infl_mean, threshold, infl_max, floor, infl_floor, threshold, infl10))
grainlab.report{
  scenario = "rotation_propagation",
  params = { n = n, seed = seed, omega0 = omega0, ramp_s = ramp, hold_s = hold, dt = dt,
             threshold = threshold, pressure_pa = c.pressure },
  metrics = {
    influence_distance_d = infl_mean, influence_distance_floor_d = infl_floor,
    influence_distance_max_d = infl_max,
    far_field_floor = floor, outermost_above_threshold_d = infl10,
    outermost_above_half_threshold_d = infl5,
    far_field_mean_ratio = far_sum / math.max(1, far_n), forced_particle = forced,
    mean_diameter_m = dmean, tensor_t_xx = T[1], tensor_t_xy = T[2], tensor_t_yx = T[3],
    tensor_t_yy = T[4], sym_t_eigen_1 = l1, sym_t_eigen_2 = l2,
    sym_t_direction_deg = math.deg(phi), segments = segments, penalty_k = info.K,
    offdiag_rate_final = math.max(math.abs(bi.gradient.xy), math.abs(bi.gradient.yx)),
    prep_pressure_pa = rep.pressure, run_wall_s = run_wall, steps = ramp_steps + hold_steps,
    background_median = background_median, background_p90 = background_p90,
  },
  checks = {
    -- the paper finds 6-8 particle diameters; a check on the order of magnitude only
    { name = "influence_distance_at_least_2_d", value = infl_mean, limit = 2, op = ">=" },
    { name = "influence_distance_below_20_d", value = infl_mean, limit = 20, op = "<=" },
    -- the unforced background must stay well under the threshold, or dt is too coarse
    { name = "background_median_below_half_threshold", value = background_median,
      limit = 0.5 * threshold, op = "<=" },
  },
}
