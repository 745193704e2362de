-- Frictional contact's options on 1, 2 and 3 threads give the same bits. The contact rule runs node
-- by node in a dynamic split of the nodes (a node's velocity, its grains' velocities, their walls,
-- the rule and the conserve option's shift all by the thread that takes the node), after the
-- remap's momenta or USF's forces were scattered by the threads that own the points: a node read
-- before another thread has written it (a missing barrier, or sums taken in a different split)
-- makes the thread counts differ. Eight disks closing in, a prescribed one, on a grid with a
-- moving friction wall on the right; per case one option set: B-spline shapes with the strain
-- cap, separation and conserve (MUSL); a friction plane with the gap test and the grains' own
-- normals (USF: the force sums); linear normals with a PIC blend (USL, no remap).
local same_points = dofile("mpm_same_points.lua")
local check = grainlab.check
local mat = mpm.material{ model = "vonmises", density = 3000, shear = 2.5e6, bulk = 10e6, yield = 2e4 }

local cases = {
  { name = "musl, bspline, cap, separation, conserve", update = "musl", shape = "bspline",
    contact = { strain_cap = 0.05, separation = 0.2, conserve = true } },
  { name = "usf, friction plane with gap test, own normals", update = "usf", plane = true, wall_gap = 0.5,
    contact = { normals = "own", conserve = true } },
  { name = "usl, linear normals, pic", update = "usl", pic = 0.3, contact = { normals = "linear" } },
}

local function run(case, threads)
  grainlab.threads(threads)
  local m = mpm.scene{ cells = { 60, 60 }, size = { 6, 6 }, gravity = { 0.5, -9.8 }, periodic = { false, true },
                       update = case.update, shape = case.shape, pic = case.pic, wall_gap = case.wall_gap,
                       walls = { left = "noslip", right = { kind = "friction", mu = 0.3, velocity = { 0, 0.2 } } } }
  local ids = {}
  for k = 0, 7 do
    -- columns 1.3 apart and rows 1.25 apart (radius 0.62: gaps under a cell), the last column
    -- reaching the right wall's nodes
    ids[k] = m:add_disk{ center = { 1.4 + 1.3 * (k % 4), 1.5 + 1.25 * (k // 4) }, radius = 0.62, material = mat,
                         points_per_cell = 3,
                         velocity = { (k % 2 == 0) and 1 or -1, (k // 4 == 0) and 0.5 or -0.5 } }
  end
  m:prescribe(ids[5], { -0.5, -0.5 })
  if case.plane then m:plane{ point = { 5.95, 0 }, normal = { 1, 0.2 }, kind = "friction", mu = 0.4 } end
  local c = { model = "friction", mu = 0.4 }
  for k, v in pairs(case.contact) do c[k] = v end
  m:contact(c)
  m:run{ steps = 25, cfl = 0.3 }
  return m:points()
end

for _, case in ipairs(cases) do
  local a = run(case, 1)
  check.gt(a.count, 8192, case.name .. ": enough points for threads")
  -- the grains met: the first (moving right at 1) was slowed by its neighbour
  local slowed = 0
  for i = 1, a.count do
    if a.grain[i] == 1 then slowed = math.max(slowed, 1 - a.vx[i]) end
  end
  check.gt(slowed, 0.05, case.name .. ": the grains met")
  for _, threads in ipairs({ 2, 3 }) do
    local b = run(case, threads)
    check.is_true(same_points(a, b), case.name .. ": " .. threads .. " threads give the bits of 1")
  end
end
grainlab.threads(1)
check.done()
