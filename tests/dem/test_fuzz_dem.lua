-- Generated bad-input test of the dem module (see fuzz_driver.lua): every field of every dem
-- function and dem.scene method gets every bad-value class; only the classes declared below are
-- accepted, everything else must end in an error naming the call and the field.
local fuzz = dofile("../lua/lib/fuzz_driver.lua")
local check = grainlab.check
local mat = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3, friction = 0.3 }

local function scene2()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } }
  s:add_disk{ pos = { 0.5, 0.5 }, radius = 0.01 }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  return s
end
local function scene3()
  local s = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } }, gravity = { 0, 0, 0 } }
  s:add_sphere{ pos = { 0.5, 0.5, 0.5 }, radius = 0.01 }
  return s
end
local function self(ctx) return ctx end
-- Checkpoint files of the save/load cases go to a scratch directory, never the source tree.
local tmp = os.tmpname()
os.remove(tmp)
assert(os.execute("mkdir -p '" .. tmp .. "'"))
local OPT = { "nil" }
local BOOL = { "nil", "boolean" }
local ID = {} -- a particle or wall id: nothing but a valid id

local calls = {
  ["dem.scene"] = {
    args = function() return { { dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, -9.81 },
                                 periodic = { false, false }, thickness = 0.01, skin = 0.001 } } end,
    opts = 1,
    accept = { dim = OPT, box = {}, gravity = OPT, periodic = OPT, thickness = { "nil", "zero" },
               skin = { "nil", "zero" } },
  },
  ["dem.scene:contact"] = {
    { setup = scene2, self = self, opts = 1,
      args = function() return { { normal = "linear", stiffness = 1e4, damping = "viscous",
                                   gamma_n = 0.1, tangential = "spring", kt = 1e3, clip = true, rolling = false } } end,
      accept = { normal = {}, stiffness = {}, beta = OPT, damping = {}, gamma_n = { "nil", "zero" },
                 damping_time = OPT, restitution = OPT, impact_velocity = OPT, tangential = {},
                 gamma_t = OPT, kt = OPT, v_r = OPT, exponent = OPT, clip = BOOL,
                 rolling = BOOL,
                 rolling_resistance = OPT, rolling_friction = OPT, rolling_stiffness = OPT,
                 rolling_damping = OPT, rolling_rate = OPT, work_of_adhesion = OPT, cohesion = OPT, liquid_volume = OPT,
                 surface_tension = OPT, contact_angle = OPT } },
    { setup = scene2, self = self, opts = 1,
      args = function() return { { normal = "power", stiffness = 1e4, beta = 1.5,
                                   tangential = "coulomb_regularized", v_r = 1e-3, exponent = 2 } } end,
      accept = { normal = {}, stiffness = {}, beta = OPT, damping = OPT, gamma_n = OPT,
                 damping_time = OPT, restitution = OPT, impact_velocity = OPT, tangential = {},
                 gamma_t = OPT, kt = OPT, v_r = OPT, exponent = OPT, clip = BOOL, rolling = BOOL,
                 rolling_resistance = OPT, rolling_friction = OPT, rolling_stiffness = OPT,
                 rolling_damping = OPT, rolling_rate = OPT, work_of_adhesion = OPT, cohesion = OPT, liquid_volume = OPT,
                 surface_tension = OPT, contact_angle = OPT } },
    { setup = scene2, self = self, opts = 1,
      args = function() return { { tangential = "viscous", gamma_t = 0.1, damping = "brilliantov",
                                   damping_time = 1e-5 } } end,
      accept = { normal = OPT, stiffness = OPT, beta = OPT, damping = {}, gamma_n = OPT,
                 damping_time = { "nil", "zero" }, restitution = OPT, impact_velocity = OPT, tangential = {},
                 gamma_t = { "nil", "zero" }, kt = OPT, v_r = OPT, exponent = OPT, clip = BOOL, rolling = BOOL,
                 rolling_resistance = OPT, rolling_friction = OPT, rolling_stiffness = OPT,
                 rolling_damping = OPT, rolling_rate = OPT, work_of_adhesion = OPT, cohesion = OPT, liquid_volume = OPT,
                 surface_tension = OPT, contact_angle = OPT } },
    { setup = scene2, self = self, opts = 1,
      args = function() return { { damping = "brilliantov", restitution = 0.7, impact_velocity = 1 } } end,
      accept = { normal = OPT, stiffness = OPT, beta = OPT, damping = {}, gamma_n = OPT,
                 damping_time = OPT, restitution = { "nil" }, impact_velocity = OPT, tangential = OPT,
                 gamma_t = OPT, kt = OPT, v_r = OPT, exponent = OPT, clip = BOOL, rolling = BOOL,
                 rolling_resistance = OPT, rolling_friction = OPT, rolling_stiffness = OPT,
                 rolling_damping = OPT, rolling_rate = OPT, work_of_adhesion = OPT, cohesion = OPT, liquid_volume = OPT,
                 surface_tension = OPT, contact_angle = OPT } },
    -- rolling resistance: EPSD with its parameters, then the constant torque with its rate
    { setup = scene2, self = self, opts = 1,
      args = function() return { { tangential = "spring", rolling_resistance = "epsd",
                                   rolling_friction = 0.1, rolling_stiffness = 1e-3,
                                   rolling_damping = 0.3 } } end,
      accept = { normal = OPT, stiffness = OPT, beta = OPT, damping = OPT, gamma_n = OPT,
                 damping_time = OPT, restitution = OPT, impact_velocity = OPT, tangential = OPT,
                 gamma_t = OPT, kt = OPT, v_r = OPT, exponent = OPT, clip = BOOL, rolling = BOOL,
                 rolling_resistance = {}, rolling_friction = { "nil", "zero" },
                 rolling_stiffness = OPT, rolling_damping = { "nil", "zero" }, rolling_rate = OPT, work_of_adhesion = OPT, cohesion = OPT, liquid_volume = OPT,
                 surface_tension = OPT, contact_angle = OPT } },
    { setup = scene2, self = self, opts = 1,
      args = function() return { { tangential = "spring", rolling_resistance = "constant",
                                   rolling_friction = 0.1, rolling_rate = 0.01 } } end,
      accept = { normal = OPT, stiffness = OPT, beta = OPT, damping = OPT, gamma_n = OPT,
                 damping_time = OPT, restitution = OPT, impact_velocity = OPT, tangential = OPT,
                 gamma_t = OPT, kt = OPT, v_r = OPT, exponent = OPT, clip = BOOL, rolling = BOOL,
                 rolling_resistance = {}, rolling_friction = { "nil", "zero" },
                 rolling_stiffness = OPT, rolling_damping = OPT, rolling_rate = OPT, work_of_adhesion = OPT, cohesion = OPT, liquid_volume = OPT,
                 surface_tension = OPT, contact_angle = OPT } },
    -- cohesion: JKR with the contact's work of adhesion, then a liquid bridge on Hertz
    { setup = scene2, self = self, opts = 1,
      args = function() return { { normal = "jkr", work_of_adhesion = 0.05, tangential = "spring" } } end,
      accept = { normal = {}, stiffness = OPT, beta = OPT, damping = OPT, gamma_n = OPT,
                 damping_time = OPT, restitution = OPT, impact_velocity = OPT, tangential = OPT,
                 gamma_t = OPT, kt = OPT, v_r = OPT, exponent = OPT, clip = BOOL, rolling = BOOL,
                 rolling_resistance = OPT, rolling_friction = OPT, rolling_stiffness = OPT,
                 rolling_damping = OPT, rolling_rate = OPT, work_of_adhesion = { "nil", "zero" },
                 cohesion = OPT, liquid_volume = OPT, surface_tension = OPT, contact_angle = OPT } },
    { setup = scene2, self = self, opts = 1,
      args = function() return { { cohesion = "capillary", liquid_volume = 1e-12, surface_tension = 0.07,
                                   contact_angle = 30 } } end,
      accept = { normal = OPT, stiffness = OPT, beta = OPT, damping = OPT, gamma_n = OPT,
                 damping_time = OPT, restitution = OPT, impact_velocity = OPT, tangential = OPT,
                 gamma_t = OPT, kt = OPT, v_r = OPT, exponent = OPT, clip = BOOL, rolling = BOOL,
                 rolling_resistance = OPT, rolling_friction = OPT, rolling_stiffness = OPT,
                 rolling_damping = OPT, rolling_rate = OPT, work_of_adhesion = OPT, cohesion = {},
                 liquid_volume = {}, surface_tension = { "zero" }, contact_angle = { "nil", "zero" } } },
  },
  ["dem.scene:add_disk"] = {
    setup = scene2, self = self, opts = 1,
    args = function() return { { pos = { 0.2, 0.2 }, radius = 0.01, material = mat, vel = { 1, 0 },
                                 omega = 1, fixed = false, prescribed = false } } end,
    accept = { pos = {}, radius = {}, material = OPT, vel = OPT, omega = { "nil", "zero", "negative" },
               fixed = BOOL, prescribed = BOOL },
  },
  ["dem.scene:add_sphere"] = {
    setup = scene3, self = self, opts = 1,
    args = function() return { { pos = { 0.2, 0.2, 0.2 }, radius = 0.01, material = mat,
                                 vel = { 1, 0, 0 }, omega = { 0, 0, 1 }, fixed = false,
                                 prescribed = false } } end,
    accept = { pos = {}, radius = {}, material = OPT, vel = OPT, omega = OPT, fixed = BOOL,
               prescribed = BOOL },
  },
  ["dem.scene:add_wall"] = {
    setup = scene2, self = self, opts = 1,
    args = function() return { { point = { 0, 1 }, normal = { 0, -1 }, velocity = { 0, 0 },
                                 friction = 0.3, material = mat } } end,
    accept = { point = {}, normal = {}, velocity = OPT, friction = { "nil", "zero" }, material = OPT },
  },
  -- walls beyond planes: base calls with a motion table (a function is its own case)
  ["dem.scene:add_polyline"] = {
    { setup = scene2, self = self, opts = 1,
      args = function() return { { points = { { 0.1, 0.9 }, { 0.5, 0.95 }, { 0.9, 0.9 } }, closed = false,
                                   center = { 0.5, 0.9 }, motion = { { 0, 0, 0, 0 }, { 1, 0, 0, 1 } },
                                   friction = 0.3, material = mat } } end,
      accept = { points = { "short" }, closed = BOOL, center = OPT, velocity = OPT, omega = OPT,
                 motion = { "nil", "short" }, motion_step = OPT, motion_until = OPT,
                 friction = { "nil", "zero" }, material = OPT } },
    { setup = scene2, self = self, opts = 1,
      args = function() return { { points = { { 0.1, 0.9 }, { 0.9, 0.9 } }, velocity = { 0, -0.1 },
                                   omega = 0.5 } } end,
      accept = { points = {}, closed = OPT, center = OPT, velocity = OPT,
                 omega = { "nil", "zero", "negative" }, motion = OPT, motion_step = OPT,
                 motion_until = OPT, friction = { "nil", "zero" }, material = OPT } },
    { setup = scene2, self = self, opts = 1,
      args = function() return { { points = { { 0.1, 0.9 }, { 0.9, 0.9 } },
                                   motion = function(t) return { 0, -t }, t end,
                                   motion_step = 0.1, motion_until = 1 } } end,
      accept = { points = {}, closed = OPT, center = OPT, velocity = OPT, omega = OPT,
                 motion = {}, motion_step = {}, motion_until = {}, friction = { "nil", "zero" },
                 material = OPT } },
  },
  ["dem.scene:add_mesh"] = {
    setup = scene3, self = self, opts = 1,
    args = function() return { { triangles = { { { 0, 0, 0.9 }, { 1, 0, 0.9 }, { 0, 1, 0.9 } },
                                               { { 1, 0, 0.9 }, { 1, 1, 0.9 }, { 0, 1, 0.9 } } },
                                 center = { 0.5, 0.5, 0.9 }, velocity = { 0, 0, 0 }, omega = { 0, 0, 1 },
                                 friction = 0.3, material = mat } } end,
    accept = { triangles = { "short" }, center = OPT, velocity = OPT, omega = OPT, motion = OPT,
               motion_step = OPT, motion_until = OPT, friction = { "nil", "zero" }, material = OPT },
  },
  ["dem.scene:add_cylinder"] = {
    { setup = scene2, self = self, opts = 1,
      args = function() return { { center = { 0.5, 0.5 }, radius = 0.3, inside = true, omega = 1,
                                   friction = 0.3, material = mat } } end,
      accept = { center = {}, radius = {}, axis = OPT, length = OPT, inside = BOOL, velocity = OPT,
                 omega = { "nil", "zero", "negative" }, motion = OPT, motion_step = OPT,
                 motion_until = OPT, friction = { "nil", "zero" }, material = OPT } },
    { setup = scene3, self = self, opts = 1,
      args = function() return { { center = { 0.5, 0.5, 0.5 }, radius = 0.3, axis = { 0, 0, 1 },
                                   length = 0.5, inside = true, omega = { 0, 0, 1 } } } end,
      accept = { center = {}, radius = {}, axis = {}, length = { "nil", "zero" }, inside = BOOL,
                 velocity = OPT, omega = OPT, motion = OPT, motion_step = OPT, motion_until = OPT,
                 friction = { "nil", "zero" }, material = OPT } },
  },
  ["dem.scene:wall_load"] = { setup = scene2, self = self, args = function() return { 1 } end, pos = { ID } },
  ["dem.scene:remove_wall"] = { setup = scene2, self = self, args = function() return { 1 } end, pos = { ID } },
  ["dem.scene:wall_point"] = { setup = scene2, self = self, args = function() return { 1 } end, pos = { ID } },
  ["dem.scene:wall_force"] = { setup = scene2, self = self, args = function() return { 1 } end, pos = { ID } },
  ["dem.scene:wall_velocity"] = {
    setup = scene2, self = self, args = function() return { 1, { 0, 0.1 } } end, pos = { ID, {} },
  },
  ["dem.scene:wall_servo"] = {
    setup = scene2, self = self, args = function() return { 1, { force = 1, mass = 1, rate = 1 } } end,
    opts = 2, opts_optional = true, pos = { ID },
    accept = { force = { "zero" }, mass = {}, rate = { "nil", "zero" } },
  },
  ["dem.scene:set_velocity"] = {
    setup = scene2, self = self, args = function() return { 1, { 0, 0.1 } } end, pos = { ID, {} },
  },
  ["dem.scene:timestep"] = {
    setup = scene2, self = self, args = function() return { { impact_velocity = 1 } } end,
    opts = 1, opts_optional = true, accept = { impact_velocity = OPT },
  },
  ["dem.scene:run"] = {
    setup = scene2, self = self, opts = 1,
    args = function() return { { steps = 2, dt = 1e-6, force = false, impact_velocity = 1,
                                 integrator = "velocity_verlet", m = 2, n = 2, q = 2, every = 1,
                                 on_step = function() end, progress = false } } end,
    accept = { steps = { "zero" }, time = OPT, dt = OPT, force = BOOL, impact_velocity = OPT,
               integrator = OPT, m = OPT, n = OPT, q = { "nil", "zero" }, every = OPT,
               on_step = { "nil", "function" }, progress = BOOL },
  },
  ["dem.scene:measure"] = {
    -- the modes without options: an empty table (or none), nothing else; the mode name fuzzed once
    { setup = scene2, self = self, mode = "energy", opts = 2, opts_optional = true,
      args = function() return { "energy", {} } end, pos = { {} } },
    { setup = scene2, self = self, mode = "coordination", opts = 2, opts_optional = true,
      args = function() return { "coordination", {} } end },
    { setup = scene2, self = self, mode = "slip", opts = 2, opts_optional = true,
      args = function() return { "slip", {} } end },
    { setup = scene2, self = self, mode = "contacts", opts = 2, opts_optional = true,
      args = function() return { "contacts", {} } end },
    { setup = scene2, self = self, mode = "stress", opts = 2, opts_optional = true,
      args = function() return { "stress", { volume = 1 } } end, accept = { volume = OPT } },
    { setup = function() local s = scene2(); s:set_reference(); return s end, self = self,
      mode = "displacement", opts = 2, opts_optional = true,
      args = function() return { "displacement", { affine = { { 0, 0 }, { 0, 0 } }, center = { 0, 0 } } } end,
      accept = { center = OPT, affine = OPT } },
  },
  ["dem.clump_template"] = {
    args = function() return { { members = { { offset = { 0, 0 }, radius = 0.01 },
                                             { offset = { 0.015, 0 }, radius = 0.01 } },
                                 resolution = 64 } } end,
    opts = 1, accept = { members = { "short", "long" }, resolution = OPT },
  },
  ["dem.scene:add_clump"] = {
    setup = scene2, self = self, opts = 1,
    args = function() return { { members = { { offset = { 0, 0 }, radius = 0.01 },
                                             { offset = { 0.015, 0 }, radius = 0.01 } },
                                 material = mat, position = { 0.2, 0.2 }, orientation = 0.1,
                                 velocity = { 1, 0 }, spin = 1, resolution = 64 } } end,
    accept = { template = OPT, members = { "short", "long" }, material = OPT, position = {},
               orientation = { "nil", "zero", "negative" }, velocity = OPT,
               spin = { "nil", "zero", "negative" }, resolution = OPT },
  },
  ["dem.scene:clump"] = {
    setup = function() local s = scene2()
      s:add_clump{ members = { { offset = { 0, 0 }, radius = 0.01 } }, material = mat,
                   position = { 0.2, 0.2 } }; return s end,
    self = self, args = function() return { 1 } end, pos = { ID },
  },
  ["dem.scene:clump_count"] = { setup = scene2, self = self },
  ["dem.scene:particles"] = { setup = scene2, self = self },
  ["dem.scene:set_reference"] = { setup = scene2, self = self },
  ["dem.scene:clear_forces"] = { setup = scene2, self = self },
  ["dem.scene:info"] = { setup = scene2, self = self },
  ["dem.scene:scale_mass"] = { setup = scene2, self = self, args = function() return { 2 } end, pos = { {} } },
  ["dem.scene:scale_stiffness"] = { setup = scene2, self = self, args = function() return { 2 } end, pos = { {} } },
  ["dem.scene:gravity"] = { setup = scene2, self = self, args = function() return { { 0, -9.81 } } end, pos = { { "nil" } } },
  ["dem.scene:drag"] = { setup = scene2, self = self, args = function() return { 1 } end, pos = { { "nil", "zero" } } },
  ["dem.scene:set_forces"] = {
    setup = scene2, self = self, opts = 1,
    args = function() return { { ids = { 1 }, fx = { 1 }, fy = { 0 } } } end,
    accept = { ids = {}, fx = {}, fy = {}, fz = OPT },
  },
  ["dem.scene:damping_time"] = {
    { setup = function() local s = scene2(); s:add_disk{ pos = { 0.7, 0.5 }, radius = 0.01 }
        s:contact{ damping = "brilliantov", damping_time = 1e-5 }; return s end,
      self = self, args = function() return { 1, { wall = 1 } } end, opts = 2, pos = { ID },
      accept = { wall = {} } },
    { setup = function() local s = scene2(); s:add_disk{ pos = { 0.7, 0.5 }, radius = 0.01 }
        s:contact{ damping = "brilliantov", damping_time = 1e-5 }; return s end,
      self = self, args = function() return { 1, 2 } end, no_opts = true, pos = { ID, ID } },
  },
  ["dem.scene:inserter"] = {
    { setup = scene2, self = self, opts = 1,
      args = function() return { { box = { { 0, 0.5 }, { 1, 1 } }, rate = 100, count = 10, mass = 1,
                                   radius = { 0.01, 0.02 }, velocity = { 0, -1 }, spread = 0.1,
                                   material = mat, seed = 3, every = 10, attempts = 5 } } end,
      accept = { box = {}, center = OPT, extent = OPT, rate = { "nil", "zero" }, count = { "nil", "zero" },
                 mass = OPT, radius = {}, radii = OPT, weights = OPT, velocity = OPT,
                 spread = { "nil", "zero" }, material = OPT, seed = { "nil", "zero" }, every = OPT,
                 attempts = OPT } },
    { setup = scene2, self = self, opts = 1,
      args = function() return { { center = { 0.5, 0.5 }, extent = 0.2, count = 10,
                                   radii = { 0.01, 0.02 }, weights = { 1, 2 } } } end,
      accept = { box = OPT, center = {}, extent = {}, rate = { "nil", "zero" }, count = { "zero" },
                 mass = OPT, radius = OPT, radii = {}, weights = { "nil", "entry_huge" }, velocity = OPT,
                 spread = { "nil", "zero" }, material = OPT, seed = { "nil", "zero" }, every = OPT,
                 attempts = OPT } },
  },
  ["dem.scene:outflow"] = {
    { setup = scene2, self = self, opts = 1, args = function() return { { box = { { 0, 0 }, { 1, 0.1 } } } } end,
      accept = { box = {}, side = OPT } },
    { setup = scene2, self = self, opts = 1, args = function() return { { side = "x-" } } end,
      accept = { box = OPT, side = {} } },
  },
  ["dem.scene:flow"] = { setup = scene2, self = self },
  ["dem.scene:quasistatic"] = {
    setup = scene2, self = self, opts = 1,
    args = function() return { { pressure = 1e5, strain_rate = 1 } } end,
    accept = { pressure = {}, strain_rate = {} },
  },
}
fuzz.checkpoint_calls(calls, "dem", scene2, tmp .. "/state.ckpt")

-- VTK output (lua_vtk.c): the files go to a scratch directory.
local vtkdir = os.tmpname()
os.remove(vtkdir)
os.execute("mkdir -p '" .. vtkdir .. "'")
calls["dem.scene:write_vtk"] = {
  setup = scene2, self = self, opts = 2, opts_optional = true, pos = { {} },
  args = function() return { vtkdir .. "/f.vtu", { contacts = true, walls = false, clumps = true } } end,
  accept = { contacts = BOOL, walls = BOOL, clumps = BOOL },
}
-- The methods lua_analysis.c registers on dem.scene have their own fuzz test.
local elsewhere = "boundary-condition methods of lua_analysis.c: fuzzed by test_fuzz_analysis.lua"
local skip = { ["dem.scene:boundary"] = elsewhere, ["dem.scene:boundary_edges"] = elsewhere,
               ["dem.scene:boundary_info"] = elsewhere, ["dem.scene:spin"] = elsewhere,
               ["dem.scene:springs"] = elsewhere, ["dem.scene:tie"] = elsewhere }
for _, k in ipairs{ "dem.read_lammps_data", "dem.scene:read_lammps_data", "dem.scene:write_lammps_data",
                    "dem.scene:write_lammps_dump" } do skip[k] = "fuzzed by test_lammps_fuzz.lua" end

local template = dem.clump_template{ members = { { offset = { 0, 0 }, radius = 0.01 } } }
calls["dem.clump_template:info"] = { self = function() return template end }
calls["dem.clump_template:members"] = { self = function() return template end }
fuzz.run{ modules = { dem = dem }, types = { ["dem.scene"] = scene2(), ["dem.clump_template"] = template },
          calls = calls, skip = skip }
os.execute("rm -rf '" .. vtkdir .. "'")
os.execute("rm -rf '" .. tmp .. "'")

-- Absurd sizes are refused with the limit in the message.
check.errors(function() dem.scene{ box = { { 0, 0 }, { 1e300, 1 } } } end,
  "bad field 'box' in argument #1 to 'scene' (box corners of magnitude at most 1e+100 expected", "box of 1e300 m")
check.errors(function() scene2():add_disk{ pos = { 0.5, 0.5 }, radius = 0.6 } end,
  "add_disk: radius 0.6 is larger than half the box's smallest extent 0.5 (field 'radius')", "radius above the box")
check.errors(function()
    dem.scene{ box = { { 0, 0 }, { 1e6, 1e6 } } }:add_disk{ pos = { 1, 1 }, radius = 1e-6 }
  end, "add_disk: radius 1e-06 is below 1e-9 of the largest box coordinate 1e+06", "radius lost in rounding")
check.errors(function() scene2():run{ time = 1e99, dt = 1e-6 } end,
  "bad field 'time' in argument #1 to 'run' (time of at most 1e15 steps of dt = 1e-06 s expected, got 1e+99)", "time of 1e99 s")
check.errors(function() scene2():set_velocity(1, { 0, 0, 1 }) end,
  "bad argument #2 to 'set_velocity' (array of 2 finite numbers expected, got table)", "3 components in 2D")
check.errors(function() scene2():wall_velocity(1, { 0, 0, 1 }) end,
  "bad argument #2 to 'wall_velocity' (array of 2 finite numbers expected, got table)", "wall velocity in 3 components")
check.done()
