-- The scenes of tests/cli/isa_same_bits.sh: short runs of the three engines whose final states are
-- written as hex floats (%a) to `out`, one block per scene, so that two builds (the AVX2 clones
-- of src/core/clones.h and the baseline) and two thread counts can be compared byte for byte.
--   grainlab isa_bits_scenes.lua threads=N out=FILE
-- MPM: frictional contact with three option sets (those of test_mpm_contact_paths.lua: MUSL with
-- B-splines, strain cap, separation and conserve; USF with a friction plane and own normals; USL
-- with linear normals and PIC) and one no-slip MUSL scene. DEM: an imploding cluster of 5,184
-- disks (Hertz, Brilliantov, Cundall-Strack spring, rolling resistance, gravity in a closed box:
-- the parallel, vectorised pair kernel) and of 343 spheres. DSMC: 20,000 inelastic disks at volume
-- fraction 0.1.
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

-- MPM (the scene of test_mpm_contact_paths.lua)
local contact_scene = dofile("../lua/lib/mpm_contact_scene.lua")
local cases = {}
for _, case in ipairs(contact_scene.cases) do cases[#cases + 1] = case end
cases[#cases + 1] = { name = "musl, noslip", update = "musl", contact = { model = "noslip" } }
for _, case in ipairs(cases) do
  local p = contact_scene.run(case):points()
  dump("mpm " .. case.name, { p.x, p.y, p.vx, p.vy, p.sxx })
end

-- DEM: imploding clusters (dem_cluster.lua), touching from the start
local cluster = dofile("../lua/lib/dem_cluster.lua")
local dmat = grainlab.material{ density = 2650, young = 1e8, poisson = 0.3, friction = 0.3,
                                restitution = 0.6 }
for _, dim in ipairs{ 2, 3 } do
  local s = cluster{ dim = dim, side = dim == 2 and 72 or 7, spacing = 1.9e-3, inward = 100,
                     gravity = 9.81, material = dmat,
                     contact = { normal = "hertz", damping = "brilliantov", restitution = 0.6,
                                 impact_velocity = 1, tangential = "spring",
                                 rolling_resistance = dim == 2 and "epsd" or nil,
                                 rolling_friction = dim == 2 and 0.05 or nil } }
  s:run{ steps = 60, dt = 2e-7, progress = false }
  local p = s:particles()
  local cols = dim == 2 and { p.x, p.y, p.vx, p.vy, p.fx, p.fy } or { p.x, p.y, p.z, p.vx, p.vy, p.vz }
  dump("dem " .. dim .. "D", cols)
end

-- DSMC: the gas of the DSMC benchmarks (scripts/bench/fig2_gas.lua), 20,000 disks
local gas = dofile("../../scripts/bench/fig2_gas.lua")(20000)
gas:run{ steps = 10, dt = 0.1 / gas:measure("temperature").collision_frequency, progress = false }
local q = gas:particles()
dump("dsmc", { q.x, q.y, q.vx, q.vy })
out:close()
