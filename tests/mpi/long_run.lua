-- A run far longer than any test waits for (test_spmd.sh stops it with SIGTERM).
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } }, gravity = { 0, -9.81 } }
s:contact{ normal = "hertz", damping = "viscous" }
s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
for i = 1, 3 do s:add_disk{ pos = { 0.025 * i, 0.05 }, radius = 0.01 } end
local f = assert(io.open("started", "w"))
f:close()
s:run{ steps = 100000000, dt = 1e-6 }
