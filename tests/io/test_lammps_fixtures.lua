-- Packings made by LAMMPS itself (tests/io/pour3d.in, pour2d.in: a short bidisperse pour, then
-- write_data and a dump custom with LAMMPS's own masses) and by LIGGGHTS (tests/io/liggghts.in)
-- load into grainlab atom for atom: count,
-- box, and every atom's radius, mass, position, velocity and angular velocity against the dump.
local check = grainlab.check

-- The dump's single frame: box and rows by column name, in the dump's (id-sorted) order.
local function read_dump(path)
  local f = assert(io.open(path))
  local lines = {}
  for l in f:lines() do lines[#lines + 1] = l end
  f:close()
  local frame = { rows = {}, box = {} }
  local i = 1
  while i <= #lines do
    local l = lines[i]
    if l == "ITEM: NUMBER OF ATOMS" then frame.count = tonumber(lines[i + 1]); i = i + 1
    elseif l:match("^ITEM: BOX BOUNDS") then
      for a = 1, 3 do
        local lo, hi = lines[i + a]:match("^(%S+)%s+(%S+)$")
        frame.box[a] = { tonumber(lo), tonumber(hi) }
      end
      i = i + 3
    elseif l:match("^ITEM: ATOMS") then
      local cols = {}
      for c in l:sub(13):gmatch("%S+") do cols[#cols + 1] = c end
      for k = i + 1, i + frame.count do
        local row, c = {}, 0
        for v in lines[k]:gmatch("%S+") do c = c + 1; row[cols[c]] = tonumber(v) end
        frame.rows[#frame.rows + 1] = row
      end
      break
    end
    i = i + 1
  end
  return frame
end

local function compare(name, s, info, dim)
  local dump = read_dump(name .. ".dump")
  local p = s:particles()
  check.eq(p.count, dump.count, name .. ": atom count")
  check.eq(info.count, dump.count, name .. ": info.count")
  check.eq(info.atom_types, 2, name .. ": atom types")
  local lo, hi = s:info().box[1], s:info().box[2]
  for a = 1, dim do
    check.eq(lo[a], dump.box[a][1], name .. ": box lower " .. a)
    check.eq(hi[a], dump.box[a][2], name .. ": box upper " .. a)
  end
  local xs, vs = { "x", "y", "z" }, { "vx", "vy", "vz" }
  for i, r in ipairs(dump.rows) do
    local what = string.format("%s: atom %d", name, r.id)
    check.eq(info.ids[i], r.id, what .. " order (grainlab ids follow LAMMPS ids)")
    check.eq(info.types[i], r.type, what .. " type")
    check.eq(p.radius[i], r.radius, what .. " radius")
    -- LAMMPS's rmass = density 4/3 pi r^3 in 2D as in 3D; the same product in grainlab
    check.near(p.mass[i], r.mass, 2e-16, what .. " mass")
    for a = 1, dim do
      check.eq(p[xs[a]][i], r[xs[a]], what .. " " .. xs[a])
      check.eq(p[vs[a]][i], r[vs[a]], what .. " " .. vs[a])
    end
    -- a file without spin makes a scene without rotational state (no arrays: all 0)
    local function w(k) return p[k] and p[k][i] or 0 end
    if dim == 3 then
      check.eq(w("wx"), r.omegax, what .. " omegax")
      check.eq(w("wy"), r.omegay, what .. " omegay")
      check.eq(w("wz"), r.omegaz, what .. " omegaz")
    else
      check.eq(r.z, 0, what .. " z in the 2D file")
      check.eq(w("omega"), r.omegaz, what .. " omega")
    end
  end
  return dump
end

-- 3D, periodic in x (boundary p f f): some atoms carry image flags -1; positions are in the box.
local s3, info3 = dem.read_lammps_data("pour3d.data", { periodic = { true, false, false } })
check.eq(s3:info().dim, 3, "pour3d is 3D (z varies)")
check.contains(info3.title, "LAMMPS data file via write_data", "title line")
check.is_true(info3.velocities, "pour3d has velocities")
compare("pour3d", s3, info3, 3)
-- without periodic x the image flags are refused, naming the atom and the line
check.errors(function() dem.read_lammps_data("pour3d.data") end,
  "which is not periodic in this scene", "image flags need a periodic axis")

-- 2D (dimension 2: z = 0, zlo < 0 < zhi): recognised as 2D without being told.
local s2, info2 = dem.read_lammps_data("pour2d.data")
check.eq(s2:info().dim, 2, "pour2d is read as 2D")
compare("pour2d", s2, info2, 2)
-- two densities in the file, no materials given: one default material per type
check.eq(#info2.ids, 143, "pour2d atoms")

-- LIGGGHTS 3.8 (atom_style granular): "Atoms" without a style hint, numbers in %.16e
local sl, infol = dem.read_lammps_data("liggghts.data", { periodic = { true, true, false } })
check.contains(infol.title, "LIGGGHTS-PUBLIC 3.8.0", "LIGGGHTS title")
compare("liggghts", sl, infol, 3)

-- with materials: type 2 (density 1200 in the file) mapped to a 2500 material is refused, unless
-- density = "file" (a copy with 1200) or "material" (masses from 2500)
local q = grainlab.material{ density = 2650, young = 1e8, friction = 0.4 }
local g = grainlab.material{ density = 2500, young = 1e8, friction = 0.4 }
check.errors(function() dem.read_lammps_data("pour2d.data", { types = { [1] = q, [2] = g } }) end,
  "has density 1200 but type 2's material has density 2500", "strict density")
local sf = dem.read_lammps_data("pour2d.data", { types = { [1] = q, [2] = g }, density = "file" })
compare("pour2d", sf, select(2, dem.read_lammps_data("pour2d.data")), 2)
local sm, im = dem.read_lammps_data("pour2d.data", { types = { [1] = q, [2] = g }, density = "material" })
local pm = sm:particles()
for i = 1, pm.count do
  if im.types[i] == 2 then
    check.near(pm.mass[i], 2500 * 4 / 3 * math.pi * pm.radius[i] ^ 3, 1e-15, "density = 'material'")
    break
  end
end
check.done()
