-- Checkpoints of walls beyond planes (section "wall_shapes"): run N + M steps, or N, save, load,
-- M: the same bits (%a) for every position, velocity and spin and for each wall's load, with a
-- drum turning by a motion table, a rotating closed polygon, a translating segment (2D), a turning
-- mesh and a finite cylinder (3D), spring friction (the walls' contact history), with velocity
-- Verlet and Gear; saved with 1 thread, loaded with 2.
local check = grainlab.check

local dir = os.tmpname()
os.remove(dir)
assert(os.execute("mkdir -p '" .. dir .. "'"))
local file = dir .. "/walls.ckpt"

local function build(dim)
  local mat = grainlab.material{ density = 1000, young = 2e6, poisson = 0.3, friction = 0.5 }
  local s
  if dim == 2 then
    s = dem.scene{ dim = 2, box = { { -0.06, -0.06 }, { 0.06, 0.06 } }, gravity = { 0, -9.81 } }
  else
    s = dem.scene{ dim = 3, box = { { -0.06, -0.06, -0.06 }, { 0.06, 0.06, 0.06 } },
                   gravity = { 0, 0, -9.81 } }
  end
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.6, impact_velocity = 0.5,
             tangential = "spring" }
  local walls = {}
  if dim == 2 then
    walls[#walls + 1] = s:add_cylinder{ center = { 0, 0 }, radius = 0.05, material = mat,
                                        motion = { { 0, 0, 0, 0 }, { 0.002, 0, 0, 5 }, { 1, 0, 0, 5 } } }
    walls[#walls + 1] = s:add_polyline{ points = { { -0.008, -0.033 }, { 0.008, -0.033 }, { 0.008, -0.017 },
                                                   { -0.008, -0.017 } }, closed = true, omega = -3 }
    walls[#walls + 1] = s:add_polyline{ points = { { -0.04, 0.035 }, { 0.04, 0.035 } },
                                        velocity = { 0, -0.05 } }
  else
    walls[#walls + 1] = s:add_cylinder{ center = { 0, 0, 0 }, radius = 0.05, axis = { 1, 0, 0 },
                                        length = 0.1, material = mat, omega = { 4, 0, 0 } }
    local a, b, c = { -0.03, -0.03, -0.01 }, { 0.03, -0.03, -0.01 }, { 0, 0.03, -0.02 }
    walls[#walls + 1] = s:add_mesh{ triangles = { { a, b, c } }, center = { 0, 0, -0.015 },
                                    omega = { 0, 0, 2 } }
  end
  local k = 0
  for i = 0, 5 do
    for j = 0, 1 do
      k = k + 1
      local x, y = -0.025 + 0.01 * i, 0.015 + 0.011 * j
      local jig = ((k * 7919) % 13) / 13 - 0.5
      if dim == 2 then
        s:add_disk{ pos = { x, y }, radius = 0.005 + 0.0005 * jig, material = mat,
                    vel = dim == 2 and { 0.2 * jig, -1 } or { 0, 0.2 * jig, -1 } }
      else
        s:add_sphere{ pos = { 0.01 * jig, x, y }, radius = 0.005 + 0.0005 * jig, material = mat,
                    vel = dim == 2 and { 0.2 * jig, -1 } or { 0, 0.2 * jig, -1 } }
      end
    end
  end
  return s, walls
end

local function dump(s, walls)
  local p = s:particles()
  local out = { string.format("t %a", s:info().time) }
  for i = 1, p.count do
    local row = {}
    for _, key in ipairs{ "x", "y", "z", "vx", "vy", "vz", "omega", "wx", "wy", "wz" } do
      if p[key] then row[#row + 1] = string.format("%a", p[key][i]) end
    end
    out[#out + 1] = table.concat(row, " ")
  end
  for _, w in ipairs(walls) do
    local f, t = s:wall_load(w)
    local q = s:wall_point(w)
    out[#out + 1] = string.format("wall %a %a %a | %a %a %a | %s | %a", f[1], f[2], f[3] or 0,
                                  q[1], q[2], q[3] or 0,
                                  type(t) == "table" and string.format("%a %a %a", t[1], t[2], t[3])
                                    or string.format("%a", t), s:wall_force(w))
  end
  return table.concat(out, "\n")
end

local N, M = 2000, 2000
for _, dim in ipairs{ 2, 3 } do
  for _, integ in ipairs{ "velocity_verlet", "gear" } do
    local what = string.format("%dD %s", dim, integ)
    grainlab.threads(1)
    local a, wa = build(dim)
    a:run{ steps = N + M, dt = 2e-5, integrator = integ }
    local b, wb = build(dim)
    b:run{ steps = N, dt = 2e-5, integrator = integ }
    b:save(file)
    grainlab.threads(2)
    local c = dem.load(file)
    check.eq(dump(c, wb), dump(b, wb), what .. ": the loaded scene is the saved one")
    c:run{ steps = M, dt = 2e-5, integrator = integ }
    check.eq(dump(c, wb), dump(a, wa), what .. ": N + M against N, save, load, M")
    -- the run must see what it claims to: wall contacts with tangential (history) forces
    local d = build(dim)
    local walled, sliding = 0, 0
    d:run{ steps = N + M, dt = 2e-5, integrator = integ, every = 25, on_step = function(sc)
      local C = sc:measure("contacts")
      for k = 1, C.count do
        if C.j[k] < 0 then walled = walled + 1 end
        if C.j[k] < 0 and C.ft[k] > 0 then sliding = sliding + 1 end
      end
    end }
    check.gt(walled, 10, what .. ": particles touch the shaped walls")
    check.gt(sliding, 0, what .. ": with tangential (history) forces")
  end
end
grainlab.threads(1)
os.remove(file)
os.execute("rmdir '" .. dir .. "'")
check.done()
