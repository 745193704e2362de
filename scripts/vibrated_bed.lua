-- grainlab DSMC: a vibrated granular bed of disks under gravity in a box periodic
-- in x, driven by a bottom wall oscillating sinusoidally (amplitude A, frequency f), a specular lid
-- high above. The wall injects energy at the bottom; collisions (e < 1) dissipate it on the way
-- up, so the granular temperature falls with height through the bed, while the density falls
-- roughly barometrically with a height scale T/(m g). (In the very dilute top, where particles
-- fly ballistically, the temperature can rise again: the known temperature inversion of
-- vibrofluidised beds; the check therefore looks at the bulk of the bed.)
--
-- Set-up: R = 0.5 mm, quartz, e = 0.9, N = 900 disks in a 0.3 m wide box (3 monolayers at rest),
-- A = 1.5 mm, f = 60 Hz (Gamma = A (2 pi f)^2 / g = 21.7), cells 3 mm (below the mean free path in the bulk), dt = 5e-5 s (333 steps per
-- period). Settle 2 s, then average profiles (100 layers of 3 mm) and cell fields over `avg` s,
-- sampled every 2 ms.
-- Checks: the temperature falls with height through the bulk: T at the layer 1-2 cm above the
-- wall's top exceeds T at the height below which 80% of the particles lie; the DSMC conditions
-- hold in the bulk (mean free path above the cell, collision time above dt).
-- A more dissipative bed collapses: with e=0.85 a cell fills past close packing at t = 0.95 s
-- and the run stops there with an error (docs/dsmc.md).
--   grainlab scripts/vibrated_bed.lua [n=900] [e=0.9] [amplitude=1.5e-3] [frequency=60]
--                                     [settle=2] [avg=4] [csv=out/vibrated_bed.csv]
local N = params.n or 900
local e = params.e or 0.9
local A = params.amplitude or 1.5e-3
local f = params.frequency or 60
local settle = params.settle or 2
local avg = params.avg or 4
local csv_path = params.csv or "out/vibrated_bed.csv"
-- images/ only from the default run (docs/dsmc.md shows it); any other run writes to out/.
local figures = require("grainlab.figures")
local fig = { published = figures.published({ n = N, e = e, amplitude = A, frequency = f, settle = settle, avg = avg },
                                            { n = 900, e = 0.9, amplitude = 1.5e-3, frequency = 60, settle = 2, avg = 4 }) }
local W, H, R, g = 0.3, 0.3, 0.5e-3, 9.81
local nx, ny = 100, 100
local dt = 5e-5

local s = dsmc.scene{ dim = 2, size = { W, H }, cells = { nx, ny }, periodic = { true, false },
                      gravity = { 0, -g }, radius = R, restitution = e, seed = 4 }
local m = s:info().mass
s:wall{ side = "bottom", amplitude = A, frequency = f }
s:fill{ n = N, temperature = m * 0.5, region = { { 0, 2 * A }, { W, 0.1 } }, seed = 9 }
local validity = s:measure("validity", { dt = dt })
s:run{ time = settle, dt = dt, warn = false }

-- time averages: per layer sum of counts and of count x T, per cell the same
local nb = ny
-- per cell: visits, sum of v and of |v|^2 over all samples (the time-averaged local temperature
-- about the time-averaged local velocity, as for the layers)
local lay_n, lay_nT, cell_n, cell_vx, cell_vy, cell_v2 = {}, {}, {}, {}, {}, {}
for i = 1, nb do lay_n[i] = 0; lay_nT[i] = 0 end
for i = 1, nx * ny do cell_n[i] = 0; cell_vx[i] = 0; cell_vy[i] = 0; cell_v2[i] = 0 end
local samples = 0
local worst = { mfp_over_cell = math.huge, tcoll_over_dt = math.huge }
local sample_dt = 2e-3
local t_end = settle + avg
while s:info().time < t_end - 1e-9 do
  s:run{ time = sample_dt, dt = dt, warn = false }
  local p = s:measure("profile", { axis = 2, bins = nb })
  for i = 1, nb do
    lay_n[i] = lay_n[i] + p.count[i]
    if p.count[i] >= 2 then lay_nT[i] = lay_nT[i] + p.count[i] * p.temperature[i] end
  end
  local pts = s:particles()
  for k = 1, pts.count do
    local i = math.min(nx - 1, math.floor(pts.x[k] / W * nx))
    local j = math.min(ny - 1, math.floor(pts.y[k] / H * ny))
    local c = j * nx + i + 1
    cell_n[c] = cell_n[c] + 1
    cell_vx[c] = cell_vx[c] + pts.vx[k]
    cell_vy[c] = cell_vy[c] + pts.vy[k]
    cell_v2[c] = cell_v2[c] + pts.vx[k]^2 + pts.vy[k]^2
  end
  samples = samples + 1
  local v = s:measure("validity", { dt = dt })
  worst.mfp_over_cell = math.min(worst.mfp_over_cell, v.mean_free_path / v.cell_size)
  worst.tcoll_over_dt = math.min(worst.tcoll_over_dt, v.collision_time / dt)
end

local layer_h = H / nb
local z, packing, t_over_m, cum = {}, {}, {}, {}
local total = 0
for i = 1, nb do total = total + lay_n[i] end
local acc = 0
for i = 1, nb do
  z[i] = (i - 0.5) * layer_h
  packing[i] = lay_n[i] / samples * math.pi * R * R / (W * layer_h)
  t_over_m[i] = lay_n[i] > 0 and lay_nT[i] / lay_n[i] / m or 0 / 0
  acc = acc + lay_n[i]
  cum[i] = acc / total
end
-- the bulk: from 1-2 cm above the wall's highest point to the height holding 80% of the particles
local z_wall = 2 * A
local i_low = math.floor((z_wall + 0.01) / layer_h) + 1
local i80 = 1
while cum[i80] < 0.8 do i80 = i80 + 1 end
local i_low2 = math.floor((z_wall + 0.02) / layer_h)
local T_low, n_low = 0, 0
for i = i_low, i_low2 do T_low = T_low + lay_nT[i]; n_low = n_low + lay_n[i] end
T_low = T_low / n_low / m
local T_80 = t_over_m[i80]
-- monotone through the bulk: count layers (above the wall zone, below z80) where T rises by more
-- than 5% from one layer to the next
local rises = 0
for i = i_low, i80 - 1 do
  if t_over_m[i + 1] > 1.05 * t_over_m[i] then rises = rises + 1 end
end
local z_mean = 0
for i = 1, nb do z_mean = z_mean + z[i] * lay_n[i] / total end

print(string.format("%8s %10s %12s", "z (mm)", "packing", "T/m (m2/s2)"))
for i = 1, nb do
  if lay_n[i] > 0 then print(string.format("%8.1f %10.4f %12.5f", 1000 * z[i], packing[i], t_over_m[i])) end
end

local lines = { "z_m,packing,t_over_m_m2_per_s2,cumulative_fraction" }
for i = 1, nb do lines[#lines + 1] = string.format("%.6g,%.6g,%.6g,%.6g", z[i], packing[i], t_over_m[i], cum[i]) end
if csv_path:find("/") then os.execute("mkdir -p '" .. csv_path:match("^(.*)/[^/]*$") .. "'") end
assert(grainlab.write_file(csv_path, table.concat(lines, "\n") .. "\n"))

-- plots: profiles against height (height on the vertical axis, as in the bed)
local zc, pc, tc = {}, {}, {}
for i = 1, nb do
  if lay_n[i] / samples >= 0.5 then
    zc[#zc + 1] = 1000 * z[i]; pc[#pc + 1] = packing[i]; tc[#tc + 1] = t_over_m[i]
  end
end
render.plot{ file = figures.path("vibrated_bed_density.png", fig), width = 640, height = 640,
             title = string.format("Vibrated bed: packing fraction (A = %g mm, f = %g Hz, e = %g)", 1000 * A, f, e),
             xlabel = "packing fraction nu", ylabel = "height z (mm)",
             series = { { x = pc, y = zc, label = "DSMC, time average", style = "both" } } }
render.plot{ file = figures.path("vibrated_bed_temperature.png", fig), width = 640, height = 640,
             title = "Vibrated bed: granular temperature against height",
             xlabel = "T/m = <|v - u|^2>/2  (m^2/s^2)", ylabel = "height z (mm)",
             series = { { x = tc, y = zc, label = "DSMC, time average", style = "both" } } }
-- fields: time-averaged packing and temperature on the cells; a snapshot of the particles
local dens, temp = {}, {}
local cellA = (W / nx) * (H / ny)
for i = 1, nx * ny do
  dens[i] = cell_n[i] / samples * math.pi * R * R / cellA
  local c = cell_n[i]
  temp[i] = c >= 10 and (cell_v2[i] - (cell_vx[i]^2 + cell_vy[i]^2) / c) / (2 * (c - 1)) or 0 / 0
end
-- show the lower part of the box where the particles are
local rows = math.min(ny, math.max(10, math.floor(1.5 * i80 + 0.5)))
local dsub, tsub = {}, {}
for j = 0, rows - 1 do
  for i = 1, nx do dsub[#dsub + 1] = dens[j * nx + i]; tsub[#tsub + 1] = temp[j * nx + i] end
end
local ext = { { 0, 0 }, { W, rows * H / ny } }
render.field{ file = figures.path("vibrated_bed_density_field.png", fig), nx = nx, ny = rows, values = dsub,
              extent = ext, title = "Vibrated bed: time-averaged packing fraction",
              label = "packing fraction", interpolation = "bilinear" }
render.field{ file = figures.path("vibrated_bed_temperature_field.png", fig), nx = nx, ny = rows, values = tsub,
              extent = ext, title = "Vibrated bed: time-averaged T/m (white: under 10 visits)",
              label = "T/m (m^2/s^2)", interpolation = "bilinear" }
local pts = s:particles()
render.points{ file = figures.path("vibrated_bed_particles.png", fig), x = pts.x, y = pts.y, values = pts.speed,
               extent = ext, size = 5, title = string.format("Vibrated bed at t = %.2f s", s:info().time),
               label = "speed (m/s)" }

grainlab.report{
  scenario = "vibrated_bed",
  params = { n = N, restitution = e, amplitude_m = A, frequency_hz = f,
             gamma = A * (2 * math.pi * f)^2 / g, dt_s = dt, settle_s = settle, average_s = avg,
             cells = nx .. "x" .. ny },
  metrics = { t_over_m_low = T_low, t_over_m_at_z80 = T_80, z80_m = z[i80], mean_height_m = z_mean,
              temperature_ratio_low_over_z80 = T_low / T_80, layers_where_t_rises = rises,
              bottom_packing_max = math.max(table.unpack(packing)), samples = samples,
              min_mfp_over_cell = worst.mfp_over_cell, min_collision_time_over_dt = worst.tcoll_over_dt,
              initial_mfp_over_cell = validity.mean_free_path / validity.cell_size },
  checks = {
    { name = "temperature_falls_with_height", value = T_low / T_80, limit = 1.1, op = ">" },
    { name = "temperature_monotone_in_bulk", value = rises, limit = 0, op = "==" },
    { name = "cells_below_mean_free_path", value = worst.mfp_over_cell, limit = 1, op = ">" },
    { name = "dt_below_collision_time", value = worst.tcoll_over_dt, limit = 1, op = ">" },
  },
}
