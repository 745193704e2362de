-- Frictional contact: a grain's normals are its own. Two disks meet head-on, once alone and once
-- with a third, isolated disk added after them (a different size, far from both); the first two
-- must move bit for bit the same. The normals are built from per-thread scratch records that
-- every grain reuses, so a normal read from a record of another grain (the last one scattered)
-- makes the runs differ. Both the normals that the transfer's shape functions give (linear
-- shapes with normals = "linear"; B-spline shapes) and the default B-spline normals of linear
-- shapes, with 1 and 2 threads.
local check = grainlab.check
local mat = mpm.material{ model = "vonmises", density = 3000, shear = 2.5e6, bulk = 10e6, yield = 2e4 }

local function run(shape, normals, threads, third)
  grainlab.threads(threads)
  local m = mpm.scene{ cells = { 60, 60 }, size = { 6, 6 }, shape = shape }
  m:add_disk{ center = { 2.2, 3 }, radius = 0.7, material = mat, points_per_cell = 3, velocity = { 1, 0.2 } }
  m:add_disk{ center = { 3.8, 3.1 }, radius = 0.7, material = mat, points_per_cell = 3, velocity = { -1, 0 } }
  if third then
    m:add_disk{ center = { 1, 1 }, radius = 0.45, material = mat, points_per_cell = 3, velocity = { 0, 0.3 } }
  end
  m:contact{ model = "friction", mu = 0.3, normals = normals }
  m:run{ steps = 120 }
  return m:points()
end

for _, case in ipairs({ { "linear", "linear" }, { "bspline", nil }, { "linear", nil } }) do
  for _, threads in ipairs({ 1, 2 }) do
    local shape, normals = case[1], case[2]
    local name = shape .. " shapes, " .. (normals or "default") .. " normals, " .. threads .. " thread(s)"
    local a, b = run(shape, normals, threads, false), run(shape, normals, threads, true)
    local d, moved = 0, 0
    for i = 1, a.count do
      d = math.max(d, math.abs(a.x[i] - b.x[i]), math.abs(a.y[i] - b.y[i]), math.abs(a.vx[i] - b.vx[i]),
                   math.abs(a.vy[i] - b.vy[i]))
      if a.grain[i] == 1 then moved = math.max(moved, 1 - a.vx[i]) end
    end
    check.gt(moved, 0.05, name .. ": the disks met (the first slowed)")
    check.eq(d, 0, name .. ": an isolated third grain changes nothing")
  end
end
grainlab.threads(1)
check.done()
