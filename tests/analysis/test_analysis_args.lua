-- The analysis binding's contract on bad input: every table is checked for its shape
-- (type, length, element types, finite numbers, matching lengths, ids in range and distinct)
-- before it is indexed, and every refusal is a Lua error naming the call, the field and the
-- value. Each case here used to crash (segfault, heap overflow) or to print lua_pushfstring's
-- "invalid option '%z'" instead of the message. Runs in the sanitizer build too.
local check = grainlab.check

local square = { x = { 0, 1, 0, 1, 0.5 }, y = { 0, 0, 1, 1, 0.5 } }
local nan = 0 / 0

-- ---- a square and its centre, valid input (once a heap-buffer-overflow under ASan) -----------
local m = analysis.delaunay({ x = square.x, y = square.y, radius = { 0.3, 0.3, 0.3, 0.3, 0.3 } })
local info = m:info()
check.eq(info.delaunay, 4, "square + centre: Delaunay triangles")
check.eq(info.peeled, 1, "square + centre: one side triangle peeled (1 > 1.5 x 0.6)")
check.eq(info.cells, 3, "square + centre: cells kept")
check.eq(info.boundary, 5, "square + centre: the centre joins the loop")
check.near(info.area, 0.75, 1e-14, "square + centre: area")
-- A row of centres along a wall: qhull's flat sliver is peeled even at alpha = 0.
local row = analysis.delaunay({ x = { 0, 0.001, 0.002, 0.001 }, y = { 0, 1.73505, 3.4701, 1 } }, { alpha = 0 })
for _, a in ipairs(row:cells().area) do check.gt(a, 1e-6, "no flat cell at alpha = 0") end

-- ---- analysis.delaunay: ids out of range, duplicated, not integers, given without radii --------
local function ids_error(ids, got, what)
  check.errors(function() analysis.delaunay(square, { ids = ids }) end,
    "bad field 'ids' in argument #2 to 'delaunay' (" .. got .. ")", what)
end
ids_error({ 1, 2, 9 }, "particle ids in [1, 5] expected, got 9 at entry 3", "id above the count")
ids_error({ 0, 1, 2 }, "particle ids in [1, 5] expected, got 0 at entry 1", "id 0")
ids_error({ 1, -3, 2 }, "particle ids in [1, 5] expected, got -3 at entry 2", "negative id")
ids_error({ 1, 2.5, 4 }, "particle ids in [1, 5] expected, got 2.5 at entry 2", "fractional id")
ids_error({ 1, "2", 4 }, "particle ids in [1, 5] expected, got '2' at entry 2", "id as a string")
ids_error({ 1, 2, math.huge }, "particle ids in [1, 5] expected, got inf at entry 3", "infinite id")
ids_error({ 1, 2, 1e300 }, "particle ids in [1, 5] expected, got 1e+300 at entry 3", "huge id")
ids_error({ 1, 2, {} }, "particle ids in [1, 5] expected, got table at entry 3", "table as an id")
ids_error({ 1, 2, 2, 3 }, "distinct particle ids expected, got 2 at entries 2 and 3", "duplicated id")
ids_error({ 4, 1, 3, 4 }, "distinct particle ids expected, got 4 at entries 1 and 4", "duplicated id, apart")
ids_error(3, "array of particle ids expected, got 3", "ids not a table")
local msg = check.errors(function() analysis.delaunay(square, { ids = { 1, 2, nan } }) end,
  "bad field 'ids' in argument #2 to 'delaunay' (particle ids in [1, 5] expected, got ", "NaN id")
check.contains(msg, "nan at entry 3)", "NaN id shown")
-- Without radii (this crashed: the ids table was looked up at the wrong stack slot).
local sub = analysis.delaunay(square, { ids = { 1, 2, 4 } })
check.eq(sub:info().cells, 1, "ids without radii: one triangle")
check.eq(table.concat(sub:boundary(), " "), "1 2 4", "ids without radii: the loop names the ids")
local subr = analysis.delaunay({ x = square.x, y = square.y, radius = { 1, 1, 1, 1, 1 } }, { ids = { 5, 1, 2 } })
check.eq(subr:info().cells, 1, "ids with radii")
check.errors(function() analysis.delaunay(square, { ids = {} }) end,
  "bad field 'ids' in argument #2 to 'delaunay' (array of at least 3 distinct particle ids expected, got table)", "empty ids")

-- ---- analysis.delaunay: the coordinate and radius arrays --------------------------------------
check.errors(function() analysis.delaunay({ x = { 0, 1, 0 }, y = { 0, 0 } }) end,
  "bad field 'y' in argument #1 to 'delaunay' (array of 3 finite numbers expected, got 2 values)", "y shorter than x")
check.errors(function() analysis.delaunay({ x = { 0, 1, 0 }, y = { 0, 0, 1 }, radius = { 1, 1 } }) end,
  "bad field 'radius' in argument #1 to 'delaunay' (array of 3 finite numbers expected, got 2 values)", "radius shorter")
msg = check.errors(function() analysis.delaunay({ x = { 0, 1, nan }, y = { 0, 0, 1 } }) end,
  "bad field 'x' in argument #1 to 'delaunay' (array of finite numbers expected, got ", "NaN x")
check.contains(msg, "nan at entry 3)", "NaN x shown")
check.errors(function() analysis.delaunay({ x = { 0, 1, 0 }, y = { 0, math.huge, 1 } }) end,
  "bad field 'y' in argument #1 to 'delaunay' (array of 3 finite numbers expected, got inf at entry 2)", "infinite y")
check.errors(function() analysis.delaunay({ x = { 0, "1", 0 }, y = { 0, 0, 1 } }) end,
  "bad field 'x' in argument #1 to 'delaunay' (array of finite numbers expected, got '1' at entry 2)", "string in x")
check.errors(function() analysis.delaunay({ x = 5, y = { 0, 0, 1 } }) end,
  "bad field 'x' in argument #1 to 'delaunay' (array of finite numbers expected, got 5)", "x not a table")
check.errors(function() analysis.delaunay({ y = { 0, 0, 1 } }) end,
  "bad field 'x' in argument #1 to 'delaunay' (array of finite numbers expected, got nil)", "x missing")
check.errors(function() analysis.delaunay({ x = { 0, 1, 0 }, y = { 0, 0, 1 }, radius = { 1, -1, 1 } }) end,
  "bad field 'radius' in argument #1 to 'delaunay' (array of positive radii expected, got -1 at entry 2)", "negative radius")
check.errors(function() analysis.delaunay({ x = { 0, 1, 0 }, y = { 0, 0, 1 }, radius = { 1, 1, 0 } }) end,
  "bad field 'radius' in argument #1 to 'delaunay' (array of positive radii expected, got 0 at entry 3)", "zero radius")
check.errors(function() analysis.delaunay({ x = { 0, 1, 2 }, y = { 0, 1, 2 } }) end,
  "delaunay: all 3 particle centres are collinear", "collinear")
check.errors(function() analysis.delaunay({ x = { 0, 1, 0, 1 }, y = { 0, 0, 1, 0 } }) end,
  "delaunay: particles 2 and 4 have the same position (1, 0)", "duplicate position")
check.errors(function() analysis.delaunay({ x = { 1, 1, 1 }, y = { 2, 2, 2 } }) end,
  "delaunay: all 3 particles have the same position (1, 2)", "one point")
check.errors(function() analysis.delaunay(square, { alpha = -1 }) end,
  "bad field 'alpha' in argument #2 to 'delaunay' (non-negative number expected, got -1)", "negative alpha")
check.errors(function() analysis.delaunay(square, { idz = { 1, 2, 3 } }) end,
  "argument #2 to 'delaunay'", "unknown option")

-- ---- mesh methods: state tables, raster (two formats used %zu) --------------------------------
check.errors(function() m:strain({ x = { 1, 2 }, y = { 1, 2 } }) end,
  "bad field 'x' in argument #1 to 'strain' (array of 5 finite numbers expected, got 2 values)", "strain state length")
check.errors(function() m:strain_rate({ x = square.x, y = square.y, vx = { 0, 0, 0, 0, 0 }, vy = { 0, 0, 0, nan, 0 } }) end,
  "bad field 'vy' in argument #1 to 'strain_rate' (array of 5 finite numbers expected, got ", "strain_rate NaN vy")
msg = check.errors(function() m:raster({ 1, 2 }, { nx = 2, ny = 2, extent = { { 0, 0 }, { 1, 1 } } }) end,
  "bad argument #1 to 'raster' (array of 3 cell values expected, got 2 values)", "raster: values length (was %zu)")
check.is_true(not msg:find("invalid option", 1, true), "no lua_pushfstring option error")
check.errors(function() m:raster({ 1, "x", 3 }, { nx = 2, ny = 2, extent = { { 0, 0 }, { 1, 1 } } }) end,
  "bad argument #1 to 'raster' (array of numbers expected, got 'x' at entry 2)", "raster: string value")
check.errors(function() m:raster({ 1, 2, 3 }, { nx = 2, ny = 2, extent = { 1, 2 } }) end,
  "bad field 'extent' in argument #2 to 'raster' ({{lower corner}, {upper corner}} with 2 numbers each expected, got table)",
  "raster: extent rows are numbers (crashed)")
check.errors(function() m:raster({ 1, 2, 3 }, { nx = 2, ny = 2, extent = { { 0, 0 }, { 0, 1 } } }) end,
  "bad field 'extent' in argument #2 to 'raster' (upper corner above the lower one on every axis expected", "raster: empty extent")
-- raster's state is a field of argument #2: its errors say so (they named a stack slot).
local ro = { nx = 2, ny = 2, extent = { { 0, 0 }, { 1, 1 } } }
ro.state = 5
check.errors(function() m:raster({ 1, 2, 3 }, ro) end,
  "bad field 'state' in argument #2 to 'raster' (dem.scene or {x =, y =} expected, got 5)", "raster: state a number")
ro.state = { x = { 1, 2 }, y = { 1, 2 } }
check.errors(function() m:raster({ 1, 2, 3 }, ro) end,
  "bad field 'state.x' in argument #2 to 'raster' (array of 5 finite numbers expected, got 2 values)", "raster: state.x length")
ro.state = { x = square.x, y = square.y, z = 1 }
check.errors(function() m:raster({ 1, 2, 3 }, ro) end,
  "bad field 'state' in argument #2 to 'raster' (unknown field 'z'; valid fields: x, y, vx, vy)", "raster: state typo")
local img = m:raster({ 1, 2, 3 }, { nx = 4, ny = 4, extent = { { 0, 0 }, { 1, 1 } } })
check.eq(#img, 16, "raster of a valid call")
check.errors(function() m.info() end, "bad argument #1 to 'info' (analysis.mesh expected", "mesh method with '.'")

-- ---- a scene: the mesh/scene size check (used %zu) ---------------------------------------------
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 }, thickness = 0.1 }
for i = 1, 4 do s:add_disk{ pos = { 0.2 * i, 0.3 + 0.1 * (i % 2) }, radius = 0.05 } end
msg = check.errors(function() m:strain(s) end, "strain: the mesh has 5 particles, the scene 4", "mesh vs scene size (was %zu)")
check.is_true(not msg:find("invalid option", 1, true), "no lua_pushfstring option error")
check.errors(function() analysis.delaunay(s, { ids = { 1, 2, 3, 9 } }) end,
  "bad field 'ids' in argument #2 to 'delaunay' (particle ids in [1, 4] expected, got 9 at entry 4)", "scene ids range")
check.errors(function() analysis.delaunay(s, { ids = { 1, 2, 3, 3 } }) end,
  "bad field 'ids' in argument #2 to 'delaunay' (distinct particle ids expected, got 3 at entries 3 and 4)", "scene ids repeated")
local ms = analysis.delaunay(s, { ids = { 4, 2, 3 } })
check.eq(ms:info().particles, 3, "scene subset mesh")
check.near_abs(ms:strain(s).volumetric, 0, 1e-15, "scene subset strain")

-- ---- s:measure('displacement', {affine}): D rows of D finite numbers (crashed) ----------------
s:set_reference()
local function affine_error(affine, got, what)
  check.errors(function() s:measure("displacement", { affine = affine }) end,
    "bad field 'affine' in argument #2 to 'measure' (2x2 matrix of finite numbers (displacement gradient) expected, got "
    .. got .. ")", what)
end
affine_error({ 1, 2 }, "1 as row 1", "affine rows are numbers")
affine_error({ { 1, 2 }, 3 }, "3 as row 2", "second row a number")
affine_error({ { 1, 2 }, { 3 } }, "1 entries in row 2", "short row")
affine_error({ { 1, 2, 0 }, { 3, 4 } }, "3 entries in row 1", "long row")
affine_error({ { 1, 2 }, { 3, 4 }, { 5, 6 } }, "3 rows", "three rows in 2D")
affine_error({ { 1, 2 } }, "1 rows", "one row")
affine_error({}, "0 rows", "empty affine")
affine_error(5, "5", "affine a number")
affine_error("I", "'I'", "affine a string")
affine_error({ { 1, 2 }, { "3", 4 } }, "'3' at row 2, column 1", "string entry")
affine_error({ { 1, math.huge }, { 3, 4 } }, "inf at row 1, column 2", "infinite entry")
msg = check.errors(function() s:measure("displacement", { affine = { { 1, 2 }, { 3, nan } } }) end,
  "bad field 'affine' in argument #2 to 'measure' (2x2 matrix of finite numbers (displacement gradient) expected, got ", "NaN entry")
check.contains(msg, "nan at row 2, column 2)", "NaN entry shown")
check.errors(function() s.measure(s, "displacement", { affine = { { 1, 2 }, 3 } }) end,
  "bad field 'affine' in argument #3 to 'measure'", "called with '.': the argument counts self")
check.errors(function() s:measure("displacement", { affine = { { 0, 0 }, { 0, 0 } }, center = { 1 } }) end,
  "bad field 'center' in argument #2 to 'measure' (array of 2 finite numbers expected, got table)", "center length")
local d = s:measure("displacement", { affine = { { 0.01, 0 }, { 0, -0.01 } }, center = { 0.5, 0.5 } })
check.eq(#d.x, 4, "a valid affine")
check.near_abs(d.x[1], -0.01 * (0.2 - 0.5), 1e-15, "displacement minus the affine field")
local s3 = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } }, gravity = { 0, 0, 0 } }
s3:add_sphere{ pos = { 0.5, 0.5, 0.5 }, radius = 0.05 }
s3:set_reference()
check.errors(function() s3:measure("displacement", { affine = { { 1, 0 }, { 0, 1 } } }) end,
  "bad field 'affine' in argument #2 to 'measure' (3x3 matrix of finite numbers (displacement gradient) expected, got 2 rows)",
  "2x2 affine in 3D")
check.errors(function() s3:measure("displacement", { affine = { { 1, 0, 0 }, { 0, 1 }, { 0, 0, 1 } } }) end,
  "got 2 entries in row 2)", "short row in 3D")

-- ---- the boundary methods of dem.scene: ids, edges, springs, tie, mbc matrices ----------------
check.errors(function() s:boundary{ mode = "delaunay", ids = { 1, 2, 2 } } end,
  "bad field 'ids' in argument #1 to 'boundary' (distinct particle ids expected, got 2 at entries 2 and 3)", "boundary ids repeated")
check.errors(function() s:boundary{ mode = "delaunay", ids = { 1, 2, 7 } } end,
  "bad field 'ids' in argument #1 to 'boundary' (particle ids in [1, 4] expected, got 7 at entry 3)", "boundary ids range")
check.errors(function() s:boundary{ mode = "edges", edges = { a = { 1, 2 }, b = { 2, "x" } } } end,
  "bad field 'edges.b' in argument #1 to 'boundary' (particle ids in [1, 4] expected, got 'x' at entry 2)", "edge id a string")
check.errors(function() s:boundary{ mode = "edges", edges = { a = { 1, 1e300 }, b = { 2, 3 } } } end,
  "bad field 'edges.a' in argument #1 to 'boundary' (particle ids in [1, 4] expected, got 1e+300 at entry 2)", "edge id huge")
check.errors(function() s:boundary{ mode = "edges", edges = { a = { 1, 2 }, b = { 2 } } } end,
  "bad field 'edges' in argument #1 to 'boundary' ({a = {ids}, b = {ids}} of equal length expected", "edges lengths")
check.errors(function() s:boundary{ mode = "delaunay", mbc = { strain_rate = { { 1, 0 }, 5 } } } end,
  "bad field 'mbc.strain_rate' in argument #1 to 'boundary' (2x2 matrix {{xx, xy}, {yx, yy}} of finite numbers expected, got 5 as row 2)",
  "mbc row a number")
check.errors(function() s:boundary{ mode = "delaunay", mbc = { strain_rate = { { 1, 0 }, { 0, 1 }, { 1, 1 } } } } end,
  "bad field 'mbc.strain_rate' in argument #1 to 'boundary' (2x2 matrix {{xx, xy}, {yx, yy}} of finite numbers expected, got 3 rows)",
  "mbc three rows")
check.errors(function() s:boundary{ mode = "delaunay", mbc = { gradient = { { 1, 0, 0 }, { 0, 1 } } } } end,
  "bad field 'mbc.gradient' in argument #1 to 'boundary' (2x2 matrix {{xx, xy}, {yx, yy}} of finite numbers expected, got 3 entries in row 1)",
  "mbc long row")
msg = check.errors(function() s:boundary{ mode = "delaunay", mbc = { strain_rate = { { 1, 0 }, { 0, 1 } }, mask = { { 1, 0 }, { 0, nan } } } } end,
  "bad field 'mbc.mask' in argument #1 to 'boundary' (2x2 matrix {{xx, xy}, {yx, yy}} of finite numbers expected, got ", "mbc mask NaN")
check.contains(msg, "nan at row 2, column 2)", "mbc NaN shown")
check.errors(function() s:boundary{ mode = "delaunay", mbc = { strain_rate = { { 1, 0 }, { 0, 1 } }, K = -1 } } end,
  "bad field 'mbc.K' in argument #1 to 'boundary' (positive number expected, got -1)", "mbc.K named (was argument #2)")
check.errors(function() s:boundary{ mode = "delaunay", mbc = { strain_rate = { { 1, 0 }, { 0, 1 } }, tau = "x" } } end,
  "bad field 'mbc.tau' in argument #1 to 'boundary' (non-negative number expected, got 'x')", "mbc.tau named")
check.errors(function() s:boundary{ mode = "delaunay", mbc = { strain_rate = { { 1, 0 }, { 0, 1 } }, Kx = 1 } } end,
  "bad field 'mbc' in argument #1 to 'boundary' (unknown field 'Kx'; valid fields: strain_rate, gradient, mask, K, kappa, rate, dt, tau)",
  "mbc typo")
check.errors(function() s:boundary{ mode = "delaunay", mbc = { strain_rate = { { 1, 0 }, { 0, 1 } }, k = 1 } } end,
  "(unknown field 'k'; did you mean 'K'? Valid fields:", "mbc: a key in the wrong case")
-- mask entries switch a component on (1) or off (0): a weight of 2 or 0.5 is refused, not used
check.errors(function() s:boundary{ mode = "delaunay", mbc = { strain_rate = { { 1, 0 }, { 0, 1 } }, mask = { { 2, 0 }, { 0, 1 } } } } end,
  "bad field 'mbc.mask' in argument #1 to 'boundary' (2x2 matrix of 0 (component free) and 1 (component held) expected, got 2 at row 1, column 1)",
  "mbc mask 2")
check.errors(function() s:boundary{ mode = "delaunay", mbc = { gradient = { { 1, 0 }, { 0, 1 } }, mask = { { 1, 0.5 }, { 1, 1 } } } } end,
  "(2x2 matrix of 0 (component free) and 1 (component held) expected, got 0.5 at row 1, column 2)", "mbc mask 0.5")
-- every = 0 would never rebuild the outline it says is rebuilt
check.errors(function() s:boundary{ mode = "delaunay", every = 0 } end,
  "bad field 'every' in argument #1 to 'boundary' (positive integer expected, got 0)", "every = 0")
check.errors(function() s:boundary{ mode = "delaunay", mbc = 5 } end,
  "bad field 'mbc' in argument #1 to 'boundary' (table expected, got 5)", "mbc not a table")
check.eq(s:boundary{ mode = "delaunay", ids = { 1, 2, 3, 4 } }.edges, 4, "boundary on listed ids")
s:boundary{ mode = "none" }
check.errors(function() s:springs{ i = { 1, 2 }, j = { 3 }, k = 1 } end,
  "bad field 'j' in argument #1 to 'springs' (as many ids as 'i' (2) expected, got 1 values)", "springs lengths")
check.errors(function() s:springs{ i = { 1, 2 }, j = { 3, 1e300 }, k = 1 } end,
  "bad field 'j' in argument #1 to 'springs' (particle ids in [1, 4] expected, got 1e+300 at entry 2)", "springs id huge (was UB)")
check.errors(function() s:springs{ i = { 1.5 }, j = { 3 }, k = 1 } end,
  "bad field 'i' in argument #1 to 'springs' (particle ids in [1, 4] expected, got 1.5 at entry 1)", "springs id fractional")
check.errors(function() s:springs{ i = { 1 }, j = { 3 }, k = 1, rest = { -1 } } end,
  "springs: spring 1: rest length must be >= 0, got -1", "springs rest")
check.errors(function() s:tie{ ids = { 1.5 }, wall = 1 } end,
  "bad field 'ids' in argument #1 to 'tie' (particle ids in [1, 4] expected, got 1.5 at entry 1)", "tie id fractional (was particle 1)")
check.errors(function() s:tie{ ids = { 0 }, wall = 1 } end,
  "bad field 'ids' in argument #1 to 'tie' (particle ids in [1, 4] expected, got 0 at entry 1)", "tie id 0")
check.done()
