-- One DEM scene for the rank-count comparisons of tests/dem/mpi_compare.sh: run on 1, 2 and 3
-- ranks. Every rank formats what it sees (positions, velocities, spins, forces as %a, energies,
-- stress, coordination, wall forces) and checks it against rank 0's (grainlab.mpi.bcast): queries
-- give the same answer on every rank. Rank 0 writes it to out.0; every rank count must give the
-- same bits.
--   grainlab tests/dem/mpi_case.lua dim=2 integrator=velocity_verlet spring=1 walls=1
--            periodic=0 servo=0 gravity=1 n=150 steps=300 out=PREFIX fast=0 dt=5e-7|auto chunks=1
--            rolling=0|1|2
local P = params
local dim = P.dim or 2
local n = P.n or 150
local steps = P.steps or 300
local mpi = grainlab.mpi
local lines = {} -- what this rank sees
local per = (P.periodic or 0) >= 1
local allper = (P.periodic or 0) == 2 -- every axis periodic, no walls: momentum is conserved
local L = P.L or 0.02
local LX = L * (P.wide or 1) -- a long x axis: 3 ranks cut it into 3 slabs
local box = dim == 2 and { { 0, 0 }, { LX, L } } or { { 0, 0, 0 }, { LX, L, L } }
local periodic = dim == 2 and { per, allper } or { per, allper, per }
local g = (P.gravity or 1) == 1 and -9.81 * (P.gscale or 1) or 0
local grav = dim == 2 and { 0, g } or { 0, g, 0 }
local s = dem.scene{ dim = dim, box = box, gravity = grav, periodic = periodic,
                     skin = P.skin }
-- rolling=1: rolling resistance EPSD (its history migrates with the tangential one), 2: constant
local rolling = ({ "epsd", "constant" })[P.rolling or 0]
local quartz = grainlab.material{ name = "quartz", density = 2650, young = 1e8, poisson = 0.3,
                                  friction = 0.45, restitution = 0.9,
                                  rolling_friction = rolling and 0.2 or 0 }
s:contact{ normal = "hertz", damping = "viscous",
           tangential = (P.spring or 1) == 1 and "spring" or "none", rolling_resistance = rolling,
           rolling_damping = rolling == "epsd" and 0.3 or nil }
-- a deterministic generator (the same on every rank, without grainlab's streams)
local seed = 12345
local function rnd()
  seed = (seed * 1103515245 + 12345) % 2147483648
  return seed / 2147483648
end
local walls = (P.walls or 1) == 1 and not allper
if walls then
  s:add_wall{ point = dim == 2 and { 0, 0 } or { 0, 0, 0 }, normal = dim == 2 and { 0, 1 } or { 0, 1, 0 } }
  if not per then
    s:add_wall{ point = dim == 2 and { 0, 0 } or { 0, 0, 0 }, normal = dim == 2 and { 1, 0 } or { 1, 0, 0 } }
    s:add_wall{ point = dim == 2 and { LX, 0 } or { LX, 0, 0 }, normal = dim == 2 and { -1, 0 } or { -1, 0, 0 } }
    if dim == 3 then
      s:add_wall{ point = { 0, 0, 0 }, normal = { 0, 0, 1 } }
      s:add_wall{ point = { 0, 0, L }, normal = { 0, 0, -1 } }
    end
  end
  if (P.servo or 0) == 0 then
    s:add_wall{ point = dim == 2 and { 0, L } or { 0, L, 0 }, normal = dim == 2 and { 0, -1 } or { 0, -1, 0 } }
  end
end
local top
if (P.servo or 0) == 1 then
  top = s:add_wall{ point = dim == 2 and { 0, 0.8 * L } or { 0, 0.8 * L, 0 },
                    normal = dim == 2 and { 0, -1 } or { 0, -1, 0 } }
  s:wall_servo(top, { force = 0.05, mass = 1e-3, rate = 50 })
end
-- particles on a jittered lattice in the lower part of the box (a pile that fills ~60 %)
local r0 = dim == 2 and 0.0004 or 0.0007
local sp = 2.3 * r0
local per_row = math.floor((LX - 2 * r0) / sp)
local added = 0
local k = 0
while added < n do
  local i, j, l = k % per_row, (k // per_row) % per_row, k // (per_row * per_row)
  if dim == 2 then j, l = k // per_row, 0 end
  k = k + 1
  local x = r0 * 1.1 + i * sp + 0.2 * r0 * rnd()
  local y = r0 * 1.1 + j * sp * (P.spread or 1) + 0.2 * r0 * rnd()
  local z = r0 * 1.1 + l * sp + 0.2 * r0 * rnd()
  local vs = P.vscale or 1
  local v = { (rnd() - 0.5) * 2 * vs, (rnd() - 0.5) * 2 * vs, (rnd() - 0.5) * 2 * vs }
  local rad = r0 * (0.8 + 0.2 * rnd())
  v[1] = v[1] + (P.drift or 0) -- a pile moving along a periodic axis: the load shifts
  if dim == 2 then
    s:add_disk{ pos = { x, y }, radius = rad, material = quartz, vel = { v[1], v[2] } }
  else
    s:add_sphere{ pos = { x, y, z }, radius = rad, material = quartz, vel = v }
  end
  added = added + 1
end
if (P.fast or 0) == 1 then
  -- one fast particle high above the others: with a skin wider than two slabs it crosses two
  -- rank boundaries before the list is rebuilt
  local pos = dim == 2 and { 1.5 * r0, 0.8 * L } or { 1.5 * r0, 0.8 * L, 0.5 * L }
  local vel = dim == 2 and { P.fast_v or 10, 0 } or { P.fast_v or 10, 0, 0 }
  if dim == 2 then
    s:add_disk{ pos = pos, radius = r0, material = quartz, vel = vel }
  else
    s:add_sphere{ pos = pos, radius = r0, material = quartz, vel = vel }
  end
end
local function momentum()
  local p = s:particles()
  local m, scale = { 0, 0, 0 }, 0
  for i = 1, #p.x do
    m[1] = m[1] + p.mass[i] * p.vx[i]
    m[2] = m[2] + p.mass[i] * p.vy[i]
    scale = scale + p.mass[i] * (math.abs(p.vx[i]) + math.abs(p.vy[i]))
  end
  return m, scale
end
local m0, mscale = momentum()
local integ = P.integrator or "velocity_verlet"
local dt = P.dt or 5e-7
local chunks = P.chunks or 1
for c = 1, chunks do
  if integ == "two_timescales" then
    s:run{ steps = steps // chunks, dt = dt / 2, integrator = integ, n = 2, q = 2, m = 1 }
  else
    s:run{ steps = steps // chunks, dt = dt, integrator = integ, force = (P.force or 0) == 1 }
  end
end
if (P.check_momentum or 0) == 1 then -- no walls, no gravity: contacts conserve momentum
  local m1 = momentum()
  for d = 1, 2 do
    assert(math.abs(m1[d] - m0[d]) <= 1e-12 * mscale,
           string.format("momentum %d: %.17g before, %.17g after (scale %g)", d, m0[d], m1[d], mscale))
  end
end
local f = { write = function(_, ...) lines[#lines + 1] = table.concat({ ... }) end }
local p = s:particles()
local axes = dim == 2 and { "x", "y" } or { "x", "y", "z" }
local vax = dim == 2 and { "vx", "vy" } or { "vx", "vy", "vz" }
local px, py, pz = 0, 0, 0
for i = 1, #p.x do
  local line = {}
  for _, a in ipairs(axes) do line[#line + 1] = string.format("%a", p[a][i]) end
  for _, a in ipairs(vax) do line[#line + 1] = string.format("%a", p[a][i]) end
  for _, a in ipairs({ "omega", "angle", "wx", "wy", "wz", "fx", "fy", "fz" }) do
    if p[a] then line[#line + 1] = string.format("%a", p[a][i]) end
  end
  px = px + p.mass[i] * p.vx[i]
  py = py + p.mass[i] * p.vy[i]
  if dim == 3 then pz = pz + p.mass[i] * p.vz[i] end
  f:write(table.concat(line, " "), "\n")
end
local e = s:measure("energy")
f:write(string.format("count %d energy %a %a %a\n", #p.x, e.kinetic, e.elastic, e.total))
f:write(string.format("momentum %a %a %a\n", px, py, pz))
local st = s:measure("stress")
f:write(string.format("stress %a %a\n", st.xx, st.yy))
local co = s:measure("coordination")
f:write(string.format("coordination %a\n", co.z))
local w = 1
while walls do
  local ok, fw = pcall(s.wall_force, s, w)
  if not ok then break end
  f:write(string.format("wall %d %a\n", w, fw))
  w = w + 1
end
if top then
  local wp = s:wall_point(top)
  f:write(string.format("servo %a\n", wp[2]))
end
local mine = table.concat(lines)
local ref = mpi.bcast(mine) -- rank 0's
if ref ~= mine then
  error(string.format("rank %d of %d sees other answers than rank 0", mpi.rank(), mpi.size()))
end
local fo = assert(io.open((P.out or "out") .. ".0", "w")) -- rank 0 writes it
fo:write(mine)
fo:close()
local info = s:info()
if info.distributed then -- how the ranks shared the work (not compared: one rank has none)
  local d = info.distributed
  local g = assert(io.open((P.out or "out") .. ".stats.0", "w")) -- the same on every rank
  g:write(string.format("ranks %d rebuilds %d rebalances %d migrations %d owned_min %d owned_max %d" ..
                        " rebuild_ms %.3f rebalance_ms %.3f comm_ms %.3f halos %d\n",
                        d.ranks, d.rebuilds, d.rebalances, d.migrations, d.owned_min, d.owned_max,
                        1000 * d.rebuild_s, 1000 * d.rebalance_s, 1000 * d.comm_s, d.halos))
  g:close()
end
