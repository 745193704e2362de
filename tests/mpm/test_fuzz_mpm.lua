-- Generated bad-input test of the mpm module (see fuzz_driver.lua): every field of every mpm
-- function and mpm.scene method gets every bad-value class; only the classes declared below are
-- accepted, everything else must end in an error naming the call and the field.
local fuzz = dofile("../lua/lib/fuzz_driver.lua")
local check = grainlab.check
local mat = mpm.material{ density = 1000, shear = 1e6, bulk = 2e6 }

local function scene()
  local m = mpm.scene{ cells = { 8, 8 }, size = { 1, 1 } }
  m:add_disk{ center = { 0.5, 0.5 }, radius = 0.2, material = mat }
  return m
end
local function self(ctx) return ctx end
local OPT = { "nil" }
local BOOL = { "nil", "boolean" }

-- A checkpoint file for the save and load entries (removed at the end).
local ckpt = os.tmpname()

local calls = {
  ["mpm.scene"] = {
    args = function() return { { cells = { 8, 8 }, size = { 1, 1 }, origin = { 0, 0 },
                                 periodic = { false, false }, gravity = { 0, -9.81 }, walls = "slip",
                                 update = "musl", pic = 0.1, shape = "linear", wall_gap = 0.1 } } end,
    opts = 1,
    accept = { cells = {}, size = {}, origin = OPT, periodic = OPT, gravity = OPT, walls = OPT,
               update = OPT, pic = { "nil", "zero" }, shape = OPT, wall_gap = { "nil", "zero" } },
  },
  ["mpm.material"] = {
    { args = function() return { { model = "vonmises", density = 1000, shear = 1e6, bulk = 2e6,
                                   yield = 1e4, hardening = 1e3 } } end,
      opts = 1,
      accept = { model = {}, density = {}, shear = {}, bulk = {}, yield = {},
                 hardening = { "nil", "zero" }, friction = OPT, dilatancy = OPT, cohesion = OPT,
                 mu_s = OPT, mu_2 = OPT, i0 = OPT, grain_diameter = OPT, grain_density = OPT } },
    { args = function() return { { density = 1000, shear = 1e6, bulk = 2e6 } } end,
      opts = 1,
      accept = { model = OPT, density = {}, shear = {}, bulk = {}, yield = OPT, hardening = OPT,
                 friction = OPT, dilatancy = OPT, cohesion = OPT, mu_s = OPT, mu_2 = OPT,
                 i0 = OPT, grain_diameter = OPT, grain_density = OPT } },
    { args = function() return { { model = "drucker_prager", density = 1500, shear = 1e6,
                                   bulk = 2e6, friction = 30, dilatancy = 5, cohesion = 100 } } end,
      opts = 1,
      accept = { model = {}, density = {}, shear = {}, bulk = {}, friction = {},
                 dilatancy = { "nil", "zero" }, cohesion = { "nil", "zero" }, yield = OPT,
                 hardening = OPT, mu_s = OPT, mu_2 = OPT, i0 = OPT, grain_diameter = OPT,
                 grain_density = OPT } },
    { args = function() return { { model = "mu_i", density = 1500, shear = 1e6, bulk = 2e6,
                                   mu_s = 0.38, mu_2 = 0.64, i0 = 0.279, grain_diameter = 5e-4,
                                   grain_density = 2500 } } end,
      opts = 1,
      accept = { model = {}, density = {}, shear = {}, bulk = {}, mu_s = {}, mu_2 = {},
                 i0 = OPT, grain_diameter = {}, grain_density = OPT, yield = OPT,
                 hardening = OPT, friction = OPT, dilatancy = OPT, cohesion = OPT } },
  },
  ["mpm.scene:add_disk"] = {
    setup = scene, self = self, opts = 1,
    args = function() return { { center = { 0.2, 0.2 }, radius = 0.1, material = mat, points_per_cell = 2,
                                 velocity = { 1, 0 }, omega = 1, clip = false, hydrostatic = false } } end,
    accept = { center = {}, radius = {}, material = {}, points_per_cell = OPT, velocity = OPT,
               omega = { "nil", "zero", "negative" }, clip = BOOL, hydrostatic = BOOL },
  },
  ["mpm.scene:add_rect"] = {
    setup = scene, self = self, opts = 1,
    args = function() return { { lo = { 0.05, 0.05 }, hi = { 0.2, 0.2 }, material = mat, points_per_cell = 2,
                                 velocity = { 1, 0 }, omega = 1, clip = false, hydrostatic = false } } end,
    accept = { lo = {}, hi = {}, material = {}, points_per_cell = OPT, velocity = OPT,
               omega = { "nil", "zero", "negative" }, clip = BOOL, hydrostatic = BOOL },
  },
  ["mpm.scene:add_polygon"] = {
    setup = scene, self = self, opts = 1,
    args = function() return { { vertices = { { 0.05, 0.05 }, { 0.25, 0.05 }, { 0.05, 0.25 } }, material = mat,
                                 points_per_cell = 2, velocity = { 1, 0 }, omega = 1, clip = false,
                                 hydrostatic = false } } end,
    accept = { vertices = { "long" }, material = {}, points_per_cell = OPT, velocity = OPT,
               omega = { "nil", "zero", "negative" }, clip = BOOL, hydrostatic = BOOL },
  },
  ["mpm.scene:contact"] = {
    { setup = scene, self = self, opts = 1,
      args = function() return { { model = "friction", mu = 0.3, normals = "averaged", separation = 0.5,
                                   strain_cap = 0.1, conserve = true } } end,
      accept = { model = {}, mu = { "zero" }, normals = OPT, separation = { "nil", "zero" },
                 strain_cap = { "nil", "zero" }, conserve = BOOL } },
    { setup = scene, self = self, opts = 1,
      args = function() return { { model = "noslip" } } end,
      accept = { model = {}, mu = OPT, normals = OPT, separation = { "nil", "zero" },
                 strain_cap = { "nil", "zero" }, conserve = BOOL } },
  },
  ["mpm.scene:prescribe"] = {
    setup = scene, self = self, args = function() return { 1, { 0, 0.1 } } end, pos = { {}, {} },
  },
  ["mpm.scene:plane"] = {
    setup = scene, self = self, opts = 1,
    args = function() return { { point = { 0, 0.1 }, normal = { 0, 1 }, kind = "friction", mu = 0.3,
                                 velocity = { 0, 0 } } } end,
    accept = { point = {}, normal = {}, kind = OPT, mu = { "zero" }, velocity = OPT },
  },
  ["mpm.scene:field"] = { setup = scene, self = self, args = function() return { "speed" } end, pos = { {} } },
  ["mpm.scene:timestep"] = {
    setup = scene, self = self, args = function() return { { cfl = 0.3 } } end,
    opts = 1, opts_optional = true, accept = { cfl = OPT },
  },
  ["mpm.scene:run"] = {
    setup = scene, self = self, opts = 1,
    args = function() return { { steps = 2, dt = 1e-5, cfl = 0.3, force = false, every = 1,
                                 on_step = function() end, progress = false } } end,
    accept = { steps = { "zero" }, time = OPT, dt = OPT, cfl = OPT, force = BOOL, every = OPT,
               on_step = { "nil", "function" }, progress = BOOL },
  },
  -- no mode takes options: an empty table (or none), nothing else; the mode name fuzzed once
  ["mpm.scene:measure"] = {
    { setup = scene, self = self, mode = "energy", opts = 2, opts_optional = true,
      args = function() return { "energy", {} } end, pos = { {} } },
    { setup = scene, self = self, mode = "momentum", opts = 2, opts_optional = true,
      args = function() return { "momentum", {} } end },
    { setup = scene, self = self, mode = "columns", opts = 2, opts_optional = true,
      args = function() return { "columns", {} } end },
    { setup = scene, self = self, mode = "shear", opts = 2, opts_optional = true,
      args = function() return { "shear", {} } end },
  },
  ["mpm.scene:grain"] = { setup = scene, self = self, args = function() return { 1 } end, pos = { {} } },
  ["mpm.scene:points"] = { setup = scene, self = self },
  ["mpm.scene:info"] = { setup = scene, self = self },
  ["mpm.scene:timings"] = { setup = scene, self = self },
  ["mpm.scene:set_velocities"] = {
    setup = scene, self = self, opts = 1,
    args = function(m)
      local n = #m:points().x
      local vx, vy = {}, {}
      for i = 1, n do vx[i], vy[i] = 0.1, 0 end
      return { { vx = vx, vy = vy } }
    end,
    accept = { vx = {}, vy = {} },
  },
}
fuzz.checkpoint_calls(calls, "mpm", scene, ckpt)

-- VTK output (lua_vtk.c): the files go to a scratch directory.
local vtkdir = os.tmpname()
os.remove(vtkdir)
os.execute("mkdir -p '" .. vtkdir .. "'")
calls["mpm.scene:write_vtk"] = {
  setup = scene, self = self, opts = 2, opts_optional = true, pos = { {} },
  args = function() return { vtkdir .. "/f.vtu", { grid = true } } end, accept = { grid = BOOL },
}
fuzz.run{ modules = { mpm = mpm }, types = { ["mpm.scene"] = scene() }, calls = calls }
os.execute("rm -rf '" .. vtkdir .. "'")

-- An mpm.material is read-only: an assignment is refused, naming the field.
check.errors(function() mat.density = -5 end, "an mpm.material is read-only: field 'density' cannot be set",
  "mpm.material read-only")
check.eq(mat.density, 1000, "density unchanged")

-- Absurd sizes are refused with the limit in the message.
check.errors(function() mpm.scene{ cells = { 1048576, 1048576 }, size = { 1, 1 } } end,
  "bytes (the machine's memory, or GRAINLAB_MEMORY_LIMIT); use fewer cells (field 'cells')", "grid above the memory budget")
check.errors(function() mpm.scene{ cells = { 8, 8 }, size = { 1e300, 1 } } end,
  "bad field 'size' in argument #1 to 'scene' (array of 2 positive numbers of at most 1e+100 expected", "size 1e300")
check.errors(function() scene():run{ time = 1e99 } end,
  "bad field 'time' in argument #1 to 'run' (time of at most 1e15 steps of dt", "time of 1e99 s")
os.remove(ckpt)
check.done()
