-- The law table honours a restitution: every normal law (linear, power with beta 1, 3/2 and 2,
-- hertz) with every damping (none, viscous, brilliantov), asked a restitution either in
-- s:contact{ restitution = e, impact_velocity = v } or through the materials (the smaller of a
-- pair's two), rebounds from a head-on impact at v with e, within 1 %, for an equal pair, an
-- unequal pair (radii 1:2, Young's moduli 1:2) and a disk against a wall (of the stiffer
-- material), at v = 0.1, 1 and 10 m/s. Where a combination cannot honour it, s:contact refuses
-- it with a message naming the alternative; e depends on speed for all but the linear spring with
-- viscous damping, so elsewhere e holds at the impact_velocity it was asked for (checked here:
-- the direction it moves at other speeds). dt = the pair's contact time / 400 (the kernel's
-- velocity Verlet gives e to ~5e-4 there). Also: gamma_n and damping_time, when given, win over
-- the restitution; a run with damping solved from restitutions continues bit for bit from a
-- checkpoint, and a file without the coefficients its law needs is refused.
local check = grainlab.check
grainlab.threads(1)

local E = 30e9
local laws = {
  { name = "linear", c = { normal = "linear", stiffness = 1e5 }, beta = 1 },
  { name = "power beta 1", c = { normal = "power", beta = 1, stiffness = 1e5 }, beta = 1 },
  { name = "power beta 1.5", c = { normal = "power", beta = 1.5, stiffness = 1e7 }, beta = 1.5 },
  { name = "power beta 2", c = { normal = "power", beta = 2, stiffness = 1e9 }, beta = 2 },
  { name = "hertz", c = { normal = "hertz" }, beta = 1.5 },
}
local speeds = { 0.1, 1, 10 }
local cases = { "equal", "unequal", "wall" }

local function law_def(law, damping, extra)
  local c = {}
  for k, v in pairs(law.c) do c[k] = v end
  c.damping = damping
  for k, v in pairs(extra or {}) do c[k] = v end
  return c
end

-- A head-on impact at v of case `case`; restitutions e1 (particle 1), e2 (particle 2 or the
-- wall). Returns the measured e and the steps run.
local function collide(c, case, v, e1, e2)
  local m1 = grainlab.material{ density = 2650, young = E, poisson = 0.3, restitution = e1 }
  local m2 = grainlab.material{ density = 2650, young = case == "equal" and E or 2 * E, poisson = 0.3,
                                restitution = case == "equal" and e1 or e2 }
  local s = dem.scene{ dim = 2, box = { { -0.01, -0.01 }, { 0.01, 0.01 } } }
  s:contact(c)
  local r1, r2, gap = 1e-3, case == "unequal" and 2e-3 or 1e-3, 1e-9
  if case == "wall" then
    s:add_wall{ point = { 0, 0 }, normal = { 1, 0 }, material = m2 }
    s:add_disk{ pos = { r1 + gap, 0 }, radius = r1, material = m1, vel = { -v, 0 } }
  else
    s:add_disk{ pos = { -r1 - gap / 2, 0 }, radius = r1, material = m1, vel = { v / 2, 0 } }
    s:add_disk{ pos = { r2 + gap / 2, 0 }, radius = r2, material = m2, vel = { -v / 2, 0 } }
  end
  -- the lightest pair's contact time (the other pairs' are longer), and the dashpot's limit
  local ts = s:timestep{ impact_velocity = v }
  local dt = math.min(ts.contact_time / 400, ts.limit / 40)
  local steps, t_end = 0, gap / v + ts.contact_time
  repeat
    s:run{ steps = 200, dt = dt, progress = false }
    steps = steps + 200
  until (s:measure("contacts").count == 0 and s:info().time > t_end) or steps > 20000
  check.eq(s:measure("contacts").count, 0, "the contact has ended")
  local p = s:particles()
  return case == "wall" and p.vx[1] / v or (p.vx[2] - p.vx[1]) / v, steps
end

local measured, n_runs = {}, 0
local function expect(what, c, case, v, e1, e2, want)
  local e = collide(c, case, v, e1, e2)
  n_runs = n_runs + 1
  measured[#measured + 1] = string.format("%-44s %-8s %5g m/s  e = %.5f (asked %g)", what, case, v, e, want)
  check.near(e, want, 0.01, string.format("%s, %s pair, %g m/s", what, case, v))
  return e
end

local function speed_dependent(law, damping) return not (damping == "viscous" and law.beta == 1) end

for _, law in ipairs(laws) do
  for _, damping in ipairs{ "none", "viscous", "brilliantov" } do
    local what = law.name .. " + " .. damping
    local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }
    if damping == "brilliantov" and law.c.normal ~= "hertz" then
      -- refused whatever is asked, naming the alternative
      check.errors(function() s:contact(law_def(law, damping, { restitution = 0.7 })) end,
        "bad field 'damping' in argument #1 to 'contact' ('none' or 'viscous' with the linear and power laws " ..
        "(brilliantov damping needs normal = 'hertz', 'jkr' or 'dmt'; viscous damping honours a restitution with every law) " ..
        "expected, got 'brilliantov')", what .. ": refused")
    elseif damping == "none" then
      -- no damping rebounds with 1: a restitution below 1 is refused, 1 is honoured
      local alt = law.c.normal == "hertz" and "damping = 'viscous' or 'brilliantov'" or "damping = 'viscous'"
      check.errors(function() s:contact(law_def(law, damping, { restitution = 0.7 })) end,
        "bad field 'restitution' in argument #1 to 'contact' (1 when 'damping' is 'none' (for a rebound " ..
        "below 1 give " .. alt .. ") expected, got 0.7)", what .. ": restitution 0.7 refused")
      check.errors(function() s:contact(law_def(law, damping, { impact_velocity = 1 })) end,
        "bad field 'impact_velocity' in argument #1 to 'contact' (nothing unless 'damping' is 'viscous' or " ..
        "'brilliantov'", what .. ": impact_velocity refused")
      for _, case in ipairs(cases) do
        for _, v in ipairs(speeds) do
          expect(what .. ", restitution 1", law_def(law, damping, { restitution = 1 }), case, v, 0.5, 0.5, 1)
        end
      end
    else
      for _, case in ipairs(cases) do
        for _, v in ipairs(speeds) do
          local at = speed_dependent(law, damping) and { impact_velocity = v } or {}
          -- s:contact's restitution (the materials' are elastic)
          local c = law_def(law, damping, at)
          c.restitution = 0.7
          expect(what .. ", contact e = 0.7", c, case, v, 1, 1, 0.7)
          -- the materials': the smaller of the two (the wall's material too)
          expect(what .. ", materials' e = 0.5, 0.8", law_def(law, damping, at), case, v, 0.8, 0.5,
                 case == "equal" and 0.8 or 0.5)
        end
      end
      if speed_dependent(law, damping) then
        local c = law_def(law, damping, { restitution = 0.7, impact_velocity = 1 })
        local slow, fast = collide(c, "equal", 0.1, 1, 1), collide(c, "equal", 10, 1, 1)
        measured[#measured + 1] = string.format("%-44s asked 0.7 at 1 m/s: e = %.4f at 0.1 m/s, %.4f at 10 m/s",
                                                what, slow, fast)
        if damping == "viscous" then -- gamma fixed: the slower contact is the more damped
          check.lt(slow, 0.69, what .. ": asked at 1 m/s, lower at 0.1 m/s")
          check.gt(fast, 0.71, what .. ": asked at 1 m/s, higher at 10 m/s")
        else -- Brilliantov: higher when slower
          check.gt(slow, 0.71, what .. ": asked at 1 m/s, higher at 0.1 m/s")
          check.lt(fast, 0.69, what .. ": asked at 1 m/s, lower at 10 m/s")
        end
      else
        local s2 = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }
        check.errors(function() s2:contact(law_def(law, damping, { restitution = 0.7, impact_velocity = 1 })) end,
          "bad field 'impact_velocity' in argument #1 to 'contact' (nothing with viscous damping of a linear " ..
          "spring (beta = 1): its restitution holds at every speed expected, got 1)", what .. ": impact_velocity refused")
      end
    end
  end
end
check.ge(n_runs, 150, "collisions run")

-- given coefficients win over the materials' restitution, and refuse a contact restitution
for _, law in ipairs{ laws[1], laws[5] } do
  check.near(collide(law_def(law, "viscous", { gamma_n = 0 }), "equal", 1, 0.5, 0.5), 1, 1e-6,
             law.name .. ": gamma_n = 0 wins over the materials' restitution 0.5")
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } }
  check.errors(function() s:contact(law_def(law, "viscous", { gamma_n = 1, restitution = 0.5 })) end,
    "bad field 'restitution' in argument #1 to 'contact' (nothing when 'gamma_n' is given: give gamma_n (one " ..
    "coefficient for every pair) or restitution (one per pair), not both", law.name .. ": gamma_n and restitution")
  check.errors(function() s:contact(law_def(law, "viscous", { gamma_n = 1, impact_velocity = 1 })) end,
    "bad field 'impact_velocity' in argument #1 to 'contact' (nothing when 'gamma_n' is given", law.name ..
    ": gamma_n and impact_velocity")
end
check.near(collide(law_def(laws[5], "brilliantov", { damping_time = 0 }), "equal", 1, 0.5, 0.5), 1, 1e-6,
           "hertz: damping_time = 0 wins over the materials' restitution 0.5")

-- the README's drum (hertz + viscous, sand of restitution 0.5, impact_velocity = 0.5): a grain
-- falling at 0.5 m/s onto the drum's cylinder (its own material) rebounds with 0.5
do
  local sand = grainlab.material{ density = 2650, young = 5e6, poisson = 0.3, friction = 0.5,
                                  restitution = 0.5, rolling_friction = 0.05 }
  local s = dem.scene{ dim = 2, box = { { -0.03, -0.03 }, { 0.03, 0.03 } } }
  s:contact{ normal = "hertz", damping = "viscous", impact_velocity = 0.5, tangential = "spring",
             rolling_resistance = "epsd" }
  s:add_cylinder{ center = { 0, 0 }, radius = 0.025, material = sand }
  local r, v = 1.15e-3, 0.5
  s:add_disk{ pos = { 0, -0.025 + r + 1e-9 }, radius = r, material = sand, vel = { 0, -v } }
  local dt = s:timestep{ impact_velocity = v }.contact_time / 400
  local steps = 0
  repeat s:run{ steps = 200, dt = dt, progress = false }; steps = steps + 200
  until (s:measure("contacts").count == 0 and s:particles().vy[1] > 0) or steps > 20000
  local e = s:particles().vy[1] / v
  measured[#measured + 1] = string.format("README drum: a sand grain on the cylinder at 0.5 m/s: e = %.5f", e)
  check.near(e, 0.5, 0.01, "the README's drum: a grain on the cylinder at 0.5 m/s rebounds with 0.5")
end

-- ---- checkpoints: the solved coefficients are saved; a file without them is refused -----------
local F = dofile("../lua/lib/ckpt_files.lua")
local dir = os.tmpname()
os.remove(dir)
assert(os.execute("mkdir -p '" .. dir .. "'"))
local function path(name) return dir .. "/" .. name end

-- a small damped pile of two materials against a floor
local function pile(c)
  local a = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3, friction = 0.3, restitution = 0.6 }
  local b = grainlab.material{ density = 2650, young = 2e7, poisson = 0.3, friction = 0.3, restitution = 0.3 }
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.04 } }, gravity = { 0, -9.81 } }
  s:contact(c)
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 }, material = b }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.02, 0 }, normal = { -1, 0 } }
  for k = 0, 11 do -- three rows of four, overlapping, thrown down
    s:add_disk{ pos = { 0.003 + (k % 4) * 0.0042 + (k // 4) * 0.0008, 0.0016 + (k // 4) * 0.0031 },
                radius = 0.0015 + 0.0001 * (k % 3 - 1), material = k % 2 == 0 and a or b, vel = { 0, -0.3 } }
  end
  return s
end
local function dump(s)
  local p, out = s:particles(), {}
  for i = 1, p.count do out[#out + 1] = string.format("%a %a %a %a", p.x[i], p.y[i], p.vx[i], p.vy[i]) end
  return table.concat(out, "\n")
end
local run = function(s, n) s:run{ steps = n, dt = 2e-6, progress = false } end
local solved = {
  { "hertz + viscous, materials' e", { normal = "hertz", damping = "viscous", impact_velocity = 0.3, tangential = "spring" } },
  { "hertz + brilliantov, materials' e", { normal = "hertz", damping = "brilliantov", impact_velocity = 0.3 } },
  { "power beta 2 + viscous, contact e", { normal = "power", beta = 2, stiffness = 1e8, damping = "viscous",
                                           restitution = 0.4, impact_velocity = 0.3 } },
  { "linear + viscous, clipped, materials' e", { normal = "linear", stiffness = 2e3, damping = "viscous" } },
}
for _, case in ipairs(solved) do
  local what, c = case[1], case[2]
  local a = pile(c)
  run(a, 3000)
  local b = pile(c)
  run(b, 1500)
  b:save(path("law.ckpt"))
  local l = dem.load(path("law.ckpt"))
  run(l, 1500)
  check.is_true(dump(a) == dump(l), what .. ": N + M against N, save, load, M (bits)")
  local undamped = {}
  for k, v in pairs(c) do undamped[k] = v end
  undamped.damping, undamped.restitution, undamped.impact_velocity = "none", nil, nil
  local u = pile(undamped)
  run(u, 3000)
  check.is_true(dump(a) ~= dump(u), what .. ": the damping acts (the run differs from an undamped one)")
end

-- a file whose law needs the coefficients but lacks the section (renamed and made optional: the
-- section header is a 16-byte tag, then its uint32 flags) is refused by the writer's list of
-- sections, naming what is missing
do
  local s = pile(solved[1][2])
  run(s, 10)
  s:save(path("good.ckpt"))
  local bytes = F.read(path("good.ckpt"))
  local at = bytes:find("damping\0", 1, true)
  check.is_true(at ~= nil, "the file has a 'damping' section")
  local forged = F.put(F.put(bytes, at - 1, "dampinx\0"), at - 1 + 16, string.pack("=I4", 0))
  F.write(path("forged.ckpt"), F.reseal(forged))
  check.errors(function() dem.load(path("forged.ckpt")) end,
    "'" .. path("forged.ckpt") .. "' is corrupt (section 'dampinx', number 7 of the file, is not where its " ..
    "writer listed it)", "a file without the solved coefficients")
  check.is_true(dem.load(path("good.ckpt")) ~= nil, "the unforged file loads")
  -- a law with a closed form (the unclipped linear spring) writes no section
  local u = pile{ normal = "linear", stiffness = 2e3, damping = "viscous", clip = false }
  run(u, 10)
  u:save(path("closed.ckpt"))
  check.is_true(F.read(path("closed.ckpt")):find("damping\0", 1, true) == nil,
                "the unclipped linear spring (a closed form) saves no coefficients")
end
os.execute("rm -rf '" .. dir .. "'")

if os.getenv("GRAINLAB_VERBOSE") then print(table.concat(measured, "\n")) end
check.done()
