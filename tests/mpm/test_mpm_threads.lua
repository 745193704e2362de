-- MPM on 1 and 2 threads: the same scene (about 13,000 points, above the 8,192 at which threads
-- start) gives the same answer. With friction every grain's nodal entries are built by one thread
-- and packed in thread order, so the bits agree; noslip adds the threads' node buffers, which
-- changes only the summation order (round-off).
local check = grainlab.check
local mat = mpm.material{ model = "vonmises", density = 3000, shear = 2.5e6, bulk = 10e6, yield = 2e4 }

local function run(threads, model)
  grainlab.threads(threads)
  local m = mpm.scene{ cells = { 60, 60 }, size = { 6, 6 }, gravity = { 0.5, -9.8 }, periodic = { false, true } }
  for k = 0, 7 do
    m:add_disk{ center = { 0.9 + 1.4 * (k % 4), 1.5 + 2.5 * (k // 4) + 0.2 * (k % 2) }, radius = 0.62,
                material = mat, points_per_cell = 3, velocity = { (k % 2 == 0) and 1 or -1, 0.3 * k } }
  end
  if model == "friction" then m:contact{ model = "friction", mu = 0.4 } end
  m:run{ steps = 60 }
  return m:points()
end

for _, model in ipairs({ "friction", "noslip" }) do
  local a, b = run(1, model), run(2, model)
  check.gt(a.count, 8192, "enough points for threads")
  local d, scale = 0, 0
  for i = 1, a.count do
    d = math.max(d, math.abs(a.x[i] - b.x[i]), math.abs(a.vx[i] - b.vx[i]), math.abs(a.vy[i] - b.vy[i]))
    scale = math.max(scale, math.abs(a.vx[i]), math.abs(a.vy[i]))
  end
  if model == "friction" then
    check.eq(d, 0, "friction: 2 threads give the bits of 1")
  else
    check.lt(d, 1e-10 * scale, "noslip: 2 threads agree with 1 to round-off")
  end
end
grainlab.threads(1)
check.done()
