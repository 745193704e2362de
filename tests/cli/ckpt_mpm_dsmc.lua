-- For test_checkpoint.sh: one scene of each kind (MPM with frictional contact, MPM noslip, DSMC
-- 2D and 3D with walls), run as params say, its state printed with %a.
--   engine=mpm_friction|mpm_noslip|dsmc2|dsmc3  mode=full|save|load  path=FILE  n=N  m=M
local engine, mode, path = params.engine, params.mode, params.path
local n, m = params.n or 30, params.m or 30

local function make()
  if engine:sub(1, 3) == "mpm" then
    local el = mpm.material{ density = 3000, shear = 2.5e6, bulk = 10e6 }
    local pl = mpm.material{ model = "vonmises", density = 2500, shear = 2e6, bulk = 8e6,
                             yield = 4e4 }
    local friction = engine == "mpm_friction"
    local s = mpm.scene{ cells = { 24, 20 }, size = { 2.4, 2 }, gravity = { 0.4, -9.8 },
                         walls = friction and { bottom = { kind = "friction", mu = 0.5 } }
                                 or "noslip",
                         shape = friction and "linear" or "bspline" }
    s:add_disk{ center = { 0.7, 0.32 }, radius = 0.3, material = el, velocity = { 0.8, 0 },
                omega = 1.5 }
    s:add_disk{ center = { 1.35, 0.33 }, radius = 0.3, material = pl, velocity = { -0.6, 0 } }
    s:add_rect{ lo = { 0.8, 0.7 }, hi = { 1.3, 1.1 }, material = pl, velocity = { 0, -1 } }
    if friction then s:contact{ model = "friction", mu = 0.3 } end
    return s
  end
  local d3 = engine == "dsmc3"
  local s = dsmc.scene{ dim = d3 and 3 or 2, size = d3 and { 0.05, 0.05, 0.08 } or { 0.1, 0.15 },
                        cells = d3 and { 5, 5, 8 } or { 10, 15 }, radius = 1e-3, restitution = 0.8,
                        gravity = d3 and { 0, 0, -9.81 } or { 0, -9.81 },
                        periodic = d3 and { true, false, false } or { false, false }, seed = 7 }
  s:fill{ n = 1500, temperature = 1e-4, seed = 3 }
  s:wall{ side = "bottom", restitution = 0.7, amplitude = 1e-3, frequency = 60 }
  s:wall{ side = "top", kind = "diffuse", temperature = 1e-4 }
  return s
end

local function run(s, steps)
  if engine:sub(1, 3) == "mpm" then
    s:run{ steps = steps }
  else
    s:run{ steps = steps, dt = 2e-4, warn = false }
  end
end

local function dump(s)
  local p = engine:sub(1, 3) == "mpm" and s:points() or s:particles()
  print(string.format("t %a steps %d count %d", s:info().time, s:info().steps, p.count))
  for i = 1, p.count do
    print(p.z and string.format("%a %a %a %a %a %a", p.x[i], p.y[i], p.z[i], p.vx[i], p.vy[i],
                                p.vz[i])
          or string.format("%a %a %a %a", p.x[i], p.y[i], p.vx[i], p.vy[i]))
  end
end

if mode == "full" then
  local s = make()
  run(s, n + m)
  dump(s)
elseif mode == "save" then
  local s = make()
  run(s, n)
  s:save(path)
else
  local s = (engine:sub(1, 3) == "mpm" and mpm or dsmc).load(path)
  run(s, m)
  dump(s)
end
