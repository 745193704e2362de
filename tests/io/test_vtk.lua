-- VTK XML output read back by VTK itself: this script writes every kind of file grainlab makes
-- (DEM particles, contacts and walls in 2D and 3D, clumps, Delaunay cells, MPM points and grid,
-- DSMC particles and cells, .pvd series) together with what each must contain according to
-- grainlab's own accessors (s:particles(), s:measure('contacts'), mesh:strain(), m:points(),
-- m:field(), ...), then runs tests/io/vtk_read.py under Debian's /usr/bin/python3, which opens
-- each file with vtkXMLUnstructuredGridReader / vtkXMLImageDataReader (the .pvd with Python's
-- XML parser) and compares. Float64 values are printed with %.17g and must match exactly.
--   grainlab tests/io/test_vtk.lua reader=tests/io/vtk_read.py out=DIR [python=/usr/bin/python3]
local check = grainlab.check
local out = assert(params.out, "give out=DIR")
local reader = assert(params.reader, "give reader=vtk_read.py")
local python = params.python or "/usr/bin/python3"
os.execute("rm -rf '" .. out .. "' && mkdir -p '" .. out .. "'")

local lines = {}
local function expect(fmt, ...) lines[#lines + 1] = string.format(fmt, ...) end
local function g17(v) return string.format("%.17g", v) end
local function P(name) return out .. "/" .. name end

-- Errors first: they write nothing.
local s0 = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }
s0:add_disk{ pos = { 0.5, 0.5 }, radius = 0.1 }
check.errors(function() s0:write_vtk(P("x.txt")) end,
  "bad argument #1 to 'write_vtk' (file name ending in .vtu expected, got '", "extension")
check.errors(function() s0:write_vtk(P("x.vtu"), { contact = true }) end,
  "bad argument #2 to 'write_vtk' (unknown field 'contact'; did you mean 'contacts'? Valid fields: contacts, walls, clumps)",
  "typo in an option")
check.errors(function() s0:write_vtk(P("x.vtu"), { walls = 1 }) end,
  "bad field 'walls' in argument #2 to 'write_vtk' (boolean expected, got 1)", "option type")
check.errors(function() s0:write_vtk(P("x.vtu"), { grid = true }) end,
  "bad argument #2 to 'write_vtk' (unknown field 'grid'; valid fields: contacts, walls, clumps)",
  "option of another engine")
check.errors(function() grainlab.vtk.series(P("r.pvd"), { grid = false }):add(s0) end,
  "add: option 'grid' is for a mpm.scene, not a dem.scene", "series option of another engine")
check.errors(function() s0.write_vtk(P("x.vtu")) end,
  "write_vtk: a dem.scene expected as self, got '", "called with a dot")
check.errors(function() s0:write_vtk(P("no/such/dir/x.vtu")) end,
  "write_vtk: cannot write '" .. P("no/such/dir/x.vtu") .. "': No such file or directory",
  "missing directory")
check.errors(function() grainlab.vtk.series(P("run.vtu")) end,
  "bad argument #1 to 'series' (file name ending in .pvd expected", "series extension")
check.errors(function() grainlab.vtk.series(P("r.pvd")):add({}) end,
  "bad argument #1 to 'add' (dem.scene, mpm.scene or dsmc.scene expected, got table)", "add a table")
check.errors(function() grainlab.vtk.series(P("r.pvd")):add(s0, 0 / 0) end,
  "bad argument #2 to 'add' (finite number expected, got", "NaN time")
expect("absent x.vtu")
expect("absent r.pvd")

-- ---- DEM 2D: a frictionless block of disks pressed on two walls, a few steps in. -------------
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.03 } }, gravity = { 0, -9.81 } }
s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
s:add_wall{ point = { 0.02, 0 }, normal = { -1, 0 } }
local n = 0
for j = 1, 4 do
  for i = 1, 4 do
    n = n + 1 -- a square lattice: neighbours overlap by up to 2e-5 m; the larger disks of the
              -- first row and column touch the walls, and are pressed into them
    s:add_disk{ pos = { 0.00101 + 0.00199 * (i - 1), 0.00101 + 0.00199 * (j - 1) }, radius = 0.001 + 0.00001 * (n % 2) }
  end
end
s:contact{ normal = "linear", stiffness = 1e4 } -- undamped: the force depends on positions only
s:run{ steps = 5 }
local files = s:write_vtk(P("pile.vtu"))
check.eq(#files, 3, "pile: particles, contacts, walls")
check.eq(files[2], P("pile_contacts.vtu"), "pile: contacts file name")
check.eq(files[3], P("pile_walls.vtu"), "pile: walls file name")
local p = s:particles()
local c = s:measure("contacts")
check.gt(#c.i, 20, "pile: contacts to export")
expect("open pile.vtu vtu %d %d", p.count, p.count)
expect("field pile.vtu TimeValue 0 0 %s", g17(s:info().time))
for _, name in ipairs { "id", "radius", "velocity", "angular_velocity", "force", "mass", "material" } do
  expect("ncomp point pile.vtu %s %d", name, (name == "velocity" or name == "angular_velocity" or name == "force") and 3 or 1)
end
expect("type point pile.vtu id Int64")
expect("type point pile.vtu radius Float64")
-- Net force on each particle: its contacts (frictionless: fn along the normal from j to i) plus
-- gravity; summed in another order than the engine's, hence a tolerance.
local fx, fy = {}, {}
for i = 1, p.count do fx[i], fy[i] = 0, -9.81 * p.mass[i] end
local fmax = 0
for k = 1, #c.i do
  local i, j = c.i[k], c.j[k]
  fx[i], fy[i] = fx[i] + c.fn[k] * c.nx[k], fy[i] + c.fn[k] * c.ny[k]
  if j > 0 then fx[j], fy[j] = fx[j] - c.fn[k] * c.nx[k], fy[j] - c.fn[k] * c.ny[k] end
  fmax = math.max(fmax, c.fn[k])
end
for i = 1, p.count do
  local t = i - 1
  expect("cellpoints pile.vtu %d %d", t, t)
  expect("celltype pile.vtu %d 1", t)
  expect("coord pile.vtu %d 0 %s", t, g17(p.x[i]))
  expect("coord pile.vtu %d 1 %s", t, g17(p.y[i]))
  expect("coord pile.vtu %d 2 0", t)
  expect("point pile.vtu id %d 0 %d", t, i)
  expect("point pile.vtu radius %d 0 %s", t, g17(p.radius[i]))
  expect("point pile.vtu mass %d 0 %s", t, g17(p.mass[i]))
  expect("point pile.vtu velocity %d 0 %s", t, g17(p.vx[i]))
  expect("point pile.vtu velocity %d 1 %s", t, g17(p.vy[i]))
  expect("point pile.vtu velocity %d 2 0", t)
  expect("point pile.vtu angular_velocity %d 2 0", t) -- no rotations without friction
  expect("point pile.vtu material %d 0 1", t)
  expect("near point pile.vtu force %d 0 %s %s", t, g17(fx[i]), g17(1e-12 * fmax))
  expect("near point pile.vtu force %d 1 %s %s", t, g17(fy[i]), g17(1e-12 * fmax))
end
expect("open pile_contacts.vtu vtu %d %d", 2 * #c.i, #c.i)
for k = 1, #c.i do
  local t, i, j = k - 1, c.i[k], c.j[k]
  expect("celltype pile_contacts.vtu %d 3", t)
  expect("cellpoints pile_contacts.vtu %d %d %d", t, 2 * t, 2 * t + 1)
  expect("cell pile_contacts.vtu i %d 0 %d", t, i)
  expect("cell pile_contacts.vtu j %d 0 %d", t, j)
  expect("cell pile_contacts.vtu fn %d 0 %s", t, g17(c.fn[k]))
  expect("cell pile_contacts.vtu ft %d 0 %s", t, g17(c.ft[k]))
  expect("cell pile_contacts.vtu overlap %d 0 %s", t, g17(c.overlap[k]))
  expect("cell pile_contacts.vtu normal %d 0 %s", t, g17(c.nx[k]))
  expect("cell pile_contacts.vtu normal %d 1 %s", t, g17(c.ny[k]))
  expect("cell pile_contacts.vtu normal_force %d 0 %s", t, g17(c.fn[k] * c.nx[k]))
  expect("cell pile_contacts.vtu normal_force %d 1 %s", t, g17(c.fn[k] * c.ny[k]))
  expect("near cell pile_contacts.vtu tangential_force %d 0 0 %s", t, g17(1e-12 * fmax))
  -- the line starts at i's centre and ends at j's (pairs), at i's surface point (walls)
  expect("coord pile_contacts.vtu %d 0 %s", 2 * t, g17(p.x[i]))
  expect("coord pile_contacts.vtu %d 1 %s", 2 * t, g17(p.y[i]))
  if j > 0 then
    -- j's centre, as x_i - (r_i + r_j - overlap) n: equal to rounding
    expect("near coord pile_contacts.vtu %d 0 %s 1e-15", 2 * t + 1, g17(p.x[j]))
    expect("near coord pile_contacts.vtu %d 1 %s 1e-15", 2 * t + 1, g17(p.y[j]))
    expect("point pile_contacts.vtu fn %d 0 %s", 2 * t + 1, g17(c.fn[k]))
  else
    expect("coord pile_contacts.vtu %d 0 %s", 2 * t + 1, g17(p.x[i] - p.radius[i] * c.nx[k]))
  end
end
-- Walls: each a line across the box.
expect("open pile_walls.vtu vtu 6 3")
for w = 0, 2 do expect("celltype pile_walls.vtu %d 3", w) expect("cell pile_walls.vtu id %d 0 %d", w, w + 1) end
expect("cell pile_walls.vtu force 0 0 %s", g17(s:wall_force(1)))
expect("cell pile_walls.vtu normal 2 0 -1")
expect("coord pile_walls.vtu 0 1 0") -- the floor across the box
expect("coord pile_walls.vtu 1 1 0")

-- Without contacts and walls, only the particle file; with walls = false on a scene with walls.
files = s:write_vtk(P("only.vtu"), { contacts = false, walls = false })
check.eq(#files, 1, "only the particles")
expect("absent only_contacts.vtu")
expect("absent only_walls.vtu")

-- ---- Ids are tags: after a removal the indices shift, the id array (which ParaView and OVITO
-- track a grain by) does not. Disk 1 leaves through the open side; the stack 3-4-5 rests on the
-- floor, so the contacts name the particles too.
do
  local st = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.02 } }, gravity = { 0, -9.81 } }
  st:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  st:add_disk{ pos = { 0.018, 0.015 }, radius = 0.001, vel = { 2, 0 } }  -- leaves through x+
  st:add_disk{ pos = { 0.003, 0.015 }, radius = 0.001, vel = { -2, 0 } } -- leaves through x-
  for k = 0, 2 do st:add_disk{ pos = { 0.01, 0.001 + 0.002 * k }, radius = 0.001 } end
  st:contact{ normal = "linear", stiffness = 1e4, damping = "viscous", gamma_n = 0.05 }
  st:outflow{ side = "x+" }
  st:outflow{ side = "x-" }
  st:run{ time = 0.02 }
  local pt, ct = st:particles(), st:measure("contacts")
  check.eq(pt.count, 3, "tags: two of five removed")
  check.eq(pt.tag[1], 3, "tags: the first left is the third made")
  check.eq(#ct.i, 3, "tags: floor-3, 3-4, 4-5 in contact")
  st:write_vtk(P("tags.vtu"))
  expect("open tags.vtu vtu 3 3")
  for i = 1, pt.count do expect("point tags.vtu id %d 0 %d", i - 1, pt.tag[i]) end
  for k = 1, #ct.i do
    expect("cell tags_contacts.vtu i %d 0 %d", k - 1, pt.tag[ct.i[k]])
    expect("cell tags_contacts.vtu j %d 0 %d", k - 1, ct.j[k] > 0 and pt.tag[ct.j[k]] or ct.j[k])
  end
end

-- ---- Delaunay cells of the pile --------------------------------------------------------------
local mesh = analysis.delaunay(s)
s:drag(0)
s:set_velocity(1, { 0.01, 0 })
s:run{ steps = 50 }
local info = mesh:info()
local extra = {}
for k = 1, info.cells do extra[k] = k * 0.5 end
check.eq(mesh:write_vtk(P("cells.vtu"), s, { depth = 1e-3, cells = { half_index = extra } }), P("cells.vtu"), "cells: path")
local cl, st, sr, sg = mesh:cells(s), mesh:strain(s), mesh:strain_rate(s), mesh:stress(s, { depth = 1e-3 })
expect("open cells.vtu vtu %d %d", s:info().count, info.cells)
for k = 1, info.cells do
  local t = k - 1
  expect("celltype cells.vtu %d 5", t)
  expect("cellpoints cells.vtu %d %d %d %d", t, cl.a[k] - 1, cl.b[k] - 1, cl.c[k] - 1)
  expect("cell cells.vtu area %d 0 %s", t, g17(cl.area[k]))
  expect("cell cells.vtu strain %d 0 %s", t, g17(st.xx[k]))
  expect("cell cells.vtu strain %d 1 %s", t, g17(st.xy[k]))
  expect("cell cells.vtu strain %d 3 %s", t, g17(st.yx[k]))
  expect("cell cells.vtu strain %d 4 %s", t, g17(st.yy[k]))
  expect("cell cells.vtu velocity_gradient %d 1 %s", t, g17(sr.xy[k]))
  expect("cell cells.vtu lii %d 0 %s", t, g17(sr.lii[k]))
  expect("cell cells.vtu stress %d 0 %s", t, g17(sg.xx[k]))
  expect("cell cells.vtu stress %d 4 %s", t, g17(sg.yy[k]))
  expect("cell cells.vtu pressure %d 0 %s", t, g17(sg.pressure[k]))
  expect("cell cells.vtu half_index %d 0 %s", t, g17(extra[k]))
end
check.errors(function() mesh:write_vtk(P("bad.vtu"), s, { cells = { short = { 1, 2 } } }) end,
  string.format("bad field 'cells.short' in argument #3 to 'write_vtk' (array of %d numbers expected, got table)", info.cells),
  "cells: wrong length")
check.errors(function() mesh:write_vtk(P("bad.vtu"), s, { stress = true }) end,
  "write_vtk: give opts.depth (m): the scene has no thickness", "cells: stress without a depth")
expect("absent bad.vtu")
-- Without a depth (spheres in the plane): no stress arrays, the rest as before.
mesh:write_vtk(P("cells_nostress.vtu"), s)
expect("ncomp cell cells_nostress.vtu strain 9")

-- ---- DEM 3D with friction: rotations and wall polygons ---------------------------------------
local s3 = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 0.01, 0.01, 0.01 } }, gravity = { 0, 0, -9.81 } }
s3:contact{ tangential = "spring" }
s3:add_wall{ point = { 0, 0, 0 }, normal = { 0, 0, 1 } }
s3:add_wall{ point = { 0.005, 0.005, 0.005 }, normal = { 1, 1, 1 } } -- a hexagon through the centre
for k = 0, 7 do -- a 2 x 2 x 2 block in the corner above the diagonal wall
  s3:add_sphere{ pos = { 0.0066 + 0.0022 * (k % 2), 0.0066 + 0.0022 * (k // 2 % 2), 0.0045 + 0.0025 * (k // 4) },
                 radius = 0.001, omega = { k, -k, 0.5 * k } }
end
s3:run{ steps = 200 }
s3:write_vtk(P("s3.vtu"))
local p3 = s3:particles()
expect("open s3.vtu vtu %d %d", p3.count, p3.count)
for i = 1, p3.count do
  expect("coord s3.vtu %d 2 %s", i - 1, g17(p3.z[i]))
  expect("point s3.vtu velocity %d 2 %s", i - 1, g17(p3.vz[i]))
  expect("point s3.vtu angular_velocity %d 0 %s", i - 1, g17(p3.wx[i]))
  expect("point s3.vtu angular_velocity %d 1 %s", i - 1, g17(p3.wy[i]))
  expect("point s3.vtu angular_velocity %d 2 %s", i - 1, g17(p3.wz[i]))
end
expect("open s3_walls.vtu vtu 10 2")
expect("celltype s3_walls.vtu 0 9") -- the floor: a quad
expect("celltype s3_walls.vtu 1 7") -- the diagonal plane cuts the cube in a hexagon
expect("cellpoints s3_walls.vtu 1 4 5 6 7 8 9")
-- the hexagon's corners lie on the plane x + y + z = 0.015 (coordinates summed by the reader)
expect("sum coord s3_walls.vtu 4 9 0.015 1e-12")

-- ---- MPM: a spinning elastic disk, points and grid -------------------------------------------
local mat = mpm.material{ density = 3000, shear = 2.5e6, bulk = 10e6 }
local m = mpm.scene{ cells = { 8, 6 }, size = { 0.8, 0.6 }, origin = { -0.1, 0.2 } }
m:add_disk{ center = { 0.3, 0.5 }, radius = 0.2, material = mat, omega = 2, velocity = { 0.3, 0 } }
m:run{ steps = 5 }
files = m:write_vtk(P("disk.vtu"))
check.eq(files[2], P("disk_grid.vti"), "mpm: grid file name")
local mp = m:points()
expect("open disk.vtu vtu %d %d", mp.count, mp.count)
local total = 0
for i = 1, mp.count do
  local t = i - 1
  total = total + mp.mass[i]
  expect("coord disk.vtu %d 0 %s", t, g17(mp.x[i]))
  expect("coord disk.vtu %d 1 %s", t, g17(mp.y[i]))
  expect("point disk.vtu velocity %d 0 %s", t, g17(mp.vx[i]))
  expect("point disk.vtu velocity %d 1 %s", t, g17(mp.vy[i]))
  expect("point disk.vtu mass %d 0 %s", t, g17(mp.mass[i]))
  expect("point disk.vtu volume %d 0 %s", t, g17(mp.volume[i]))
  expect("point disk.vtu grain %d 0 1", t)
  expect("point disk.vtu stress %d 0 %s", t, g17(mp.sxx[i]))
  expect("point disk.vtu stress %d 1 %s", t, g17(mp.sxy[i]))
  expect("point disk.vtu stress %d 3 %s", t, g17(mp.sxy[i]))
  expect("point disk.vtu stress %d 4 %s", t, g17(mp.syy[i]))
  expect("point disk.vtu stress %d 8 %s", t, g17(mp.szz[i]))
  expect("point disk.vtu deformation_gradient %d 3 %s", t, g17(mp.Fyx[i]))
  expect("point disk.vtu displacement %d 0 %s", t, g17(mp.ux[i]))
  expect("point disk.vtu eps_p %d 0 %s", t, g17(mp.eps_p[i]))
end
expect("open disk_grid.vti vti %d %d", 9 * 7, 8 * 6)
expect("image disk_grid.vti 9 7 1 -0.10000000000000001 0.20000000000000001 0 0.10000000000000001 0.099999999999999992 1")
-- The nodal masses carry the points' mass (a partition of unity).
expect("sum point disk_grid.vti mass 0 %s 1e-12", g17(total))
for _, name in ipairs { "vx", "pressure", "psd", "grain", "mass" } do
  local f = m:field(name)
  for k = 1, #f.values, 5 do
    local v = f.values[k]
    expect("cell disk_grid.vti %s %d 0 %s", name, k - 1, v ~= v and "nan" or g17(v))
  end
end

-- ---- DSMC: particles and cells ---------------------------------------------------------------
local d = dsmc.scene{ dim = 3, size = { 0.1, 0.1, 0.05 }, cells = { 8, 8, 4 }, radius = 1e-3 }
d:fill{ n = 2000, temperature = 1e-6, seed = 3 }
d:run{ steps = 3, dt = 1e-4 }
d:write_vtk(P("gas.vtu"))
local dp = d:particles()
expect("open gas.vtu vtu 2000 2000")
for i = 1, 2000, 37 do
  expect("coord gas.vtu %d 2 %s", i - 1, g17(dp.z[i]))
  expect("point gas.vtu velocity %d 0 %s", i - 1, g17(dp.vx[i]))
  expect("point gas.vtu velocity %d 2 %s", i - 1, g17(dp.vz[i]))
  expect("point gas.vtu radius %d 0 0.001", i - 1)
end
expect("open gas_cells.vti vti %d %d", 9 * 9 * 5, 8 * 8 * 4)
expect("sum cell gas_cells.vti count 0 2000 0")
local fields = d:measure("fields")
for k = 1, 256, 5 do
  expect("cell gas_cells.vti count %d 0 %s", k - 1, g17(fields.count[k]))
  local T = fields.temperature[k]
  expect("cell gas_cells.vti temperature %d 0 %s", k - 1, T ~= T and "nan" or g17(T))
end

-- ---- a series from on_step, and one that stops with an error ----------------------------------
local series = grainlab.vtk.series(P("run.pvd"))
local times = {}
s:run{ steps = 30, every = 10, on_step = function(sc)
  series:add(sc)
  times[#times + 1] = sc:info().time
end }
series:add(s, 1.5) -- an explicit time
times[#times + 1] = 1.5
check.errors(function() series:add(m) end, "add: this series holds dem.scene frames, got a mpm.scene",
  "one kind per series")
local sinfo = series:info()
check.eq(sinfo.frames, 4, "series: frames")
check.eq(#sinfo.collections, 3, "series: particles, contacts, walls")
for _, part in ipairs { "", "_contacts", "_walls" } do
  local args = {}
  for k, t in ipairs(times) do
    args[#args + 1] = g17(t)
    args[#args + 1] = string.format("run%s_%04d.vtu", part, k)
  end
  expect("pvd run%s.pvd 4 %s", part, table.concat(args, " "))
end
expect("absent run_0005.vtu")

-- MPM and DSMC series: their own parts.
local ms = grainlab.vtk.series(P("mpm.pvd"), { grid = false })
ms:add(m)
expect("pvd mpm.pvd 1 %s mpm_0001.vtu", g17(m:info().time))
expect("absent mpm_grid.pvd")
local ds = grainlab.vtk.series(P("gas.pvd"))
ds:add(d, 0)
expect("pvd gas_cells.pvd 1 0 gas_cells_0001.vti")

-- ---- walls beyond planes: a polyline and a circle (2D; polylines), a mesh (triangles) and a
-- finite cylinder (its two rims) in 3D, with their id, kind, load and torque ----------------------
do
  local s = dem.scene{ dim = 2, box = { { -1, -1 }, { 1, 1 } }, gravity = { 0, -9.81 } }
  s:add_disk{ pos = { 0, -0.45 }, radius = 0.05 }
  s:add_wall{ point = { 0, -0.9 }, normal = { 0, 1 } }
  s:add_polyline{ points = { { -0.5, 0.5 }, { 0, 0.6 }, { 0.5, 0.5 } } }
  local c = s:add_cylinder{ center = { 0, 0 }, radius = 0.5, omega = 2 }
  s:run{ steps = 2000 }
  s:write_vtk(P("shapes2.vtu"))
  expect("open shapes2_walls.vtu vtu %d 3", 2 + 3 + 65)
  expect("celltype shapes2_walls.vtu 0 3")
  expect("celltype shapes2_walls.vtu 1 4")
  expect("celltype shapes2_walls.vtu 2 4")
  expect("cellpoints shapes2_walls.vtu 1 2 3 4")
  expect("coord shapes2_walls.vtu 3 1 0.59999999999999998")
  for k, v in ipairs{ 0, 1, 3 } do expect("cell shapes2_walls.vtu kind %d 0 %d", k - 1, v) end
  expect("cell shapes2_walls.vtu id 2 0 3")
  local f, t = s:wall_load(c)
  expect("cell shapes2_walls.vtu load 2 1 %s", g17(f[2]))
  expect("cell shapes2_walls.vtu torque 2 2 %s", g17(t))
  local s3 = dem.scene{ dim = 3, box = { { -1, -1, -1 }, { 1, 1, 1 } } }
  s3:add_sphere{ pos = { 0, 0, 0.5 }, radius = 0.05 }
  s3:add_mesh{ triangles = { { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } }, { { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 } } } }
  s3:add_cylinder{ center = { 0, 0, 0 }, radius = 0.8, axis = { 0, 0, 1 }, length = 1 }
  s3:write_vtk(P("shapes3.vtu"))
  expect("open shapes3_walls.vtu vtu %d 4", 6 + 2 * 65)
  expect("celltype shapes3_walls.vtu 0 5")
  expect("celltype shapes3_walls.vtu 1 5")
  expect("celltype shapes3_walls.vtu 2 4")
  expect("celltype shapes3_walls.vtu 3 4")
  expect("coord shapes3_walls.vtu 4 0 1")
  expect("coord shapes3_walls.vtu 4 1 1")
  expect("near coord shapes3_walls.vtu 6 2 -0.5 1e-15") -- the lower rim at z = -length/2
  expect("near coord shapes3_walls.vtu 71 2 0.5 1e-15")
  expect("cell shapes3_walls.vtu kind 3 0 3")
end

-- ---- coarse-grained fields (analysis.coarse_grain's vtk =): ImageData with the cell centres as
-- points, scalars, vectors (3 components) and tensors (3 x 3) as point data -------------------------
do
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 }, thickness = 1e-3 }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  for k, p in ipairs{ { 0.002, 0.0005 }, { 0.0029, 0.0005 }, { 0.0025, 0.0012 } } do
    s:add_disk{ pos = p, radius = 0.0005, vel = { 0.01 * k, 0 } }
  end
  local F = analysis.coarse_grain(s, { width = 1e-3, cells = { 5, 4 }, region = { { 0, 0 }, { 0.01, 0.008 } },
                                       vtk = P("cg.vti") })
  expect("open cg.vti vti 20 12")
  expect("image cg.vti 5 4 1 %s %s 0 %s %s 1", g17(0.001), g17(0.001), g17(0.002), g17(0.002))
  expect("ncomp point cg.vti density 1")
  expect("ncomp point cg.vti velocity 3")
  expect("ncomp point cg.vti stress 9")
  expect("type point cg.vti stress Float64")
  for _, k in ipairs{ 1, 7, 12 } do
    expect("point cg.vti density %d 0 %s", k - 1, g17(F.density[k]))
    expect("point cg.vti stress %d 1 %s", k - 1, g17(F.stress.xy[k]))
    expect("point cg.vti stress %d 4 %s", k - 1, g17(F.stress.yy[k]))
    expect("point cg.vti stress %d 8 0", k - 1)
    expect("point cg.vti traction %d 1 %s", k - 1, g17(F.traction.y[k]))
    local vx = F.velocity.x[k]
    expect("point cg.vti velocity %d 0 %s", k - 1, vx ~= vx and "nan" or g17(vx))
    expect("point cg.vti psd %d 0 %s", k - 1, g17(F.stress.psd[k]))
  end
  local s3 = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 0.01, 0.01, 0.01 } } }
  s3:add_sphere{ pos = { 0.005, 0.005, 0.005 }, radius = 0.001 }
  s3:add_sphere{ pos = { 0.0069, 0.005, 0.005 }, radius = 0.001 }
  local F3 = analysis.coarse_grain(s3, { width = 1e-3, cells = { 4, 3, 2 }, vtk = P("cg3.vti") })
  expect("open cg3.vti vti 24 6")
  expect("point cg3.vti density 9 0 %s", g17(F3.density[10]))
  expect("point cg3.vti fabric 9 0 %s", g17(F3.fabric.xx[10]))
end

-- ---- clumps: the members' clump id (0 for a loose grain) and a vertex per body, 2D and 3D -------
for _, dim in ipairs{ 2, 3 } do
  local box = dim == 2 and { { 0, 0 }, { 0.02, 0.02 } } or { { 0, 0, 0 }, { 0.02, 0.02, 0.02 } }
  local s = dem.scene{ dim = dim, box = box, gravity = dim == 2 and { 0, -9.81 } or { 0, 0, -9.81 } }
  local mat = grainlab.material{ density = 1500, young = 2e6, poisson = 0.3, friction = 0.5 }
  s:contact{ tangential = "spring" }
  local function v(x, y, z) if dim == 2 then return { x, y } else return { x, y, z } end end
  local pair = { { offset = v(0, 0, 0), radius = 0.001 }, { offset = v(0.0012, 0, 0.0003), radius = 0.0008 } }
  local loose = { pos = v(0.004, 0.01, 0.01), radius = 0.001, material = mat }
  if dim == 2 then s:add_disk(loose) else s:add_sphere(loose) end
  s:add_clump{ members = pair, material = mat, position = v(0.01, 0.01, 0.01), spin = dim == 2 and 3 or { 1, 2, 3 } }
  s:add_clump{ members = pair, material = mat, position = v(0.01, 0.005, 0.005), velocity = v(0.1, 0, 0),
               orientation = dim == 2 and 0.5 or { axis = { 0, 0, 1 }, angle = 0.5 } }
  s:run{ steps = 5 }
  local name = "clumps" .. dim
  local files = s:write_vtk(P(name .. ".vtu"))
  check.eq(files[#files], P(name .. "_clumps.vtu"), dim .. "D clumps: the bodies' file")
  expect("type point %s.vtu clump Int64", name)
  for i, k in ipairs{ 0, 1, 1, 2, 2 } do expect("point %s.vtu clump %d 0 %d", name, i - 1, k) end
  expect("open %s_clumps.vtu vtu 2 2", name)
  for k = 1, 2 do
    local c = s:clump(k)
    expect("point %s_clumps.vtu id %d 0 %d", name, k - 1, k)
    expect("point %s_clumps.vtu mass %d 0 %s", name, k - 1, g17(c.mass))
    expect("point %s_clumps.vtu members %d 0 2", name, k - 1)
    expect("point %s_clumps.vtu first_member %d 0 %d", name, k - 1, c.members[1])
    for d = 1, dim do
      expect("coord %s_clumps.vtu %d %d %s", name, k - 1, d - 1, g17(c.position[d]))
      expect("point %s_clumps.vtu velocity %d %d %s", name, k - 1, d - 1, g17(c.velocity[d]))
    end
    if dim == 2 then
      expect("point %s_clumps.vtu orientation %d 0 %s", name, k - 1, g17(c.orientation))
      expect("point %s_clumps.vtu angular_velocity %d 2 %s", name, k - 1, g17(c.spin))
      expect("point %s_clumps.vtu inertia %d 2 %s", name, k - 1, g17(c.inertia))
    else
      expect("ncomp point %s_clumps.vtu orientation 4", name)
      for q = 1, 4 do expect("point %s_clumps.vtu orientation %d %d %s", name, k - 1, q - 1, g17(c.orientation[q])) end
      for d = 1, 3 do
        expect("point %s_clumps.vtu angular_velocity %d %d %s", name, k - 1, d - 1, g17(c.spin[d]))
        expect("point %s_clumps.vtu angular_momentum %d %d %s", name, k - 1, d - 1, g17(c.angular_momentum[d]))
        expect("point %s_clumps.vtu inertia %d %d %s", name, k - 1, d - 1, g17(c.inertia[d]))
      end
    end
  end
end

-- ---- VTK reads it all --------------------------------------------------------------------------
local ef = assert(io.open(P("expect.txt"), "w"))
ef:write(table.concat(lines, "\n"), "\n")
ef:close()
local cmd = string.format("%s '%s' '%s' '%s'", python, reader, out, P("expect.txt"))
local ok, how, code = os.execute(cmd)
check.is_true(ok, string.format("VTK's readers accept every file (%s %s: %s)", how, tostring(code), cmd))
print(string.format("vtk: %d expectations checked by VTK", #lines))
