-- One run of a known length for each engine (params.engine), plus the options under test:
-- params.progress (true/false/absent), params.stop_at (on_step returns false there), params.steps.
local engine, steps = params.engine or "dem", params.steps or 2000
local opts = { steps = steps, progress = params.progress }
if params.stop_at then
  opts.every = params.stop_at
  opts.on_step = function() return false end
end
if engine == "dem" then
  local s = dem.scene{ box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  local quartz = grainlab.material{ density = 2650, young = 30e9, friction = 0.45 }
  for i = 1, 4 do s:add_disk{ pos = { 0.002 * i, 0.002 }, radius = 4e-4, material = quartz } end
  s:run(opts)
elseif engine == "mpm" then
  local m = mpm.scene{ cells = { 8, 8 }, size = { 1, 1 } }
  m:add_disk{ center = { 0.5, 0.5 }, radius = 0.2, material = mpm.material{ density = 1000, shear = 1e5, bulk = 2e5 } }
  m:run(opts)
else
  local g = dsmc.scene{ dim = 2, size = { 0.1, 0.1 }, cells = { 4, 4 }, radius = 1e-3, seed = 3 }
  g:fill{ n = 50, speed = 1, seed = 2 }
  opts.dt, opts.warn = 1e-4, false
  g:run(opts)
end
print("ran")
