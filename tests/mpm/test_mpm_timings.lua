-- m:timings(): the per-stage wall seconds of the MPM step. They count the steps run since the
-- scene was created or loaded, every stage is >= 0 and the total is their sum; with friction the
-- stencil is taken inside p2g (its entry stays 0), with noslip the contact stages stay 0; and
-- reading the clocks does not change the answer (the same bits as the same run without looking).
local check = grainlab.check
local mat = mpm.material{ density = 1000, shear = 1e6, bulk = 2e6 }
local names = { "stencil", "p2g", "normals", "grid", "contact", "g2p", "remap", "material", "check" }

local function scene(model)
  local m = mpm.scene{ cells = { 20, 20 }, size = { 1, 1 }, gravity = { 0, -9.8 } }
  m:add_disk{ center = { 0.3, 0.4 }, radius = 0.15, material = mat, velocity = { 1, 0 } }
  m:add_disk{ center = { 0.62, 0.4 }, radius = 0.15, material = mat, velocity = { -1, 0 } }
  if model == "friction" then m:contact{ model = "friction", mu = 0.3 } end
  return m
end

for _, model in ipairs({ "friction", "noslip" }) do
  local m = scene(model)
  local t0 = m:timings()
  check.eq(t0.steps, 0, model .. ": no steps yet")
  check.eq(t0.total, 0, model .. ": no time yet")
  m:run{ steps = 7 }
  m:run{ steps = 5 }
  local t = m:timings()
  check.eq(t.steps, 12, model .. ": steps counted over runs")
  local sum = 0
  for _, k in ipairs(names) do
    check.ge(t[k], 0, model .. ": " .. k .. " >= 0")
    sum = sum + t[k]
  end
  check.near(t.total, sum, 1e-12, model .. ": total is the sum")
  check.gt(t.p2g + t.g2p + t.material, 0, model .. ": the transfers took time")
  if model == "friction" then
    check.eq(t.stencil, 0, "friction: the stencil is inside p2g")
  else
    check.eq(t.contact, 0, "noslip: no contact rule")
    check.eq(t.normals, 0, "noslip: no contact normals")
    check.gt(t.stencil, 0, "noslip: a separate stencil")
  end
  -- the same run without reading the timings gives the same points
  local a, b = m:points(), scene(model)
  b:run{ steps = 12 }
  local pb = b:points()
  local d = 0
  for i = 1, a.count do d = math.max(d, math.abs(a.x[i] - pb.x[i]), math.abs(a.vx[i] - pb.vx[i])) end
  check.eq(d, 0, model .. ": timings do not change the run")
end
