-- What a scene's own on_step may do while its run is in progress (the table in docs): calls that
-- would pull the running state from under the run are refused with the call's name and the
-- reason; the others take effect at the next step, the kernel rebuilding what it must. After a
-- refusal (or any error) the run is over and the scene is idle again, intact.
local check = grainlab.check

-- ---- DEM ---------------------------------------------------------------------------------------
local function dem_box()
  local s = dem.scene{ box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.01, 0 }, normal = { -1, 0 } }
  for i = 1, 4 do s:add_disk{ pos = { 0.002 * i, 0.002 }, radius = 4e-4 } end
  return s
end

-- calls `fn(scene)` from on_step (once, at the first chunk); returns the run's error or nil
local function from_on_step(s, fn, opts)
  opts = opts or {}
  local once = false
  local run = { steps = opts.steps or 200, every = 50, dt = opts.dt, force = opts.force,
                on_step = function(sc) if not once then once = true; fn(sc) end end }
  local ok, err = pcall(s.run, s, run)
  return not ok and err or nil, ok and err or nil
end

local s = dem_box()
local function refused(fn, text, what, opts)
  local err = from_on_step(s, fn, opts)
  check.is_true(err ~= nil, what .. ": refused")
  check.contains(err, text, what)
  -- the scene is idle again: a plain call and a run work
  s:run{ steps = 10 }
end
refused(function(sc) sc:run{ steps = 1 } end,
  "run: this dem.scene is already running (called from its on_step); return false from on_step to stop it",
  "nested run")
refused(function(sc) sc:contact{ normal = "hertz" } end,
  "contact: this dem.scene is running (called from its on_step); the contact law cannot change",
  "contact")
refused(function(sc) sc:add_disk{ pos = { 0.005, 0.008 }, radius = 1e-4 } end,
  "add_disk: this dem.scene is running (called from its on_step); a particle smaller than any of its material (radius 0.0001 m < 0.0004 m)",
  "smaller particle")
refused(function(sc) sc:add_disk{ pos = { 0.005, 0.008 }, radius = 5e-4,
                                  material = grainlab.material{ density = 2650, young = 70e9, poisson = 0.3 } } end,
  "a particle of a material new to the scene", "new material")
refused(function(sc) sc:scale_mass(0.5) end, "scale_mass: this dem.scene is running", "lighter")
refused(function(sc) sc:scale_stiffness(2) end, "scale_stiffness: this dem.scene is running", "stiffer")
refused(function(sc) getmetatable(sc).__close(sc) end,
  "close: this dem.scene is running (called from its on_step); it can be closed once its run has returned",
  "close")
check.eq(s:info().count, 4, "nothing was added by the refused calls")
check.is_true(tostring(s):find("closed") == nil, "not closed")

-- allowed: each takes effect, and the run does all its steps
local function allowed(fn, what, opts)
  local steps0 = s:info().steps
  local err, res = from_on_step(s, fn, opts)
  check.eq(err, nil, what .. ": no error")
  check.eq(res.steps, (opts and opts.steps) or 200, what .. ": all steps")
  check.eq(s:info().steps - steps0, res.steps, what .. ": scene steps")
end
allowed(function(sc) sc:add_disk{ pos = { 0.005, 0.008 }, radius = 5e-4 } end, "particle as large as the smallest")
check.eq(s:info().count, 5, "the particle joined")
allowed(function(sc) sc:add_disk{ pos = { 0.005, 0.0065 }, radius = 1e-4 } end, "smaller one in a forced run",
        { dt = 5e-8, force = true })
check.eq(s:info().count, 6, "forced: joined")
allowed(function(sc) sc:scale_mass(2) end, "heavier")
allowed(function(sc) sc:scale_stiffness(0.5) end, "softer")
allowed(function(sc) sc:scale_mass(0.5) end, "lighter in a forced run", { dt = 5e-8, force = true })
allowed(function(sc) sc:wall_velocity(1, { 0, 1e-3 }) end, "wall velocity")
local y0 = s:wall_point(1)[2]
s:wall_velocity(1, { 0, 0 })
check.gt(y0, 0, "the floor moved up while the run went on")
allowed(function(sc) sc:wall_servo(1, { force = 1, mass = 1e-3 }) end, "wall servo")
s:wall_servo(1)
allowed(function(sc) sc:set_velocity(1, { 0, 0.01 }) end, "set_velocity")
allowed(function(sc) sc:gravity({ 0.5, -9.8 }) end, "gravity")
check.near(s:gravity()[1], 0.5, 0, "gravity set from on_step")
s:gravity({ 0, -9.81 })
allowed(function(sc) sc:set_forces{ ids = { 2 }, fx = { 0 }, fy = { -1e-6 } } end, "set_forces")
allowed(function(sc) sc:clear_forces() end, "clear_forces")
allowed(function(sc) sc:drag(10) end, "drag")
allowed(function(sc) sc:set_reference() end, "set_reference")
local wall = s:add_wall{ point = { 0, 0.0095 }, normal = { 0, -1 } }
allowed(function(sc) sc:remove_wall(wall) end, "remove_wall")
check.errors(function() s:wall_point(wall) end, "no wall", "the wall is gone")
allowed(function(sc) sc:add_wall{ point = { 0, 0.0099 }, normal = { 0, -1 } } end, "add_wall")
allowed(function(sc) sc:measure("energy"); sc:particles(); sc:timestep{}; sc:info() end, "reads")

-- a time-based run keeps the step count it was given at its start
local dt = s:timestep{ impact_velocity = 1 }.dt_auto
local res = s:run{ time = 100 * dt, dt = dt, every = 10,
                   on_step = function(sc) sc:wall_velocity(1, { 0, 0 }) end }
check.eq(res.steps, 100, "time-based run: steps fixed at the start")

-- another scene's run from on_step is allowed, nested runs of the first refused
local other = dem_box()
local inner_steps = 0
s:run{ steps = 100, every = 50, on_step = function(sc)
  inner_steps = inner_steps + other:run{ steps = 20, every = 10, on_step = function()
    check.errors(function() sc:run{ steps = 1 } end, "already running", "outer scene from inner on_step")
  end }.steps
end }
check.eq(inner_steps, 40, "the other scene ran from on_step")
-- an error in on_step ends the run and leaves the scene idle
check.errors(function() s:run{ steps = 20, every = 10, on_step = function() error("boom") end } end, "boom", "error in on_step")
s:contact{ normal = "hertz" }
-- a scene closed after its run returns
do
  local c <close> = dem_box()
  c:run{ steps = 10, on_step = function() end }
end

-- the boundary conditions of lua_analysis.c (pressure on the Delaunay boundary) switched on and
-- off from on_step: rebuilt by the kernel between steps
local packed = dem.scene{ box = { { 0, 0 }, { 0.02, 0.02 } } }
for i = 1, 5 do for j = 1, 5 do packed:add_disk{ pos = { 0.004 + 0.0021 * i, 0.004 + 0.0021 * j }, radius = 1e-3 } end end
res = packed:run{ steps = 200, every = 50, on_step = function(sc)
  sc:boundary{ pressure = 1e4, every = 10, depth = 1e-3 }
end }
check.eq(res.steps, 200, "boundary switched on from on_step")
check.eq(packed:run{ steps = 100, every = 50, on_step = function(sc) sc:boundary{ mode = "none" } end }.steps,
         100, "and off")

-- ---- MPM ---------------------------------------------------------------------------------------
local function mpm_scene()
  local m = mpm.scene{ cells = { 16, 16 }, size = { 1, 1 }, gravity = { 0, -9.81 } }
  m:add_disk{ center = { 0.3, 0.4 }, radius = 0.12, material = mpm.material{ density = 1000, shear = 1e5, bulk = 2e5 } }
  m:plane{ point = { 0, 0.1 }, normal = { 0, 1 }, kind = "noslip" }
  return m
end
local m = mpm_scene()
local soft = mpm.material{ density = 1000, shear = 1e5, bulk = 2e5 }
local function mpm_on_step(fn, opts)
  local once = false
  local run = { steps = 40, every = 10, dt = opts and opts.dt, force = opts and opts.force,
                on_step = function(sc) if not once then once = true; fn(sc) end end }
  return pcall(m.run, m, run)
end
local ok, err = mpm_on_step(function(sc) sc:run{ steps = 1 } end)
check.contains(err, "run: this mpm.scene is already running", "mpm nested run")
local fixed = m:timestep{}.dt_auto
ok, err = mpm_on_step(function(sc) sc:add_disk{ center = { 0.7, 0.5 }, radius = 0.1, material = soft } end, { dt = fixed })
check.contains(err, "add_disk: this mpm.scene is running (called from its on_step); a new grain can raise the wave speed", "mpm grain, fixed dt")
check.eq(m:info().grains, 1, "refused grain not added")
ok, err = mpm_on_step(function(sc) getmetatable(sc).__close(sc) end)
check.contains(err, "close: this mpm.scene is running", "mpm close")
ok = mpm_on_step(function(sc) sc:add_rect{ lo = { 0.6, 0.4 }, hi = { 0.8, 0.6 }, material = soft } end)
check.is_true(ok, "mpm grain with dt = 'auto'")
check.eq(m:info().grains, 2, "grain joined")
ok = mpm_on_step(function(sc) sc:add_disk{ center = { 0.5, 0.8 }, radius = 0.08, material = soft } end, { dt = fixed, force = true })
check.is_true(ok, "mpm grain, forced fixed dt")
ok = mpm_on_step(function(sc) sc:contact{ model = "friction", mu = 0.3 } end)
check.is_true(ok, "mpm contact switched to friction during the run")
ok = mpm_on_step(function(sc) sc:contact{ model = "noslip" } end)
check.is_true(ok, "and back")
ok = mpm_on_step(function(sc) sc:prescribe(1, { 0.1, 0 }); sc:plane{ point = { 0.98, 0 }, normal = { -1, 0 }, kind = "slip" } end)
check.is_true(ok, "mpm prescribe and plane")
ok = mpm_on_step(function(sc) local p = sc:points(); sc:set_velocities{ vx = p.vx, vy = p.vy } end)
check.is_true(ok, "mpm set_velocities")
local t0 = m:info().time
local r = m:run{ time = 0.01, every = 5, on_step = function(sc) sc:prescribe(1, { 0, 0 }) end }
check.near(m:info().time - t0, 0.01, 1e-9, "mpm time-based run ends at its time")

-- ---- DSMC --------------------------------------------------------------------------------------
local g = dsmc.scene{ dim = 2, size = { 0.1, 0.1 }, cells = { 8, 8 }, radius = 1e-3, seed = 3, periodic = { true, false } }
g:fill{ n = 300, speed = 1, seed = 2 }
ok, err = pcall(g.run, g, { steps = 20, dt = 1e-4, warn = false, every = 5, on_step = function(sc) sc:run{ steps = 1, dt = 1e-4 } end })
check.contains(err, "run: this dsmc.scene is already running", "dsmc nested run")
ok, err = pcall(g.run, g, { steps = 20, dt = 1e-4, warn = false, every = 5, on_step = function(sc) getmetatable(sc).__close(sc) end })
check.contains(err, "close: this dsmc.scene is running", "dsmc close")
local added = false
r = g:run{ steps = 20, dt = 1e-4, warn = false, every = 5, on_step = function(sc)
  if not added then
    added = true
    sc:fill{ n = 50, speed = 1, seed = 9 }
    sc:add{ x = { 0.05 }, y = { 0.05 }, vx = { 1 }, vy = { 0 } }
    sc:wall{ side = "top", kind = "diffuse", temperature = 1e-6 }
    sc:reset_stats()
  end
end }
check.eq(r.steps, 20, "dsmc: all steps")
check.eq(g:info().count, 351, "dsmc: particles joined during the run")
check.eq(g:measure("stats").steps, 15, "dsmc: statistics reset during the run")
check.done()
