-- Packing and sample preparation (grainlab.pack): random sequential addition places the asked
-- number without overlaps, reproducibly; 2D deposition rests every disk on supports with no
-- overlap; 3D deposition settles into a bed in contact; bad input is refused by name.
local check = grainlab.check
grainlab.threads(1)

local function max_overlap(s)
  local c, worst = s:measure("contacts"), 0
  for k = 1, c.count do worst = math.max(worst, c.overlap[k]) end
  return worst
end

-- random addition: count, no overlap, inside the region, same seed -> same packing
local function rsa(seed)
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.02 } } }
  local ids, st = grainlab.pack.random(s, { n = 60, radius = { 0.5e-3, 1e-3 }, seed = seed })
  return s, ids, st
end
local s1, ids, st = rsa(4)
check.eq(#ids, 60, "random: all placed")
check.eq(max_overlap(s1), 0, "random: no overlap")
-- the expected area fraction: 60 disks of mean r^2 = (a^2 + ab + b^2)/3 over 4e-4 m^2
check.near(st.fraction, 60 * math.pi * (0.5e-3 ^ 2 + 0.5e-3 * 1e-3 + 1e-3 ^ 2) / 3 / 4e-4, 0.15, "random: area fraction")
local s2 = rsa(4)
check.eq(s2:particles().x[47], s1:particles().x[47], "random: reproducible from the seed")
check.is_true(rsa(5):particles().x[47] ~= s1:particles().x[47], "random: another seed, another packing")
check.errors(function()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.005, 0.005 } } }
  grainlab.pack.random(s, { n = 4, radius = 1e-3, max_tries = 4 })
end, "grainlab.pack.random: placed 1 of 4 particles in 4 tries", "random: out of tries says how many it placed")
-- more than random addition can ever place: refused at entry with the numbers (asked, limit, what fits)
check.errors(function()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.005, 0.005 } } }
  grainlab.pack.random(s, { n = 500, radius = 1e-3, max_tries = 2000 })
end, "bad field 'n' in argument #2 to 'grainlab.pack.random' (at most 4 particles (random addition saturates at " ..
     "a packing fraction of 0.547 of the region; 500 of mean area 3.14e-06 m^2 ask for 62.8;",
  "random: a region too full is refused at entry")
do -- the particles already in the region count
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.02 } } }
  grainlab.pack.random(s, { n = 30, radius = 1e-3, seed = 2 })
  check.errors(function() grainlab.pack.random(s, { n = 50, radius = 1e-3, seed = 3 }) end,
    "(at most 39 particles (random addition saturates at a packing fraction of 0.547 of the region; 50 of mean " ..
    "area 3.14e-06 m^2 with the 0.236 already there ask for 0.628;", "random: counts what is there")
end
check.errors(function() grainlab.pack.random(dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }, { n = 0 }) end,
  "bad field 'n' in argument #2 to 'grainlab.pack.random' (integer in [1, 10000000] expected, got 0)", "random: n")
check.errors(function() grainlab.pack.random(dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }, { n = 5, radus = 1 }) end,
  "bad argument #2 to 'grainlab.pack.random' (unknown field 'radus'", "random: typo")

-- 2D deposition: geometric, no overlap before relaxation, every disk at or above the floor
do
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.03, 0.04 } }, gravity = { 0, -9.81 } }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.03, 0 }, normal = { -1, 0 } }
  local mat = grainlab.material{ density = 2650, young = 1e8, friction = 0.5, restitution = 0.5 }
  local d_ids = grainlab.pack.deposit(s, { n = 300, seed = 2, material = mat, relax_steps = 0 })
  check.eq(#d_ids, 300, "deposit: all placed")
  check.le(max_overlap(s), 1e-9, "deposit: geometric pile has no overlaps")
  local P, ytop = s:particles(), 0
  for i = 1, P.count do ytop = math.max(ytop, P.y[i]) end
  -- 300 disks of mean area pi 0.583e-6 m^2 at packing fraction > 0.6 fill well under 2/3 of the box
  check.le(ytop, 0.025, "deposit: a compact pile, not a suspension")
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, tangential = "spring" }
  -- collapse: let the few frictionally unstable spots of a geometric pile fail under a weak drag,
  -- so the pile stays at rest once the drag is off
  local r = grainlab.pack.settle(s, { max_steps = 20000, collapse = 0.3 })
  check.ge(r.z, 3, "deposit + settle: a contact network (z >= 3)")
  check.le(r.v_rms, 1e-5, "deposit + settle: at rest after the drag-free steps")
  check.errors(function() grainlab.pack.deposit(s, { n = 5000, seed = 1 }) end,
    "grainlab.pack.deposit: the region is full after", "deposit: a full region says so")
end

-- 3D deposition: random suspension, softened fall, stiffness restored, settled bed in contact
do
  local s = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 0.01, 0.01, 0.02 } }, gravity = { 0, 0, -9.81 } }
  local mat = grainlab.material{ density = 2650, young = 1e8, poisson = 0.3, friction = 0.4, restitution = 0.5 }
  s:contact{ normal = "hertz", damping = "viscous", tangential = "spring" }
  for _, w in ipairs { { { 0, 0, 0 }, { 0, 0, 1 } }, { { 0, 0, 0 }, { 1, 0, 0 } }, { { 0.01, 0, 0 }, { -1, 0, 0 } },
                       { { 0, 0, 0 }, { 0, 1, 0 } }, { { 0, 0.01, 0 }, { 0, -1, 0 } } } do
    s:add_wall{ point = w[1], normal = w[2] }
  end
  grainlab.pack.deposit(s, { n = 150, radius = { 0.5e-3, 1e-3 }, seed = 3, material = mat })
  local P, ztop = s:particles(), 0
  for i = 1, P.count do ztop = math.max(ztop, P.z[i]) end
  check.le(ztop, 0.01, "3D deposit: the spheres settled into the lower half")
  check.ge(s:measure("coordination").z, 3, "3D deposit: a contact network")
  check.le(max_overlap(s), 0.05 * 0.5e-3, "3D deposit: overlaps below 5% of the smallest radius")
end
check.done()
