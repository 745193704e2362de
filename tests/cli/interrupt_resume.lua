-- Ctrl-C caught by the script, twice: first during a run (pcall around it), then in plain Lua
-- (the interrupt hook). After each, later runs of every engine go to their end. Each phase says
-- "runningN" on stderr when it is ready for the signal; the test sends one SIGINT per phase.
local function say(text) io.stderr:write(text, "\n"); io.stderr:flush() end

local s = dem.scene{ box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
for i = 1, 4 do s:add_disk{ pos = { 0.002 * i, 0.002 }, radius = 4e-4 } end
local m = mpm.scene{ cells = { 10, 10 }, size = { 1, 1 } }
m:add_disk{ center = { 0.5, 0.5 }, radius = 0.2,
            material = mpm.material{ model = "elastic", density = 1000, shear = 1e5, bulk = 1e5 } }
local g = dsmc.scene{ dim = 2, size = { 1, 1 }, cells = { 4, 4 }, radius = 1e-3 }
g:fill{ n = 100, temperature = g:info().mass, seed = 1 }

local function later_runs(phase)
  print(phase, "dem", s:run{ steps = 10, progress = false }.steps)
  print(phase, "mpm", m:run{ steps = 10, progress = false }.steps)
  print(phase, "dsmc", g:run{ steps = 10, dt = 1e-3, warn = false, progress = false }.steps)
end

local announced = false
local ok, msg = pcall(s.run, s, { steps = 1000000000, every = 100, progress = false, on_step = function()
  if not announced then announced = true; say("running1") end
end })
print("caught1", ok, msg)
later_runs("after1")

ok, msg = pcall(function()
  say("running2")
  while true do end
end)
print("caught2", ok, msg)
later_runs("after2")
