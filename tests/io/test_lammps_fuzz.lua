-- Generated bad-input test (fuzz_driver.lua) of the LAMMPS calls: dem.read_lammps_data and the
-- dem.scene methods read_lammps_data, write_lammps_data and write_lammps_dump. Every field and the
-- file name get every bad-value class; only the classes declared below are accepted.
local fuzz = dofile("../lua/lib/fuzz_driver.lua")
local check = grainlab.check
local mat = grainlab.material{ density = 1000, young = 1e7, poisson = 0.3, friction = 0.3 }

local base = os.tmpname()
local data = base .. "_in.data"
local f = assert(io.open(data, "w"))
f:write("fuzz\n\n2 atoms\n2 atom types\n\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms # sphere\n\n",
        "1 1 0.02 1000 0.5 0.5 0.5\n2 2 0.02 1000 0.2 0.5 0.5\n")
f:close()
local out = base .. "_out"

local function scene()
  local s = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } }, gravity = { 0, 0, 0 } }
  s:add_sphere{ pos = { 0.8, 0.8, 0.8 }, radius = 0.01, material = mat }
  return s
end
local function self(ctx) return ctx end
local OPT = { "nil" }
-- types maps type 2 and material covers type 1, so that the base table is not an array (the
-- driver's derived classes would copy the read-only materials inside it); {} leaves all to material,
-- and without material type 1 has none (refused, naming both fields)
local TYPES = { "nil", "empty" }
-- fixed_types: no list, an empty list, or a repeated type are all fine
local FIXED = { "nil", "empty", "short", "long" }

local calls = {
  ["dem.read_lammps_data"] = {
    args = function() return { data, { types = { [2] = mat }, material = mat, density = "strict",
                                       fixed_types = { 1 }, dim = 3, gravity = { 0, 0, -9.81 },
                                       periodic = { false, false, false }, thickness = 0, skin = 0.001 } } end,
    opts = 2, opts_optional = true, pos = { { "string" } }, strings = { [1] = data },
    accept = { types = TYPES, material = {}, density = OPT, fixed_types = FIXED, dim = OPT,
               gravity = OPT, periodic = OPT, thickness = { "nil", "zero" }, skin = { "nil", "zero" } },
  },
  ["dem.scene:read_lammps_data"] = {
    setup = scene, self = self, opts = 2, opts_optional = true,
    args = function() return { data, { types = { [2] = mat }, material = mat, density = "file",
                                       fixed_types = { 1 } } } end,
    pos = { { "string" } }, strings = { [1] = data },
    accept = { types = TYPES, material = {}, density = OPT, fixed_types = FIXED },
  },
  ["dem.scene:write_lammps_data"] = {
    setup = scene, self = self, opts = 2, opts_optional = true,
    args = function() return { out .. ".data", { types = { [2] = mat }, title = "fuzz" } } end,
    pos = { { "string" } }, strings = { [1] = out .. ".data" },
    accept = { types = OPT, title = { "nil", "string" } },
  },
  ["dem.scene:write_lammps_dump"] = {
    setup = scene, self = self, opts = 2, opts_optional = true,
    args = function() return { out .. ".dump", { types = { [2] = mat }, append = true } } end,
    pos = { { "string" } }, strings = { [1] = out .. ".dump" },
    accept = { types = OPT, append = { "nil", "boolean" } },
  },
}

-- Everything else of dem is fuzzed by test_fuzz_dem.lua and test_fuzz_analysis.lua.
local skip, s = {}, scene()
for k in pairs(dem) do
  if not calls["dem." .. k] then skip["dem." .. k] = "fuzzed by test_fuzz_dem.lua" end
end
for k in pairs(getmetatable(s).__index) do
  if not calls["dem.scene:" .. k] then skip["dem.scene:" .. k] = "fuzzed by test_fuzz_dem.lua / test_fuzz_analysis.lua" end
end
fuzz.run{ modules = { dem = dem }, types = { ["dem.scene"] = s }, calls = calls, skip = skip }
-- A number is not a file name (luaL_checkstring would take 5 and write a file called "5").
check.errors(function() s:write_lammps_data(5) end,
  "bad argument #1 to 'write_lammps_data' (file path (string) expected, got 5)", "a number as the path")
check.errors(function() dem.read_lammps_data(data, { gravity = { 0, 0, 0 / 0 } }) end,
  "bad field 'gravity' in argument #2 to 'read_lammps_data'", "dem.scene's checks, as this call's")
for _, p in ipairs{ data, out .. ".data", out .. ".dump", base } do os.remove(p) end
check.done()
