-- Files from elsewhere are read defensively: DEM, MPM and DSMC checkpoints and LAMMPS data files,
-- damaged in every way the readers must catch, each refused at once with a message that names the
-- file and the line, section or value. Every case runs in a child grainlab under a watchdog
-- (reader_fuzz.lua): a case that takes more than 10 s is killed and fails the test, and so does a
-- child that dies (a sanitizer report, under the sanitizer build).
--   1. named cases, one per class: a LAMMPS header counting 10^8 or 2^31 atoms over a few hundred
--      lines; a data file cut in its Velocities section, inside its last number, inside a z;
--      image flags on an axis that is not periodic and on z in 2D; +-1e308 as a coordinate or a
--      box bound; a NUL byte; DEM, MPM and DSMC step counters near 2^63; a boundary spring joining particle
--      2^63 - 1; a checkpoint without its rolling-resistance section, or its clumps; a clump count
--      of 2^63 - 1; MPM and DSMC grids inflated;
--      a FIFO, /dev/zero and a directory given to each reader;
--   2. 300 generated mutations (seed 1): bit flips with and without the checksum, cuts at section
--      boundaries and inside numbers, sections shortened, grown, deleted, duplicated and moved,
--      counts, indices and counters inflated, doubles made NaN, inf or 1e308; a case fails when a
--      file that must be refused loads, or a refusal does not name the file.
-- scripts: `grainlab tests/lua/lib/reader_fuzz.lua role=campaign n=5000` is the large campaign.
local check = grainlab.check
local R = dofile("../lua/lib/reader_fuzz.lua")
local F = dofile("../lua/lib/ckpt_files.lua")

local exe = arg[-1]
for i = -2, -10, -1 do if arg[i] then exe = arg[i] else break end end
check.is_true(type(exe) == "string", "the binary's path is arg[-1]")
if exe:find("/") and exe:sub(1, 1) ~= "/" then
  local pwd = io.popen("pwd")
  exe = pwd:read("l") .. "/" .. exe
  pwd:close()
end

local dir = os.tmpname()
os.remove(dir)
assert(os.execute("mkdir -p '" .. dir .. "'"))
local seeds = R.make_seeds(dir)
local by = {}
for _, s in ipairs(seeds) do by[s.name] = s end

-- ---- 1. named cases -------------------------------------------------------------------------
local cases = {}
local function case(name, kind, text, expect, opts)
  local path = string.format("%s/named%d.%s", dir, #cases + 1, kind == "lammps" and "data" or "ckpt")
  F.write(path, text)
  cases[#cases + 1] = { name = name, kind = kind, path = path, expect = expect, opts = opts }
end

-- LAMMPS data files
local l3, l2 = by.lammps3, by.lammps2
local p3 = { periodic = { true, true, false } }
local t3 = l3.bytes
local n3 = l3.info.n
check.eq(select(2, t3:gsub("\nVelocities\n", "")), 1, "the 3D seed has velocities")
case("10^8 atoms", "lammps", (t3:gsub("\n" .. n3 .. " atoms\n", "\n100000000 atoms\n", 1)),
     ":3: the header announces 100000000 atoms, but the", p3)
case("2^31 atoms", "lammps", (t3:gsub("\n" .. n3 .. " atoms\n", "\n2147483648 atoms\n", 1)),
     ":3: the header announces 2147483648 atoms, but the", p3)
do -- cut on a line boundary in the middle of the Velocities section
  local vstart = t3:find("\nVelocities\n", 1, true)
  local at = vstart
  for _ = 1, 2 + n3 // 2 do at = t3:find("\n", at + 1, true) end
  case("cut in Velocities", "lammps", t3:sub(1, at),
       "the file ends in the Velocities section after " .. (n3 // 2) .. " of " .. n3 .. " atoms", p3)
end
case("cut in the last number", "lammps", t3:sub(1, #t3 - 3),
     "the file ends inside this line, without a newline (cut short?)", p3)
do -- an atoms-only file cut inside the last atom's z: the image flags are gone with it
  local atoms = t3:sub(1, l3.info.atoms_end)
  local last = atoms:match("([^\n]*)\n$")
  local z = last:match("^%S+ %S+ %S+ %S+ %S+ %S+ (%S+)")
  local cut = #atoms - #last - 1 + last:find(z, 1, true) + 4
  case("cut inside a z", "lammps", atoms:sub(1, cut) .. "\n",
       "an Atoms line has 7 values where the lines before have 10", p3)
end
local t2 = l2.bytes
local function first_atom(text, f)
  local a, b = text:find("\nAtoms # sphere\n\n", 1, true)
  local line = text:match("^[^\n]*", b + 1)
  return text:sub(1, b) .. f(line) .. text:sub(b + 1 + #line)
end
local function flags(ix, iy, iz) return function(line) return (line:gsub("%S+ %S+ %S+$", ix .. " " .. iy .. " " .. iz)) end end
case("image flag, axis not periodic", "lammps", first_atom(t2, flags(1, 0, 0)),
     "has image flag 1 on axis x, which is not periodic in this scene")
case("image flag z in 2D", "lammps", first_atom(t2, flags(0, 0, -1)),
     "has image flag -1 on axis z of a 2D scene")
local function coordinate(v) return function(line)
  local t = {}
  for w in line:gmatch("%S+") do t[#t + 1] = w end
  t[5] = v
  return table.concat(t, " ")
end end
case("x = 1e308, not periodic", "lammps", first_atom(t2, coordinate("1e308")),
     "x = 1e+308 is outside the scene's box [0, 0.1] on an axis that is not periodic")
case("x = -1e308, periodic", "lammps", first_atom(t3, coordinate("-1e308")),
     "x = -1e+308 is more than 512 box lengths (LAMMPS's image range) outside the periodic box [0, 0.1]", p3)
case("xlo = -1e308", "lammps", (t2:gsub("\n0 0.10000000000000001 xlo xhi\n", "\n-1e308 0.10000000000000001 xlo xhi\n", 1)),
     ":6: xlo xhi -1e+308 0.1: box bounds of magnitude at most 1e100 expected")
case("NUL byte", "lammps", first_atom(t2, function(line) return line:sub(1, 5) .. "\0" .. line:sub(6) end),
     "the line holds a NUL byte")

-- checkpoints, behind a recomputed checksum
local function forged(seed, tag, edit)
  local t = R.ckpt_parse(seed.bytes)
  local found = false
  for k = #t.sections, 1, -1 do
    local sec = t.sections[k]
    if sec.tag == tag then
      found = true
      local payload = edit(sec.payload)
      if payload then sec.payload = payload else table.remove(t.sections, k) end
    end
  end
  assert(found, "no section " .. tag)
  return R.ckpt_build(t)
end
local function put_i64(at, v) return function(p) return p:sub(1, at) .. string.pack("<i8", v) .. p:sub(at + 9) end end
-- the DEM scene: dim (4), lo, hi (48), periodic (12), gravity, thickness, drag, skin, skin, r_max
-- (64), n (8), rot (4), time (8), then the step count
case("DEM steps near 2^63", "dem", forged(by.dem2, "scene", put_i64(148, math.maxinteger)),
     "(section 'scene': steps = 9223372036854775807 is outside [0, 9007199254740992])")
case("DEM steps 2^53 + 1", "dem", forged(by.dem2, "scene", put_i64(148, (1 << 53) + 1)),
     "steps = 9007199254740993 is outside [0, 9007199254740992]")
do -- the first spring of the boundary: after the definition (128 bytes), ne and its edges of
  -- 20 bytes, closed (4) and the spring count (8)
  local edit = function(p)
    local ne = string.unpack("<I8", p, 129)
    return put_i64(128 + 8 + 20 * ne + 4 + 8, math.maxinteger)(p)
  end
  case("boundary spring index 2^63 - 1", "dem", forged(by.dem2_boundary, "boundary", edit),
       "(section 'boundary': spring 1 joins particle index 9223372036854775807, outside [0, 49))")
end
case("rolling section removed", "dem", forged(by.dem3_rolling, "rolling", function() return nil end),
     "is incomplete: section 'rolling' (number 7 of the 7 its writer listed) is missing")
case("flow section removed", "dem", forged(by.dem2_flow, "flow", function() return nil end),
     "is incomplete: section 'flow'")
case("clumps section removed", "dem", forged(by.dem3_clumps, "clumps", function() return nil end),
     "is incomplete: section 'clumps'")
case("clump count 2^63 - 1", "dem", forged(by.dem3_clumps, "clumps", put_i64(0, math.maxinteger)),
     "(section 'clumps': clump count = 9223372036854775807 is outside [0, ")
case("MPM steps near 2^63", "mpm", forged(by.mpm, "mpm.clock", put_i64(8, math.maxinteger - 1)),
     "steps = 9223372036854775806 is outside [0, 9007199254740992]")
case("DSMC steps near 2^63", "dsmc", forged(by.dsmc2, "dsmc.clock", put_i64(8, math.maxinteger)),
     "steps = 9223372036854775807 is outside [0, 9007199254740992]")
-- the MPM grid: cells, origin, size, periodic, gravity per axis (40 bytes)
case("MPM grid 5000 x 5000", "mpm",
     forged(by.mpm, "mpm.scene", function(p) return put_i64(40, 5000)(put_i64(0, 5000)(p)) end),
     "is a corrupt mpm checkpoint: cells 5000 x 5000 (cell 0.00024 x 0.0002) do not match point 1's reference volume")
-- the DSMC grid: dim, then lo, hi, cells, periodic, gravity per axis
case("DSMC grid 100000 x 15", "dsmc", forged(by.dsmc2, "dsmc.scene", put_i64(24, 100000)),
     "is a corrupt dsmc checkpoint: cells 100000 x 15 x 1 make 1500000 cells, but section 'dsmc.cells' holds 150")

-- what is not a regular file
local fifo = dir .. "/fifo"
assert(os.execute("mkfifo '" .. fifo .. "'"))
for _, kind in ipairs{ "dem", "mpm", "dsmc", "lammps" } do
  local what = kind == "lammps" and "LAMMPS data file" or "checkpoint"
  cases[#cases + 1] = { name = "FIFO", kind = kind, path = fifo,
                        expect = "cannot read " .. what .. " '" .. fifo .. "': it is a FIFO (named pipe), not a regular file" }
  cases[#cases + 1] = { name = "/dev/zero", kind = kind, path = "/dev/zero",
                        expect = "cannot read " .. what .. " '/dev/zero': it is a character device, not a regular file" }
  cases[#cases + 1] = { name = "directory", kind = kind, path = dir,
                        expect = "it is a directory, not a regular file" }
end

local list = dir .. "/cases.lua"
local f = assert(io.open(list, "w"))
f:write("return {\n")
for _, c in ipairs(cases) do
  f:write(string.format("{ name = %q, kind = %q, path = %q, expect = %q, opts = %s },\n", c.name, c.kind,
                        c.path, c.expect, c.opts and "{ periodic = { true, true, false } }" or "nil"))
end
f:write("}\n")
f:close()
local res = R.drive{ exe = exe, dir = dir, role = "explicit", list = list, first = 1, last = #cases,
                     limit = 10 }
for _, l in ipairs(res.failures) do check.is_true(false, l) end
for _, l in ipairs(res.run_hangs) do check.is_true(false, l) end
check.eq(res.cases, #cases, "every named case ran")
check.eq(res.refused, #cases, "every named case refused")

-- ---- 2. generated mutations ------------------------------------------------------------------
local N = 300
local gen = R.drive{ exe = exe, dir = dir, seed = 1, first = 1, last = N, limit = 10 }
for _, l in ipairs(gen.failures) do check.is_true(false, l) end
for _, l in ipairs(gen.run_hangs) do check.is_true(false, l) end
check.eq(gen.cases, N, "every generated case ran")
-- every class is in the sample (a file that must be refused and loads is a failure above)
for _, kind in ipairs{ "dem", "mpm", "dsmc" } do
  for _, class in ipairs{ "flip", "flip_raw", "cut", "cut_section", "grow_section", "drop", "dup",
                          "move", "int", "steps", "double", "zero" } do
    local bc = gen.by_class[kind .. "/" .. class]
    check.is_true(bc and bc[1] > 0, kind .. "/" .. class .. ": generated")
  end
end
for _, class in ipairs{ "cut_line", "cut_mid", "count", "types", "token", "drop_line", "dup_line",
                        "drop_section", "flip" } do
  local bc = gen.by_class["lammps/" .. class]
  check.is_true(bc and bc[2] > 0, "lammps/" .. class .. ": generated, and refused at least once")
end
check.gt(gen.refused, N // 2, "most mutations are refused")
check.gt(gen.ran or 0, 0, "some mutations leave a valid file, which loads and runs")

os.execute("rm -rf '" .. dir .. "'")
check.done()
