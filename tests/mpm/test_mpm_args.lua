-- The mpm binding's contract on bad input: every error names the call, the field and the value.
local check = grainlab.check
local mat = mpm.material{ density = 3000, shear = 2.5e6, bulk = 10e6 }
local m = mpm.scene{ cells = { 10, 10 }, size = { 1, 1 } }

-- materials: non-positive moduli, unknown model, plastic fields on an elastic material
check.errors(function() mpm.material{ density = 3000, shear = 0, bulk = 1e6 } end,
  "bad field 'shear' in argument #1 to 'material' (positive number expected, got 0)", "zero shear")
check.errors(function() mpm.material{ density = 3000, shear = 1e6, bulk = -1 } end,
  "bad field 'bulk' in argument #1 to 'material' (positive number expected, got -1)", "negative bulk")
check.errors(function() mpm.material{ shear = 1e6, bulk = 1e6 } end,
  "bad field 'density' in argument #1 to 'material' (positive number expected, got nil)", "missing density")
check.errors(function() mpm.material{ model = "mohr", density = 1, shear = 1, bulk = 1 } end,
  "bad field 'model' in argument #1 to 'material' (one of 'elastic', 'vonmises', 'drucker_prager', 'mu_i' expected, got 'mohr')", "unknown model")
check.errors(function() mpm.material{ model = "vonmises", density = 1, shear = 1, bulk = 1 } end,
  "bad field 'yield' in argument #1 to 'material' (positive number expected, got nil)", "von Mises needs a yield stress")
check.errors(function() mpm.material{ density = 1, shear = 1, bulk = 1, yield = 5 } end,
  "bad field 'yield' in argument #1 to 'material' (nothing for model 'elastic'", "yield on elastic")
check.errors(function() mpm.material{ density = 1, shear = 1, bulk = 1, young = 5 } end,
  "bad argument #1 to 'material' (unknown field 'young'", "unknown material field")
local vm = mpm.material{ model = "vonmises", density = 1900, shear = 7.5e9, bulk = 11.4e9, yield = 0.3e9, hardening = 0.01e9 }
check.eq(vm.model, "vonmises", "material fields readable")

-- scenes
check.errors(function() mpm.scene{ cells = { 0, 10 }, size = { 1, 1 } } end,
  "bad field 'cells' in argument #1 to 'scene' (array of 2 integers", "zero cells")
check.errors(function() mpm.scene{ cells = { 10, 10 }, size = { 1, -1 } } end,
  "bad field 'size' in argument #1 to 'scene' (array of 2 positive numbers of at most 1e+100 expected", "negative size")
check.errors(function() mpm.scene{ cells = { 10, 10 }, size = { 1, 1 }, walls = "sticky" } end,
  "bad field 'walls' in argument #1 to 'scene' ('noslip', 'slip', 'none' or {kind = 'noslip'|'slip'|'friction', mu =, velocity = {vx, vy}} expected, got 'sticky')", "unknown wall")
check.errors(function() mpm.scene{ cells = { 10, 10 }, size = { 1, 1 }, walls = "friction" } end,
  "bad field 'walls' in argument #1 to 'scene' ({kind = 'friction', mu = ...} (a friction wall needs mu) expected, got 'friction')", "friction wall without mu")
check.errors(function() mpm.scene{ cells = { 10, 10 }, size = { 1, 1 }, walls = { bottom = { kind = "friction" } } } end,
  "bad field 'walls.bottom.mu' in argument #1 to 'scene' (non-negative number expected, got nil)", "friction wall table without mu")
check.errors(function() mpm.scene{ cells = { 10, 10 }, size = { 1, 1 }, walls = { bottom = { kind = "friction", mu = -1 } } } end,
  "bad field 'walls.bottom.mu' in argument #1 to 'scene' (non-negative number expected, got -1)", "negative wall mu")
check.errors(function() mpm.scene{ cells = { 10, 10 }, size = { 1, 1 }, shape = "cubic" } end,
  "bad field 'shape' in argument #1 to 'scene' (one of 'linear', 'bspline' expected, got 'cubic')", "unknown shape functions")
check.errors(function() mpm.scene{ cells = { 10, 10 }, size = { 1, 1 }, walls = { left = "x" } } end,
  "bad field 'walls.left' in argument #1 to 'scene'", "unknown wall side value")
check.errors(function() mpm.scene{ cells = { 10, 10 }, size = { 1, 1 }, pic = 2 } end,
  "bad field 'pic' in argument #1 to 'scene' (number in [0, 1] expected, got 2)", "pic above 1")
check.errors(function() mpm.scene{ cells = { 10, 10 }, size = { 1, 1 }, gravty = { 0, -9.8 } } end,
  "bad argument #1 to 'scene' (unknown field 'gravty'", "typo in a field")

-- planes, prescribed grains, contact options, fields
do
  local p = mpm.scene{ cells = { 10, 10 }, size = { 1, 1 } }
  check.errors(function() p:plane{ point = { 0, 0.2 }, normal = { 0, 0 }, mu = 0.3 } end,
    "bad field 'normal' in argument #1 to 'plane' (non-zero vector expected", "plane with a zero normal")
  check.errors(function() p:plane{ point = { 0, 0.2 }, normal = { 0, 1 } } end,
    "bad field 'mu' in argument #1 to 'plane' (non-negative number expected, got nil)", "friction plane without mu")
  check.errors(function() p:prescribe(1, { 0, 1 }) end,
    "bad argument #1 to 'prescribe' (grain id in [1, 0] expected, got 1)", "prescribe a missing grain")
  local g = p:add_disk{ center = { 0.5, 0.5 }, radius = 0.2, material = mpm.material{ density = 1, shear = 1, bulk = 1 } }
  check.errors(function() p:prescribe(g, { 0, 0 / 0 }) end,
    "bad argument #2 to 'prescribe' (array of 2 finite numbers expected, got ", "prescribe NaN")
  check.errors(function() p:contact{ model = "friction", mu = 0.3, separation = 1.5 } end,
    "bad field 'separation' in argument #1 to 'contact' (number in [0, 1] expected, got 1.5)", "separation above 1")
  check.errors(function() p:contact{ model = "friction", mu = 0.3, normals = "mine" } end,
    "bad field 'normals' in argument #1 to 'contact' (one of 'averaged', 'own', 'linear' expected, got 'mine')", "unknown normals")
  check.errors(function() p:field("temperature") end, "bad argument #1 to 'field' (invalid option 'temperature'; valid options: 'vx', 'vy',", "unknown field")
  check.errors(function() p:add_disk{ center = { 0.95, 0.5 }, radius = 0.2, material = mpm.material{ density = 1, shear = 1, bulk = 1 } } end,
    "outside the grid", "disk across the edge without clip")
  local c = p:add_disk{ center = { 0.95, 0.5 }, radius = 0.2, clip = true, material = mpm.material{ density = 1, shear = 1, bulk = 1 } }
  check.lt(p:grain(c).points, p:grain(g).points, "clip keeps only the points inside the grid")
  local f = p:field("grain")
  check.eq(#f.values, 100, "field: one value per cell")
end

-- polygons: a triangle's mass and centroid (16 points per cell: within 0.2% and 2e-4 m), bad vertices
do
  local pm = mpm.scene{ cells = { 20, 20 }, size = { 2, 2 } }
  local mt = mpm.material{ density = 1000, shear = 1e5, bulk = 1e5 }
  local t = pm:add_polygon{ vertices = { { 0.5, 0.5 }, { 1.5, 0.5 }, { 1.0, 1.366 } }, material = mt, points_per_cell = 4 }
  local gi = pm:grain(t)
  check.near(gi.mass, 1000 * 0.5 * 0.866, 0.002, "triangle mass")
  check.near_abs(gi.center[2], (0.5 + 0.5 + 1.366) / 3, 2e-4, "triangle centroid")
  check.errors(function() pm:add_polygon{ vertices = { { 0, 0 }, { 1, 1 }, { 2, 2 } }, material = mt } end,
    "add_polygon: the polygon has zero area (collinear vertices)", "collinear polygon")
  check.errors(function() pm:add_polygon{ vertices = { { 0, 0 }, { 1, 1 } }, material = mt } end,
    "bad field 'vertices' in argument #1 to 'add_polygon' (array of at least 3 vertices {x, y} expected", "two vertices")
  check.errors(function() pm:add_polygon{ vertices = { { 0, 0 }, { 1, 1 }, { 1, 0 / 0 } }, material = mt } end,
    "vertex 3 is not a pair of finite numbers", "NaN vertex")
end

-- grains
check.errors(function() m:add_disk{ center = { 0.5, 0.5 }, radius = 0.2, material = mat, points_per_cell = 0 } end,
  "bad field 'points_per_cell' in argument #1 to 'add_disk' (integer in [1, 64] expected, got 0)", "points per cell < 1")
check.errors(function() m:add_disk{ center = { 0.9, 0.5 }, radius = 0.2, material = mat } end,
  "add_disk: the shape spans [0.7, 1.1] in x, outside the grid [0, 1]", "disk outside the grid")
check.errors(function() m:add_disk{ center = { 0.5, 0.5 }, radius = -0.2, material = mat } end,
  "bad field 'radius' in argument #1 to 'add_disk' (positive number expected, got -0.2)", "negative radius")
check.errors(function() m:add_disk{ center = { 0.5, 0.5 }, radius = 0.2 } end,
  "bad field 'material' in argument #1 to 'add_disk' (mpm.material expected, got nil)", "missing material")
check.errors(function() m:add_disk{ center = { 0.5, 0.5 }, radius = 0.2, material = grainlab.material{ density = 1, young = 1 } } end,
  "bad field 'material' in argument #1 to 'add_disk' (mpm.material expected, got table)", "DEM material")
check.errors(function() m:add_disk{ center = { 0.5, 0.5 }, radius = 0.001, material = mat } end,
  "add_disk: the shape holds no point", "disk smaller than the point spacing")
check.errors(function() m:add_rect{ lo = { 0.5, 0.5 }, hi = { 0.4, 0.6 }, material = mat } end,
  "add_rect: the rectangle's upper corner must be above the lower one", "inverted rectangle")
check.errors(function() m:run{ steps = 1 } end, "run: the scene has no material points", "empty scene")
check.eq(m:add_disk{ center = { 0.5, 0.5 }, radius = 0.2, material = mat }, 1, "first grain id")

-- contact
m:contact{ model = "friction", mu = 0.3 } -- accepted (tests/mpm/test_mpm_friction.lua checks it)
check.eq(m:info().mu, 0.3, "friction accepted with its mu")
m:contact{ model = "noslip" }
check.errors(function() m:contact{ model = "glue" } end,
  "bad field 'model' in argument #1 to 'contact' (one of 'noslip', 'friction' expected, got 'glue')", "unknown contact")
check.errors(function() m:contact{ model = "noslip", mu = 0.3 } end,
  "bad field 'mu' in argument #1 to 'contact' (nothing for model 'noslip'", "mu without friction")
m:contact{ model = "noslip" }

-- time step
local ts = m:timestep()
check.near(ts.wave_speed, math.sqrt((10e6 + 4 / 3 * 2.5e6) / 3000), 1e-12, "P-wave speed")
check.near(ts.dt_auto, 0.4 * ts.limit, 1e-12, "default cfl 0.4")
local msg = check.errors(function() m:run{ steps = 1, dt = 2 * ts.limit } end,
  "run: dt = ", "dt above the CFL limit")
check.contains(msg, "exceeds the CFL limit", "the limit is in the message")
check.errors(function() m:run{ steps = 1, cfl = 1.5 } end,
  "bad field 'cfl' in argument #1 to 'run' (number in (0, 1] expected, got 1.5)", "cfl above 1")
check.errors(function() m:run{ steps = 1, time = 1 } end, "bad field 'time' in argument #1 to 'run' (nothing when 'steps' is given (give one) expected, got 1)", "steps and time")
check.errors(function() m:run{ stpes = 1 } end, "bad argument #1 to 'run' (unknown field 'stpes'", "typo in run")
check.errors(function() m:grain(2) end, "bad argument #1 to 'grain' (grain id in [1, 1] expected, got 2)", "unknown grain")
check.errors(function() m:measure("stress") end, "bad argument #1 to 'measure' (invalid option 'stress'; valid options: 'energy', 'momentum', 'columns', 'shear')", "unknown measure")

-- a point leaving the grid names the step and the grain
local open = mpm.scene{ cells = { 10, 10 }, size = { 1, 1 }, walls = "none" }
open:add_disk{ center = { 0.8, 0.5 }, radius = 0.1, material = mat, velocity = { 5, 0 } }
msg = check.errors(function() open:run{ time = 0.1 } end, "run: point ", "leaving the grid")
check.contains(msg, "of grain 1 left the grid at step ", "names the grain and the step")
check.contains(msg, "likely cause: no wall on the right edge of the grid: give it one (walls = { right = 'noslip' }",
               "names the open edge")
check.is_true(not msg:find("time step", 1, true), "an open edge: dt not blamed")
-- a point through an edge that has a wall is not blamed on the edge
local walled = mpm.scene{ cells = { 10, 10 }, size = { 1, 1 }, walls = { left = "none" } }
walled:add_disk{ center = { 0.8, 0.5 }, radius = 0.1, material = mat, velocity = { 5, 0 } }
msg = check.errors(function() walled:run{ steps = 3, dt = 0.05, force = true } end, "run: point ", "through the right wall")
check.contains(msg, "likely cause: the time step is too large: dt = 0.05 s is ", "through a wall at a forced dt: dt blamed")
-- a modulus in the wrong units: gravity alone strains the disk by 1.2e4
local soft = mpm.scene{ cells = { 40, 40 }, size = { 2, 2 }, gravity = { 0, -9.8 } }
soft:add_disk{ center = { 1, 0.5 }, radius = 0.5, points_per_cell = 3,
               material = mpm.material{ model = "elastic", density = 3000, shear = 2.5, bulk = 10 } }
msg = check.errors(function() soft:run{ time = 2 } end, "run: point ", "shear = 2.5 Pa")
check.contains(msg, string.format("likely cause: the material is too soft for the load: shear = 2.5 Pa gives strains of %.3g under gravity alone",
                                  3000 * 9.8 * 1 / 2.5), "shear = 2.5 Pa: the strain rho g h / G")
check.contains(msg, "h = 1 m); check the units (Pa)", "shear = 2.5 Pa: the grain's height and the remedy")

-- forced large dt blows up with an error naming the step and the grain
local blow = mpm.scene{ cells = { 10, 10 }, size = { 1, 1 } }
blow:add_disk{ center = { 0.5, 0.5 }, radius = 0.3, material = mat, velocity = { 1, 0 }, omega = 3 }
msg = check.errors(function() blow:run{ steps = 200, dt = 20 * blow:timestep().limit, force = true } end,
  "run: point ", "forced unstable step")
check.contains(msg, "of grain 1 ", "blow-up names the grain")
check.contains(msg, "at step ", "blow-up names the step")
check.contains(msg, "likely cause: the time step is too large: dt = ", "blow-up: the forced dt blamed")
check.contains(msg, " is 20 times the CFL limit ", "blow-up: by how much")
check.is_true(tostring(m):find("mpm.scene") ~= nil, "tostring")
check.done()
