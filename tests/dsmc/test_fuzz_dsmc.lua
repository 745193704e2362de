-- Generated bad-input test of the dsmc module (see fuzz_driver.lua): every field of every dsmc
-- function and dsmc.scene method gets every bad-value class; only the classes declared below are
-- accepted, everything else must end in an error naming the call and the field.
local fuzz = dofile("../lua/lib/fuzz_driver.lua")
local check = grainlab.check

local function scene()
  local s = dsmc.scene{ size = { 1, 1 }, cells = { 4, 4 }, radius = 0.001 }
  s:fill{ n = 20, temperature = 1, seed = 3 }
  return s
end
local function walled()
  local s = dsmc.scene{ size = { 1, 1 }, cells = { 4, 4 }, radius = 0.001, periodic = { true, false } }
  s:fill{ n = 20, temperature = 1, seed = 3 }
  return s
end
local function self(ctx) return ctx end
local OPT = { "nil" }
local BOOL = { "nil", "boolean" }

-- A checkpoint file for the save and load entries (removed at the end).
local ckpt = os.tmpname()

local calls = {
  ["dsmc.scene"] = {
    { args = function() return { { dim = 2, box = { { 0, 0 }, { 1, 1 } }, cells = { 4, 4 },
                                   periodic = { true, false }, gravity = { 0, -1 }, restitution = 0.9,
                                   radius = 0.001, mass = 1e-6, excluded_volume = "enskog",
                                   packing_limit = 0.5, seed = 2 } } end,
      opts = 1,
      accept = { dim = OPT, box = {}, size = OPT, cells = {}, periodic = { "nil", "boolean" },
                 gravity = OPT, restitution = { "nil", "zero" }, radius = {}, mass = OPT,
                 density = OPT, excluded_volume = OPT, packing_limit = OPT, seed = { "nil", "zero" } } },
    { args = function() return { { size = { 1, 1 }, cells = { 4, 4 }, radius = 0.001, density = 2000 } } end,
      opts = 1,
      accept = { dim = OPT, box = OPT, size = {}, cells = {}, periodic = { "nil", "boolean" },
                 gravity = OPT, restitution = { "nil", "zero" }, radius = {}, mass = OPT,
                 density = OPT, excluded_volume = OPT, packing_limit = OPT, seed = { "nil", "zero" } } },
  },
  ["dsmc.scene:fill"] = {
    { setup = scene, self = self, opts = 1,
      args = function() return { { n = 10, temperature = 1, region = { { 0, 0 }, { 0.5, 0.5 } },
                                   velocity = { 1, 0 }, seed = 4 } } end,
      accept = { n = {}, temperature = {}, speed = OPT, region = OPT, velocity = OPT,
                 seed = { "nil", "zero" } } },
    { setup = scene, self = self, opts = 1,
      args = function() return { { n = 10, speed = 1 } } end,
      accept = { n = {}, temperature = OPT, speed = {}, region = OPT, velocity = OPT,
                 seed = { "nil", "zero" } } },
  },
  ["dsmc.scene:add"] = {
    setup = scene, self = self, opts = 1,
    args = function() return { { x = { 0.5 }, y = { 0.5 }, vx = { 1 }, vy = { 0 } } } end,
    accept = { x = {}, y = {}, z = OPT, vx = {}, vy = {}, vz = OPT },
  },
  ["dsmc.scene:wall"] = {
    { setup = walled, self = self, opts = 1,
      args = function() return { { side = "bottom", kind = "diffuse", restitution = 0.9, temperature = 1,
                                   amplitude = 0.01, frequency = 10, phase = 0.1, velocity = { 0, 0 } } } end,
      accept = { side = {}, kind = {}, restitution = { "nil", "zero" }, temperature = {},
                 amplitude = {}, frequency = {}, phase = { "nil", "zero", "negative" },
                 velocity = OPT } },
    { setup = walled, self = self, opts = 1,
      args = function() return { { side = "top" } } end,
      accept = { side = {}, kind = OPT, restitution = { "nil", "zero" }, temperature = OPT,
                 amplitude = { "nil", "zero" }, frequency = OPT, phase = OPT, velocity = OPT } },
  },
  ["dsmc.scene:run"] = {
    setup = scene, self = self, opts = 1,
    args = function() return { { steps = 2, dt = 1e-4, every = 1, on_step = function() end,
                                 progress = false, warn = false, force = false } } end,
    accept = { steps = { "zero" }, time = OPT, dt = OPT, every = OPT, on_step = { "nil", "function" },
               progress = BOOL, warn = BOOL, force = BOOL },
  },
  ["dsmc.scene:measure"] = {
    -- the modes without options: an empty table (or none), nothing else; the mode name fuzzed once
    { setup = scene, self = self, mode = "temperature", opts = 2, opts_optional = true,
      args = function() return { "temperature", {} } end, pos = { {} } },
    { setup = scene, self = self, mode = "a2", opts = 2, opts_optional = true,
      args = function() return { "a2", {} } end },
    { setup = scene, self = self, mode = "fields", opts = 2, opts_optional = true,
      args = function() return { "fields", {} } end },
    { setup = scene, self = self, mode = "stats", opts = 2, opts_optional = true,
      args = function() return { "stats", {} } end },
    { setup = scene, self = self, mode = "histogram", opts = 2, opts_optional = true,
      args = function() return { "histogram", { bins = 10, range = { -1, 1 }, quantity = "component" } } end,
      accept = { bins = OPT, range = OPT, quantity = OPT } },
    { setup = scene, self = self, mode = "profile", opts = 2, opts_optional = true,
      args = function() return { "profile", { axis = 1, bins = 4 } } end,
      accept = { axis = OPT, bins = OPT } },
    { setup = scene, self = self, mode = "validity", opts = 2, opts_optional = true,
      args = function() return { "validity", { dt = 1e-4 } } end,
      accept = { dt = { "nil", "zero" } } },
  },
  ["dsmc.scene:particles"] = { setup = scene, self = self },
  ["dsmc.scene:reset_stats"] = { setup = scene, self = self },
  ["dsmc.scene:info"] = { setup = scene, self = self },
}
fuzz.checkpoint_calls(calls, "dsmc", scene, ckpt)

-- VTK output (lua_vtk.c): the files go to a scratch directory.
local vtkdir = os.tmpname()
os.remove(vtkdir)
os.execute("mkdir -p '" .. vtkdir .. "'")
calls["dsmc.scene:write_vtk"] = {
  setup = scene, self = self, opts = 2, opts_optional = true, pos = { {} },
  args = function() return { vtkdir .. "/f.vtu", { cells = true } } end, accept = { cells = BOOL },
}
fuzz.run{ modules = { dsmc = dsmc }, types = { ["dsmc.scene"] = scene() }, calls = calls }
os.execute("rm -rf '" .. vtkdir .. "'")

-- Absurd sizes are refused with the limit in the message.
-- The limit is the machine's physical memory: its digits differ between machines.
local msg = check.errors(function() dsmc.scene{ size = { 1, 1 }, cells = { 1000000, 1000000 }, radius = 1e-9 } end,
  " bytes (the machine's memory, or GRAINLAB_MEMORY_LIMIT); use fewer cells (field 'cells')",
  "cell grid above the memory budget")
check.is_true(msg:find("scene: 1e%+12 cells need 2%.4e%+13 bytes, above the limit of %d[%d.e+]* bytes") ~= nil,
  "the grid's message gives the bytes and the limit")
check.errors(function() dsmc.scene{ size = { 1e300, 1 }, cells = { 4, 4 }, radius = 1e-3 } end,
  "bad field 'size' in argument #1 to 'scene'", "size 1e300")
check.errors(function() scene():fill{ n = 1000000, temperature = 1 } end,
  "fill: cannot add 1000000 particles: the box holds at most 261014", "a million particles in a small box")
check.errors(function()
    dsmc.scene{ size = { 1, 1 }, cells = { 4, 4 }, radius = 1e-9 }:fill{ n = 1e12, temperature = 1 }
  end, "bytes (the machine's memory, or GRAINLAB_MEMORY_LIMIT) (field 'n')", "a trillion particles in a large box")
os.remove(ckpt)
check.done()
