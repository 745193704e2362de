-- Run by test_spmd.sh under mpirun -np 3 (and plain): everything this script prints or writes
-- must appear once, whole, whatever the number of ranks. Every rank checks what it can see.
local mpi = grainlab.mpi
local check = grainlab.check
print("printed once", mpi.size())
io.write("io.write once\n")
io.stderr:write("stderr once\n")

-- io.open for writing: rank 0 writes, the other ranks write into nothing
local f = assert(io.open("io.txt", "w"))
for i = 1, 100 do f:write("line ", i, "\n") end
f:close()
-- the same failures on every rank
local bad, msg = io.open("no/such/dir/x.txt", "w")
check.eq(bad, nil, "io.open into a missing directory fails on every rank")
check.contains(msg, "No such file or directory", "io.open's message")
local ok, err = grainlab.write_file("no/such/dir/y.txt", "x")
check.eq(ok, nil, "write_file into a missing directory fails on every rank")
check.contains(err, "cannot write 'no/such/dir/y.txt'", "write_file's message")

-- grainlab's writers: a whole file, a recorder CSV, a PNG of a small DEM scene
assert(grainlab.write_file("whole.txt", string.rep("x", 1000)))
local rec = grainlab.recorder{ file = "rec.csv", columns = { "i", "sq" } }
for i = 1, 50 do rec:add{ i = i, sq = i * i } end
rec:write()
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } } }
for i = 1, 3 do s:add_disk{ pos = { 0.025 * i, 0.05 }, radius = 0.01 } end
render.png(s, "scene.png", { width = 64, height = 64 })

-- a progress reporter: its lines (on stderr) once
local p = grainlab.progress{ label = "spmd", total = 10 }
for i = 1, 10 do p:update(i) end
p:finish()

-- every rank reads what rank 0 wrote, once all of it is there
mpi.barrier()
local n = 0
for _ in io.lines("io.txt") do n = n + 1 end
check.eq(n, 100, "every rank reads rank 0's io.txt whole")
check.eq(#assert(io.open("whole.txt")):read("a"), 1000, "every rank reads whole.txt")

-- a value only rank 0 knows, the same on every rank after bcast
local v = mpi.bcast(mpi.rank() == 0 and { n = 42, name = "rank0", list = { 1.5, true } } or "other")
check.eq(v.n, 42, "bcast number")
check.eq(v.name, "rank0", "bcast string")
check.eq(v.list[2], true, "bcast nested")
check.eq(mpi.bcast(mpi.rank(), mpi.size() - 1), mpi.size() - 1, "bcast from the last rank")

grainlab.report{ scenario = "spmd_output", metrics = { ranks = mpi.size(), lines = n },
  checks = { { name = "lines", value = n, limit = 100, op = "==" } } }
