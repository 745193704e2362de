-- The dem binding's contract on bad input: every error names the call, the field and the value,
-- at the caller's line, and nothing bad gets into a scene.
local check = grainlab.check

local mat = grainlab.material{ density = 2650, young = 30e9, poisson = 0.3 }
local function scene2() return dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } } end
local function scene3() return dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } }, gravity = { 0, 0, 0 } } end
local s = scene2()

-- ---- sizes and moduli: zero, negative, NaN, infinite -----------------------------------------
local msg = check.errors(function() s:add_disk{ pos = { 0.5, 0.5 }, radius = 0 } end,
  "bad field 'radius' in argument #1 to 'add_disk' (positive number expected, got 0)", "zero radius")
check.contains(msg, "test_dem_args.lua:11:", "error at the caller's line")
check.errors(function() s:add_disk{ pos = { 0.5, 0.5 }, radius = -1e-3 } end,
  "bad field 'radius' in argument #1 to 'add_disk' (positive number expected, got -0.001)", "negative radius")
check.errors(function() s:add_disk{ pos = { 0.5, 0.5 }, radius = math.huge } end,
  "bad field 'radius' in argument #1 to 'add_disk' (positive number expected, got inf)", "infinite radius")
check.errors(function() s:add_disk{ pos = { 0.5, 0.5 } } end,
  "bad field 'radius' in argument #1 to 'add_disk' (positive number expected, got nil)", "missing radius")
check.errors(function() s:add_disk{ pos = { 0.5, 0.5 }, radius = "1mm" } end,
  "bad field 'radius' in argument #1 to 'add_disk' (positive number expected, got '1mm')", "string radius")
local s3 = scene3()
check.errors(function() s3:add_sphere{ pos = { 0.5, 0.5, 0.5 }, radius = -2 } end,
  "bad field 'radius' in argument #1 to 'add_sphere' (positive number expected, got -2)", "negative sphere radius")

check.errors(function() grainlab.material{ density = 0, young = 1e9 } end,
  "bad field 'density' in argument #1 to 'material' (positive number expected, got 0)", "zero density")
check.errors(function() grainlab.material{ density = -2650, young = 1e9 } end,
  "bad field 'density' in argument #1 to 'material' (positive number expected, got -2650)", "negative density")
check.errors(function() grainlab.material{ young = 1e9 } end,
  "bad field 'density' in argument #1 to 'material' (positive number expected, got nil)", "missing density")
check.errors(function() grainlab.material{ density = 2650, young = 0 } end,
  "bad field 'young' in argument #1 to 'material' (positive number expected, got 0)", "zero modulus")
check.errors(function() grainlab.material{ density = 2650, young = -3e9 } end,
  "bad field 'young' in argument #1 to 'material' (positive number expected, got -3000000000.0)", "negative modulus")
check.errors(function() grainlab.material{ density = 2650, young = math.huge } end,
  "bad field 'young' in argument #1 to 'material' (positive number expected, got inf)", "infinite modulus")
check.errors(function() grainlab.material{ density = 2650, young = 1e9, poisson = 0.5 } end,
  "bad field 'poisson' in argument #1 to 'material' (number in [0, 0.5) expected, got 0.5)", "poisson 0.5")
check.errors(function() s:contact{ normal = "linear", stiffness = 0 } end,
  "bad field 'stiffness' in argument #1 to 'contact' (positive number expected, got 0)", "zero stiffness")
check.errors(function() s:contact{ normal = "linear", stiffness = -1e4 } end,
  "bad field 'stiffness' in argument #1 to 'contact' (positive number expected, got -10000.0)", "negative stiffness")
check.errors(function() s:contact{ normal = "linear" } end,
  "bad field 'stiffness' in argument #1 to 'contact' (positive number expected, got nil)", "linear law needs a stiffness")
check.errors(function() s:contact{ normal = "power", stiffness = 1e4, beta = 3 } end,
  "contact: beta must be 1, 1.5 or 2, got 3", "power exponent")
check.errors(function() s:scale_mass(0) end, "bad argument #1 to 'scale_mass' (positive number expected, got 0)", "mass scale 0")

-- ---- NaN anywhere ------------------------------------------------------------------------------
local nan = 0 / 0
local function is_nan_msg(m) return m:find("got %-?nan%)") ~= nil end
msg = check.errors(function() s:add_disk{ pos = { 0.5, 0.5 }, radius = nan } end,
  "bad field 'radius' in argument #1 to 'add_disk' (positive number expected, got ", "NaN radius")
check.is_true(is_nan_msg(msg), "NaN radius shown: " .. msg)
check.errors(function() s:add_disk{ pos = { nan, 0.5 }, radius = 1e-3 } end,
  "bad field 'pos' in argument #1 to 'add_disk' (array of 2 finite numbers expected, got ", "NaN position")
check.errors(function() s:add_disk{ pos = { 0.5, math.huge }, radius = 1e-3 } end,
  "bad field 'pos' in argument #1 to 'add_disk' (array of 2 finite numbers expected, got ", "infinite position")
check.errors(function() s:add_disk{ pos = { 0.5, 0.5 }, radius = 1e-3, vel = { 0, nan } } end,
  "bad field 'vel' in argument #1 to 'add_disk' (array of 2 finite numbers expected, got ", "NaN velocity")
msg = check.errors(function() s:add_disk{ pos = { 0.5, 0.5 }, radius = 1e-3, omega = nan } end,
  "bad field 'omega' in argument #1 to 'add_disk' (finite number expected, got ", "NaN spin")
check.is_true(is_nan_msg(msg), "NaN spin shown: " .. msg)
check.errors(function() s3:add_sphere{ pos = { 0.5, 0.5, nan }, radius = 1e-3 } end,
  "bad field 'pos' in argument #1 to 'add_sphere' (array of 3 finite numbers expected, got ", "NaN sphere position")
check.errors(function() s3:add_sphere{ pos = { 0.5, 0.5, 0.5 }, radius = 1e-3, omega = { 0, nan, 0 } } end,
  "bad field 'omega' in argument #1 to 'add_sphere' (array of 3 finite numbers expected, got ", "NaN sphere spin")
msg = check.errors(function() grainlab.material{ density = nan, young = 1e9 } end,
  "bad field 'density' in argument #1 to 'material' (positive number expected, got ", "NaN density")
check.is_true(is_nan_msg(msg), "NaN density shown: " .. msg)
msg = check.errors(function() grainlab.material{ density = 2650, young = nan } end,
  "bad field 'young' in argument #1 to 'material' (positive number expected, got ", "NaN modulus")
check.is_true(is_nan_msg(msg), "NaN modulus shown: " .. msg)
check.errors(function() grainlab.material{ density = 2650, young = 1e9, friction = nan } end,
  "bad field 'friction' in argument #1 to 'material' (non-negative number expected, got ", "NaN friction")
check.errors(function() grainlab.material{ density = 2650, young = 1e9, restitution = nan } end,
  "bad field 'restitution' in argument #1 to 'material' (number in (0, 1] expected, got ", "NaN restitution")
check.errors(function() dem.scene{ box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, nan } } end,
  "bad field 'gravity' in argument #1 to 'scene' (array of 2 finite numbers expected, got ", "NaN gravity")
check.errors(function() dem.scene{ box = { { 0, 0 }, { 1, nan } } } end,
  "bad field 'box' in argument #1 to 'scene' ({{lower corner}, {upper corner}} with 2 numbers each expected", "NaN box")
check.errors(function() s:add_wall{ point = { 0, nan }, normal = { 0, 1 } } end,
  "bad field 'point' in argument #1 to 'add_wall' (array of 2 finite numbers expected, got ", "NaN wall point")
check.errors(function() s:add_wall{ point = { 0, 0 }, normal = { nan, 1 } } end,
  "bad field 'normal' in argument #1 to 'add_wall' (array of 2 finite numbers expected, got ", "NaN wall normal")
check.errors(function() s:contact{ normal = "linear", stiffness = nan } end,
  "bad field 'stiffness' in argument #1 to 'contact' (positive number expected, got ", "NaN stiffness")
check.eq(s:info().count, 0, "no bad particle got into the scene")

-- ---- particles against the box and the walls -------------------------------------------------
check.errors(function() s:add_disk{ pos = { 2, 0.5 }, radius = 1e-3 } end,
  "add_disk: position 2 on axis 1 is outside the box [0, 1]", "outside the box (x)")
check.errors(function() s:add_disk{ pos = { 0.5, -0.1 }, radius = 1e-3 } end,
  "add_disk: position -0.1 on axis 2 is outside the box [0, 1]", "outside the box (y)")
check.errors(function() s3:add_sphere{ pos = { 0.5, 0.5, 1.5 }, radius = 1e-3 } end,
  "add_sphere: position 1.5 on axis 3 is outside the box [0, 1]", "outside the box (z)")
local w = scene2()
w:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
check.errors(function() w:add_disk{ pos = { 0.5, 3e-4 }, radius = 5e-4, material = mat } end,
  "add_disk: particle at pos (0.5, 0.0003) overlaps wall 1: its centre is 0.0003 from the wall, less than its radius 0.0005", "overlapping a wall")
check.errors(function() w:add_disk{ pos = { 0.5, 0 }, radius = 5e-4, material = mat } end,
  "add_disk: particle at pos (0.5, 0) overlaps wall 1: its centre is 0 from the wall, less than its radius 0.0005", "centre on a wall")
w:add_disk{ pos = { 0.5, 5e-4 }, radius = 5e-4, material = mat } -- touching is fine
check.errors(function() w:add_wall{ point = { 0, 5e-4 }, normal = { 0, 1 } } end,
  "add_wall: wall would overlap particle 1 (distance 0, radius 0.0005)", "wall through a particle")
check.errors(function() w:add_wall{ point = { 0, 0 }, normal = { 0, 0 } } end,
  "add_wall: normal must not be zero", "zero wall normal")
check.errors(function() w:add_wall{ point = { 0, 0.5 }, normal = { 0, -1 }, friction = -1 } end,
  "bad field 'friction' in argument #1 to 'add_wall' (non-negative number expected, got -1)", "negative wall friction")
check.eq(w:info().count, 1, "only the touching disk was added")

-- ---- laws and options --------------------------------------------------------------------------
check.errors(function() s:contact{ normal = "hertzian" } end,
  "bad field 'normal' in argument #1 to 'contact' (one of 'linear', 'power', 'hertz', 'dmt', 'jkr' expected, got 'hertzian')", "unknown normal law")
check.errors(function() s:contact{ damping = "viscus" } end,
  "bad field 'damping' in argument #1 to 'contact' (one of 'none', 'viscous', 'brilliantov' expected, got 'viscus')", "unknown damping law")
check.errors(function() s:contact{ tangential = "coulomb" } end,
  "bad field 'tangential' in argument #1 to 'contact' (one of 'none', 'viscous', 'spring', 'coulomb_regularized' expected, got 'coulomb')", "unknown tangential law")
check.errors(function() s:contact{ normal = 3 } end,
  "bad field 'normal' in argument #1 to 'contact' (one of 'linear', 'power', 'hertz', 'dmt', 'jkr' expected, got 3)", "law not a string")
check.errors(function() s:run{ steps = 1, integrator = "verlet" } end,
  "bad field 'integrator' in argument #1 to 'run' (one of 'velocity_verlet', 'position_verlet', 'gear', 'two_timescales' expected, got 'verlet')", "unknown integrator")
check.errors(function() s:measure("energie") end, "bad argument #1 to 'measure' (invalid option 'energie'; did you mean 'energy'? Valid options: 'energy', 'stress',", "unknown measurement")

-- friction < 0, restitution outside (0, 1]
check.errors(function() grainlab.material{ density = 2650, young = 1e9, friction = -0.1 } end,
  "bad field 'friction' in argument #1 to 'material' (non-negative number expected, got -0.1)", "negative friction")
check.errors(function() grainlab.material{ density = 2650, young = 1e9, restitution = 0 } end,
  "bad field 'restitution' in argument #1 to 'material' (number in (0, 1] expected, got 0)", "restitution 0")
check.errors(function() grainlab.material{ density = 2650, young = 1e9, restitution = 1.5 } end,
  "bad field 'restitution' in argument #1 to 'material' (number in (0, 1] expected, got 1.5)", "restitution 1.5")
check.errors(function() grainlab.material{ density = 2650, young = 1e9, restitution = -0.5 } end,
  "bad field 'restitution' in argument #1 to 'material' (number in (0, 1] expected, got -0.5)", "negative restitution")
do
  local b = scene2()
  b:add_disk{ pos = { 0.5, 0.5 }, radius = 1e-3, material = mat }
  check.errors(function() b:contact{ damping = "brilliantov", restitution = 0 } end,
    "bad field 'restitution' in argument #1 to 'contact' (number in (0, 1] expected, got 0)", "brilliantov restitution 0")
  check.errors(function() b:contact{ damping = "brilliantov", restitution = 1.01 } end,
    "bad field 'restitution' in argument #1 to 'contact' (number in (0, 1] expected, got 1.01)", "brilliantov restitution > 1")
  check.eq(b:contact{ damping = "brilliantov" }, nil,
    "brilliantov without damping_time or restitution: a T per pair from the materials' restitution")
end

-- ---- unknown fields (typos) --------------------------------------------------------------------
check.errors(function() dem.scene{ box = { { 0, 0 }, { 1, 1 } }, gravty = { 0, -9.81 } } end,
  "bad argument #1 to 'scene' (unknown field 'gravty'; did you mean 'gravity'? Valid fields: dim, box, gravity, periodic, thickness, skin)", "scene typo")
check.errors(function() s:add_disk{ pos = { 0.5, 0.5 }, radius = 1e-3, velocity = { 1, 0 } } end,
  "bad argument #1 to 'add_disk' (unknown field 'velocity'; valid fields: pos, radius, material, vel, omega, fixed, prescribed)", "add_disk typo")
check.errors(function() s3:add_sphere{ pos = { 0.5, 0.5, 0.5 }, raduis = 1e-3 } end,
  "bad argument #1 to 'add_sphere' (unknown field 'raduis'", "add_sphere typo")
check.errors(function() s:add_wall{ point = { 0, 0 }, norm = { 0, 1 } } end,
  "bad argument #1 to 'add_wall' (unknown field 'norm'; did you mean 'normal'? Valid fields: point, normal, velocity, friction, material)", "add_wall typo")
check.errors(function() s:contact{ frction = 1 } end,
  "bad argument #1 to 'contact' (unknown field 'frction'; valid fields: normal, stiffness,", "contact typo")
check.errors(function() s:run{ step = 10 } end,
  "bad argument #1 to 'run' (unknown field 'step'; did you mean 'steps'? Valid fields: steps, time, dt,", "run typo")
check.errors(function() s:timestep{ impact = 1 } end,
  "bad argument #1 to 'timestep' (unknown field 'impact'; did you mean 'impact_velocity'? Valid fields: impact_velocity)", "timestep typo")
check.errors(function() grainlab.material{ densty = 2650, young = 1e9 } end,
  "bad argument #1 to 'material' (unknown field 'densty'; did you mean 'density'? Valid fields: density, friction, name, poisson, restitution, rolling_friction, work_of_adhesion, young)", "material typo")
check.errors(function() s:add_disk{ pos = { 0.5, 0.5 }, radius = 1e-3, material = { density = 2650 } } end,
  "bad field 'material' in argument #1 to 'add_disk' (grainlab.material expected, got table)", "plain table as material")

-- ---- wrong dimension -----------------------------------------------------------------------------
check.errors(function() s:add_sphere{ pos = { 0.5, 0.5, 0.5 }, radius = 1e-3 } end,
  "add_sphere: this is a 2D scene (use add_disk)", "sphere in a 2D scene")
check.errors(function() s3:add_disk{ pos = { 0.5, 0.5 }, radius = 1e-3 } end,
  "add_disk: this is a 3D scene (use add_sphere)", "disk in a 3D scene")
check.errors(function() s:add_disk{ pos = { 0.5, 0.5, 0.5 }, radius = 1e-3 } end,
  "bad field 'pos' in argument #1 to 'add_disk' (array of 2 finite numbers expected, got table)", "3 coordinates in 2D")
check.errors(function() s3:add_wall{ point = { 0, 0 }, normal = { 0, 1 } } end,
  "bad field 'point' in argument #1 to 'add_wall' (array of 3 finite numbers expected, got table)", "2D wall in 3D")
check.errors(function() dem.scene{ dim = 4, box = { { 0, 0 }, { 1, 1 } } } end,
  "bad field 'dim' in argument #1 to 'scene' (integer in [2, 3] expected, got 4)", "dim 4")
check.errors(function() dem.scene{ dim = 3, box = { { 0, 0 }, { 1, 1 } } } end,
  "bad field 'box' in argument #1 to 'scene' ({{lower corner}, {upper corner}} with 3 numbers each expected, got table)", "2D box in 3D")
check.errors(function() dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } }, thickness = 1e-3 } end,
  "bad field 'thickness' in argument #1 to 'scene' (nothing in 3D (thickness is for 2D disks) expected, got 0.001)", "thickness in 3D")

-- ---- run: steps xor time, and their values -------------------------------------------------------
local r = scene2()
r:add_disk{ pos = { 0.5, 0.5 }, radius = 1e-3, material = mat }
check.errors(function() r:run{ steps = 10, time = 1e-3 } end, "bad field 'time' in argument #1 to 'run' (nothing when 'steps' is given (give one) expected, got 0.001)", "steps and time")
check.errors(function() r:run{} end, "bad field 'steps' in argument #1 to 'run' (step count (or field 'time') expected, got nil)", "neither steps nor time")
check.errors(function() r:run{ steps = -5 } end,
  "bad field 'steps' in argument #1 to 'run' (non-negative integer expected, got -5)", "negative steps")
check.errors(function() r:run{ steps = 1.5 } end,
  "bad field 'steps' in argument #1 to 'run' (non-negative integer expected, got 1.5)", "fractional steps")
check.errors(function() r:run{ time = -1 } end,
  "bad field 'time' in argument #1 to 'run' (non-negative number expected, got -1)", "negative time")
msg = check.errors(function() r:run{ steps = 1, dt = nan } end,
  "bad field 'dt' in argument #1 to 'run' (positive number expected, got ", "NaN dt")
check.is_true(is_nan_msg(msg), "NaN dt shown: " .. msg)
check.errors(function() r:run{ steps = 1, dt = -1 } end,
  "bad field 'dt' in argument #1 to 'run' (positive number expected, got -1)", "negative dt")
check.errors(function() r:run{ steps = 1, dt = "fast" } end,
  "bad field 'dt' in argument #1 to 'run' (positive number expected, got 'fast')", "dt not a number")
check.errors(function() r:run(10) end, "bad argument #1 to 'run' (table expected, got number)", "run without a table")
check.errors(function() r:set_velocity(1, { nan, 0 }) end, "bad argument #2 to 'set_velocity' (array of 2 finite numbers expected, got ", "NaN set_velocity")
check.eq(r:info().steps, 0, "no bad run took a step")
check.errors(function() scene3():run{ steps = 1 } end, "run: the scene has no particles", "run on an empty scene")
-- Measurements of an empty scene are zeros, not undefined behaviour (UBSan: memcpy of NULL in
-- the neighbour build).
for _, e in ipairs{ scene2(), scene3() } do
  check.eq(e:measure("energy").total, 0, "energy of an empty scene")
  check.eq(e:measure("contacts").count, 0, "contacts of an empty scene")
  check.eq(e:measure("coordination").z, 0, "coordination of an empty scene")
end



-- Values given out of range are refused rather than read as "not given".
local c = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }
check.errors(function() c:contact{ normal = "linear", stiffness = 1, damping = "viscous", restitution = 7 } end,
  "bad field 'restitution' in argument #1 to 'contact' (number in (0, 1] expected, got 7)", "restitution 7 with viscous damping")
check.errors(function() c:contact{ normal = "hertz", damping = "viscous", gamma_n = -1 } end,
  "bad field 'gamma_n' in argument #1 to 'contact' (non-negative number expected, got -1)", "negative gamma_n")
check.errors(function() c:contact{ normal = "hertz", damping = "brilliantov", damping_time = -1 } end,
  "bad field 'damping_time' in argument #1 to 'contact' (non-negative number expected, got -1)", "negative damping_time")
check.errors(function() c:contact{ normal = "hertz", tangential = "spring", kt = -5 } end,
  "bad field 'kt' in argument #1 to 'contact' (positive number expected, got -5)", "negative kt")
c:add_disk{ pos = { 0.5, 0.5 }, radius = 0.01 }
check.errors(function() c:set_velocity(5, { 0, 0 }) end,
  "bad argument #1 to 'set_velocity' (particle id in [1, 1] expected, got 5)", "set_velocity id")
check.errors(function() c:run{ steps = 1, dt = 1 } end, "run: dt = 1 s exceeds the stability limit", "refusal names dt")
check.done()
