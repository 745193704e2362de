-- Boundary conditions (here springs) do not run distributed yet: under mpirun -np K > 1 the run
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

-- An instability found by one rank (a particle through a wall, checked by its owner only) stops
-- every rank at the same step with the one-rank message, without a hang.
local t = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.01 } } }
t:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
t:add_wall{ point = { 0.02, 0 }, normal = { -1, 0 } }
t:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
t:add_wall{ point = { 0, 0.01 }, normal = { 0, -1 } }
for k = 0, 19 do
  t:add_disk{ pos = { 0.0007 + k * 0.00095, 0.001 }, radius = 0.0004, material = m,
              vel = { k == 17 and 400 or 0, 0 } }
end
local ok2, err2 = pcall(t.run, t, { steps = 200, dt = 2e-7, force = true })
assert(not ok2, "the run through the wall went ahead")
local mine = tostring(err2) .. "\n" .. t:info().steps .. "\n"
assert(grainlab.mpi.bcast(mine) == mine, "rank " .. grainlab.mpi.rank() .. " stopped otherwise than rank 0")

-- A particle leaving through a side with no wall (not periodic): its owner's kicks flag it, the
-- full checks find it, and every rank stops at the one-rank step with the one-rank message (the
-- checks run only on the rank whose kicks flagged something, as on one rank).
local u = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.01 } } }
u:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
u:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
for k = 0, 19 do
  u:add_disk{ pos = { 0.0007 + k * 0.00095, 0.001 }, radius = 0.0004, material = m,
              vel = { k == 18 and 60 or 0, 0 } }
end
local ok3, err3 = pcall(u.run, u, { steps = 400, dt = 2e-7, force = true })
assert(not ok3, "the run that lost a particle went ahead")
assert(tostring(err3):find("left the domain", 1, true), err3)
local mine3 = tostring(err3) .. "\n" .. u:info().steps .. "\n"
assert(grainlab.mpi.bcast(mine3) == mine3, "rank " .. grainlab.mpi.rank() .. " stopped otherwise than rank 0")

local f = assert(io.open((params.out or "refuse") .. ".0", "w")) -- rank 0 writes it
f:write(mine .. mine3)
f:close()
