-- Frictional contact on 1, 2 and 3 threads gives the same bits (the node sums follow each node's
-- chain of pairs in pair order, whichever thread adds them up; the contact rule takes the
-- shared nodes in dynamic chunks): two rows of grains one gap apart, so that on 3 threads grains of the
-- first and the last thread share nodes, with the middle thread's pairs absent there (the chain
-- skips a thread); a prescribed grain (the nodes it forces, the last in grain order); the
-- momentum-conserving correction (three grains at a node); MUSL (the remap's sums) and USF (the
-- force scatter's).
local same_points = dofile("../lua/lib/mpm_same_points.lua")
local check = grainlab.check
local mat = mpm.material{ model = "vonmises", density = 3000, shear = 2.5e6, bulk = 10e6, yield = 2e4 }

local function run(threads, update)
  grainlab.threads(threads)
  local m = mpm.scene{ cells = { 60, 60 }, size = { 6, 6 }, gravity = { 0.5, -9.8 }, periodic = { false, true },
                       update = update }
  local ids = {}
  for k = 0, 7 do
    -- rows 1.3 apart (radius 0.62: a gap under a cell), columns 1.4 apart, closing in
    ids[k] = m:add_disk{ center = { 0.9 + 1.4 * (k % 4), 1.5 + 1.3 * (k // 4) }, radius = 0.62, material = mat,
                         points_per_cell = 3,
                         velocity = { (k % 2 == 0) and 1 or -1, (k // 4 == 0) and 0.5 or -0.5 } }
  end
  m:prescribe(ids[5], { -0.5, -0.5 })
  m:contact{ model = "friction", mu = 0.4, conserve = true }
  m:run{ steps = 25 }
  return m:points(), m:measure("momentum")
end

for _, update in ipairs({ "musl", "usf" }) do
  local a = run(1, update)
  check.gt(a.count, 8192, "enough points for threads")
  for _, threads in ipairs({ 2, 3 }) do
    local b = run(threads, update)
    check.is_true(same_points(a, b), update .. ": " .. threads .. " threads give the bits of 1")
  end
end
grainlab.threads(1)
check.done()
