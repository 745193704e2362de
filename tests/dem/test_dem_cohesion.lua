-- Cohesive contacts (normal 'jkr' and 'dmt', cohesion 'capillary'): their checkpoints continue
-- bit for bit (the contacts that hold beyond touch are contact history, of pairs and planes),
-- sticky grains stay stuck where plain ones part, on each other and on planes, and every bad value is refused naming the call, field and value.
-- The closed forms are scripts/cohesion.lua's (script_cohesion_small).
local check = grainlab.check

-- Every position, velocity and spin there is, and the counters, in %a.
local function dump(s)
  local p, info = s:particles(), s:info()
  local out = { string.format("t %a steps %d", info.time, info.steps) }
  for _, key in ipairs({ "x", "y", "z", "vx", "vy", "vz", "omega", "wx", "wy", "wz", "fx", "fy", "fz" }) do
    for i = 1, p[key] and p.count or 0 do out[#out + 1] = string.format("%s %d %a", key, i, p[key][i]) end
  end
  return table.concat(out, "\n")
end

local dir = os.tmpname()
os.remove(dir)
assert(os.execute("mkdir -p '" .. dir .. "'"))
local function path(name) return dir .. "/" .. name end

-- A cluster of sticky grains thrown onto a floor: contacts form, hold past touch and break.
local function build(dim, contact, tang)
  local mat = grainlab.material{ density = 1000, young = 1e6, poisson = 0.3, friction = 0.4,
                                 work_of_adhesion = 2 }
  local L = 0.02
  local box = dim == 2 and { { 0, 0 }, { L, L } } or { { 0, 0, 0 }, { L, L, L } }
  local s = dem.scene{ dim = dim, box = box, gravity = dim == 2 and { 0, -9.81 } or { 0, 0, -9.81 } }
  local c = { tangential = tang }
  for k, v in pairs(contact) do c[k] = v end
  s:contact(c)
  local up = dim == 2 and { 0, 1 } or { 0, 0, 1 }
  s:add_wall{ point = dim == 2 and { 0, 0 } or { 0, 0, 0 }, normal = up }
  local k = 0
  for a = 0, 3 do
    for b = 0, 3 do
      k = k + 1
      local jig = ((k * 7919) % 13) / 13 - 0.5
      local x, y = 0.006 + a * 0.0021 + 0.0001 * jig, 0.003 + b * 0.0021
      local p = { radius = 0.001 * (1 + 0.1 * jig), material = mat }
      if dim == 2 then
        p.pos, p.vel = { x, y }, { 0.05 * jig, -0.2 - 0.1 * jig }
      else
        p.pos, p.vel = { x, 0.01 + 0.0002 * jig, y }, { 0.05 * jig, 0.03 * jig, -0.2 - 0.1 * jig }
      end
      if dim == 2 then s:add_disk(p) else s:add_sphere(p) end
    end
  end
  return s
end

local function run(s, steps) s:run{ steps = steps, dt = 2e-6, progress = false } end

local cases = {
  { name = "jkr", contact = { normal = "jkr" } },
  { name = "jkr, viscous damping", contact = { normal = "jkr", damping = "viscous", gamma_n = 1e-3 } },
  { name = "dmt", contact = { normal = "dmt", work_of_adhesion = 1 } },
  { name = "capillary", contact = { normal = "hertz", cohesion = "capillary", liquid_volume = 1e-11,
                                    surface_tension = 0.07, contact_angle = 30 } },
}
local N, M = 1500, 1500
for _, dim in ipairs({ 2, 3 }) do
  for _, cs in ipairs(cases) do
    for _, tang in ipairs({ "none", "spring" }) do
      local what = string.format("%dD %s, tangential %s", dim, cs.name, tang)
      local a = build(dim, cs.contact, tang)
      run(a, N + M)
      local b = build(dim, cs.contact, tang)
      run(b, N)
      b:save(path("coh.ckpt"))
      local c = dem.load(path("coh.ckpt"))
      check.eq(c:info().normal, cs.contact.normal, what .. ": the law is loaded")
      run(c, M)
      local da, dc = dump(a), dump(c)
      check.is_true(da == dc, what .. ": saved, loaded, continued: the same bits")
    end
  end
end

-- The same bits on 1 and 2 threads: a bed large enough for the threads (over 4096 pairs), with
-- bonds forming and holding across gaps as it settles.
for _, contact in ipairs({ { normal = "jkr", tangential = "spring" },
                           { normal = "hertz", cohesion = "capillary", liquid_volume = 1e-11,
                             surface_tension = 0.07, tangential = "spring" } }) do
  local function bed()
    local mat = grainlab.material{ density = 1000, young = 1e6, friction = 0.4, work_of_adhesion = 2 }
    local s = dem.scene{ box = { { 0, 0 }, { 0.16, 0.16 } }, gravity = { 0, -9.81 } }
    s:contact(contact)
    s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
    for a = 0, 69 do
      for b = 0, 69 do
        local jig = (((a * 70 + b) * 7919) % 13) / 13 - 0.5
        s:add_disk{ pos = { 0.0011 + a * 0.00199, 0.0011 + b * 0.00199 },
                    radius = 0.001 * (1 + 0.004 * jig), material = mat, vel = { 0.3 * jig, -0.05 } }
      end
    end
    return s
  end
  local function go(threads)
    grainlab.threads(threads)
    local s = bed()
    s:run{ steps = 200, dt = 2e-6, progress = false }
    grainlab.threads(1)
    return dump(s)
  end
  check.is_true(go(1) == go(2), (contact.cohesion or contact.normal) .. ": 1 and 2 threads, the same bits")
end

-- Sticky grains stay stuck: a pair pulled apart gently holds with JKR, parts with Hertz.
do
  local function pair(normal)
    local mat = grainlab.material{ density = 1000, young = 1e6, poisson = 0.3, work_of_adhesion = 2 }
    local s = dem.scene{ dim = 3, box = { { -0.01, -0.01, -0.01 }, { 0.01, 0.01, 0.01 } } }
    s:contact{ normal = normal, damping = "viscous", gamma_n = 0.05 }
    s:add_sphere{ pos = { 0, 0, 0 }, radius = 0.001, material = mat, fixed = true }
    s:add_sphere{ pos = { 0.00199, 0, 0 }, radius = 0.001, material = mat, vel = { 0.001, 0, 0 } }
    s:run{ steps = 20000, dt = 2e-6, progress = false }
    return s:particles().x[2] - 0.002
  end
  check.lt(pair("jkr"), 0, "jkr: the pair holds together")
  check.gt(pair("hertz"), 1e-5, "hertz: the pair parts")
end

-- Planes stick too (R* = r): a sphere on a floor pulled up by 0.9 of its pull-off force stays,
-- by 1.1 it leaves; the same for a liquid bridge (pull-off 4 pi r gamma cos(theta)), in 2D and 3D.
for _, dim in ipairs({ 2, 3 }) do
  for _, law in ipairs({ "jkr", "dmt", "capillary" }) do
    local function pull(load)
      local r, G = 50e-6, 0.1
      local mat = grainlab.material{ density = 2500, young = 1e8, poisson = 0.25, work_of_adhesion = G }
      local box = dim == 2 and { { -1e-3, 0 }, { 1e-3, 1e-2 } } or { { -1e-3, -1e-3, 0 }, { 1e-3, 1e-3, 1e-2 } }
      local s = dem.scene{ dim = dim, box = box }
      local c = { normal = law == "capillary" and "hertz" or law, damping = "viscous", gamma_n = 1e-4,
                  tangential = "spring" }
      local gcos = 0.07 * math.cos(math.rad(30))
      if law == "capillary" then
        c.cohesion, c.liquid_volume, c.surface_tension, c.contact_angle = "capillary", 1e-16, 0.07, 30
      end
      s:contact(c)
      local up = dim == 2 and { 0, 1 } or { 0, 0, 1 }
      s:add_wall{ point = dim == 2 and { 0, 0 } or { 0, 0, 0 }, normal = up }
      local p0 = r + 1e-9                               -- approaching: it touches, and sticks
      local add = dim == 2 and s.add_disk or s.add_sphere
      add(s, { pos = dim == 2 and { 0, p0 } or { 0, 0, p0 }, radius = r, material = mat,
               vel = dim == 2 and { 0, -0.01 } or { 0, 0, -0.01 } })
      local f_po = law == "jkr" and 1.5 * math.pi * G * r or law == "dmt" and 2 * math.pi * G * r
                   or 4 * math.pi * r * gcos
      local f = { ids = { 1 }, fx = { 0 }, fy = { 0 } }
      if dim == 2 then f.fy[1] = load * f_po else f.fz = { load * f_po } end
      s:set_forces(f)
      s:run{ time = 3e-4, progress = false }
      local p = s:particles()
      return (dim == 2 and p.y[1] or p.z[1]) - r
    end
    local held, torn = pull(0.9), pull(1.1)
    local what = string.format("%dD %s on a plane", dim, law)
    check.lt(held, 2e-7, what .. ": 0.9 of the pull-off force, it stays")
    check.gt(torn, 1e-6, what .. ": 1.1 of it, it leaves")
  end
end

-- A scene whose normal law stops being cohesive drops its bonds and runs as before.
do
  local s = build(2, { normal = "jkr" }, "spring")
  run(s, 200)
  s:contact{ normal = "hertz", tangential = "spring" }
  run(s, 200)
  check.eq(s:info().normal, "hertz", "the law changed back")
end

-- ---- bad values ----------------------------------------------------------------------------
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }
check.errors(function() s:contact{ normal = "jkr", work_of_adhesion = -1 } end,
             "bad field 'work_of_adhesion' in argument #1 to 'contact' (non-negative number expected, got -1)",
             "a negative work of adhesion")
check.errors(function() s:contact{ normal = "hertz", work_of_adhesion = 0.1 } end,
             "bad field 'work_of_adhesion' in argument #1 to 'contact' (nothing unless 'normal' is 'jkr' or 'dmt'",
             "a work of adhesion without jkr or dmt")
check.errors(function() s:contact{ cohesion = "capillary", liquid_volume = 1e-9, surface_tension = 0.07,
                                   contact_angle = 180 } end,
             "bad field 'contact_angle' in argument #1 to 'contact' (number of degrees in [0, 180) expected, got 180)",
             "a contact angle of 180 degrees")
check.errors(function() s:contact{ cohesion = "capillary", liquid_volume = 1e-9, surface_tension = 0.07,
                                   contact_angle = -5 } end,
             "bad field 'contact_angle' in argument #1 to 'contact' (non-negative number expected, got -5)",
             "a negative contact angle")
check.errors(function() s:contact{ cohesion = "capillary", liquid_volume = 0, surface_tension = 0.07 } end,
             "bad field 'liquid_volume' in argument #1 to 'contact' (positive number expected, got 0)",
             "a liquid volume of 0")
check.errors(function() s:contact{ cohesion = "capillary", surface_tension = 0.07 } end,
             "bad field 'liquid_volume' in argument #1 to 'contact'", "the liquid volume is required")
check.errors(function() s:contact{ normal = "jkr", cohesion = "capillary", liquid_volume = 1e-9,
                                   surface_tension = 0.07 } end,
             "bad field 'cohesion' in argument #1 to 'contact' ('none' with normal = 'jkr' or 'dmt'",
             "a liquid bridge on jkr is refused by name")
check.errors(function() s:contact{ liquid_volume = 1e-9 } end,
             "bad field 'liquid_volume' in argument #1 to 'contact' (nothing unless 'cohesion' is 'capillary'",
             "a liquid volume without a bridge")
check.errors(function() s:contact{ normal = "dmt", stiffness = 1e5 } end,
             "bad field 'stiffness' in argument #1 to 'contact'", "dmt takes the materials' moduli")
check.errors(function() grainlab.material{ density = 1, young = 1, work_of_adhesion = -0.5 } end,
             "bad field 'work_of_adhesion' in argument #1 to 'material' (non-negative number expected, got -0.5)",
             "a material's negative work of adhesion")
s:contact{ normal = "dmt", damping = "brilliantov", damping_time = 1e-6 }
check.eq(s:info().normal, "dmt", "brilliantov damping composes with dmt")
s:contact{ normal = "linear", stiffness = 1e4, cohesion = "capillary", liquid_volume = 1e-9,
           surface_tension = 0.07, contact_angle = 45 }
check.eq(s:info().cohesion, "capillary", "a bridge on the linear law")

os.execute("rm -rf '" .. dir .. "'")
check.done()
