-- grainlab.mpi on one rank (the plain run every test uses): rank/size, bcast's round trip of
-- every kind of value it sends and its refusals, the traffic counters. tests/mpi/ runs the same
-- calls under mpirun.
local check = grainlab.check
local mpi = grainlab.mpi
check.eq(mpi.rank(), 0, "rank without mpirun")
check.eq(mpi.size(), 1, "size without mpirun")
check.eq(type(mpi.available), "boolean", "available")
mpi.barrier()

-- values come back equal, integers stay integers, floats floats, bytes intact
local v = { 1, 2.5, -0.0, 1 / 0, "a\0b", true, false, n = { m = { 3 } }, [2.5] = "key", [true] = 1 }
local w = mpi.bcast(v)
check.eq(math.type(w[1]), "integer", "integer stays integer")
check.eq(math.type(w[2]), "float", "float stays float")
check.eq(1 / w[3], -1 / 0, "-0.0 keeps its sign")
check.eq(w[4], 1 / 0, "inf")
check.eq(w[5], "a\0b", "string with a zero byte")
check.eq(w[6], true, "true"); check.eq(w[7], false, "false")
check.eq(w.n.m[1], 3, "nested table")
check.eq(w[2.5], "key", "float key"); check.eq(w[true], 1, "boolean key")
check.eq(mpi.bcast(nil), nil, "nil")
check.eq(mpi.bcast("x", 0), "x", "root 0")
local nan = mpi.bcast(0 / 0)
check.eq(nan ~= nan, true, "NaN")

-- refusals, with the call's name
check.errors(function() mpi.bcast(print) end,
  "bad argument #1 to 'bcast' (nil, boolean, number, string or table of them expected, got function: a function cannot be sent)",
  "a function")
check.errors(function() mpi.bcast({ f = { io.stdout } }) end, "a userdata (a scene, a file) cannot be sent", "a userdata inside")
local cyc = {}; cyc.self = cyc
check.errors(function() mpi.bcast(cyc) end, "tables nested deeper than 100 levels (or a cycle)", "a cycle")
check.errors(function() mpi.bcast(1, 1) end, "bad argument #2 to 'bcast'", "root beyond the ranks")

-- no traffic on one rank
mpi.reset_stats()
mpi.bcast({ 1, 2, 3 })
local st = mpi.stats()
check.eq(st.bytes, 0, "no bytes on one rank"); check.eq(st.calls, 0, "no calls on one rank")
check.done()
