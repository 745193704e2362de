-- Generated bad-input test of grainlab.biax (see fuzz_driver.lua): every configuration field of
-- every biax function taking one, and every positional argument, gets every bad-value class;
-- only the classes declared below are accepted.
local fuzz = dofile("../lua/lib/fuzz_driver.lua")
local OPT = { "nil" }
local calls = {}

-- grainlab.biax: a small state (a 3 x 3 block of disks) and the configuration fields, accepted
-- classes declared once (every biax function taking a configuration checks the same list).
local function state()
  local st = { x = {}, y = {}, r = {} }
  for i = 0, 2 do for j = 0, 2 do
    st.x[#st.x + 1], st.y[#st.y + 1], st.r[#st.r + 1] = 2e-3 * i, 2e-3 * j, 1e-3
  end end
  return st
end
local POS, NONNEG, STEPS = OPT, { "nil", "zero" }, { "nil", "zero" }
local BIAX = { young = POS, poisson = NONNEG, pressure = POS, density = POS, mass_scale = POS,
  friction = NONNEG, rate = POS, dt = POS, rmin = POS, rmax = POS, thickness = NONNEG,
  damping_time = NONNEG, exponent = POS, membrane_k = POS, membrane_radius = POS, every = OPT,
  alpha = POS, kappa = NONNEG, v_r = POS, n = OPT, seed = { "nil", "zero" }, method = OPT,
  shape = OPT, width = POS, ramp_steps = STEPS, hold_steps = STEPS, friction_steps = STEPS,
  rest_steps = STEPS, ramp_stages = OPT, prep_drag = NONNEG, settle_tol = POS,
  settle_rounds = OPT, cache = { "nil", "string" } }
local BIAX_SETUP = {}
for k, v in pairs(BIAX) do BIAX_SETUP[k] = v end
BIAX_SETUP.thickness = OPT -- the boundary pressure needs a depth
local function biax_cfg() return { rate = 1e-3 } end
calls["grainlab.biax.config"] = { args = function() return { biax_cfg() } end, opts = 1,
  opts_optional = true, accept = BIAX }
calls["grainlab.biax.scene"] = { args = function() return { state(), biax_cfg() } end, opts = 2,
  opts_optional = true, pos = { {} }, accept = BIAX }
calls["grainlab.biax.contact"] = { setup = function() return grainlab.biax.scene(state()) end,
  args = function(s) return { s, biax_cfg(), false } end, opts = 2, opts_optional = true,
  pos = { {}, nil, { "nil", "boolean" } }, accept = BIAX }
calls["grainlab.biax.setup"] = { args = function() return { state(), "pressure", biax_cfg() } end,
  opts = 3, opts_optional = true, pos = { {}, {} }, accept = BIAX_SETUP }
calls["grainlab.biax.save"] = { setup = function() return grainlab.biax.scene(state()) end,
  args = function(s) return { s } end, pos = { {} } }
local function lab() local _, l = grainlab.biax.setup(state(), "pressure"); return l end
calls["grainlab.biax.plate_forces"] = { setup = lab, args = function(l) return { l } end, pos = { {} } }
calls["grainlab.biax.axial"] = { setup = lab, args = function(l) return { l } end, pos = { {} } }

-- biax.prepare and biax.prepared: a sample of 3 disks without ramp or rest (a fifth of a second)
-- is the base call; every refused class runs (refused at the entry), every accepted class is
-- printed, not run (a preparation each, of up to 400 disks with the defaults; the same entry
-- check accepts them in grainlab.biax.config above).
local function tiny()
  return { n = 3, ramp_steps = 0, hold_steps = 0, friction_steps = 0, rest_steps = 0, ramp_stages = 1,
           settle_rounds = 1, cache = false }
end
local SLOW = {}
for field, classes in pairs(BIAX) do
  SLOW[field] = {}
  for _, c in ipairs(classes) do SLOW[field][c] = "a sample preparation (accepted as in grainlab.biax.config)" end
end
calls["grainlab.biax.prepare"] = { args = function() local c = tiny(); c.cache = nil; return { c } end,
  opts = 1, opts_optional = true, accept = BIAX, slow = SLOW }
calls["grainlab.biax.prepared"] = { args = function() return { tiny() } end, opts = 1, opts_optional = true,
  accept = BIAX, slow = SLOW }

-- Not fuzzed here, with its reason (printed).
local skip = {
  ["grainlab.biax.start"] = "a servo run of thousands of steps (test_biax_servo covers it); entry checks in biax.lua",
}
for k, why in pairs(skip) do print(k .. ": not fuzzed: " .. why) end

fuzz.run{ modules = { ["grainlab.biax"] = grainlab.biax }, calls = calls, skip = skip }
