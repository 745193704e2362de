-- A DEM run far too long to finish, writing a 4 MB file from on_step (params.write = true), that
-- announces itself on stderr once it is running: the tests stop it with a signal.
local s = dem.scene{ box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
s:add_wall{ point = { 0.01, 0 }, normal = { -1, 0 } }
for i = 1, 4 do s:add_disk{ pos = { 0.002 * i, 0.002 }, radius = 4e-4 } end
local big = string.rep("x", 4000000)
local announced = false
s:run{ steps = 1000000000, every = 500, on_step = function()
  if params.write then assert(grainlab.write_file(params.out, big)) end
  if not announced then announced = true; io.stderr:write("running\n"); io.stderr:flush() end
end }
