-- LAMMPS files: a grainlab write -> read round trip gives the identical state (every number to the
-- bit), dump frames have LAMMPS's layout and append, and bad files are refused with the file, the
-- line and the problem, leaving the scene untouched.
local check = grainlab.check
local dir = os.tmpname()
os.remove(dir)
local function path(name) return dir .. "_" .. name end
local made = {}
local function write(name, text)
  local p = path(name)
  local f = assert(io.open(p, "w")); f:write(text); f:close()
  made[#made + 1] = p
  return p
end
local function slurp(p)
  local f = assert(io.open(p)); local t = f:read("a"); f:close(); return t
end

local q = grainlab.material{ density = 2650, young = 30e9, friction = 0.4, restitution = 0.8 }
local g = grainlab.material{ density = 2500.123456789012, young = 60e9, friction = 0.3 }

local function same_state(a, b, what, dim)
  local pa, pb = a:particles(), b:particles()
  check.eq(pb.count, pa.count, what .. ": count")
  local keys = dim == 3 and { "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz", "radius", "mass" }
                         or { "x", "y", "vx", "vy", "omega", "radius", "mass" }
  for _, k in ipairs(keys) do
    for i = 1, pa.count do
      if pa[k][i] ~= pb[k][i] then
        check.eq(string.format("%a", pb[k][i]), string.format("%a", pa[k][i]), what .. ": " .. k .. " of " .. i)
      end
    end
    check.count = check.count + 1
  end
  local ia, ib = a:info(), b:info()
  for c = 1, 2 do for d = 1, dim do check.eq(ib.box[c][d], ia.box[c][d], what .. ": box") end end
end

-- ---- 3D round trip: two materials, spin, a particle across the periodic x side ------------------
local s = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 0.01, 0.01, 0.02 } }, periodic = { true, false, false },
                     gravity = { 0, 0, -9.81 } }
s:contact{ normal = "hertz", tangential = "spring" }
for i = 1, 5 do
  s:add_sphere{ pos = { 0.002 * i - 0.001, 0.005, 0.005 }, radius = 0.0005 + 0.00005 * i,
                material = i % 2 == 0 and g or q, vel = { 0.1 * i, 0.01, -0.02 }, omega = { 1, 2, 3 * i } }
end
s:add_sphere{ pos = { 0.00995, 0.002, 0.01 }, radius = 0.0005, material = q, vel = { 1, 0.1, 0 } }
s:run{ steps = 300 }
local types = { [1] = q, [2] = g }
local p3 = path("r3.data")
made[#made + 1] = p3
s:write_lammps_data(p3, { types = types })
local t3, info = dem.read_lammps_data(p3, { types = types, periodic = { true, false, false }, gravity = { 0, 0, -9.81 } })
same_state(s, t3, "3D round trip", 3)
check.eq(info.atom_types, 2, "3D: atom types")
check.eq(t3:info().dim, 3, "3D file read as 3D")
local text = slurp(p3)
check.contains(text, "\n6 atoms\n2 atom types\n", "header counts")
check.contains(text, "\n0 0.01 xlo xhi\n0 0.01 ylo yhi\n0 0.02 zlo zhi\n", "box lines")
check.contains(text, "\nAtoms # sphere\n\n1 1 0.0011", "Atoms: id type diameter (2 r)")
check.contains(text, " 2500.12345678901", "density of material 2 at full precision")
check.contains(text, "\nVelocities\n\n1 ", "Velocities section")
-- the same scene through the types it was written with: type 2 is g, and g's density
local t3b = dem.read_lammps_data(p3, { types = { [1] = q, [2] = g }, periodic = { true, false, false } })
check.eq(t3b:particles().mass[2], s:particles().mass[2], "type 2 carries g")
-- without types, each type keeps the file's density (a copy of the default material): the density
-- column round-trips exactly, so the masses do
local t3c = dem.read_lammps_data(p3, { periodic = { true, false, false } })
for i = 1, 6 do check.eq(t3c:particles().mass[i], s:particles().mass[i], "file density, mass of " .. i) end
-- a second read into the same scene adds, all or nothing (the box is the scene's)
local before = t3:particles().count
check.errors(function() t3:read_lammps_data(p3, { types = { [1] = q } }) end,
  "bad field 'types' in argument #2 to 'read_lammps_data' (a grainlab.material for atom type 2 (atom 2,", "unmapped type")
check.eq(t3:particles().count, before, "nothing added after the refusal")

-- ---- 2D round trip: z = 0, zlo < 0 < zhi, disks with spin -------------------------------------
local s2 = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
s2:contact{ tangential = "spring" }
for i = 1, 4 do s2:add_disk{ pos = { 0.002 * i, 0.003 }, radius = 0.0007, material = q, vel = { 0.1, -0.1 * i }, omega = 5 * i } end
s2:run{ steps = 100 }
local p2 = path("r2.data")
made[#made + 1] = p2
s2:write_lammps_data(p2)
local text2 = slurp(p2)
check.contains(text2, "-0.00069999999999999999 0.00069999999999999999 zlo zhi", "2D: thin z slab about 0")
local t2 = dem.read_lammps_data(p2, { types = { [1] = q }, gravity = { 0, -9.81 } })
check.eq(t2:info().dim, 2, "2D file read as 2D")
same_state(s2, t2, "2D round trip", 2)
-- continuing both gives the same bits (the file holds the whole particle state of a scene without
-- contact history: the particles are apart)
local r1 = s2:run{ steps = 50 }
local r2 = t2:run{ steps = 50 }
check.eq(r2.dt, r1.dt, "same automatic dt")
same_state(s2, t2, "2D, 50 steps after the round trip", 2)
-- no default material given and the file's density 2650 = the default's: same masses
local t2d = dem.read_lammps_data(p2)
check.eq(t2d:particles().mass[1], s2:particles().mass[1], "default material, file density")
-- wrong dimension: the 3D file into a 2D scene, and a 2D scene asked of a 3D file
local e2 = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.02 } } }
check.errors(function() e2:read_lammps_data(p3, { types = types }) end,
  "a 2D scene needs all four 0 (is this a 3D file?)", "3D file into a 2D scene")
check.eq(e2:particles().count, 0, "nothing half-loaded")
check.errors(function() dem.read_lammps_data(p3, { dim = 2, types = types }) end,
  "a 2D file needs zlo < 0 < zhi", "dim = 2 for a 3D box")

-- ---- dump custom: LAMMPS's layout, frames appended ---------------------------------------------
local pd = path("frames.dump")
made[#made + 1] = pd
s:write_lammps_dump(pd, { types = types })
s:run{ steps = 10 }
s:write_lammps_dump(pd, { types = types, append = true })
local dump = slurp(pd)
local _, frames = dump:gsub("ITEM: TIMESTEP\n", "")
check.eq(frames, 2, "two frames")
check.contains(dump, "ITEM: TIMESTEP\n300\nITEM: NUMBER OF ATOMS\n6\nITEM: BOX BOUNDS pp ff ff\n0 0.01\n0 0.01\n0 0.02\n", "first frame header")
check.contains(dump, "ITEM: TIMESTEP\n310\n", "second frame's step")
check.contains(dump, "ITEM: ATOMS id type radius mass x y z vx vy vz fx fy fz omegax omegay omegaz\n1 1 0.00055000000000000003 ", "columns")
s:write_lammps_dump(pd, { types = types })
local _, again = slurp(pd):gsub("ITEM: TIMESTEP\n", "")
check.eq(again, 1, "without append the file starts anew")
check.errors(function() s:write_lammps_dump(pd, { types = { [1] = q } }) end,
  "bad field 'types' in argument #2 to 'write_lammps_dump' (a type for every particle's material (particle 2's has none)", "a material without a type")
check.errors(function() s:write_lammps_dump(pd, { typo = 1 }) end,
  "bad argument #2 to 'write_lammps_dump' (unknown field 'typo'", "unknown option")

-- ---- bad files: the file, the line, the problem; nothing half-loaded ------------------------------
local head = "title\n\n3 atoms\n1 atom types\n\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms # sphere\n\n"
local good = head .. "1 1 0.1 1000 0.5 0.5 0.5\n2 1 0.1 1000 0.2 0.5 0.5\n3 1 0.1 1000 0.8 0.5 0.5\n"
local scene = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } } }
local ok = write("good.data", good)
check.eq(scene:read_lammps_data(ok).count, 3, "the well-formed file loads")
-- (one atom: a header counting 3 atoms before a single line is refused by its count first)
local head1 = (head:gsub("\n3 atoms\n", "\n1 atoms\n"))
local bad = {
  { "short line", head1 .. "1 1 0.1 1000 0.5 0.5\n", ":12: an Atoms line has 6 values; atom_style sphere needs 7" },
  { "zero diameter", head1 .. "1 1 0 1000 0.5 0.5 0.5\n", ":12: atom 1: diameter '0' must be a positive number" },
  { "negative density", head1 .. "1 1 0.1 -5 0.5 0.5 0.5\n", ":12: atom 1: density '-5' must be a positive number" },
  { "not a number", head1 .. "1 1 0.1 1000 0.5 abc 0.5\n", ":12: atom 1: coordinate y 'abc' is not a number" },
  { "bad type", head1 .. "1 2 0.1 1000 0.5 0.5 0.5\n", ":12: atom 1: type '2' is not an integer in [1, 1]" },
  { "duplicate id", head .. "1 1 0.1 1000 0.5 0.5 0.5\n2 1 0.1 1000 0.2 0.5 0.5\n1 1 0.1 1000 0.8 0.5 0.5\n",
    ":14: atom id 1 appears twice (also line 12)" },
  { "truncated", head .. "1 1 0.1 1000 0.5 0.5 0.5\n2 1 0.1 1000 0.2 0.5 0.5\n",
    "the file ends in the Atoms section after 2 of 3 atoms (truncated?)" },
  { "count beyond the file", head .. "1 1 0.1 1000 0.5 0.5 0.5\n",
    ":3: the header announces 3 atoms, but the 26 bytes after it hold at most 1 Atoms lines" },
  { "no Atoms", "title\n\n3 atoms\n1 atom types\n\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n",
    "the header announces 3 atoms but the file has no Atoms section" },
  { "no box", "title\n\n0 atoms\n1 atom types\n\n0 1 xlo xhi\n0 1 ylo yhi\n", "the header has no 'zlo zhi' box bounds" },
  { "bonds", "title\n\n3 atoms\n2 bonds\n", ":4: 2 bonds: grainlab's DEM reads spheres only" },
  { "unknown header", "title\n\n3 atoms\n7 widgets\n", ":4: unknown header line '7 widgets'" },
  { "other atom style", (head1:gsub("# sphere", "# atomic")) .. "1 1 0.5 0.5 0.5\n",
    ":10: the Atoms section is for atom_style atomic" },
  { "triclinic", "title\n\n0 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n0.1 0 0 xy xz yz\n", ":8: a triclinic box" },
  { "unknown section", good .. "\nBonds\n\n1 1 1 2\n", ":16: section 'Bonds' is not read by grainlab" },
  { "velocity of a stranger", good .. "\nVelocities\n\n1 0 0 0 0 0 0\n9 0 0 0 0 0 0\n3 0 0 0 0 0 0\n",
    ":19: atom 9 has a velocity but is not in Atoms" },
  { "short velocities", good .. "\nVelocities\n\n1 0 0 0 0 0\n", ":18: a Velocities line has 6 values" },
  { "outside the box", head .. "1 1 0.1 1000 0.5 0.5 0.5\n2 1 0.1 1000 1.5 0.5 0.5\n3 1 0.1 1000 0.8 0.5 0.5\n",
    ":13: atom 2: x = 1.5 is outside the scene's box [0, 1]" },
  { "extra lines", good .. "4 1 0.1 1000 0.8 0.5 0.5\n", ":15: '4 1 0.1 1000 0.8 0.5 0.5' after the end of a section" },
  { "empty", "", "the file is empty" },
}
for k, case in ipairs(bad) do
  local p = write("bad" .. k .. ".data", case[2])
  local msg = check.errors(function() scene:read_lammps_data(p) end, case[3], case[1])
  check.contains(msg, "read_lammps_data: " .. p, case[1] .. ": names the call and the file")
  check.eq(scene:particles().count, 3, case[1] .. ": nothing half-loaded")
end
check.errors(function() dem.read_lammps_data(path("missing.data")) end, "cannot read LAMMPS data file", "missing file")
-- skipped sections: Masses and Pair Coeffs carry nothing grainlab takes from a file
local skip = write("skip.data", "title\n\n1 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\n" ..
  "Masses\n\n1 1.0\n\nPair Coeffs # granular\n\n1 1 1\n\nAtoms\n\n7 1 0.1 1000 0.5 0.5 0.5 0 0 0\n")
local ss, si = dem.read_lammps_data(skip)
check.eq(si.ids[1], 7, "Masses and Pair Coeffs skipped; the LAMMPS id is kept in info.ids")
check.eq(ss:info().dim, 3, "zlo = 0: not a 2D file")
-- the density policy is checked
check.errors(function() dem.read_lammps_data(skip, { density = "fil" }) end,
  "bad field 'density'", "density option")
check.errors(function() dem.read_lammps_data(skip, { types = { [2] = q } }) end,
  "bad field 'types' in argument #2 to 'read_lammps_data'", "a type the file does not have")
-- fixed_types: those atoms are fixed particles
local sfix = dem.read_lammps_data(ok, { fixed_types = { 1 }, gravity = { 0, 0, -9.81 } })
sfix:run{ steps = 10 }
check.eq(sfix:particles().z[1], 0.5, "fixed atoms stay")

-- not from on_step: a packing can shorten the stability limit the run's dt was checked at; a
-- dump frame can be written there
scene:run{ steps = 2, every = 1, on_step = function(sc)
  check.errors(function() sc:read_lammps_data(ok) end,
    "read_lammps_data: this dem.scene is running (called from its on_step)", "read from on_step")
  sc:write_lammps_dump(path("on_step.dump"), { append = true })
end }
made[#made + 1] = path("on_step.dump")
check.eq(select(2, slurp(path("on_step.dump")):gsub("ITEM: TIMESTEP", "")), 2, "frames from on_step")
-- a failure after atoms went in (the third overlaps a wall of the scene) takes them out again
local walled = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } } }
walled:add_wall{ point = { 0.75, 0, 0 }, normal = { -1, 0, 0 } }
walled:add_sphere{ pos = { 0.1, 0.1, 0.1 }, radius = 0.05 }
check.errors(function() walled:read_lammps_data(ok) end, ":14: atom 3: particle at pos", "wall overlap")
check.eq(walled:particles().count, 1, "rolled back: only the particle from before")
walled:add_sphere{ pos = { 0.3, 0.3, 0.3 }, radius = 0.05 }
check.eq(walled:particles().count, 2, "the scene still takes particles")
walled:run{ steps = 5 }

-- ---- ids are tags: after removals a dump and a data file give each atom its tag, and a data file
-- with the gaps reads back with those tags (and writes the same file again) --------------------
do
  local function removed_scene()
    local t = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.02 } } }
    t:add_disk{ pos = { 0.018, 0.01 }, radius = 0.001, vel = { 2, 0 }, material = q }  -- leaves: x+
    for k = 0, 3 do t:add_disk{ pos = { 0.004 + 0.003 * k, 0.005 }, radius = 0.001, material = q } end
    t:add_disk{ pos = { 0.003, 0.015 }, radius = 0.001, vel = { -2, 0 }, material = q } -- leaves: x-
    t:outflow{ side = "x+" }
    t:outflow{ side = "x-" }
    t:run{ time = 0.01 }
    return t
  end
  local t = removed_scene()
  local pt = t:particles()
  check.eq(pt.count, 4, "ids: two of six removed")
  check.eq(pt.tag[1], 2, "ids: the first left is the second made")
  local pdump, pdata = path("tags.dump"), path("tags.data")
  made[#made + 1], made[#made + 1] = pdump, pdata
  t:write_lammps_dump(pdump)
  local ids = {}
  for id in slurp(pdump):match("ITEM: ATOMS[^\n]*\n(.*)"):gmatch("(%d+) [^\n]*\n") do ids[#ids + 1] = tonumber(id) end
  check.eq(#ids, 4, "ids: four atoms in the dump")
  for i = 1, 4 do check.eq(ids[i], pt.tag[i], "ids: dump atom " .. i .. " is its tag") end
  t:write_lammps_data(pdata)
  local text = slurp(pdata)
  check.contains(text, "\nAtoms # sphere\n\n2 ", "ids: the data file's first atom is tag 2")
  check.contains(text, "\nVelocities\n\n2 ", "ids: and its velocity line")
  local back = dem.read_lammps_data(pdata)
  local pb = back:particles()
  check.eq(#(pb.tag or {}), 4, "ids: non-contiguous ids come back as tags")
  for i = 1, 4 do check.eq(pb.tag[i], pt.tag[i], "ids: tag " .. i .. " round-trips") end
  local again = path("tags2.data")
  made[#made + 1] = again
  back:write_lammps_data(again)
  check.eq(slurp(again):match("\n.*"), text:match("\n.*"), "ids: the data file round-trips (all but the title's time)")
  -- checkpoints keep the tags (a scene that has tags but no inserter or outflow)
  local ck = path("tags.ckpt")
  made[#made + 1] = ck
  back:save(ck)
  local loaded = dem.load(ck):particles()
  for i = 1, 4 do check.eq(loaded.tag[i], pt.tag[i], "ids: tag " .. i .. " survives a checkpoint") end
  -- a new particle takes a number above every id read
  back:add_disk{ pos = { 0.01, 0.015 }, radius = 0.001 }
  check.eq(back:particles().tag[5], 6, "ids: the next tag is above the largest id")
  -- ids 1..n stay indices (no tags); an id that is a tag already is refused
  check.is_true(dem.read_lammps_data(path("r2.data")):particles().tag == nil, "ids 1..n: no tags")
  local full = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.02 } } }
  for k = 1, 3 do full:add_disk{ pos = { 0.004 * k, 0.015 }, radius = 0.001 } end
  check.errors(function() full:read_lammps_data(pdata) end,
    "atom id 2 is already the tag of particle 2 of the scene", "ids: a clash is refused")
  check.eq(full:particles().count, 3, "ids: nothing read after the clash")
end

for _, p in ipairs(made) do os.remove(p) end
check.done()
