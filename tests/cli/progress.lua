-- Drives a progress reporter through 50 updates.
local p = grainlab.progress{ label = "sweep", total = 50, unit = "cases" }
for i = 1, 50 do p:update(i) end
p:finish()
