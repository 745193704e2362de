-- A file name with a NUL byte is refused wherever a path crosses from Lua into C (or into the
-- shell): C would end the name at the NUL and write "a" for "a\0b.txt". Every call that takes a
-- file name gets dir/a\0b.<ext>; each must raise an error naming the call and the argument or
-- field, and nothing may appear in the directory.
local check = grainlab.check
local figures = require("grainlab.figures")

local dir = os.tmpname()
os.remove(dir)
assert(os.execute("mkdir -p '" .. dir .. "'"))
local function bad(ext) return dir .. "/a\0b" .. ext end

local function dem2()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } }
  s:add_disk{ pos = { 0.5, 0.5 }, radius = 0.1 }
  s:set_reference()
  return s
end
local function dem3()
  local s = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } }, gravity = { 0, 0, 0 } }
  s:add_sphere{ pos = { 0.5, 0.5, 0.5 }, radius = 0.1 }
  return s
end
local function mpm2()
  local m = mpm.scene{ cells = { 8, 8 }, size = { 1, 1 } }
  m:add_disk{ center = { 0.5, 0.5 }, radius = 0.2, material = mpm.material{ density = 1000, shear = 1e6, bulk = 2e6 } }
  return m
end
local function dsmc2()
  local d = dsmc.scene{ size = { 1, 1 }, cells = { 4, 4 }, radius = 0.001 }
  d:fill{ n = 10, temperature = 1, seed = 1 }
  return d
end
local function rec()
  local r = grainlab.recorder{ columns = { "t", "e" } }
  r:add{ t = 1, e = 1 }
  r:add{ t = 2, e = 2 }
  return r
end

-- { what, function, text the error must contain }
local calls = {
  { "grainlab.write_file", function() return grainlab.write_file(bad(".txt"), "x") end,
    "bad argument #1 to 'write_file' (non-empty file path without NUL bytes expected, got '" },
  { "render.png", function() render.png(dem2(), bad(".png")) end, "bad argument #2 to 'png' (non-empty file path without NUL bytes" },
  { "image:save", function() render.image(dem2(), { width = 32, height = 32 }):save(bad(".png")) end,
    "bad argument #1 to 'save' (non-empty file path without NUL bytes" },
  { "render.plot", function() render.plot{ file = bad(".png"), series = { { x = { 1, 2 }, y = { 1, 2 } } } } end,
    "bad field 'file' in argument #1 to 'plot' (non-empty file path without NUL bytes" },
  { "render.field", function() render.field{ file = bad(".png"), values = { 1, 2, 3, 4 }, nx = 2, ny = 2 } end,
    "bad field 'file' in argument #1 to 'field' (non-empty file path without NUL bytes" },
  { "render.points", function() render.points{ file = bad(".png"), x = { 0, 1 }, y = { 0, 1 } } end,
    "bad field 'file' in argument #1 to 'points' (non-empty file path without NUL bytes" },
  { "dem save", function() dem2():save(bad(".ckpt")) end, "bad argument #1 to 'save' (non-empty file path without NUL bytes" },
  { "dem.load", function() dem.load(bad(".ckpt")) end, "bad argument #1 to 'load' (non-empty file path without NUL bytes" },
  { "mpm save", function() mpm2():save(bad(".ckpt")) end, "bad argument #1 to 'save' (non-empty file path without NUL bytes" },
  { "mpm.load", function() mpm.load(bad(".ckpt")) end, "bad argument #1 to 'load' (non-empty file path without NUL bytes" },
  { "dsmc save", function() dsmc2():save(bad(".ckpt")) end, "bad argument #1 to 'save' (non-empty file path without NUL bytes" },
  { "dsmc.load", function() dsmc.load(bad(".ckpt")) end, "bad argument #1 to 'load' (non-empty file path without NUL bytes" },
  { "dem write_vtk", function() dem2():write_vtk(bad(".vtu")) end, "bad argument #1 to 'write_vtk' (non-empty file path without NUL bytes" },
  { "mpm write_vtk", function() mpm2():write_vtk(bad(".vtu")) end, "bad argument #1 to 'write_vtk' (non-empty file path without NUL bytes" },
  { "dsmc write_vtk", function() dsmc2():write_vtk(bad(".vtu")) end, "bad argument #1 to 'write_vtk' (non-empty file path without NUL bytes" },
  { "mesh write_vtk", function()
      local s = dem2()
      for _, p in ipairs{ { 0.2, 0.2 }, { 0.8, 0.2 }, { 0.2, 0.8 }, { 0.8, 0.8 } } do s:add_disk{ pos = p, radius = 0.1 } end
      analysis.delaunay(s):write_vtk(bad(".vtu"), s)
    end, "bad argument #1 to 'write_vtk' (non-empty file path without NUL bytes" },
  { "grainlab.vtk.series", function() grainlab.vtk.series(bad(".pvd")) end,
    "bad argument #1 to 'series' (non-empty file path without NUL bytes" },
  { "dem.read_lammps_data", function() dem.read_lammps_data(bad(".data")) end,
    "bad argument #1 to 'read_lammps_data' (non-empty file path without NUL bytes" },
  { "s:read_lammps_data", function() dem3():read_lammps_data(bad(".data")) end,
    "bad argument #1 to 'read_lammps_data' (non-empty file path without NUL bytes" },
  { "s:write_lammps_data", function() dem3():write_lammps_data(bad(".data")) end,
    "bad argument #1 to 'write_lammps_data' (non-empty file path without NUL bytes" },
  { "s:write_lammps_dump", function() dem3():write_lammps_dump(bad(".dump")) end,
    "bad argument #1 to 'write_lammps_dump' (non-empty file path without NUL bytes" },
  { "grainlab.recorder", function() grainlab.recorder{ file = bad(".csv"), columns = { "t" } } end,
    "bad field 'file' in argument #1 to 'recorder' (file name without NUL bytes expected, got '" },
  { "rec:write", function() rec():write(bad(".csv")) end, "bad argument #1 to 'write' (file name without NUL bytes expected" },
  { "rec:plot", function() rec():plot{ file = bad(".png") } end,
    "bad field 'file' in argument #1 to 'plot' (file name without NUL bytes expected" },
  { "grainlab.biax.prepared", function() grainlab.biax.prepared{ cache = bad(".lua") } end,
    "bad field 'cache' in argument #1 to 'grainlab.biax.prepared' (false or a file name (no NUL byte) expected" },
  { "figures.path", function() figures.path("a\0b.png", { published = false, out = dir }) end,
    "bad argument #1 to 'path' (file name without NUL bytes expected" },
  { "figures.dir", function() figures.dir{ published = false, out = dir .. "/d\0e" } end,
    "bad field 'out' in argument #1 to 'dir' (directory name without NUL bytes expected" },
}
for _, c in ipairs(calls) do
  local msg = check.errors(c[2], c[3], c[1])
  check.contains(msg, "\\0", c[1] .. ": the NUL shown in the value")
end

-- Nothing was written: not "a" (the name cut at the NUL), nor a directory "d".
local listing = io.popen("ls -A '" .. dir .. "'"):read("a")
check.eq(listing, "", "nothing written in the directory")
os.execute("rm -rf '" .. dir .. "'")
check.done()
