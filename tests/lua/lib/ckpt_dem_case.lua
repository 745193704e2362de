-- The scenes of the DEM checkpoint tests (tests/dem/test_checkpoint_dem.lua and
-- tests/cli/test_checkpoint.sh): a small box of disks (2D) or spheres (3D) falling under gravity
-- onto a floor, with Hertz contacts, Brilliantov damping from a restitution, Cundall-Strack
-- spring friction (contact history), two materials, a wall moving sideways, a servo lid, one
-- fixed and one prescribed particle, an external force, drag and mass scaling. Every state the
-- checkpoint must carry is exercised within a few hundred steps.
local M = {}

M.integrators = { "velocity_verlet", "position_verlet", "gear", "two_timescales" }
M.dt = { [2] = 2e-5, [3] = 2e-5 }

-- rolling: nil, or a rolling resistance law ("epsd" with its damping, "constant"): the
-- materials get rolling frictions 0.2 and 0.1, the walls take the particles' own.
function M.build(dim, rolling)
  local soft = grainlab.material{ density = 1000, young = 2e6, poisson = 0.3, friction = 0.5,
                                  rolling_friction = rolling and 0.2 or 0 }
  local hard = grainlab.material{ density = 2000, young = 5e6, poisson = 0.25, friction = 0.3,
                                  rolling_friction = rolling and 0.1 or 0 }
  local L = 0.02
  local box = dim == 2 and { { 0, 0 }, { L, 2 * L } } or { { 0, 0, 0 }, { L, L, 2 * L } }
  local g = dim == 2 and { 0, -9.81 } or { 0, 0, -9.81 }
  local s = dem.scene{ dim = dim, box = box, gravity = g }
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.6, impact_velocity = 0.5,
             tangential = "spring", rolling_resistance = rolling,
             rolling_damping = rolling == "epsd" and 0.3 or nil }
  local up = dim == 2 and 2 or 3
  local function vec(x, y, z) if dim == 2 then return { x, y } else return { x, y, z } end end
  -- floor, left wall moving right slowly, a servo lid pushing down, fixed side walls
  s:add_wall{ point = vec(0, 0, 0), normal = dim == 2 and { 0, 1 } or { 0, 0, 1 } }
  s:add_wall{ point = vec(0, 0, 0), normal = vec(1, 0, 0), velocity = vec(0.01, 0, 0) }
  local lid = s:add_wall{ point = vec(0, 1.8 * L, 1.8 * L),
                          normal = dim == 2 and { 0, -1 } or { 0, 0, -1 } }
  s:add_wall{ point = vec(L, 0, 0), normal = vec(-1, 0, 0) }
  if dim == 3 then
    s:add_wall{ point = { 0, 0, 0 }, normal = { 0, 1, 0 } }
    s:add_wall{ point = { 0, L, 0 }, normal = { 0, -1, 0 } }
  end
  local r, k = 0.0011, 0
  local per = dim == 2 and 7 or 5
  for a = 0, per - 1 do
    for b = 0, per - 1 do
      for c = 0, (dim == 2 and 0 or 2) do
        k = k + 1
        local jig = ((k * 7919) % 13) / 13 - 0.5 -- a fixed irregularity, no random stream
        local x = 0.0015 + a * 0.0023 + 0.0002 * jig
        local y = 0.0015 + b * 0.0023 - 0.0001 * jig
        local z = 0.0015 + c * 0.0023 + 0.0003 * jig
        local p = { pos = dim == 2 and { x, y } or { x, z, y + 0.0006 * c },
                    radius = r * (1 + 0.15 * jig), material = (k % 3 == 0) and hard or soft,
                    vel = vec(0.05 * jig, -0.1, 0.02 * jig) }
        if dim == 2 then p.omega = 3 * jig
        else p.omega = { jig, -jig, 2 * jig } end
        if k == 5 then p.fixed = true end
        if k == 9 then p.prescribed = true; p.vel = vec(0.02, 0, 0.01) end
        if dim == 2 then s:add_disk(p) else s:add_sphere(p) end
      end
    end
  end
  s:wall_servo(lid, { force = 0.02, mass = 0.01, rate = 50 })
  local f = { ids = { 3, 7 }, fx = { 1e-4, -2e-4 }, fy = { 0, 1e-4 } }
  if dim == 3 then f.fz = { 1e-4, 0 } end
  s:set_forces(f)
  s:drag(0.5)
  s:scale_mass(1.5)
  s:set_reference()
  return s
end

-- The 2D scene with boundary conditions: pressure on the closed loop of the outer particles, the
-- minimal-boundary penalty with its integral term, springs along the top row, the bottom-left
-- particle tied to the moving wall, one prescribed spin.
function M.build_boundary()
  local s = M.build(2)
  local loop = {}
  for a = 0, 6 do loop[#loop + 1] = a * 7 + 1 end          -- bottom, left to right
  for b = 1, 6 do loop[#loop + 1] = 6 * 7 + b + 1 end      -- right, upwards
  for a = 5, 0, -1 do loop[#loop + 1] = a * 7 + 7 end      -- top, right to left
  for b = 5, 1, -1 do loop[#loop + 1] = b + 1 end          -- left, downwards
  local ea, eb = {}, {}
  for k = 1, #loop do ea[k], eb[k] = loop[k], loop[k % #loop + 1] end
  s:boundary{ mode = "edges", edges = { a = ea, b = eb }, closed = true, pressure = 20,
              depth = 0.002,
              mbc = { strain_rate = { { -1, 0 }, { 0, 1 } }, rate = 1, kappa = 1, dt = M.dt[2],
                      tau = 50 * M.dt[2] } }
  local si, sj = {}, {}
  for a = 0, 5 do si[#si + 1], sj[#sj + 1] = a * 7 + 7, (a + 1) * 7 + 7 end
  s:springs{ i = si, j = sj, k = 5 }
  s:tie{ ids = { 1 }, wall = 2, axis = 1 }
  s:spin{ id = 25, omega = 5 }
  return s
end

-- The 2D scene with a Delaunay boundary (s:boundary{ mode = 'delaunay' }), whose edges are rebuilt
-- every `every` steps: one variant per combination the binding offers, each with an integrator
-- and the N and M of its round trip, chosen so that rebuilds after step N give other edges than
-- those saved (the tests check that they do).
local ids42 = {}
for k = 1, 42 do ids42[k] = k end -- all but the top row
M.delaunay = {
  { name = "pressure", integ = "two_timescales", n = 500, m = 500,
    def = { every = 50, alpha = 1.2, pressure = 20, depth = 0.002 } },
  { name = "pressure + MBC strain rate with integral", integ = "gear", n = 500, m = 500,
    def = { every = 50, alpha = 1.2, pressure = 20, depth = 0.002,
            mbc = { strain_rate = { { -1, 0 }, { 0, 1 } }, rate = 1, kappa = 1, dt = M.dt[2],
                    tau = 50 * M.dt[2] } } },
  { name = "lateral sides, no band, MBC gradient", integ = "position_verlet", n = 600, m = 400,
    def = { every = 100, sides = "lateral", band = false, pressure = 20, depth = 0.002,
            mbc = { gradient = { { -1, 0.5 }, { 0, 1 } }, rate = 1, kappa = 1, dt = M.dt[2],
                    tau = 20 * M.dt[2] } } },
  { name = "ids, MBC with K and a mask", integ = "velocity_verlet", n = 700, m = 500,
    def = { every = 60, ids = ids42, pressure = 20, depth = 0.002,
            mbc = { strain_rate = { { 0, 0 }, { 0, 0 } }, mask = { { 1, 0 }, { 0, 0 } }, K = 1e-9,
                    tau = 30 * M.dt[2] } } },
}

function M.build_delaunay(k)
  local s = M.build(2)
  local def = { mode = "delaunay" }
  for key, v in pairs(M.delaunay[k].def) do def[key] = v end
  s:boundary(def)
  return s
end

-- The boundary edges and their counters, for comparing rebuilds.
function M.dump_edges(s)
  local e, bi = s:boundary_edges(), s:boundary_info()
  local out = { string.format("boundary %d edges, %d loaded, %d updates", bi.edges, bi.loaded,
                              bi.updates) }
  for k = 1, #e.a do out[#out + 1] = string.format("%d>%d%s", e.a[k], e.b[k], e.loaded[k] and "" or "-") end
  return table.concat(out, " ")
end

function M.run(s, integrator, steps, every, on_step)
  local dt = M.dt[s:info().dim] / (integrator == "two_timescales" and 2 or 1)
  return s:run{ steps = steps, dt = dt, integrator = integrator, m = 2, n = 2,
                q = 2, every = every, on_step = on_step }
end

-- Every position, velocity, angular velocity and angle, the walls and the counters, in %a.
function M.dump(s, nwalls)
  local p = s:particles()
  local info = s:info()
  local keys = info.dim == 2 and { "x", "y", "vx", "vy", "omega", "angle" }
               or { "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz" }
  local out = { string.format("t %a steps %d evals %d", info.time, info.steps,
                              info.force_evaluations) }
  for i = 1, p.count do
    local row = {}
    for _, key in ipairs(keys) do row[#row + 1] = string.format("%a", p[key][i]) end
    out[#out + 1] = table.concat(row, " ")
  end
  for w = 1, nwalls or (info.dim == 2 and 4 or 6) do
    local q = s:wall_point(w)
    out[#out + 1] = string.format("wall %d %a %a %a force %a", w, q[1], q[2], q[3] or 0,
                                  s:wall_force(w))
  end
  local e = s:measure("energy")
  out[#out + 1] = string.format("energy %a %a %a", e.kinetic, e.rotational, e.elastic)
  return table.concat(out, "\n")
end

-- The scene with clumps (tests/dem/test_dem_clump_io.lua, the reader fuzz's seed): dimers and
-- trimers of disks (2D) or spheres (3D) with loose grains between them, dropped at angles and
-- spins into a box with a floor and side walls, Hertz contacts with spring friction (contact
-- history), so that clumps touch each other, loose grains and the walls within a few hundred
-- steps. Runs with velocity Verlet or two timescales (M.run).
function M.build_clumps(dim)
  local mat = grainlab.material{ density = 1500, young = 2e6, poisson = 0.3, friction = 0.5 }
  local L = 0.02
  local box = dim == 2 and { { 0, 0 }, { L, 2 * L } } or { { 0, 0, 0 }, { L, L, 2 * L } }
  local s = dem.scene{ dim = dim, box = box, gravity = dim == 2 and { 0, -9.81 } or { 0, 0, -9.81 } }
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.6, impact_velocity = 0.5,
             tangential = "spring" }
  local function vec(x, y, z) if dim == 2 then return { x, y } else return { x, y, z } end end
  s:add_wall{ point = vec(0, 0, 0), normal = dim == 2 and { 0, 1 } or { 0, 0, 1 } }
  s:add_wall{ point = vec(0, 0, 0), normal = vec(1, 0, 0) }
  s:add_wall{ point = vec(L, 0, 0), normal = vec(-1, 0, 0) }
  if dim == 3 then
    s:add_wall{ point = { 0, 0, 0 }, normal = { 0, 1, 0 } }
    s:add_wall{ point = { 0, L, 0 }, normal = { 0, -1, 0 } }
  end
  local r = 0.001
  local dimer = dem.clump_template{ members = { { offset = vec(-0.7 * r, 0, 0), radius = r },
                                                { offset = vec(0.7 * r, 0, 0), radius = 0.8 * r } } }
  local trimer = dem.clump_template{ members = {
    { offset = vec(0, 0, 0), radius = r }, { offset = vec(1.2 * r, 0, 0), radius = 0.7 * r },
    { offset = vec(0, 1.1 * r, 0.3 * r), radius = 0.8 * r } } }
  local k = 0
  local per, h = dim == 2 and 5 or 4, 0.0036
  for a = 0, per - 1 do
    for b = 0, (dim == 2 and 0 or per - 1) do
      for c = 0, (dim == 2 and 5 or 2) do
        k = k + 1
        local jig = ((k * 7919) % 13) / 13 - 0.5
        local x = 0.0025 + a * h + 0.0003 * jig
        local y = 0.0025 + b * h
        local z = 0.002 + c * h
        local pos = dim == 2 and { x, z } or { x, y, z }
        if k % 4 == 0 then -- a loose grain now and then
          local p = { pos = pos, radius = 0.9 * r, material = mat, vel = vec(0.3 * jig, 0, -0.3) }
          if dim == 2 then s:add_disk(p) else s:add_sphere(p) end
        else
          s:add_clump{ template = k % 2 == 0 and dimer or trimer, material = mat, position = pos,
                       orientation = dim == 2 and 2.1 * k or { axis = { jig, 1, 0.5 }, angle = 0.9 * k },
                       velocity = vec(0.6 * jig, 0.3 * jig, -0.3), spin = dim == 2 and 20 * jig or { 5, -10 * jig, 3 } }
        end
      end
    end
  end
  return s
end

-- M.dump with every clump's state (its s:clump table, numbers in %a).
function M.dump_clumps(s)
  local out = { M.dump(s, s:info().dim == 2 and 3 or 5) }
  local function fmt(v)
    if type(v) ~= "table" then return math.type(v) == "float" and string.format("%a", v) or tostring(v) end
    local t = {}
    for i = 1, #v do t[i] = fmt(v[i]) end
    return "{" .. table.concat(t, " ") .. "}"
  end
  for k = 1, s:clump_count() do
    local c, keys = s:clump(k), {}
    for key in pairs(c) do keys[#keys + 1] = key end
    table.sort(keys)
    local row = { "clump " .. k }
    for _, key in ipairs(keys) do row[#row + 1] = key .. "=" .. fmt(c[key]) end
    out[#out + 1] = table.concat(row, " ")
  end
  return table.concat(out, "\n")
end

return M
