-- Frictional contact's options on 1, 2 and 3 threads give the same bits. The contact rule runs node
-- by node in a dynamic split of the nodes (a node's velocity, its grains' velocities, their walls,
-- the rule and the conserve option's shift all by the thread that takes the node), after the
-- remap's momenta or USF's forces were scattered by the threads that own the points: a node read
-- before another thread has written it (a missing barrier, or sums taken in a different split)
-- makes the thread counts differ. Eight disks closing in, a prescribed one, on a grid with a
-- moving friction wall on the right; per case one option set: B-spline shapes with the strain
-- cap, separation and conserve (MUSL); a friction plane with the gap test and the grains' own
-- normals (USF: the force sums); linear normals with a PIC blend (USL, no remap).
local same_points = dofile("../lua/lib/mpm_same_points.lua")
local check = grainlab.check
local contact_scene = dofile("../lua/lib/mpm_contact_scene.lua")
local cases = contact_scene.cases
local function run(case, threads)
  grainlab.threads(threads)
  return contact_scene.run(case):points()
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
