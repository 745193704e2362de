-- Mutation fuzzing of the readers of files from elsewhere: DEM, MPM and DSMC checkpoints
-- (dem.load, mpm.load, dsmc.load) and LAMMPS data files (dem.read_lammps_data). Deterministic:
-- case k of seed s is a pure function of (s, k) and the seed files, so a failure is reproduced
-- by its number.
--
-- Seed files are written by the engines themselves (every optional checkpoint section: rolling
-- resistance, boundary conditions, clumps, inserters and outflows, shaped walls, DSMC identities; LAMMPS
-- files with image flags, velocities and a Masses section, in 2D and 3D). A case mutates one:
--   checkpoints: a flipped bit with the checksum recomputed, or without (refused); a cut at a
--     section boundary, inside a section or anywhere (refused); a section shortened or grown
--     with the sizes and checksum made consistent (refused); a section deleted, duplicated or
--     moved (refused); a count- or index-like integer inflated (2^31, 2^53 + 1, 2^63 - 1, -1,
--     10^8, n +- 1) or a step counter near 2^63; a double replaced by NaN, +-inf, +-1e308, 0;
--     a run of bytes zeroed;
--   LAMMPS data files: a cut at every kind of line boundary and inside a number (refused unless
--     what is left is a whole file); the atoms count inflated (10^8, 2^31, 2^63 - 1, n +- 1) or
--     the atom types count changed; a number replaced by +-1e308, NaN, inf, 2^31, a bad token;
--     a body line deleted or duplicated (refused); the Atoms, Velocities or Masses section
--     deleted; a flipped bit.
-- Each case is loaded; what is loaded runs 3 steps. A case fails when the reader accepts a file
-- that must be refused, refuses it without naming the file, hangs (the driver's watchdog), or
-- crashes (a sanitizer report ends the worker). M.explicit_worker runs named cases instead (the
-- test's, with the message each must give, FIFOs and devices among them).
--
-- Used by tests/io/test_reader_fuzz.lua (a few hundred cases) and, for a campaign,
--   grainlab tests/lua/lib/reader_fuzz.lua role=campaign n=5000 seed=1 [exe=build-asan/grainlab]
--            [limit=20 (s per case)] [log=cases.txt (every case's line)] [dir=... keep=1]
-- (run from the repository; the workers are `exe`, the sanitizer build's grainlab for instance).
local M = {}

local here = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
local F = dofile(here .. "ckpt_files.lua")
local C = dofile(here .. "ckpt_dem_case.lua")

-- ---- a deterministic stream (splitmix64; Lua integers wrap) ------------------------------------
local function stream(seed)
  local x = seed
  local r = {}
  function r.u64()
    x = x + -7046029254386353131 -- 0x9e3779b97f4a7c15
    local z = x
    z = (z ~ (z >> 30)) * -4658895280553007687 -- 0xbf58476d1ce4e5b9
    z = (z ~ (z >> 27)) * -7723592293110705685 -- 0x94d049bb133111eb
    return z ~ (z >> 31)
  end
  function r.int(n) return (r.u64() >> 1) % n + 1 end -- 1..n
  function r.pick(t) return t[r.int(#t)] end
  return r
end
M.stream = stream

-- ---- checkpoints as sections ------------------------------------------------------------------
local HEADER, TRAILER = 64, 24

-- {header, sections = {{tag, flags, payload, at (offset of its header, 0-based)}}}
function M.ckpt_parse(s)
  local t = { header = s:sub(1, HEADER), sections = {} }
  local at, stop = HEADER, #s - TRAILER
  while at < stop do
    local tag = s:sub(at + 1, at + 16):gsub("%z+$", "")
    local flags = string.unpack("<I4", s, at + 17)
    local size = string.unpack("<I8", s, at + 25)
    local pad = (8 - size % 8) % 8
    t.sections[#t.sections + 1] = { tag = tag, flags = flags, payload = s:sub(at + 33, at + 32 + size),
                                    at = at }
    at = at + 32 + size + pad
  end
  return t
end

-- The file of t's sections, padded, with a trailer whose size and checksum are right.
function M.ckpt_build(t)
  local out = { t.header }
  for _, sec in ipairs(t.sections) do
    local tag = sec.tag .. string.rep("\0", 16 - #sec.tag)
    out[#out + 1] = tag .. string.pack("<I4I4I8", sec.flags, 0, #sec.payload) .. sec.payload ..
                    string.rep("\0", (8 - #sec.payload % 8) % 8)
  end
  local body = table.concat(out) .. "GRAINEND"
  return F.reseal(body .. string.pack("<I8", #body + 16) .. string.rep("\0", 8))
end

local function copy_sections(t)
  local c = { header = t.header, sections = {} }
  for k, s in ipairs(t.sections) do
    c.sections[k] = { tag = s.tag, flags = s.flags, payload = s.payload, at = s.at }
  end
  return c
end

-- ---- seed files -------------------------------------------------------------------------------
local function write_text(path, text) F.write(path, text) end

local function lammps_info(text)
  -- byte offsets: end of the last Atoms line, start of the Velocities header (or the end)
  local info = { atoms_end = nil, tail_start = #text }
  local pos, section, left = 1, nil, 0
  local n = tonumber(text:match("\n%s*(%d+)%s+atoms")) or 0
  local types = tonumber(text:match("\n%s*(%d+)%s+atom types")) or 0
  for line, nl in text:gmatch("([^\n]*)()\n?") do
    if nl > #text + 1 then break end
    local word = line:match("^%s*(%a[%a ]-)%s*$") or line:match("^%s*(%a+)%s*#")
    if word == "Atoms" then section, left = "Atoms", n
    elseif word == "Velocities" then
      section, left = "Velocities", n
      if info.atoms_end then info.tail_start = pos - 1 end
    elseif word == "Masses" then section, left = "Masses", types
    elseif line:match("%S") and section and left > 0 then
      left = left - 1
      if left == 0 and section == "Atoms" then info.atoms_end = nl end
    end
    pos = nl + 1
    if pos > #text then break end
  end
  info.n = n
  return info
end

-- Writes the seed files into dir; returns the list of seeds {name, kind, path, bytes, ...}.
function M.make_seeds(dir)
  grainlab.threads(1)
  local seeds = {}
  local function ckpt(name, kind, scene, steps, run)
    local path = dir .. "/seed_" .. name .. ".ckpt"
    scene:run(run or { steps = steps })
    scene:save(path)
    local bytes = F.read(path)
    seeds[#seeds + 1] = { name = name, kind = kind, path = path, bytes = bytes,
                          parsed = M.ckpt_parse(bytes) }
  end
  ckpt("dem2", "dem", C.build(2), 40)
  ckpt("dem3_rolling", "dem", C.build(3, "epsd"), 40)
  ckpt("dem2_boundary", "dem", C.build_boundary(), 40)
  ckpt("dem3_clumps", "dem", C.build_clumps(3), 40) -- section "clumps"
  do -- inserters and outflows (section "flow", particle tags)
    local mat = grainlab.material{ density = 2500, young = 1e7, poisson = 0.3, friction = 0.4 }
    local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.05, 0.1 } }, gravity = { 0, -9.81 } }
    s:contact{ damping = "viscous", tangential = "spring" }
    s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
    s:inserter{ box = { { 0, 0.07 }, { 0.05, 0.1 } }, rate = 3000, radius = { 0.0015, 0.0025 },
                velocity = { 0, -2 }, material = mat, seed = 3, every = 10 }
    s:outflow{ box = { { 0.03, 0 }, { 0.05, 0.02 } } }
    ckpt("dem2_flow", "dem", s, nil, { steps = 400, dt = 5e-6 })
  end
  do -- walls beyond planes (section "wall_shapes")
    local mat = grainlab.material{ density = 1000, young = 2e6, poisson = 0.3, friction = 0.5 }
    local s = dem.scene{ dim = 2, box = { { -0.06, -0.06 }, { 0.06, 0.06 } }, gravity = { 0, -9.81 } }
    s:contact{ tangential = "spring" }
    s:add_cylinder{ center = { 0, 0 }, radius = 0.05, material = mat, omega = 2 }
    s:add_polyline{ points = { { -0.03, -0.02 }, { 0.03, -0.02 } }, velocity = { 0, 0.01 } }
    for i = 0, 5 do
      for j = 0, 3 do
        s:add_disk{ pos = { -0.025 + 0.01 * i, -0.01 + 0.01 * j }, radius = 0.004, material = mat }
      end
    end
    ckpt("dem2_shapes", "dem", s, 30)
  end
  do
    local elastic = mpm.material{ density = 3000, shear = 2.5e6, bulk = 10e6 }
    local plastic = mpm.material{ model = "vonmises", density = 2500, shear = 2e6, bulk = 8e6,
                                  yield = 4e4, hardening = 1e5 }
    local m = mpm.scene{ cells = { 12, 10 }, size = { 1.2, 1 }, gravity = { 0, -9.8 },
                         walls = { bottom = { kind = "friction", mu = 0.5 }, left = "slip" } }
    m:add_disk{ center = { 0.35, 0.25 }, radius = 0.2, material = elastic, velocity = { 0.5, 0 } }
    m:add_disk{ center = { 0.8, 0.25 }, radius = 0.2, material = plastic }
    local top = m:add_rect{ lo = { 0.2, 0.7 }, hi = { 0.6, 0.8 }, material = elastic }
    m:prescribe(top, { 0.1, 0 })
    m:plane{ point = { 1.2, 0.2 }, normal = { -0.5, 1 }, kind = "friction", mu = 0.3 }
    m:contact{ model = "friction", mu = 0.3 }
    ckpt("mpm", "mpm", m, 3)
  end
  do
    local s = dsmc.scene{ dim = 2, size = { 0.1, 0.15 }, cells = { 10, 15 }, radius = 1e-3,
                          restitution = 0.9, gravity = { 0, -9.81 }, periodic = { true, false },
                          seed = 11 }
    s:fill{ n = 300, temperature = 1e-4, seed = 5 }
    s:wall{ side = "top", kind = "diffuse", temperature = 2e-4 }
    ckpt("dsmc2", "dsmc", s, nil, { steps = 5, warn = false })
    local g = dsmc.scene{ dim = 3, size = { 0.04, 0.04, 0.06 }, cells = { 4, 4, 6 }, radius = 1e-3,
                          restitution = 0.7, gravity = { 0, 0, -9.81 }, seed = 23,
                          periodic = { true, false, false } }
    g:fill{ n = 200, speed = 1, seed = 9 }
    g:wall{ side = "bottom", restitution = 0.9, amplitude = 1e-3, frequency = 50 }
    ckpt("dsmc3", "dsmc", g, nil, { steps = 5, warn = false })
  end
  -- LAMMPS data files
  local function lammps(name, scene, opts, edit)
    local path = dir .. "/seed_" .. name .. ".data"
    scene:write_lammps_data(path)
    local text = F.read(path)
    if edit then text = edit(text) end
    write_text(path, text)
    seeds[#seeds + 1] = { name = name, kind = "lammps", path = path, bytes = text, opts = opts,
                          info = lammps_info(text) }
  end
  do
    local mat = grainlab.material{ density = 1000, young = 1e7, poisson = 0.3, friction = 0.3 }
    local s = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 0.1, 0.1, 0.1 } }, gravity = { 0, 0, -9.81 },
                         periodic = { true, true, false } }
    local k = 0
    for i = 0, 5 do
      for j = 0, 5 do
        for l = 0, 2 do
          k = k + 1
          s:add_sphere{ pos = { 0.008 + 0.016 * i, 0.008 + 0.016 * j, 0.01 + 0.02 * l },
                        radius = 0.006, material = mat, vel = { 0.5, -0.3, 0.1 * (k % 3) },
                        omega = { 1, 2, 3 } }
        end
      end
    end
    s:run{ steps = 200 } -- grains cross the periodic sides: image flags
    -- a Masses section before Atoms, as LAMMPS's write_data puts it
    lammps("lammps3", s, { periodic = { true, true, false } }, function(t)
      return (t:gsub("\nAtoms # sphere\n", "\nMasses\n\n1 0.0009\n\nAtoms # sphere\n", 1))
    end)
    local d = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.05 } }, gravity = { 0, -9.81 } }
    for i = 0, 9 do
      for j = 0, 3 do
        d:add_disk{ pos = { 0.005 + 0.01 * i, 0.005 + 0.01 * j }, radius = 0.004, material = mat,
                    vel = { 0.1 * (i % 3), 0 }, omega = 0.5 * j }
      end
    end
    d:run{ steps = 50 }
    lammps("lammps2", d, {})
  end
  return seeds
end

-- Reads the seeds written by make_seeds (a worker does not make them again).
function M.load_seeds(dir)
  local list = {}
  for _, name in ipairs{ "dem2", "dem3_rolling", "dem2_boundary", "dem3_clumps", "dem2_flow",
                         "dem2_shapes", "mpm", "dsmc2", "dsmc3" } do
    local path = dir .. "/seed_" .. name .. ".ckpt"
    local bytes = F.read(path)
    list[#list + 1] = { name = name, kind = name:match("^%l+"), path = path,
                        bytes = bytes, parsed = M.ckpt_parse(bytes) }
  end
  list[#list + 1] = { name = "lammps3", kind = "lammps", opts = { periodic = { true, true, false } } }
  list[#list + 1] = { name = "lammps2", kind = "lammps", opts = {} }
  for k = #list - 1, #list do
    local s = list[k]
    s.path = dir .. "/seed_" .. s.name .. ".data"
    s.bytes = F.read(s.path)
    s.info = lammps_info(s.bytes)
  end
  return list
end

-- ---- mutations --------------------------------------------------------------------------------
local BIG_INTS = { 1 << 31, (1 << 31) - 1, 1 << 32, (1 << 53) + 1, 1 << 62, math.maxinteger,
                   math.maxinteger - 1, math.maxinteger - 5, -1, math.mininteger, 100000000, 0 }
local BAD_DOUBLES = { 0 / 0, 1 / 0, -1 / 0, 1e308, -1e308, 0.0, -0.0, 1e-308, -1.0, 1e30 }

-- Offsets (0-based, in the payload) where 8 bytes read as a small positive integer: a count, an
-- index or a counter (or a u32 followed by zeros).
local function int_spots(p)
  local spots = {}
  for i = 1, #p - 7 do
    local v = string.unpack("<i8", p, i)
    if v > 0 and v < (1 << 32) then spots[#spots + 1] = i end
  end
  return spots
end

local function double_spots(p)
  local spots = {}
  for i = 1, #p - 7, 4 do
    local v = string.unpack("<d", p, i)
    if v == v and v ~= 0 and math.abs(v) > 1e-12 and math.abs(v) < 1e12 then spots[#spots + 1] = i end
  end
  return spots
end

local function put(p, i, bytes) return p:sub(1, i - 1) .. bytes .. p:sub(i + #bytes) end

local function mutate_ckpt(seed, r)
  local t = copy_sections(seed.parsed)
  local secs = t.sections
  local classes = { "flip", "flip", "flip_raw", "cut", "cut_section", "grow_section", "drop", "dup",
                    "move", "int", "int", "int", "steps", "double", "double", "zero" }
  local class = r.pick(classes)
  local k = r.int(#secs)
  local sec = secs[k]
  local c = { class = class, must_refuse = false }
  if class == "flip" then
    local pos = r.int(math.max(#sec.payload, 1))
    if #sec.payload == 0 then c.desc = "empty section" ; return c, M.ckpt_build(t) end
    local b = sec.payload:byte(pos) ~ (1 << (r.int(8) - 1))
    sec.payload = put(sec.payload, pos, string.char(b))
    c.desc = string.format("bit flipped in section '%s' at byte %d", sec.tag, pos - 1)
    return c, M.ckpt_build(t)
  elseif class == "flip_raw" then
    local s = seed.bytes
    local pos = r.int(#s)
    c.must_refuse = true
    c.desc = string.format("bit flipped at byte %d, checksum not recomputed", pos - 1)
    return c, put(s, pos, string.char(s:byte(pos) ~ (1 << (r.int(8) - 1))))
  elseif class == "cut" then
    local s = seed.bytes
    local where = r.int(4)
    local at
    if where == 1 then at = sec.at -- a section boundary
    elseif where == 2 then at = sec.at + 32 + r.int(math.max(#sec.payload, 1)) - 1 -- inside
    elseif where == 3 then at = #s - r.int(24) -- in the trailer
    else at = r.int(#s) - 1 end
    c.must_refuse = true
    c.desc = string.format("cut to %d of %d bytes", at, #s)
    return c, s:sub(1, at)
  elseif class == "cut_section" then
    local by = math.min(#sec.payload, r.pick{ 1, 4, 8, 8, 16, #sec.payload // 2, #sec.payload })
    if by == 0 then by = 0 end
    sec.payload = sec.payload:sub(1, #sec.payload - by)
    c.must_refuse = by > 0
    c.desc = string.format("section '%s' cut by %d bytes (sizes and checksum consistent)", sec.tag, by)
    return c, M.ckpt_build(t)
  elseif class == "grow_section" then
    sec.payload = sec.payload .. string.rep("\0", r.pick{ 1, 8, 16 })
    c.must_refuse = true
    c.desc = string.format("section '%s' grown by zeros", sec.tag)
    return c, M.ckpt_build(t)
  elseif class == "drop" then
    table.remove(secs, k)
    c.must_refuse = sec.tag ~= "contents" -- without it, what is left is a whole file
    c.desc = string.format("section '%s' deleted", sec.tag)
    return c, M.ckpt_build(t)
  elseif class == "dup" then
    table.insert(secs, k, { tag = sec.tag, flags = sec.flags, payload = sec.payload })
    c.must_refuse = true
    c.desc = string.format("section '%s' duplicated", sec.tag)
    return c, M.ckpt_build(t)
  elseif class == "move" then
    local j = r.int(#secs)
    if secs[j].tag == sec.tag then j = (j % #secs) + 1 end
    secs[k], secs[j] = secs[j], secs[k]
    c.must_refuse = secs[k].tag ~= secs[j].tag
    c.desc = string.format("sections '%s' and '%s' swapped", sec.tag, secs[k].tag)
    return c, M.ckpt_build(t)
  elseif class == "int" or class == "steps" then
    local spots = int_spots(sec.payload)
    if #spots == 0 then c.desc = "no integer in '" .. sec.tag .. "'"; return c, M.ckpt_build(t) end
    local pos = r.pick(spots)
    local old = string.unpack("<i8", sec.payload, pos)
    local v = class == "steps" and r.pick{ math.maxinteger, math.maxinteger - 1, math.maxinteger - 2,
                                           (1 << 62) + 1, 1 << 63 } or
              r.pick{ r.pick(BIG_INTS), old + 1, old - 1, old * 2, old + (1 << 32) }
    sec.payload = put(sec.payload, pos, string.pack("<i8", v))
    c.desc = string.format("integer %d at byte %d of '%s' made %d", old, pos - 1, sec.tag, v)
    return c, M.ckpt_build(t)
  elseif class == "double" then
    local spots = double_spots(sec.payload)
    if #spots == 0 then c.desc = "no double in '" .. sec.tag .. "'"; return c, M.ckpt_build(t) end
    local pos = r.pick(spots)
    local old = string.unpack("<d", sec.payload, pos)
    local v = r.pick(BAD_DOUBLES)
    sec.payload = put(sec.payload, pos, string.pack("<d", v))
    c.desc = string.format("double %.17g at byte %d of '%s' made %g", old, pos - 1, sec.tag, v)
    return c, M.ckpt_build(t)
  else -- zero
    if #sec.payload == 0 then c.desc = "empty section"; return c, M.ckpt_build(t) end
    local pos = r.int(#sec.payload)
    local len = math.min(r.pick{ 8, 16, 64 }, #sec.payload - pos + 1)
    sec.payload = put(sec.payload, pos, string.rep("\0", len))
    c.desc = string.format("%d bytes zeroed at byte %d of '%s'", len, pos - 1, sec.tag)
    return c, M.ckpt_build(t)
  end
end

local function lines_of(text)
  local lines = {}
  for l in (text .. (text:sub(-1) == "\n" and "" or "\n")):gmatch("([^\n]*)\n") do lines[#lines + 1] = l end
  return lines
end

local BAD_TOKENS = { "1e308", "-1e308", "nan", "inf", "-inf", "1e-320", "2147483648", "-2147483649",
                     "9223372036854775808", "0", "-1", "1e", "0x10", "1.5", "", "1e400" }

local function mutate_lammps(seed, r)
  local text = seed.bytes
  local info = seed.info
  local classes = { "cut_line", "cut_line", "cut_mid", "cut_mid", "count", "count", "types", "token",
                    "token", "token", "drop_line", "dup_line", "drop_section", "flip" }
  local class = r.pick(classes)
  local c = { class = class, must_refuse = false }
  local function whole(at) -- what is left is a complete file
    return at == #text or (info.atoms_end and at >= info.atoms_end and at <= info.tail_start)
  end
  local lines = lines_of(text)
  if class == "cut_line" or class == "cut_mid" then
    local at
    if class == "cut_line" then
      local k = r.int(#lines)
      at = 0
      for i = 1, k do at = at + #lines[i] + 1 end
      at = at - r.pick{ 0, 0, 1 } -- with or without the newline
    else
      at = r.int(#text) - 1
    end
    c.must_refuse = not whole(at)
    c.desc = string.format("cut to %d of %d bytes", at, #text)
    return c, text:sub(1, at)
  elseif class == "count" then
    local n = info.n
    local v = r.pick{ "100000000", "2147483648", "9223372036854775807", "18446744073709551616",
                      tostring(n + 1), tostring(n - 1), "0", "-1", tostring(n * 1000) }
    c.must_refuse = v ~= tostring(n)
    c.desc = "atoms count made " .. v
    return c, (text:gsub("\n%s*%d+ atoms\n", "\n" .. v .. " atoms\n", 1))
  elseif class == "types" then
    local v = r.pick{ "0", "-1", "1000000", "1000001", "2147483648", "2", "7" }
    c.desc = "atom types made " .. v
    return c, (text:gsub("\n%s*%d+ atom types\n", "\n" .. v .. " atom types\n", 1))
  elseif class == "token" then
    local cand = {}
    for i, l in ipairs(lines) do
      if l:match("^%s*[%d%-]") and i > 3 then cand[#cand + 1] = i end
    end
    local i = r.pick(cand)
    local toks = {}
    for w in lines[i]:gmatch("%S+") do toks[#toks + 1] = w end
    local j = r.int(#toks)
    local old = toks[j]
    toks[j] = r.pick(BAD_TOKENS)
    lines[i] = table.concat(toks, " ")
    c.desc = string.format("line %d: '%s' made '%s'", i, old, toks[j])
    return c, table.concat(lines, "\n") .. "\n"
  elseif class == "drop_line" or class == "dup_line" then
    local cand = {}
    for i, l in ipairs(lines) do
      if l:match("^%s*%d+%s+%S+%s+%S+") and not l:match("atom") and not l:match("lo ") then
        cand[#cand + 1] = i
      end
    end
    local i = r.pick(cand)
    if class == "drop_line" then table.remove(lines, i) else table.insert(lines, i, lines[i]) end
    c.must_refuse = true
    c.desc = string.format("body line %d %s", i, class == "drop_line" and "deleted" or "duplicated")
    return c, table.concat(lines, "\n") .. "\n"
  elseif class == "drop_section" then
    local name = r.pick{ "Atoms", "Velocities", "Masses" }
    local out, skipping = {}, false
    for _, l in ipairs(lines) do
      local head = l:match("^(%a+)")
      if head then skipping = head == name end
      if not skipping then out[#out + 1] = l end
    end
    c.must_refuse = name == "Atoms" and info.n > 0
    c.desc = "section " .. name .. " deleted"
    return c, table.concat(out, "\n") .. "\n"
  else -- flip
    local pos = r.int(#text)
    c.desc = string.format("bit flipped at byte %d", pos - 1)
    return c, put(text, pos, string.char(text:byte(pos) ~ (1 << (r.int(8) - 1))))
  end
end

-- Case k: {seed, class, desc, must_refuse} and the file's bytes.
function M.case(seeds, seed, k)
  local r = stream(seed * 1000003 + k)
  local kind = r.pick{ "dem", "mpm", "dsmc", "lammps" } -- each reader a quarter of the cases
  local of = {}
  for _, x in ipairs(seeds) do if x.kind == kind then of[#of + 1] = x end end
  local s = r.pick(of)
  local c, bytes
  if s.kind == "lammps" then c, bytes = mutate_lammps(s, r) else c, bytes = mutate_ckpt(s, r) end
  c.seed = s
  return c, bytes
end

-- ---- running a case ---------------------------------------------------------------------------
local LOAD = { dem = dem and dem.load, mpm = mpm and mpm.load, dsmc = dsmc and dsmc.load }

-- Loads path as seed's kind; runs what loaded (after calling loaded(), if given). Returns the
-- outcome ("refused", "ran", "run error") and the message.
function M.try(seed, path, loaded)
  local ok, scene = pcall(function()
    if seed.kind == "lammps" then
      local opts = {}
      for k, v in pairs(seed.opts) do opts[k] = v end
      return (dem.read_lammps_data(path, opts))
    end
    return LOAD[seed.kind](path)
  end)
  if not ok then return "refused", tostring(scene) end
  if loaded then loaded() end
  local rok, msg = pcall(function()
    if seed.kind == "dsmc" then scene:run{ steps = 3, warn = false } else scene:run{ steps = 3 } end
  end)
  if not rok then return "run error", tostring(msg) end
  return "ran", ""
end

-- A refusal names the file (its path, or its base name), and for a data file the line.
function M.names_file(msg, path)
  local base = path:match("[^/]+$")
  return msg:find(path, 1, true) ~= nil or msg:find(base, 1, true) ~= nil
end

-- ---- worker: cases from..to, one line each ----------------------------------------------------
-- "begin K" before case K, "loaded K" once the file loaded, then
-- "case K SEED CLASS OUTCOME VERDICT | desc | message".
function M.worker(p)
  local seeds = M.load_seeds(p.dir)
  local path = p.dir .. "/case.bin"
  local out = io.stdout
  for k = p.from, p.to do
    out:write("begin ", k, "\n")
    out:flush()
    local c, bytes = M.case(seeds, p.seed, k)
    local file = path .. (c.seed.kind == "lammps" and ".data" or ".ckpt")
    F.write(file, bytes)
    local outcome, msg = M.try(c.seed, file, function()
      out:write("loaded ", k, "\n")
      out:flush()
    end)
    local verdict = "ok"
    if outcome == "refused" and not M.names_file(msg, file) then verdict = "FAIL(unnamed)" end
    if outcome ~= "refused" and c.must_refuse then verdict = "FAIL(accepted)" end
    msg = msg:gsub("\n", " ")
    out:write(string.format("case %d %s %s %s %s | %s | %s\n", k, c.seed.name, c.class,
                            outcome:gsub(" ", "_"), verdict, c.desc, msg))
    out:flush()
    os.remove(file)
  end
  out:write("end\n")
end

-- Named cases instead of generated ones: list is a file returning {{name =, kind =, opts =,
-- path =, expect =}, ...}; a case passes when the file is refused with a message that names it
-- and contains expect.
function M.explicit_worker(p)
  local list = dofile(p.list)
  local out = io.stdout
  for k = p.from, math.min(p.to, #list) do
    local c = list[k]
    out:write("begin ", k, "\n")
    out:flush()
    local outcome, msg = M.try({ kind = c.kind, opts = c.opts or {} }, c.path, function()
      out:write("loaded ", k, "\n")
      out:flush()
    end)
    local verdict = "ok"
    if outcome ~= "refused" then verdict = "FAIL(accepted)"
    elseif not M.names_file(msg, c.path) then verdict = "FAIL(unnamed)"
    elseif not msg:find(c.expect, 1, true) then verdict = "FAIL(message)" end
    out:write(string.format("case %d %s %s %s %s | %s | %s\n", k, c.kind, c.name:gsub("%s", "_"),
                            outcome:gsub(" ", "_"), verdict, c.expect, (msg:gsub("\n", " "))))
    out:flush()
  end
  out:write("end\n")
end

-- ---- driver: workers under a watchdog ---------------------------------------------------------
local function sh_quote(s) return "'" .. s:gsub("'", "'\\''") .. "'" end

local function sleep(s) os.execute("sleep " .. s) end

-- Runs cases first..last in worker processes of exe; a case that runs longer than limit seconds
-- is killed (by its process id) and counted a hang, of the reader or, once loaded, of the run;
-- a worker that dies (a sanitizer report) counts its case a crash. Returns {cases, refused, ran,
-- run_error, failures = {lines}, run_hangs = {lines}}.
function M.drive(p)
  local exe, dir, limit = p.exe, p.dir, p.limit or 20
  local script = here .. "reader_fuzz.lua"
  local res = { cases = 0, refused = 0, ran = 0, run_error = 0, failures = {}, run_hangs = {},
                by_class = {} }
  local k = p.first
  while k <= p.last do
    local out, err, pidf = dir .. "/worker.out", dir .. "/worker.err", dir .. "/worker.pid"
    os.remove(out); os.remove(pidf)
    local cmd = string.format("%s -q %s role=%s dir=%s seed=%d from=%d to=%d%s", sh_quote(exe),
                              sh_quote(script), p.role or "worker", sh_quote(dir), p.seed or 0, k,
                              p.last, p.list and (" list=" .. sh_quote(p.list)) or "")
    os.execute(string.format("sh -c %s >/dev/null 2>&1 &", sh_quote(string.format(
      "%s >%s 2>%s & echo $! >%s; wait $!; echo \"exit $?\" >>%s", cmd, sh_quote(out), sh_quote(err),
      sh_quote(pidf), sh_quote(out)))))
    local current, since, seen, finished, loaded = nil, os.time(), 0, false, false
    while not finished do
      sleep(p.poll or 0.05)
      local f = io.open(out, "r")
      local text = f and f:read("a") or ""
      if f then f:close() end
      local lines = {} -- whole lines only: the worker may be writing the last one
      for l in text:gmatch("([^\n]*)\n") do lines[#lines + 1] = l end
      for i = seen + 1, #lines do
        local l = lines[i]
        local b = l:match("^begin (%d+)$")
        if b then current, since, loaded = tonumber(b), os.time(), false end
        if l:match("^loaded %d+$") then loaded = true end
        local ck, seedname, class, outcome, verdict = l:match("^case (%d+) (%S+) (%S+) (%S+) (%S+)")
        if ck then
          if p.log then p.log:write(l, "\n") end
          res.cases = res.cases + 1
          local key = outcome:gsub("-", "_")
          res[key] = (res[key] or 0) + 1
          local bc = res.by_class[seedname:match("^%a+") .. "/" .. class] or { 0, 0 }
          bc[1] = bc[1] + 1
          if outcome == "refused" then bc[2] = bc[2] + 1 end
          res.by_class[seedname:match("^%a+") .. "/" .. class] = bc
          if verdict ~= "ok" then res.failures[#res.failures + 1] = l end
          current = nil
          k = tonumber(ck) + 1
        end
        local code = l:match("^exit (%d+)$")
        if code then
          finished = true
          if current then -- died inside a case
            local e = io.open(err, "r")
            local etext = e and e:read("a") or ""
            if e then e:close() end
            local why = etext:match("(SUMMARY: [^\n]*)") or etext:match("(runtime error: [^\n]*)") or
                        etext:sub(1, 300)
            res.cases = res.cases + 1
            res.failures[#res.failures + 1] = string.format("case %d CRASH %s (exit %s): %s", current,
                                                            loaded and "in the run" or "in the reader",
                                                            code, (why:gsub("\n", " ")))
            k = current + 1
          end
        end
      end
      seen = #lines
      if not finished and current and os.time() - since > limit then
        local pf = io.open(pidf, "r")
        local pid = pf and pf:read("n")
        if pf then pf:close() end
        if pid then os.execute("kill -9 " .. math.tointeger(pid) .. " 2>/dev/null") end
        res.cases = res.cases + 1
        local list = loaded and res.run_hangs or res.failures
        list[#list + 1] = string.format("case %d HANG %s (more than %d s)", current,
                                        loaded and "of the run after a load" or "of the reader", limit)
        k = current + 1
        -- wait for the exit line, then start again after the case
        for _ = 1, 200 do
          sleep(0.05)
          local f2 = io.open(out, "r")
          local t2 = f2 and f2:read("a") or ""
          if f2 then f2:close() end
          if t2:match("\nexit %d+\n?$") then break end
        end
        finished = true
      end
    end
  end
  return res
end

function M.main(p)
  if p.role == "worker" then
    M.worker{ dir = p.dir, seed = math.tointeger(p.seed), from = math.tointeger(p.from),
              to = math.tointeger(p.to) }
  elseif p.role == "explicit" then
    M.explicit_worker{ list = p.list, from = math.tointeger(p.from), to = math.tointeger(p.to) }
  elseif p.role == "seeds" then
    M.make_seeds(p.dir)
  elseif p.role == "campaign" then
    local dir = p.dir or os.tmpname()
    os.remove(dir)
    assert(os.execute("mkdir -p " .. sh_quote(dir)))
    M.make_seeds(dir)
    local exe = p.exe
    if not exe then
      for i = -1, -10, -1 do if arg[i] then exe = arg[i] else break end end
    end
    local n, seed = math.tointeger(p.n or 2000), math.tointeger(p.seed or 1)
    local log = p.log and assert(io.open(p.log, "w"))
    local res = M.drive{ exe = exe, dir = dir, seed = seed, first = 1, last = n,
                         limit = math.tointeger(p.limit or 20), log = log }
    if log then log:close() end
    print(string.format("reader fuzz: seed %d, %d cases: %d refused, %d ran, %d run errors, %d failures, " ..
                        "%d runs hung after a load", seed, res.cases, res.refused, res.ran or 0,
                        res.run_error or 0, #res.failures, #res.run_hangs))
    local keys = {}
    for key in pairs(res.by_class) do keys[#keys + 1] = key end
    table.sort(keys)
    for _, key in ipairs(keys) do
      print(string.format("  %-24s %5d cases, %5d refused", key, res.by_class[key][1], res.by_class[key][2]))
    end
    for _, l in ipairs(res.failures) do print(l) end
    for _, l in ipairs(res.run_hangs) do print(l) end
    if not p.keep then os.execute("rm -rf " .. sh_quote(dir)) end
    if #res.failures > 0 then os.exit(1) end
  end
end

if params and params.role then M.main(params) end
return M
