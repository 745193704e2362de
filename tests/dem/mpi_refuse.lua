-- Boundary conditions (here springs) and walls beyond planes do not run distributed yet: under mpirun -np K > 1 the run
-- must stop with an error that names them on every rank; on one rank the run works.
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } } }
local m = grainlab.material{ name = "quartz", density = 2650, young = 1e8, poisson = 0.3,
                             friction = 0.45, restitution = 0.9 }
s:add_disk{ pos = { 0.004, 0.005 }, radius = 0.0005, material = m }
s:add_disk{ pos = { 0.0052, 0.005 }, radius = 0.0005, material = m }
s:springs{ i = { 1 }, j = { 2 }, k = 10 }
local ranks = grainlab.mpi.size()
local ok, err = pcall(s.run, s, { steps = 10, dt = 1e-7 })
if ranks == 1 then
  assert(ok, err)
else
  assert(not ok, "a run with springs went ahead on " .. ranks .. " ranks")
  assert(tostring(err):find("do not yet run distributed", 1, true), err)
  assert(tostring(err):find("springs", 1, true), err)
end

-- Particles in and out (inserters, outflows) do not run distributed either: refused by name.
local fl = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } } }
fl:add_disk{ pos = { 0.005, 0.005 }, radius = 0.0005, material = m }
fl:inserter{ box = { { 0, 0.008 }, { 0.01, 0.01 } }, count = 3, radius = 0.0004, material = m }
local okf, errf = pcall(fl.run, fl, { steps = 10, dt = 1e-7 })
if ranks == 1 then
  assert(okf, errf)
  assert(fl:flow().inserted == 3, "one rank: inserted")
else
  assert(not okf, "a run with an inserter went ahead on " .. ranks .. " ranks")
  assert(tostring(errf):find("particle insertion and removal", 1, true), errf)
  assert(tostring(errf):find("do not yet run distributed", 1, true), errf)
end
print("ok")

-- Walls beyond planes (a circle here) do not run distributed yet either: refused by name.
local d = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
d:add_disk{ pos = { 0.005, 0.003 }, radius = 0.0005, material = m }
d:add_cylinder{ center = { 0.005, 0.005 }, radius = 0.004 }
local okd, errd = pcall(d.run, d, { steps = 10, dt = 1e-7 })
if ranks == 1 then
  assert(okd, errd)
else
  assert(not okd, "a run with a circle wall went ahead on " .. ranks .. " ranks")
  assert(tostring(errd):find("do not yet run distributed", 1, true), errd)
  assert(tostring(errd):find("walls beyond planes", 1, true), errd)
  assert(tostring(errd):find("circles", 1, true), errd)
end
print("ok")

-- Clumps do not run distributed yet: refused by name on every rank, run on one.
local c = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
c:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
c:add_clump{ members = { { offset = { -0.0004, 0 }, radius = 0.0005 }, { offset = { 0.0004, 0 }, radius = 0.0005 } },
             material = m, position = { 0.005, 0.002 } }
local okc, errc = pcall(c.run, c, { steps = 10, dt = 1e-7 })
if ranks == 1 then
  assert(okc, errc)
else
  assert(not okc, "a run with clumps went ahead on " .. ranks .. " ranks")
  assert(tostring(errc):find("clumps do not yet run distributed", 1, true), errc)
end
print("ok")

-- Tags alone (a LAMMPS data file whose ids have gaps) do run distributed: they travel with their
-- particles, and the queries give them back. Files are written once (rank 0); every rank reads it.
do
  local mine = os.tmpname()
  local path = grainlab.mpi.bcast(mine)
  if mine ~= path then os.remove(mine) end
  local f = assert(io.open(path, "w"))
  f:write("gaps\n\n6 atoms\n1 atom types\n\n0 0.01 xlo xhi\n0 0.01 ylo yhi\n-0.001 0.001 zlo zhi\n\n",
          "Atoms # sphere\n\n")
  local ids = { 2, 5, 7, 9, 12, 40 }
  for k, id in ipairs(ids) do
    f:write(string.format("%d 1 0.001 2650 %.17g 0.005 0 0 0 0\n", id, 0.0008 + 0.0016 * (k - 1)))
  end
  f:write("\nVelocities\n\n")
  for k, id in ipairs(ids) do f:write(string.format("%d %g 0 0 0 0 0\n", id, k % 2 == 0 and 0.3 or -0.3)) end
  f:close()
  grainlab.mpi.barrier() -- every rank waits for rank 0's file
  local t = dem.read_lammps_data(path, { material = m })
  grainlab.mpi.barrier() -- and rank 0 for every reader
  os.remove(path)
  t:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  t:add_wall{ point = { 0.01, 0 }, normal = { -1, 0 } }
  local okt, errt = pcall(t.run, t, { steps = 400, dt = 2e-7 })
  assert(okt, errt)
  local tag = t:particles().tag
  for k, id in ipairs(ids) do assert(tag[k] == id, "tag " .. k .. " after a distributed run: " .. tostring(tag[k])) end
end

-- A row of 20 disks on the floor of a 20 x 10 mm box with the walls given, disk `k` (0-based)
-- launched along x at `speed`; the run must stop with an error containing `expect` at the same
-- step on every rank. Returns the error and the step, as text (every rank checks rank 0's).
local function stops(walls, k, speed, steps, expect)
  local sc = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.01 } } }
  for _, w in ipairs(walls) do sc:add_wall{ point = w[1], normal = w[2] } end
  for q = 0, 19 do
    sc:add_disk{ pos = { 0.0007 + q * 0.00095, 0.001 }, radius = 0.0004, material = m,
                 vel = { q == k and speed or 0, 0 } }
  end
  local ok, err = pcall(sc.run, sc, { steps = steps, dt = 2e-7, force = true })
  assert(not ok, "the run went ahead: " .. expect)
  assert(tostring(err):find(expect, 1, true), err)
  local mine = tostring(err) .. "\n" .. sc:info().steps .. "\n"
  assert(grainlab.mpi.bcast(mine) == mine, "rank " .. grainlab.mpi.rank() .. " stopped otherwise than rank 0")
  return mine
end

-- An instability found by one rank (a particle through a wall, checked by its owner only) stops
-- every rank at the same step with the one-rank message, without a hang.
local mine = stops({ { { 0, 0 }, { 0, 1 } }, { { 0.02, 0 }, { -1, 0 } }, { { 0, 0 }, { 1, 0 } },
                     { { 0, 0.01 }, { 0, -1 } } }, 17, 400, 200, "went through a wall")
-- A particle leaving through a side with no wall (not periodic): its owner's kicks flag it, the
-- full checks find it, and every rank stops at the one-rank step with the one-rank message (the
-- checks run only on the rank whose kicks flagged something, as on one rank).
local mine3 = stops({ { { 0, 0 }, { 0, 1 } }, { { 0, 0 }, { 1, 0 } } }, 18, 60, 400, "left the domain")

local f = assert(io.open((params.out or "refuse") .. ".0", "w")) -- rank 0 writes it
f:write(mine .. mine3)
f:close()
