-- Generated bad-input test of the analysis module and the boundary-condition methods it adds to
-- dem.scene (see fuzz_driver.lua), with the nested tables (s:boundary's mbc, mesh:raster's state)
-- fuzzed field by field.
local fuzz = dofile("../lua/lib/fuzz_driver.lua")
local OPT = { "nil" }

local function scene()
  local s = dem.scene{ dim = 2, box = { { -1, -1 }, { 2, 2 } }, gravity = { 0, 0 }, thickness = 1e-3 }
  for _, p in ipairs{ { 0, 0 }, { 1, 0 }, { 0, 1 }, { 1, 1 }, { 0.5, 0.5 } } do
    s:add_disk{ pos = p, radius = 0.2 }
  end
  s:add_wall{ point = { -1, -1 }, normal = { 0, 1 } }
  return s
end
local function self(ctx) return ctx end
local function points()
  return { x = { 0, 1, 0, 1, 0.5 }, y = { 0, 0, 1, 1, 0.5 }, radius = { 0.3, 0.3, 0.3, 0.3, 0.3 } }
end

local calls = {
  ["analysis.delaunay"] = {
    args = function() return { points(), { alpha = 1.5, ids = { 1, 2, 3, 4, 5 } } } end,
    opts = 2, opts_optional = true, pos = { {} },
    accept = { alpha = { "nil", "zero" }, ids = { "nil", "short" } },
  },
  ["dem.scene:springs"] = {
    setup = scene, self = self, opts = 1,
    args = function() return { { i = { 1 }, j = { 2 }, k = 10, rest = { 1 } } } end,
    accept = { i = {}, j = {}, k = {}, rest = OPT },
  },
  ["dem.scene:spin"] = {
    setup = function() local s = scene(); s:contact{ tangential = "spring" }; return s end, self = self, opts = 1,
    args = function() return { { id = 1, omega = 2 } } end,
    accept = { id = {}, omega = { "zero", "negative" } },
  },
  ["dem.scene:tie"] = {
    setup = scene, self = self, opts = 1,
    args = function() return { { ids = { 1, 2 }, wall = 1, axis = 2 } } end,
    accept = { ids = { "short", "long" }, wall = {}, axis = OPT },
  },
  ["dem.scene:boundary_info"] = {
    setup = function() local s = scene(); s:boundary{ pressure = 1e3 }; return s end, self = self },
  ["dem.scene:boundary_edges"] = { setup = scene, self = self },
}
local STATE = { "x", "y", "vx", "vy" }
-- s:boundary, once per mode (each mode's own fields; the others must stay nil there).
local mbc_fields = { "strain_rate", "gradient", "mask", "K", "kappa", "rate", "dt", "tau" }
calls["dem.scene:boundary"] = {
  -- delaunay with mbc (strain_rate, K given: pressure and rate scale are optional)
  { setup = scene, self = self, opts = 1, nested = { mbc = mbc_fields },
    args = function() return { { mode = "delaunay", pressure = 1e3, depth = 1e-3, every = 10, alpha = 1.5,
      sides = "all", ids = { 1, 2, 3, 4, 5 }, band = true,
      mbc = { strain_rate = { { -1e-3, 0 }, { 0, 1e-3 } }, mask = { { 1, 1 }, { 1, 1 } }, K = 1e3,
              kappa = 20, rate = 1e-3, dt = 1e-6, tau = 1e-3 } } } end,
    accept = { mode = OPT, pressure = { "nil", "zero" }, depth = OPT, every = OPT,
               alpha = { "nil", "zero" }, sides = OPT, ids = { "nil", "short" }, edges = OPT, closed = OPT,
               band = { "nil", "boolean" }, mbc = OPT,
               ["mbc.strain_rate"] = {}, ["mbc.gradient"] = OPT, ["mbc.mask"] = OPT, ["mbc.K"] = OPT,
               ["mbc.kappa"] = OPT, ["mbc.rate"] = OPT, ["mbc.dt"] = OPT, ["mbc.tau"] = { "nil", "zero" } } },
  -- fixed edges with mbc (gradient, no K: chosen from the pressure and the target)
  { setup = scene, self = self, opts = 1, nested = { mbc = mbc_fields },
    args = function() return { { mode = "edges", pressure = 1e3, edges = { a = { 1, 2, 4, 3 }, b = { 2, 4, 3, 1 } },
      closed = true, mbc = { gradient = { { 0, 1e-3 }, { 0, 0 } } } } } end,
    accept = { mode = {}, pressure = {}, depth = OPT, every = OPT, alpha = OPT, sides = OPT, ids = OPT,
               edges = {}, closed = { "boolean" }, band = OPT, mbc = OPT,
               ["mbc.strain_rate"] = OPT, ["mbc.gradient"] = {}, ["mbc.mask"] = OPT,
               ["mbc.K"] = OPT, ["mbc.kappa"] = OPT, ["mbc.rate"] = OPT, ["mbc.dt"] = OPT,
               ["mbc.tau"] = { "nil", "zero" } } },
  -- none: every other field refused (it would be ignored); mode nil is s:boundary{} (delaunay)
  { setup = scene, self = self, opts = 1,
    args = function() return { { mode = "none" } } end,
    accept = { mode = OPT, pressure = OPT, depth = OPT, every = OPT, alpha = OPT, sides = OPT, ids = OPT,
               edges = OPT, closed = OPT, band = OPT, mbc = OPT } },
}
-- The analysis.mesh methods, on a mesh of points() (5 particles, 3 cells).
local function mesh_of() return analysis.delaunay(points()) end
local function moved() local p = points(); p.x[5] = 0.6; return { x = p.x, y = p.y } end
local function moving()
  local p = moved()
  p.vx, p.vy = { 0, 1e-3, 0, 1e-3, 5e-4 }, { 0, 0, 1e-3, 1e-3, 0 }
  return p
end
calls["analysis.mesh:info"] = { setup = mesh_of, self = self }
calls["analysis.mesh:boundary"] = { setup = mesh_of, self = self }
-- cells and strain use the positions; vx, vy (a strain_rate state passed on) are checked, optional
calls["analysis.mesh:cells"] = { setup = mesh_of, self = self, opts = 1, opts_optional = true,
  args = function() return { moving() } end,
  accept = { x = {}, y = {}, vx = OPT, vy = OPT } }
calls["analysis.mesh:strain"] = { setup = mesh_of, self = self, opts = 1,
  args = function() return { moving() } end,
  accept = { x = {}, y = {}, vx = OPT, vy = OPT } }
calls["analysis.mesh:strain_rate"] = { setup = mesh_of, self = self, opts = 1,
  args = function() return { moving() } end,
  accept = { x = {}, y = {}, vx = {}, vy = {} } }
calls["analysis.mesh:stress"] = {
  setup = function() local s = scene(); return { s = s, m = analysis.delaunay(s) } end,
  self = function(ctx) return ctx.m end, opts = 2, opts_optional = true, pos = { {} },
  args = function(ctx) return { ctx.s, { depth = 2e-3 } } end,
  accept = { depth = OPT } }
-- raster: cell values are numbers (NaN: no data, as outside the cells); state nil: the build positions
calls["analysis.mesh:raster"] = { setup = mesh_of, self = self, opts = 2,
  pos = { { "entry_nan", "entry_inf", "entry_huge" } }, nested = { state = STATE },
  args = function() return { { 1, 2, 3 }, { nx = 4, ny = 3, extent = { { -1, -1 }, { 2, 2 } }, state = moving() } } end,
  accept = { nx = {}, ny = {}, extent = {}, state = OPT,
             ["state.x"] = {}, ["state.y"] = {}, ["state.vx"] = OPT, ["state.vy"] = OPT } }
-- mesh:write_vtk (lua_vtk.c) writes into a scratch directory
local vtkdir = os.tmpname()
os.remove(vtkdir)
os.execute("mkdir -p '" .. vtkdir .. "'")
calls["analysis.mesh:write_vtk"] = {
  setup = function() local s = scene(); return { s = s, m = analysis.delaunay(s) } end,
  self = function(ctx) return ctx.m end, opts = 3, opts_optional = true, pos = { {}, {} },
  args = function(ctx) return { vtkdir .. "/m.vtu", ctx.s, { depth = 2e-3, stress = true, cells = { q = { 1, 2, 3 } } } } end,
  accept = { depth = OPT, stress = { "nil", "boolean" }, cells = { "nil", "empty" } } }
local skip = {}
skip["analysis.coarse_grain"] = "fuzzed by test_fuzz_coarse_grain.lua"
skip["analysis.cg_average"] = "fuzzed by test_fuzz_coarse_grain.lua"
-- The methods dem.scene has from lua_dem.c are fuzzed by test_fuzz_dem.lua.
for _, k in ipairs{ "contact", "add_disk", "add_sphere", "add_wall", "remove_wall", "wall_velocity",
                    "wall_point", "wall_force", "wall_servo", "set_velocity", "timestep", "run", "measure",
                    "particles", "set_reference", "scale_mass", "scale_stiffness", "drag", "gravity", "set_forces",
                    "clear_forces", "quasistatic", "info", "damping_time", "save", "write_vtk",
                    "add_polyline", "add_mesh", "add_cylinder", "wall_load" } do
  skip["dem.scene:" .. k] = "fuzzed by test_fuzz_dem.lua"
end
for _, k in ipairs{ "add_clump", "clump", "clump_count" } do -- rigid clumps (clump.c)
  skip["dem.scene:" .. k] = "fuzzed by test_fuzz_dem.lua"
end
for _, k in ipairs{ "inserter", "outflow", "flow" } do -- particles in and out (flow.c)
  skip["dem.scene:" .. k] = "fuzzed by test_fuzz_dem.lua"
end
for _, k in ipairs{ "read_lammps_data", "write_lammps_data", "write_lammps_dump" } do
  skip["dem.scene:" .. k] = "fuzzed by test_lammps_fuzz.lua"
end
local mesh = analysis.delaunay(points())
local ok, err = pcall(fuzz.run, { modules = { analysis = analysis },
  types = { ["dem.scene"] = scene(), ["analysis.mesh"] = mesh }, calls = calls, skip = skip })
os.execute("rm -rf '" .. vtkdir .. "'")
if not ok then error(err, 0) end
