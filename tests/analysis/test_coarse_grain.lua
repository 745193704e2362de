-- The binding contract of analysis.coarse_grain and analysis.cg_average: the grid's layout, points
-- give the grid's bits, 1 and 2 threads the same bits, the invariants, averages of samples, the
-- files, 3D and MPM fields, refusals by name. (The fields' exactness is scripts/cg_exactness.lua,
-- run by the ctest analysis_cg_exactness.)
local check = grainlab.check
local depth = 1e-3

-- A 2D bed of falling, colliding disks: periodic in x, a floor without friction (so that the
-- wall forces are normal and the reference virial is the floor's fn r n (x) n).
local function bed2(n, seed)
  local W, H = 0.01, 0.012
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { W, H } }, gravity = { 0, -9.81 },
                       periodic = { true, false }, thickness = depth }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 }, friction = 0 }
  local m = grainlab.material{ density = 2650, young = 5e7, poisson = 0.3, friction = 0.5, restitution = 0.6 }
  grainlab.pack.random(s, { n = n, radius = { 0.3e-3, 0.45e-3 }, seed = seed, material = m, speed = 0.05,
                            region = { { 0, 0 }, { W, 0.008 } } })
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.6, impact_velocity = 1, tangential = "spring" }
  s:run{ time = 0.04, progress = false }
  return s, W, H
end

-- ---- 2D: a grid over one period in x and beyond every support in y -----------------------------
local s, W, H = bed2(70, 5)
local P = s:particles()
local vmax = 0
for i = 1, P.count do vmax = math.max(vmax, math.abs(P.vx[i]) + math.abs(P.vy[i])) end
check.gt(vmax, 0.01, "the bed is moving (a kinetic part to integrate)")
check.gt(s:measure("coordination").z, 0.5, "the bed has contacts")
local w = 0.4e-3
local F = analysis.coarse_grain(s, { width = w, cutoff = 8 * w, cells = { 50, 90 },
                                     region = { { 0, -4e-3 }, { W, H + 3.2e-3 } } })
check.eq(F.n, 50 * 90, "grid points")
check.near(F.depth, depth, 0, "depth: the scene's thickness")
check.is_true(F.cell_volume > 0 and F.x[1] > 0 and F.x[2] > F.x[1] and F.y[51] > F.y[1], "cell centres, x fastest")

-- points: the same bits as the grid at the same places
local idx = { 1, 77, 2000, 4500 }
local px, py = {}, {}
for k, i in ipairs(idx) do px[k], py[k] = F.x[i], F.y[i] end
local G = analysis.coarse_grain(s, { width = w, cutoff = 8 * w, points = { x = px, y = py } })
for k, i in ipairs(idx) do
  check.eq(G.density[k], F.density[i], "points: density at grid point " .. i)
  check.eq(G.stress.xy[k], F.stress.xy[i], "points: stress xy at grid point " .. i)
end
check.eq(G.cells, nil, "points: no cells")

-- threads: the same bits on 1 and 2
grainlab.threads(1)
local F1 = analysis.coarse_grain(s, { width = w, kernel = "lucy", cells = { 33, 41 } })
grainlab.threads(2)
local F2 = analysis.coarse_grain(s, { width = w, kernel = "lucy", cells = { 33, 41 } })
grainlab.threads("auto")
local function bits(v) return string.format("%a", v) end -- NaN equals NaN here
for i = 1, F1.n do
  for _, k in ipairs{ "xx", "xy", "yx", "yy", "psd" } do
    if bits(F1.stress[k][i]) ~= bits(F2.stress[k][i]) or bits(F1.fabric[k][i]) ~= bits(F2.fabric[k][i]) then
      check.is_true(false, "1 and 2 threads differ at point " .. i .. " in " .. k)
    end
  end
  if bits(F1.density[i]) ~= bits(F2.density[i]) or bits(F1.velocity.y[i]) ~= bits(F2.velocity.y[i]) then
    check.is_true(false, "1 and 2 threads differ at point " .. i)
  end
end
check.eq(F1.kernel, "lucy", "kernel name")
check.eq(F1.cutoff, w, "Lucy: the cutoff is the width")

-- invariants of the total stress: pressure = tr / 2, psd >= 0, major >= minor, unit direction
for i = 1, F.n, 97 do
  local S = F.stress
  if F.density[i] > 0 then
    check.near_abs(S.pressure[i], 0.5 * (S.xx[i] + S.yy[i]), 1e-12 * (math.abs(S.xx[i]) + math.abs(S.yy[i])), "pressure")
    check.near_abs(S.major[i] - S.minor[i], S.psd[i], 1e-9 * (math.abs(S.major[i]) + 1e-30), "psd")
    check.near(S.dx[i] ^ 2 + S.dy[i] ^ 2, 1, 1e-12, "unit direction")
    check.near_abs(math.atan(S.dy[i], S.dx[i]), S.angle[i], 1e-12, "angle")
  end
end
-- the fabric's trace is the local coordination number: between 0 and 6 in a bed of disks
for i = 1, F.n, 53 do
  if F.volume_fraction[i] > 0.3 then
    local z = F.fabric.xx[i] + F.fabric.yy[i]
    check.is_true(z >= 0 and z <= 6, "fabric trace " .. z .. " at point " .. i)
  end
end

-- ---- averages ----------------------------------------------------------------------------------
local avg = analysis.cg_average(s, { width = w, cells = { 20, 24 } })
check.errors(function() avg:fields() end, "fields: no samples yet", "fields before add")
avg:add(s):add(s)
local A, one = avg:fields(), analysis.coarse_grain(s, { width = w, cells = { 20, 24 } })
check.eq(A.samples, 2, "samples")
for i = 1, A.n, 7 do
  check.near(A.density[i], one.density[i], 1e-15, "the average of one state twice")
  check.near_abs(A.stress.xy[i], one.stress.xy[i], 1e-12 * math.abs(one.stress.xx[i]) + 1e-30, "stress of a repeated state")
end
-- two states: the averaged density is the mean; the velocity is <p>/<rho>, not <V>
s:run{ steps = 200, dt = 2e-6, progress = false }
local two = analysis.coarse_grain(s, { width = w, cells = { 20, 24 } })
avg:reset():add(s)
local B = avg:fields()
avg:reset()
avg:add(s)
s:run{ steps = 0, dt = 2e-6, progress = false }
check.eq(avg:info().samples, 1, "reset")
local avg2 = analysis.cg_average(s, { width = w, cells = { 20, 24 } })
local s_first = analysis.coarse_grain(s, { width = w, cells = { 20, 24 } })
avg2:add(s)
s:run{ steps = 100, dt = 2e-6, progress = false }
local s_second = analysis.coarse_grain(s, { width = w, cells = { 20, 24 } })
avg2:add(s)
local M = avg2:fields()
for i = 1, M.n, 5 do
  local r1, r2 = s_first.density[i], s_second.density[i]
  check.near_abs(M.density[i], 0.5 * (r1 + r2), 1e-12 * (r1 + r2) + 1e-30, "mean density")
  if r1 + r2 > 0 then
    local p = (r1 * (s_first.velocity.x[i] == s_first.velocity.x[i] and s_first.velocity.x[i] or 0) +
               r2 * (s_second.velocity.x[i] == s_second.velocity.x[i] and s_second.velocity.x[i] or 0)) / (r1 + r2)
    check.near_abs(M.velocity.x[i], p, 1e-9 * (math.abs(p) + 1e-6), "mass-weighted mean velocity")
  end
end
check.is_true(M.time > M.time_first, "average times")
check.is_true(B.density and two.density and #B.density == #two.density, "fields after reset")
check.is_true(tostring(avg2):find("analysis.cg_average %(gauss, 480 points, 2 samples%)") ~= nil, tostring(avg2))

-- ---- files -------------------------------------------------------------------------------------
local dir = os.tmpname()
os.remove(dir)
os.execute("mkdir -p '" .. dir .. "'")
local Fw = analysis.coarse_grain(s, { width = w, cells = { 6, 5 }, vtk = dir .. "/f.vti", csv = dir .. "/f.csv" })
local fh = io.open(dir .. "/f.csv")
local header = fh:read("l")
local first = fh:read("l")
local nlines = 2
for _ in fh:lines() do nlines = nlines + 1 end
fh:close()
check.eq(nlines, 31, "csv: a header and 30 points")
check.is_true(header:find("^x,y,density,temperature,volume_fraction,stress_xx,stress_xy,stress_yx,stress_yy,") ~= nil, header)
check.is_true(header:find(",velocity_x,velocity_y,pressure,psd,direction_x,direction_y$") ~= nil, header)
local vals = {}
for v in first:gmatch("[^,]+") do vals[#vals + 1] = tonumber(v) end
check.eq(vals[1], Fw.x[1], "csv x")
check.eq(vals[3], Fw.density[1], "csv density (17 digits)")
local vti = io.open(dir .. "/f.vti"):read("a")
check.is_true(vti:find('<ImageData WholeExtent="0 5 0 4 0 0"') ~= nil, "vti extent")
check.is_true(vti:find('Name="stress" NumberOfComponents="9"') ~= nil, "vti stress tensor")
local A2 = avg2:fields{ csv = dir .. "/a.csv" }
check.eq(A2.samples, 2, "fields with files")
check.is_true(io.open(dir .. "/a.csv") ~= nil, "average csv written")
check.errors(function() analysis.coarse_grain(s, { width = w, points = { x = { 0 }, y = { 0 } }, vtk = dir .. "/p.vti" }) end,
  "bad field 'vtk' in argument #2 to 'coarse_grain' (nil with points", "vti needs a grid")
os.execute("rm -rf '" .. dir .. "'")

-- ---- 3D -----------------------------------------------------------------------------------------
do
  local L = 0.006
  local s3 = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { L, L, L } }, gravity = { 0, 0, -9.81 }, periodic = { true, true, false } }
  s3:add_wall{ point = { 0, 0, 0 }, normal = { 0, 0, 1 }, friction = 0 }
  local m = grainlab.material{ density = 2650, young = 5e7, poisson = 0.3, friction = 0.5, restitution = 0.6 }
  grainlab.pack.random(s3, { n = 60, radius = { 0.5e-3, 0.6e-3 }, seed = 2, material = m, speed = 0.05 })
  s3:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.6, impact_velocity = 1, tangential = "spring" }
  s3:run{ steps = 1500, dt = 2e-6, progress = false }
  local w3 = 0.6e-3
  local F3 = analysis.coarse_grain(s3, { width = w3, cutoff = 8 * w3, cells = { 20, 20, 40 },
                                         region = { { 0, 0, -5e-3 }, { L, L, L + 5e-3 } } })
  check.eq(F3.depth, nil, "3D: no depth")
  check.is_true(F3.stress.zz and F3.stress.xz and F3.stress.dz and not F3.stress.angle, "3D tensor fields")
  check.is_true(F3.velocity.z and F3.traction.z and #F3.fabric.zz == 20 * 20 * 40, "3D vectors and fabric")
end

-- ---- MPM: points' mass, momentum and stress -------------------------------------------------------
do
  -- (the fields' exactness for MPM points is scripts/cg_exactness.lua's, run by analysis_cg_exactness)
  local mm = mpm.scene{ cells = { 8, 8 }, size = { 0.008, 0.008 }, gravity = { 0, -9.81 } }
  mm:add_rect{ lo = { 0.002, 0 }, hi = { 0.006, 0.004 }, points_per_cell = 2,
               material = mpm.material{ model = "elastic", density = 2000, shear = 1e6, bulk = 2e6 } }
  mm:run{ steps = 5, progress = false }
  local Fm = analysis.coarse_grain(mm, { width = 1e-3, cells = { 8, 8 } })
  check.is_true(Fm.internal and not Fm.contact and not Fm.fabric, "MPM fields: internal stress, no contacts")
  check.errors(function() analysis.coarse_grain(mm, { width = 1e-3, cells = { 4, 4 }, contacts = false }) end,
    "bad field 'contacts' in argument #2 to 'coarse_grain' (nil for an mpm.scene (a DEM option) expected, got false)",
    "MPM: DEM options refused")
  local am = analysis.cg_average(mm, { width = 1e-3, cells = { 4, 4 } })
  check.errors(function() am:add(s) end, "add: this average was made for a mpm.scene, not a dem.scene", "kinds")
end

-- ---- refusals ----------------------------------------------------------------------------------
local function refused(opts, msg, what)
  check.errors(function() analysis.coarse_grain(s, opts) end, msg, what)
end
refused({ cells = { 4, 4 } }, "bad field 'width' in argument #2 to 'coarse_grain' (positive number expected, got nil)", "width required")
refused({ width = w }, "bad field 'cells' in argument #2 to 'coarse_grain' ({nx, ny[, nz]} (or 'points'", "cells or points")
refused({ width = w, cells = { 4, 4 }, kernl = "lucy" }, "unknown field 'kernl'; did you mean 'kernel'?", "typo")
refused({ width = w, cells = { 4, 4 }, kernel = "lucy", cutoff = 1e-3 },
  "bad field 'cutoff' in argument #2 to 'coarse_grain' (nil with kernel 'lucy' (its cutoff is its width) expected, got 0.001)", "Lucy cutoff")
refused({ width = w, cells = { 4, 4 }, cutoff = 11 * w }, "bad field 'cutoff' in argument #2 to 'coarse_grain' (cutoff at most 10 widths", "cutoff cap")
refused({ width = w, cells = { 4, 0 } }, "bad field 'cells' in argument #2 to 'coarse_grain' (positive integers of at most 100000", "cells 0")
refused({ width = w, cells = { 4, 4, 4 } }, "bad field 'cells' in argument #2 to 'coarse_grain' (array of 2 positive integers", "cells of 3D")
refused({ width = w, cells = { 1025, 1024 } }, "at most 1048576 cells in all", "too many cells")
refused({ width = w, cells = { 4, 4 }, points = { x = { 0 }, y = { 0 } } }, "bad field 'points' in argument #2 to 'coarse_grain' (nil when 'cells' or 'region' is given", "cells and points")
refused({ width = w, points = { x = { 0, 1 }, y = { 0 } } }, "bad field 'points.y' in argument #2 to 'coarse_grain' (array of 2 finite numbers (the length of 'points.x') expected, got 1 values)", "points lengths")
refused({ width = w, points = { x = { 0, 0 / 0 }, y = { 0, 0 } } }, "bad field 'points.x' in argument #2 to 'coarse_grain' (non-empty array of finite numbers expected, got ", "points NaN")
refused({ width = w, points = { x = { 0 }, y = { 0 }, z = { 0 } } }, "bad field 'points.z' in argument #2 to 'coarse_grain' (nil in 2D expected", "z in 2D")
refused({ width = w, cells = { 4, 4 }, region = { { 1, 0 }, { 0, 1 } } }, "bad field 'region' in argument #2 to 'coarse_grain' (upper corner above the lower one", "region")
refused({ width = w, cells = { 4, 4 }, displacement = true }, "coarse_grain: no reference state: call set_reference first", "displacement needs a reference")
refused({ width = 1, cells = { 4, 4 } }, "coarse_grain: the periodic x axis is 0.01 long, shorter than the kernel's reach 3", "period")
check.errors(function() analysis.coarse_grain({}, { width = 1 }) end,
  "bad argument #1 to 'coarse_grain' (dem.scene or mpm.scene expected, got table)", "scene")
check.errors(function() avg2.add(s) end, "", "add as a function")
s:set_reference()
local D = analysis.coarse_grain(s, { width = w, cells = { 4, 4 }, displacement = true })
check.eq(D.displacement.x[1] == D.displacement.x[1] and D.displacement.x[1] or 0, 0, "displacement right after set_reference")
check.done()
