-- Clump scenes in grainlab's files: checkpoints continue bit for bit (N + M steps against N,
-- save, load in a new scene, M: every particle's state and every clump's body state, in 2D and
-- 3D, with velocity Verlet and two timescales, walls, spring friction and clumps in contact);
-- a scene without clumps writes no clump section; damaged clump sections are refused with the
-- file, the section and the value named. VTK: the members' clump array and the file of bodies.
-- LAMMPS: the dump's mol column, the data file in atom_style hybrid sphere molecular, read by
-- LAMMPS itself (read_data, fix rigid/small molecule, run) when lmp is installed; grainlab's own
-- reader refuses that style by name. Rendering: color = 'clump'.
local check = grainlab.check
local C = dofile("../lua/lib/ckpt_dem_case.lua")
local F = dofile("../lua/lib/ckpt_files.lua")
local R = dofile("../lua/lib/reader_fuzz.lua")

local dir = os.tmpname()
os.remove(dir)
assert(os.execute("mkdir -p '" .. dir .. "'"))
local function path(name) return dir .. "/" .. name end
grainlab.threads(1)

local function lines(text)
  local t = {}
  for l in (text .. "\n"):gmatch("([^\n]*)\n") do t[#t + 1] = l end
  return t
end

-- The clump of each particle (0: none), from s:clump(k).members.
local function clump_of(s)
  local of = {}
  for i = 1, s:info().count do of[i] = 0 end
  for k = 1, s:clump_count() do
    for _, i in ipairs(s:clump(k).members) do of[i] = k end
  end
  return of
end

-- ---- checkpoints: N + M against N, save, load, M ------------------------------------------------
for _, dim in ipairs{ 2, 3 } do
  for _, integ in ipairs{ "velocity_verlet", "two_timescales" } do
    local what = string.format("%dD clumps, %s", dim, integ)
    local N = integ == "two_timescales" and 3000 or 1500 -- (its step is half the other's)
    local M = N
    local a = C.build_clumps(dim)
    C.run(a, integ, N + M)
    local b = C.build_clumps(dim)
    C.run(b, integ, N)
    b:save(path("clumps.ckpt"))
    local c = dem.load(path("clumps.ckpt"))
    check.eq(c:clump_count(), b:clump_count(), what .. ": clumps loaded")
    F.same_lines(lines(C.dump_clumps(b)), lines(C.dump_clumps(c)), what .. ": the loaded scene is the saved one")
    C.run(c, integ, M)
    F.same_lines(lines(C.dump_clumps(a)), lines(C.dump_clumps(c)), what .. ": N + M against N, save, load, M")
    -- the state the test claims: clumps pressed on clumps and on walls, with spring friction
    local of, co = clump_of(a), a:measure("contacts")
    local between, on_wall, sliding = 0, 0, 0
    for k = 1, #co.i do
      local i, j = co.i[k], co.j[k]
      if j > 0 and of[i] > 0 and of[j] > 0 and of[i] ~= of[j] then between = between + 1 end
      if j < 0 and of[i] > 0 then on_wall = on_wall + 1 end
      if co.ft[k] > 0 and of[i] > 0 then sliding = sliding + 1 end
    end
    check.gt(between, 3, what .. ": contacts between clumps")
    check.gt(on_wall, 3, what .. ": clumps on walls")
    check.gt(sliding, 3, what .. ": tangential spring forces on members")
  end
end

-- A loaded scene takes new clumps and runs on (its clump arrays grow with the particles).
do
  local b = C.build_clumps(2)
  C.run(b, "velocity_verlet", 200)
  b:save(path("grow.ckpt"))
  local c = dem.load(path("grow.ckpt"))
  local n0 = c:info().count
  local soft = grainlab.material{ density = 1500, young = 2e6, poisson = 0.3, friction = 0.5 }
  for k = 1, 4 do
    c:add_clump{ members = { { offset = { 0, 0 }, radius = 1e-3 }, { offset = { 1.4e-3, 0 }, radius = 1e-3 } },
                 position = { 0.0045 * k - 0.0015, 0.035 }, material = soft }
  end
  check.eq(c:clump_count(), b:clump_count() + 4, "load, then add: clump count")
  check.eq(c:info().count, n0 + 8, "load, then add: members")
  C.run(c, "velocity_verlet", 200)
  check.eq(c:clump(c:clump_count()).members[2], n0 + 8, "load, then add: the last member")
  c:save(path("grow2.ckpt"))
  F.same_lines(lines(C.dump_clumps(c)), lines(C.dump_clumps(dem.load(path("grow2.ckpt")))),
               "load, add, run, save, load")
end

-- A scene without clumps writes no clump section: its file is the one it was before.
do
  local s = C.build(2)
  C.run(s, "velocity_verlet", 20)
  s:save(path("plain.ckpt"))
  for _, sec in ipairs(R.ckpt_parse(F.read(path("plain.ckpt"))).sections) do
    check.is_true(sec.tag ~= "clumps", "no section 'clumps' without clumps")
  end
end

-- ---- damaged clump sections ----------------------------------------------------------------------
-- The section: the clump count (8 bytes), then per clump first, count (8 each), mass (8),
-- moments, x, v (3 doubles with their count: 32 each), q (40), angle (8), L, omega (32 each).
local REC = 8 + 8 + 8 + 32 * 3 + 40 + 8 + 32 * 2
local function forged(file, edit)
  local t = R.ckpt_parse(F.read(file))
  for k = #t.sections, 1, -1 do
    if t.sections[k].tag == "clumps" then
      local p = edit(t.sections[k].payload)
      if p then t.sections[k].payload = p else table.remove(t.sections, k) end
    end
  end
  local out = path("forged.ckpt")
  F.write(out, R.ckpt_build(t))
  return out
end
local function put_i64(at, v) return function(p) return F.put(p, at, string.pack("<i8", v)) end end
local function put_f64(at, v) return function(p) return F.put(p, at, string.pack("<d", v)) end end
for _, dim in ipairs{ 2, 3 } do
  local s = C.build_clumps(dim)
  C.run(s, "velocity_verlet", 50)
  local good = path("good" .. dim .. ".ckpt")
  s:save(good)
  local n = s:info().count
  local c2 = s:clump(2)
  local cases = {
    { "section removed", function() return nil end, "is incomplete: section 'clumps'" },
    { "section cut", function(p) return p:sub(1, #p - 20) end, "section 'clumps'" },
    { "clump count > particles", put_i64(0, n + 1),
      string.format("(section 'clumps': clump count = %d is outside [0, %d])", n + 1, n) },
    { "members out of order", put_i64(8 + REC, 0),
      string.format("(section 'clumps': clump 2's first member = 1 is outside [%d, %d])", c2.members[1], n) },
    { "no members", put_i64(8 + REC + 8, 0), "(section 'clumps': clump 2's member count = 0 is outside [1, " },
    { "mass NaN", put_f64(8 + 16, 0 / 0), "(section 'clumps': clump 1's mass = " },
    { "moment -1", put_f64(8 + 24 + 8 + 16, -1), "(section 'clumps': clump 1's moment of inertia = -1, a positive moment expected)" },
    { "centre far outside", put_f64(8 + 56 + 8, 1e3), "(section 'clumps': clump 1's x = 1000, a position within a box length of the box expected)" },
    { "velocity inf", put_f64(8 + 88 + 8, 1 / 0), "(section 'clumps': clump 1's state = inf, finite values expected)" },
  }
  if dim == 3 then
    cases[#cases + 1] = { "quaternion not unit", put_f64(8 + 120 + 8, 2),
                          "(section 'clumps': clump 1's orientation |q|^2 = " }
  end
  for _, case in ipairs(cases) do
    local file = forged(good, case[2])
    local ok, msg = pcall(dem.load, file)
    check.is_true(not (ok), string.format("%dD %s: refused", dim, case[1]))
    check.contains(tostring(msg), file, string.format("%dD %s: the file named", dim, case[1]))
    check.contains(tostring(msg), case[3], string.format("%dD %s: the message", dim, case[1]))
  end
  -- the offsets above point where they say: an unchanged copy loads
  check.eq(dem.load(forged(good, function(p) return p end)):clump_count(), s:clump_count(),
           dim .. "D: a rebuilt copy loads")
end

-- Each value of the first clump made NaN, infinite, huge, zero, negative or tiny: refused, or
-- loaded and run to the end or to an error, never a crash (the sanitizer build runs this too).
for _, dim in ipairs{ 2, 3 } do
  local s = C.build_clumps(dim)
  C.run(s, "velocity_verlet", 50)
  local good = path("sweep" .. dim .. ".ckpt")
  s:save(good)
  local outcome = { refused = 0, ran = 0, stopped = 0 }
  for at = 8, 8 + REC - 8, 8 do
    for _, v in ipairs{ 0 / 0, 1 / 0, 1e308, 0.0, -1.0, 1e-308 } do
      local ok, scene = pcall(dem.load, forged(good, put_f64(at, v)))
      if not ok then
        outcome.refused = outcome.refused + 1
      elseif pcall(function() scene:run{ steps = 20 } end) then
        outcome.ran = outcome.ran + 1
      else
        outcome.stopped = outcome.stopped + 1
      end
    end
  end
  check.gt(outcome.refused, REC // 8 * 3, dim .. "D sweep: most damaged values refused")
end

-- ---- VTK: the members' clump ids and the bodies' file --------------------------------------------
for _, dim in ipairs{ 2, 3 } do
  local s = C.build_clumps(dim)
  C.run(s, "velocity_verlet", 100)
  local files = s:write_vtk(path("c" .. dim .. ".vtu"))
  check.eq(files[#files], path("c" .. dim .. "_clumps.vtu"), dim .. "D: the clumps' file by default")
  local text = F.read(files[1])
  check.contains(text, 'Name="clump"', dim .. "D: the particles' clump array")
  local body = F.read(files[#files])
  check.contains(body, string.format('NumberOfPoints="%d"', s:clump_count()), dim .. "D: a point per clump")
  for _, name in ipairs{ "id", "mass", "velocity", "angular_velocity", "angular_momentum", "orientation",
                         "inertia", "members", "first_member" } do
    check.contains(body, 'Name="' .. name .. '"', dim .. "D: the clumps' array " .. name)
  end
  local without = s:write_vtk(path("n" .. dim .. ".vtu"), { clumps = false })
  check.eq(#without, #files - 1, dim .. "D: clumps = false writes no clumps' file")
end
do
  local plain = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }
  plain:add_disk{ pos = { 0.5, 0.5 }, radius = 0.1 }
  local files = plain:write_vtk(path("plain.vtu"))
  check.eq(#files, 2, "no clumps: particles and contacts only")
  check.is_true(not (F.read(files[1]):find('Name="clump"', 1, true) ~= nil), "no clumps: no clump array")
  check.errors(function() plain:write_vtk(path("plain.vtu"), { clumps = 1 }) end,
    "bad field 'clumps' in argument #2 to 'write_vtk' (boolean expected, got 1)", "clumps option type")
end

-- ---- LAMMPS --------------------------------------------------------------------------------------
local function has_lmp() return os.execute("command -v lmp >/dev/null 2>&1") == true end
for _, dim in ipairs{ 2, 3 } do
  local s = C.build_clumps(dim)
  C.run(s, "velocity_verlet", 300)
  local of = clump_of(s)
  local p = s:particles()
  -- the dump: mol after id, the clump id of every member
  local dump = path("c" .. dim .. ".dump")
  s:write_lammps_dump(dump)
  local dl = lines(F.read(dump))
  check.eq(dl[9], "ITEM: ATOMS id mol type radius mass x y z vx vy vz fx fy fz omegax omegay omegaz",
           dim .. "D dump: the columns")
  local bad = 0
  for i = 1, p.count do
    local id, mol = dl[9 + i]:match("^(%d+) (%d+) ")
    if tonumber(id) ~= i or tonumber(mol) ~= of[i] then bad = bad + 1 end
  end
  check.eq(bad, 0, dim .. "D dump: mol is each member's clump id, 0 for a loose grain")
  -- the data file: hybrid sphere molecular, id type x y z diameter density mol ix iy iz
  local data = path("c" .. dim .. ".data")
  s:write_lammps_data(data)
  local text = F.read(data)
  check.contains(text, "(atom_style hybrid sphere molecular)", dim .. "D data: the style in the title")
  check.contains(text, "\nAtoms # hybrid\n", dim .. "D data: the style hint")
  local rows = {}
  for line in text:match("\nAtoms # hybrid\n\n(.-)\n\n"):gmatch("[^\n]+") do
    local t = {}
    for w in line:gmatch("%S+") do t[#t + 1] = w end
    rows[#rows + 1] = t
  end
  check.eq(#rows, p.count, dim .. "D data: an Atoms line per particle")
  local wrong, bodies = 0, {}
  for i, t in ipairs(rows) do
    if #t ~= 11 or tonumber(t[1]) ~= i or tonumber(t[3]) ~= p.x[i] or tonumber(t[6]) ~= 2 * p.radius[i]
       or tonumber(t[8]) ~= of[i] then wrong = wrong + 1 end
    if of[i] > 0 then bodies[of[i]] = true end
  end
  check.eq(wrong, 0, dim .. "D data: id type x y z diameter density mol and image flags")
  local nbodies = 0
  for _ in pairs(bodies) do nbodies = nbodies + 1 end
  check.eq(nbodies, s:clump_count(), dim .. "D data: every clump a molecule")
  check.errors(function() dem.read_lammps_data(data) end,
    "the Atoms section is for atom_style hybrid; grainlab reads atom_style sphere", dim .. "D data: our reader refuses it")
  if has_lmp() then
    local input = path("in" .. dim .. ".lmp")
    F.write(input, table.concat({
      "dimension " .. dim, "units si", "atom_style hybrid sphere molecular", "atom_modify map array",
      "boundary f f " .. (dim == 2 and "p" or "f"), "comm_modify vel yes",
      "read_data " .. data,
      "pair_style gran/hooke/history 1000 NULL 0 NULL 0.5 0", "pair_coeff * *",
      "group clumps molecule > 0", "neigh_modify exclude molecule/intra clumps",
      "fix bodies clumps rigid/small molecule", "group loose molecule == 0", "fix loose loose nve/sphere",
      dim == 2 and "fix flat all enforce2d" or "",
      "compute ts all temp/sphere", "thermo_modify temp ts", "timestep 1e-6", "run 10", "" }, "\n"))
    local h = io.popen("lmp -in '" .. input .. "' -log none 2>&1")
    local out = h:read("a")
    h:close()
    check.contains(out, string.format("%d rigid bodies with %d atoms", s:clump_count(), #rows - (function()
      local loose = 0
      for i = 1, p.count do if of[i] == 0 then loose = loose + 1 end end
      return loose
    end)()), dim .. "D data: LAMMPS makes every clump a rigid body")
    check.contains(out, "Loop time of", dim .. "D data: LAMMPS runs it")
    check.is_true(not (out:find("ERROR", 1, true) ~= nil), dim .. "D data: no LAMMPS error")
  else
    print("lmp not found (Debian: apt-get install lammps): LAMMPS's own reading is skipped")
  end
end
-- a clump of one sphere is no molecule in the data file (LAMMPS refuses one-particle bodies)
do
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } } }
  s:add_clump{ members = { { offset = { 0, 0 }, radius = 0.001 } }, position = { 0.005, 0.005 } }
  s:add_clump{ members = { { offset = { 0, 0 }, radius = 0.001 }, { offset = { 0.001, 0 }, radius = 0.001 } },
               position = { 0.005, 0.002 } }
  s:write_lammps_data(path("one.data"))
  local text = F.read(path("one.data"))
  local mols = {}
  for line in text:match("\nAtoms # hybrid\n\n(.-)\n\n"):gmatch("[^\n]+") do
    mols[#mols + 1] = tonumber(line:match("^%S+ %S+ %S+ %S+ %S+ %S+ %S+ (%S+)"))
  end
  check.eq(table.concat(mols, " "), "0 2 2", "one-sphere clump: mol 0; the dimer: its clump id")
end

-- ---- rendering: one colour per clump -------------------------------------------------------------
do
  local s = C.build_clumps(2)
  C.run(s, "velocity_verlet", 100)
  local img = render.image(s, { width = 200, color = "clump" })
  check.eq(select(1, img:size()), 200, "color = 'clump' draws")
  check.errors(function() render.image(s, { color = "clumps" }) end,
    "bad field 'color' in argument #2 to 'image' (one of 'grain', 'speed', 'rotation', 'material', 'clump' or an array of numbers expected, got 'clumps')",
    "colour name typo")
end

os.execute("rm -rf '" .. dir .. "'")
check.done()
