-- A cluster of side^dim disks (spheres) on a jittered lattice around the centre of a 0.4 m box,
-- moving inwards: every pair law at work within a few hundred steps. Shared by the tests that
-- compare two code paths bit for bit (test_dem_pair_lanes.lua, isa_bits_scenes.lua).
--   cluster{ dim = 2|3, side = n, spacing = m, inward = 1/s, contact = {...}, material = mat,
--            periodic = bool (x periodic), gravity = m/s^2 (along -y, default 0) }
return function(o)
  local dim = o.dim
  local lo, hi, per, g = {}, {}, {}, {}
  for d = 1, dim do lo[d], hi[d], per[d], g[d] = 0, 0.4, d == 1 and o.periodic or false, 0 end
  if o.gravity then g[2] = -o.gravity end
  local s = dem.scene{ dim = dim, box = { lo, hi }, gravity = g, periodic = per }
  s:contact(o.contact)
  local rng = grainlab.rng{ seed = 7 }
  local idx = {}
  for d = 1, dim do idx[d] = 0 end
  for _ = 1, o.side ^ dim do
    local pos, vel = {}, {}
    for d = 1, dim do
      pos[d] = 0.2 + (idx[d] - o.side / 2) * o.spacing + rng:uniform(-1e-4, 1e-4)
      vel[d] = -(pos[d] - 0.2) * o.inward + rng:normal(0, 0.1)
    end
    local add = dim == 2 and s.add_disk or s.add_sphere
    add(s, { pos = pos, radius = rng:uniform(0.8e-3, 1e-3), material = o.material, vel = vel })
    for d = 1, dim do -- odometer
      idx[d] = idx[d] + 1
      if idx[d] < o.side then break end
      idx[d] = 0
    end
  end
  return s
end
