-- The scenes of tests/cli/isa_same_bits.sh: short runs of the three engines whose final states are
-- written as hex floats (%a) to `out`, one block per scene, so that two builds (the AVX2 clones
-- of src/core/clones.h and the baseline) and two thread counts can be compared byte for byte.
--   grainlab isa_bits_scenes.lua threads=N out=FILE
-- MPM: frictional contact with three option sets (those of test_mpm_contact_paths.lua: MUSL with
-- B-splines, strain cap, separation and conserve; USF with a friction plane and own normals; USL
-- with linear normals and PIC) and one no-slip MUSL scene. DEM: an imploding cluster of 5,184
-- disks (Hertz, Brilliantov, Cundall-Strack spring, rolling resistance, gravity in a closed box:
-- the parallel, vectorised pair kernel) and of 343 spheres. DSMC: 20,000 inelastic disks.
grainlab.threads(math.tointeger(params.threads) or 1)
local out = assert(io.open(assert(params.out, "out= is required"), "w"))

local function dump(name, cols)
  out:write("# ", name, "\n")
  for i = 1, #cols[1] do
    local row = {}
    for k = 1, #cols do row[k] = string.format("%a", cols[k][i]) end
    out:write(table.concat(row, " "), "\n")
  end
end

-- MPM
local mat = mpm.material{ model = "vonmises", density = 3000, shear = 2.5e6, bulk = 10e6, yield = 2e4 }
local cases = {
  { name = "mpm musl bspline cap separation conserve", update = "musl", shape = "bspline",
    contact = { model = "friction", mu = 0.4, strain_cap = 0.05, separation = 0.2, conserve = true } },
  { name = "mpm usf plane own normals", update = "usf", plane = true, wall_gap = 0.5,
    contact = { model = "friction", mu = 0.4, normals = "own", conserve = true } },
  { name = "mpm usl linear normals pic", update = "usl", pic = 0.3,
    contact = { model = "friction", mu = 0.4, normals = "linear" } },
  { name = "mpm musl noslip", update = "musl", contact = { model = "noslip" } },
}
for _, case in ipairs(cases) do
  local m = mpm.scene{ cells = { 60, 60 }, size = { 6, 6 }, gravity = { 0.5, -9.8 }, periodic = { false, true },
                       update = case.update, shape = case.shape, pic = case.pic, wall_gap = case.wall_gap,
                       walls = { left = "noslip", right = { kind = "friction", mu = 0.3, velocity = { 0, 0.2 } } } }
  local ids = {}
  for k = 0, 7 do
    ids[k] = m:add_disk{ center = { 1.4 + 1.3 * (k % 4), 1.5 + 1.25 * (k // 4) }, radius = 0.62, material = mat,
                         points_per_cell = 3,
                         velocity = { (k % 2 == 0) and 1 or -1, (k // 4 == 0) and 0.5 or -0.5 } }
  end
  m:prescribe(ids[5], { -0.5, -0.5 })
  if case.plane then m:plane{ point = { 5.95, 0 }, normal = { 1, 0.2 }, kind = "friction", mu = 0.4 } end
  m:contact(case.contact)
  m:run{ steps = 25, cfl = 0.3, progress = false }
  local p = m:points()
  dump(case.name, { p.x, p.y, p.vx, p.vy, p.sxx })
end

-- DEM: side^dim particles on a jittered lattice around the centre of a 0.4 m box, moving inwards
local dmat = grainlab.material{ density = 2650, young = 1e8, poisson = 0.3, friction = 0.3,
                                restitution = 0.6 }
for _, dim in ipairs{ 2, 3 } do
  local lo, hi, g = {}, {}, {}
  for d = 1, dim do lo[d], hi[d], g[d] = 0, 0.4, 0 end
  g[2] = -9.81
  local s = dem.scene{ dim = dim, box = { lo, hi }, gravity = g }
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.6, impact_velocity = 1,
             tangential = "spring", rolling_resistance = dim == 2 and "epsd" or nil,
             rolling_friction = dim == 2 and 0.05 or nil }
  local rng = grainlab.rng{ seed = 7 }
  local side, a = dim == 2 and 72 or 7, 1.9e-3
  local idx = {}
  for d = 1, dim do idx[d] = 0 end
  for _ = 1, side ^ dim do
    local pos, vel = {}, {}
    for d = 1, dim do
      pos[d] = 0.2 + (idx[d] - side / 2) * a + rng:uniform(-1e-4, 1e-4)
      vel[d] = -(pos[d] - 0.2) * 100 + rng:normal(0, 0.1)
    end
    local add = dim == 2 and s.add_disk or s.add_sphere
    add(s, { pos = pos, radius = rng:uniform(0.8e-3, 1e-3), material = dmat, vel = vel })
    for d = 1, dim do -- odometer
      idx[d] = idx[d] + 1
      if idx[d] < side then break end
      idx[d] = 0
    end
  end
  s:run{ steps = 60, dt = 2e-7, progress = false }
  local p = s:particles()
  local cols = dim == 2 and { p.x, p.y, p.vx, p.vy, p.fx, p.fy } or { p.x, p.y, p.z, p.vx, p.vy, p.vz }
  dump("dem " .. dim .. "D", cols)
end

-- DSMC
local n, R = 20000, 1e-3
local L = math.sqrt(n * math.pi * R * R / 0.003)
local gas = dsmc.scene{ dim = 2, size = { L, L }, cells = { 30, 30 }, radius = R, restitution = 0.9, seed = 3 }
gas:fill{ n = n, temperature = gas:info().mass * 1.0, seed = 5 }
gas:run{ steps = 10, dt = 0.1 / gas:measure("temperature").collision_frequency, progress = false }
local q = gas:particles()
dump("dsmc", { q.x, q.y, q.vx, q.vy })
out:close()
