-- The vectorised pair kernels (src/dem/forces_dim.inc, pair_lanes_2 and pair_lanes_3) against the
-- scalar one (pair_one), bit for bit, in 2D and 3D. A scene without periodic axes takes the vectorised loop; the same scene
-- with x periodic takes the scalar loop of the same laws, and its minimum image changes nothing
-- while no pair reaches across the seam (dx - L * nearbyint(dx / L) = dx - 0 = dx exactly). So a
-- cluster of disks (spheres) that implodes in the middle of a wide box must follow the same trajectory to
-- the last bit in both scenes, for every law the vectorised loop covers: Hertz and linear, no,
-- viscous and (with Hertz) Brilliantov damping, no tangential law and the Cundall-Strack spring (with a low
-- friction so that contacts slide at the Coulomb cap, and the spring's unloading rescale).
local check = grainlab.check
grainlab.threads(1)

local mat = grainlab.material{ density = 2650, young = 1e8, poisson = 0.3, friction = 0.1,
                               restitution = 0.6 }

local new_cluster = dofile("../lua/lib/dem_cluster.lua")
local function cluster(dim, periodic, contact)
  return new_cluster{ dim = dim, side = dim == 2 and 16 or 7, spacing = 2.1e-3, inward = 300,
                      periodic = periodic, contact = contact, material = mat }
end

local laws = {}
for _, normal in ipairs{ "hertz", "linear" } do
  for _, damping in ipairs{ "none", "viscous", "brilliantov" } do
    for _, tangential in ipairs((normal == "hertz" or damping ~= "brilliantov") and { "none", "spring" } or {}) do
      local c = { normal = normal, tangential = tangential }
      if damping == "viscous" then c.damping = "viscous"
      elseif damping == "brilliantov" then
        c.damping, c.restitution, c.impact_velocity = "brilliantov", 0.6, 1
      end
      if normal == "linear" then c.stiffness = 5e3 end
      laws[#laws + 1] = { name = normal .. "/" .. damping .. "/" .. tangential, contact = c }
    end
  end
end

for _, dim in ipairs{ 2, 3 } do
  for _, law in ipairs(laws) do
    local name = dim .. "D " .. law.name
    local a, b = cluster(dim, false, law.contact), cluster(dim, true, law.contact)
    local dt = a:timestep().dt_auto
    local zmax = 0
    for _ = 1, 6 do
      a:run{ steps = 250, dt = dt, progress = false }
      b:run{ steps = 250, dt = dt, progress = false }
      zmax = math.max(zmax, a:measure("coordination").z)
    end
    local pa, pb = a:particles(), b:particles()
    local keys = dim == 2 and { "x", "y", "vx", "vy", "fx", "fy" }
                 or { "x", "y", "z", "vx", "vy", "vz", "fx", "fy", "fz" }
    local differ, spread = 0, 0
    for i = 1, pa.count do
      for _, k in ipairs(keys) do
        if pa[k][i] ~= pb[k][i] then differ = differ + 1 end
      end
      spread = math.max(spread, math.abs(pa.x[i] - 0.2), math.abs(pa.y[i] - 0.2))
    end
    check.gt(zmax, 1, name .. ": the cluster is in contact (mean coordination)")
    check.lt(spread, 0.15, name .. ": no pair near the seam (largest offset from the centre, m)")
    check.eq(differ, 0, name .. ": values that differ between the two kernels")
  end
end
check.done()
