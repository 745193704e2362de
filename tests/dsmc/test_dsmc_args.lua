-- The dsmc binding's contract on bad input: every error names the call, the field and the value.
local check = grainlab.check
local ok = { dim = 2, size = { 0.1, 0.1 }, cells = { 10, 10 }, radius = 1e-3 }
local function with(t)
  local c = {}
  for _, src in ipairs{ ok, t } do for k, v in pairs(src) do c[k] = v end end
  return c
end

-- restitution outside [0, 1]
check.errors(function() dsmc.scene(with{ restitution = 1.5 }) end,
  "bad field 'restitution' in argument #1 to 'scene' (number in [0, 1] expected, got 1.5)", "e above 1")
check.errors(function() dsmc.scene(with{ restitution = -0.1 }) end,
  "bad field 'restitution' in argument #1 to 'scene' (number in [0, 1] expected, got -0.1)", "e below 0")
-- non-positive radius, mass, density
check.errors(function() dsmc.scene(with{ radius = 0 }) end,
  "bad field 'radius' in argument #1 to 'scene' (positive number expected, got 0)", "zero radius")
check.errors(function() dsmc.scene(with{ radius = -1e-3 }) end,
  "bad field 'radius' in argument #1 to 'scene' (positive number expected, got -0.001)", "negative radius")
check.errors(function() dsmc.scene(with{ mass = -1 }) end,
  "bad field 'mass' in argument #1 to 'scene' (positive number expected, got -1)", "negative mass")
check.errors(function() dsmc.scene(with{ mass = 0 }) end,
  "bad field 'mass' in argument #1 to 'scene' (positive number expected, got 0)", "zero mass")
check.errors(function() dsmc.scene(with{ density = 0 }) end,
  "bad field 'density' in argument #1 to 'scene' (positive number expected, got 0)", "zero density")
check.errors(function() dsmc.scene(with{ density = 1000, mass = 1 }) end,
  "bad field 'density' in argument #1 to 'scene' (nothing when 'mass' is given expected, got 1000)", "mass and density")
-- cells smaller than a particle
check.errors(function() dsmc.scene(with{ cells = { 100, 10 } }) end,
  "scene: cells along x are 0.001 m wide, smaller than a particle (diameter 0.002 m); use at most 50 cells",
  "cells smaller than a particle")
-- other scene fields
check.errors(function() dsmc.scene(with{ cells = { 0, 10 } }) end,
  "bad field 'cells' in argument #1 to 'scene' (array of 2 integers in [1, 16777216] expected", "zero cells")
check.errors(function() dsmc.scene(with{ dim = 4 }) end,
  "bad field 'dim' in argument #1 to 'scene' (integer in [2, 3] expected, got 4)", "dim 4")
check.errors(function() dsmc.scene(with{ box = { { 0, 0 }, { 1, 1 } } }) end,
  "bad field 'box' in argument #1 to 'scene' ('box' or 'size', not both expected", "box and size")
check.errors(function() dsmc.scene(with{ excluded_volume = "hard" }) end,
  "bad field 'excluded_volume' in argument #1 to 'scene' (one of 'none', 'free_volume', 'enskog' expected, got 'hard')",
  "unknown excluded-volume model")
check.errors(function() dsmc.scene(with{ packing_limit = 1.2 }) end,
  "bad field 'packing_limit' in argument #1 to 'scene' (number in (0, 1) expected, got 1.2)", "packing limit")
check.errors(function() dsmc.scene(with{ restitutio = 0.5 }) end,
  "bad argument #1 to 'scene' (unknown field 'restitutio'", "typo")

-- more particles than fit at the packing limit: 0.82 x 0.01 m^2 / (pi 1e-6 m^2) = 2610
local s = dsmc.scene(ok)
check.eq(s:info().capacity, 2610, "capacity at the packing limit")
check.errors(function() s:fill{ n = 3000, temperature = 1e-6 } end,
  "fill: cannot add 3000 particles: the box holds at most 2610 at the packing limit nu_rcp = 0.82 (0 already in; packing fraction would be 0.942)",
  "overfull box")
check.errors(function() s:fill{ n = 100, temperature = 1e-6, region = { { 0, 0 }, { 0.01, 0.01 } } } end,
  "fill: cannot add 100 particles: the region holds at most 26 at the packing limit", "overfull region")
check.errors(function() s:fill{ n = 10 } end,
  "bad field 'temperature' in argument #1 to 'fill' (positive number (or give 'speed') expected, got nil)", "no temperature")
check.errors(function() s:fill{ n = 10, temperature = 1, speed = 1 } end,
  "bad field 'temperature' in argument #1 to 'fill' (nothing when 'speed' is given expected, got 1)", "both")
check.errors(function() s:fill{ n = 0, speed = 1 } end,
  "bad field 'n' in argument #1 to 'fill' (positive integer expected, got 0)", "no particles")
check.errors(function() s:run{ steps = 1, dt = 1e-3 } end,
  "run: the scene has 0 particles (fill it first)", "empty scene")
check.eq(s:fill{ n = 1000, speed = 1 }, 1000, "fill returns the count")
check.errors(function() s:run{ steps = 1, dt = -1 } end,
  "bad field 'dt' in argument #1 to 'run' (positive number expected, got -1)", "negative dt")
check.errors(function() s:run{ dt = 1e-3 } end, "bad field 'steps' in argument #1 to 'run' (step count (or field 'time') expected, got nil)", "no length")
check.errors(function() s:add{ x = { 0.05 }, y = { 0.2 }, vx = { 0 }, vy = { 0 } } end,
  "add: particle 1: y = 0.2 is outside the box [0, 0.1]", "particle outside")
check.errors(function() s:add{ x = { 0.05, 0.01 }, y = { 0.02 }, vx = { 0 }, vy = { 0 } } end,
  "bad field 'y' in argument #1 to 'add' (array as long as 'x' expected", "ragged arrays")

-- walls
check.errors(function() s:wall{ side = "bottom" } end,
  "wall: the y low side is on a periodic axis (no walls there)", "wall on a periodic axis")
local w = dsmc.scene(with{ periodic = { true, false } })
check.errors(function() w:wall{ side = "floor" } end,
  "bad field 'side' in argument #1 to 'wall' (one of 'left', 'right', 'bottom', 'top' (or 'xlo', 'xhi', 'ylo', 'yhi') expected, got 'floor')",
  "unknown side")
check.errors(function() w:wall{ side = "bottom", kind = "diffuse" } end,
  "bad field 'temperature' in argument #1 to 'wall' (positive number expected, got nil)", "diffuse without T")
check.errors(function() w:wall{ side = "bottom", restitution = 2 } end,
  "bad field 'restitution' in argument #1 to 'wall' (number in [0, 1] expected, got 2)", "wall e")
check.errors(function() w:wall{ side = "bottom", amplitude = 0.03, frequency = 10 } end,
  "wall: the wall's stroke 2 x amplitude = 0.06 m takes more than half the box (0.1 m along y)", "stroke")
check.errors(function() w:wall{ side = "bottom", amplitude = 0.001 } end,
  "bad field 'frequency' in argument #1 to 'wall' (positive number with an amplitude expected, got nil)", "no frequency")
w:wall{ side = "bottom", amplitude = 0.001, frequency = 50 }
w:wall{ side = "top", kind = "diffuse", temperature = 1e-6 }

-- measurements
check.errors(function() s:measure("pressure") end, "bad argument #1 to 'measure' (invalid option 'pressure'; valid options: 'temperature', 'a2',", "unknown measurement")
check.errors(function() s:measure("histogram", { bins = 0 }) end,
  "bad field 'bins' in argument #2 to 'measure' (integer in [1, 100000] expected, got 0)", "zero bins")
check.errors(function() s:measure("profile", { axis = 3 }) end,
  "bad field 'axis' in argument #2 to 'measure' (integer in [1, 2] expected, got 3)", "axis 3 in 2D")

-- help covers every function
for _, name in ipairs { "fill", "add", "wall", "run", "measure", "particles", "reset_stats", "info" } do
  check.contains(grainlab.doc_of(s[name]).usage, "s:" .. name, "help for " .. name)
end
check.contains(grainlab.doc_of(dsmc.scene).usage, "dsmc.scene{", "help for dsmc.scene")
-- values out of range name the likely cause with the run's numbers
do
  local g = dsmc.scene{ dim = 2, size = { 1, 1 }, cells = { 4, 4 }, radius = 1e-3, gravity = { 0, -1e100 } }
  g:fill{ n = 10, temperature = g:info().mass, seed = 1 }
  local msg = check.errors(function() g:run{ steps = 3, dt = 1e100, warn = false, force = true } end, "overflowed", "gravity x dt out of range")
  check.contains(msg, "likely cause: the time step dt = 1e+100 s is out of range for the gravity: one step moves a particle |g| dt^2 / 2 = 5e+299 m against a box of 1 m",
                 "gravity x dt: the numbers")
  local h = dsmc.scene{ dim = 2, size = { 1, 1 }, cells = { 4, 4 }, radius = 1e-3 }
  h:fill{ n = 10, temperature = h:info().mass * 1e90, seed = 1 }
  msg = check.errors(function() h:run{ steps = 3, dt = 1e100, warn = false, force = true } end, "overflowed", "speeds out of range")
  check.contains(msg, "likely cause: the time step dt = 1e+100 s or the speeds given are out of range", "speeds: the cause")
end
check.done()
