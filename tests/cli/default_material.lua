-- Disks without a material, in two scenes: one note per scene, naming the call the script made
-- (add_disk; grainlab.pack.random for the disks it adds). Prints the automatic step the first
-- note must give. Disks with a material say nothing.
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.03, 0.04 } }, gravity = { 0, -9.81 } }
s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
s:add_disk{ pos = { 0.01, 0.01 }, radius = 1e-3 }
print("dt", string.format("%.3g", s:timestep().dt_auto))
s:add_disk{ pos = { 0.02, 0.01 }, radius = 1e-3 }
local t = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.03, 0.04 } } }
grainlab.pack.random(t, { n = 20, radius = 1e-3, seed = 1 })
local u = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.03, 0.04 } } }
u:add_disk{ pos = { 0.01, 0.01 }, radius = 1e-3, material = grainlab.material{ density = 2650, young = 1e7 } }
