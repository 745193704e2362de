-- DSMC distributed over MPI ranks gives the same bits as one rank.
-- Four small inelastic gases: 2D with gravity, an inelastic floor and a diffuse hot ceiling
-- (periodic sides); 2D periodic and elastic (count and momentum conserved across migrations, and
-- a checkpoint saved under mpirun continues with the same bits); 3D with a vibrating floor and a
-- diffuse side wall; 2D with every particle in one corner, so that at the first cut all but one
-- rank hold nothing and the gas then spreads over all of them (rebalanced on the way). Each is
-- run, queried in the middle (which gathers the scene and cuts it again at the next run) and run
-- on; then every particle (identity, position, velocity) and the measurements are written with
-- %a. Every rank checks that its text equals rank 0's (queries identical on every rank).
--   grainlab test_mpi_dsmc.lua                      -- one rank: the checks only
--   mpirun -np K grainlab test_mpi_dsmc.lua out=F   -- also writes F (rank 0)
-- ctest compares F from a plain run and from 2, 3 and 4 ranks (tests/mpi/compare_np.sh).
local check = require("grainlab.check")
local mpi = grainlab.mpi

local out = {}
local function put(fmt, ...) out[#out + 1] = string.format(fmt, ...) end

-- every particle, in the order s:particles() gives (cell, then identity), and the measurements
local function dump(name, s)
  local p = s:particles()
  local D = s:info().dim
  put("%s count %d", name, p.count)
  for i = 1, p.count do
    if D == 2 then
      put("%d %a %a %a %a", p.id[i], p.x[i], p.y[i], p.vx[i], p.vy[i])
    else
      put("%d %a %a %a %a %a %a", p.id[i], p.x[i], p.y[i], p.z[i], p.vx[i], p.vy[i], p.vz[i])
    end
  end
  local m = s:measure("temperature")
  put("T %a ke %a kurt %a mom %a %a cf %a", m.temperature, m.kinetic_energy, m.kurtosis,
      m.momentum[1], m.momentum[2], m.collision_frequency)
  local st = s:measure("stats")
  put("stats %d %.17g %.17g %.17g %.17g %.17g", st.steps, st.attempts, st.collisions,
      st.wall_hits, st.vmax_raised, st.particle_moves)
  local f = s:measure("fields")
  for c = 1, #f.count do put("cell %d %d %a", c, f.count[c], f.temperature[c]) end
  local v = s:measure("validity", { dt = 1e-4 })
  put("validity %a %a", v.density, v.collision_time)
end

-- the particles are a permutation of identities 1..n, on every rank
local function check_ids(s, n, what)
  local p = s:particles()
  check.eq(p.count, n, what .. ": particle count")
  check.eq(s:info().count, n, what .. ": info count")
  local seen, dup = {}, 0
  for i = 1, p.count do
    if seen[p.id[i]] then dup = dup + 1 end
    seen[p.id[i]] = true
  end
  check.eq(dup, 0, what .. ": no identity twice")
  for i = 1, n do if not seen[i] then check.is_true(false, what .. ": identity " .. i .. " lost") end end
end

-- A: 2D, gravity, inelastic floor, diffuse hot ceiling, periodic in x
do
  local s = dsmc.scene{ dim = 2, size = { 0.06, 0.09 }, cells = { 12, 18 }, radius = 5e-4,
                        restitution = 0.9, periodic = { true, false }, gravity = { 0, -9.81 },
                        seed = 11 }
  s:wall{ side = "bottom", restitution = 0.8 }
  s:wall{ side = "top", kind = "diffuse", temperature = s:info().mass * 0.05 }
  s:fill{ n = 2500, temperature = s:info().mass * 0.04, seed = 2 }
  s:run{ steps = 25, dt = 2e-4, warn = false }
  put("A mid T %a", s:measure("temperature").temperature)
  check_ids(s, 2500, "A mid-run")
  s:run{ steps = 25, dt = 2e-4, warn = false }
  check_ids(s, 2500, "A")
  dump("A", s)
end

-- B: 2D periodic, elastic: count and momentum conserved across migrations
do
  local s = dsmc.scene{ dim = 2, size = { 0.05, 0.05 }, cells = { 14, 14 }, radius = 4e-4,
                        restitution = 1, seed = 5 }
  local m = s:info().mass
  s:fill{ n = 2000, temperature = m * 0.02, velocity = { 0.3, -0.1 }, seed = 3 }
  local p0 = s:measure("temperature").momentum
  local e0 = s:measure("temperature").kinetic_energy
  s:run{ steps = 60, dt = 1e-4, warn = false }
  check_ids(s, 2000, "B")
  local mm = s:measure("temperature")
  local scale = m * 2000 * 0.5
  check.near_abs(mm.momentum[1], p0[1], 1e-12 * scale, "B: momentum x conserved")
  check.near_abs(mm.momentum[2], p0[2], 1e-12 * scale, "B: momentum y conserved")
  check.near(mm.kinetic_energy, e0, 1e-12, "B: energy conserved (elastic)")
  check.is_true(s:measure("stats").collisions > 1000, "B: the gas collides")
  dump("B", s)
  -- a checkpoint saved under mpirun (gathered, written by rank 0) continues with the same bits
  -- as the scene it was saved from (one name on every rank: rank 0's; the others read the file
  -- after the barrier)
  local path = mpi.bcast(os.tmpname())
  s:save(path)
  mpi.barrier()
  local l = dsmc.load(path)
  s:run{ steps = 10, dt = 1e-4, warn = false }
  l:run{ steps = 10, dt = 1e-4, warn = false }
  local a, b = s:particles(), l:particles()
  local same = a.count == b.count
  for i = 1, a.count do
    same = same and a.id[i] == b.id[i] and a.x[i] == b.x[i] and a.vy[i] == b.vy[i]
  end
  check.is_true(same, "B: a checkpoint saved under mpirun continues with the same bits")
  put("B after checkpoint T %a", l:measure("temperature").temperature)
  os.remove(path) -- rank 0 only
end

-- C: 3D, vibrating inelastic floor, diffuse wall on one side, periodic in y
do
  local s = dsmc.scene{ dim = 3, size = { 0.03, 0.03, 0.04 }, cells = { 6, 6, 8 },
                        radius = 5e-4, restitution = 0.85, periodic = { false, true, false },
                        gravity = { 0, 0, -9.81 }, seed = 7 }
  s:wall{ side = "bottom", restitution = 0.9, amplitude = 5e-4, frequency = 50 }
  s:wall{ side = "left", kind = "diffuse", temperature = s:info().mass * 0.03 }
  s:fill{ n = 2500, temperature = s:info().mass * 0.03, seed = 4 }
  s:run{ steps = 20, dt = 2e-4, warn = false }
  check_ids(s, 2500, "C mid-run")
  s:run{ steps = 20, dt = 2e-4, warn = false }
  dump("C", s)
end

-- D: every particle in the lower left corner, expanding into the box: the first cut leaves all
-- but one rank empty, and the counts per rank then drift until the grid is cut again
do
  local s = dsmc.scene{ dim = 2, size = { 0.04, 0.04 }, cells = { 8, 8 }, radius = 5e-5,
                        restitution = 0.95, periodic = false, seed = 9 }
  s:fill{ n = 1500, temperature = s:info().mass * 1.0, velocity = { 1, 0.7 },
          region = { { 0, 0 }, { 0.005, 0.005 } }, seed = 8 }
  s:run{ steps = 120, dt = 2e-4, force = true, warn = false } -- 10 collision times a step
  check_ids(s, 1500, "D")
  dump("D", s)
end

-- E: speeds near the largest double (gravity 1e100 for a step of 1e100 s, two particles
-- meeting head on at the floor): the number of collision candidates overflows; the run stops
-- with the same error at the same step on every rank count (agreed at the next reduction), no
-- particle is lost, and nothing undefined happens on the way (UBSan: the count was cast to a
-- long and summed)
do
  local s = dsmc.scene{ dim = 2, size = { 0.04, 0.04 }, cells = { 8, 8 }, radius = 5e-5,
                        periodic = false, gravity = { 0, -1e100 }, seed = 9 }
  s:fill{ n = 400, temperature = s:info().mass * 1.0, seed = 8 }
  s:add{ x = { 0.01, 0.011 }, y = { 0.001, 0.001 }, vx = { 0, 0 }, vy = { 1e100, -1e100 } }
  local ok, msg = pcall(s.run, s, { steps = 3, dt = 1e100, force = true, warn = false })
  check.is_true(not ok and tostring(msg):find("overflowed", 1, true) ~= nil,
                "E: the overflow is reported: " .. tostring(msg))
  put("E %s", tostring(msg))
  check_ids(s, 402, "E")
end

-- F: an inelastic bed on a fixed floor collapses: the run stops past close packing with the same
-- cell, count and step on every rank count (the ranks' verdicts agreed at the next reduction),
-- and so does a step far above the collision time (the candidate cap), here at the run's end
do
  local s = dsmc.scene{ dim = 2, size = { 0.05, 0.1 }, cells = { 10, 20 }, periodic = { true, false },
                        gravity = { 0, -9.81 }, radius = 5e-4, restitution = 0.9, seed = 1 }
  s:fill{ n = 100, temperature = s:info().mass * 0.05, region = { { 0, 0 }, { 0.05, 0.03 } } }
  local ok, msg = pcall(s.run, s, { time = 1, dt = 2e-4, warn = false })
  check.is_true(not ok and tostring(msg):find("past close packing", 1, true) ~= nil,
                "F: the collapse is reported: " .. tostring(msg))
  put("F %s", tostring(msg))
  check_ids(s, 100, "F")
  local g = dsmc.scene{ dim = 2, size = { 0.1, 0.1 }, cells = { 10, 10 }, radius = 1e-3, seed = 2 }
  g:fill{ n = 500, temperature = g:info().mass * 1.0, seed = 5 }
  ok, msg = pcall(g.run, g, { steps = 1, dt = 1e6, force = true, warn = false })
  check.is_true(not ok and tostring(msg):find("over the limit of 100 per particle", 1, true) ~= nil,
                "F: the candidate cap is reported: " .. tostring(msg))
  put("F %s", tostring(msg))
  check_ids(g, 500, "F cap")
end

local text = table.concat(out, "\n") .. "\n"
local ref = mpi.bcast(text)
if text ~= ref then
  error(string.format("rank %d: the queries differ from rank 0's", mpi.rank()))
end
if params.out then
  local f = assert(io.open(params.out, "wb"))
  f:write(text)
  f:close()
end
