-- The vectorised 2D pair kernel (src/dem/forces_dim.inc, pair_lanes_2) against the scalar one
-- (pair_one), bit for bit. A scene without periodic axes takes the vectorised loop; the same scene
-- with x periodic takes the scalar loop of the same laws, and its minimum image changes nothing
-- while no pair reaches across the seam (dx - L * nearbyint(dx / L) = dx - 0 = dx exactly). So a
-- cluster of disks that implodes in the middle of a wide box must follow the same trajectory to
-- the last bit in both scenes, for every law the vectorised loop covers: Hertz and linear, no,
-- viscous and (with Hertz) Brilliantov damping, no tangential law and the Cundall-Strack spring (with a low
-- friction so that contacts slide at the Coulomb cap, and the spring's unloading rescale).
local check = grainlab.check
grainlab.threads(1)

local mat = grainlab.material{ density = 2650, young = 1e8, poisson = 0.3, friction = 0.1,
                               restitution = 0.6 }

-- side x side disks on a jittered lattice around the centre of a 0.4 m box, moving inwards.
local function cluster(periodic, contact)
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.4, 0.4 } }, gravity = { 0, 0 },
                       periodic = { periodic, false } }
  s:contact(contact)
  local rng = grainlab.rng{ seed = 7 }
  local side, a = 16, 2.1e-3
  for ix = 0, side - 1 do
    for iy = 0, side - 1 do
      local x = 0.2 + (ix - side / 2) * a + rng:uniform(-1e-4, 1e-4)
      local y = 0.2 + (iy - side / 2) * a + rng:uniform(-1e-4, 1e-4)
      s:add_disk{ pos = { x, y }, radius = rng:uniform(0.8e-3, 1e-3), material = mat,
                  vel = { -(x - 0.2) * 300 + rng:normal(0, 0.1), -(y - 0.2) * 300 + rng:normal(0, 0.1) } }
    end
  end
  return s
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

for _, law in ipairs(laws) do
  local a, b = cluster(false, law.contact), cluster(true, law.contact)
  local dt = a:timestep().dt_auto
  local zmax = 0
  for _ = 1, 6 do
    a:run{ steps = 250, dt = dt, progress = false }
    b:run{ steps = 250, dt = dt, progress = false }
    zmax = math.max(zmax, a:measure("coordination").z)
  end
  local pa, pb = a:particles(), b:particles()
  local differ, spread = 0, 0
  for i = 1, pa.count do
    for _, k in ipairs{ "x", "y", "vx", "vy", "fx", "fy" } do
      if pa[k][i] ~= pb[k][i] then differ = differ + 1 end
    end
    spread = math.max(spread, math.abs(pa.x[i] - 0.2), math.abs(pa.y[i] - 0.2))
  end
  check.gt(zmax, 1, law.name .. ": the cluster is in contact (mean coordination)")
  check.lt(spread, 0.15, law.name .. ": no pair near the seam (largest offset from the centre, m)")
  check.eq(differ, 0, law.name .. ": values that differ between the two kernels")
end
check.done()
