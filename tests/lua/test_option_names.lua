-- String options (s:measure(what), m:field(name)) refused with the valid names listed and the
-- closest one suggested, for each engine.
local check = grainlab.check

local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } } }
s:add_disk{ pos = { 0.05, 0.05 }, radius = 0.01 }
local DEM = "'energy', 'stress', 'coordination', 'slip', 'contacts', 'displacement'"
check.errors(function() s:measure("stres") end,
  "bad argument #1 to 'measure' (invalid option 'stres'; did you mean 'stress'? Valid options: " .. DEM .. ")",
  "dem: one letter missing")
check.errors(function() s:measure("Stress") end, "did you mean 'stress'?", "dem: case")
check.errors(function() s:measure("sterss") end, "did you mean 'stress'?", "dem: swapped letters")
check.errors(function() s:measure("coord") end, "did you mean 'coordination'?", "dem: unique prefix")
check.errors(function() s:measure("contact") end, "did you mean 'contacts'?", "dem: singular")
local msg = check.errors(function() s:measure("volume") end,
  "(invalid option 'volume'; valid options: " .. DEM .. ")", "dem: nothing close")
check.is_true(not msg:find("did you mean", 1, true), "no suggestion when nothing is close")
check.errors(function() s:measure() end,
  "bad argument #1 to 'measure' (one of " .. DEM .. " expected, got no value)", "dem: missing")
check.errors(function() s:measure(3) end, "(one of 'energy', 'stress',", "dem: not a string")
check.eq(type(s:measure("energy")), "table", "a valid name still works")

-- The options of each mode: an unknown key is refused with the closest field, a mode without
-- options says so, and anything but a table is refused.
check.errors(function() s:measure("stress", { volum = 1 }) end,
  "bad argument #2 to 'measure' (unknown field 'volum'; did you mean 'volume'? Valid fields for 'stress': volume)",
  "dem: misspelt option")
check.errors(function() s:measure("energy", { foo = 1 }) end,
  "bad argument #2 to 'measure' (unknown field 'foo'; measure('energy') takes no options)", "dem: energy takes none")
for _, mode in ipairs{ "coordination", "slip", "contacts" } do
  check.errors(function() s:measure(mode, { foo = 1 }) end, "measure('" .. mode .. "') takes no options", "dem: " .. mode)
end
check.errors(function() s:measure("energy", 5) end,
  "bad argument #2 to 'measure' (nothing ('energy' takes no options) expected, got 5)", "dem: energy given a number")
check.errors(function() s:measure("stress", "big") end,
  "bad argument #2 to 'measure' (options table for 'stress' expected, got 'big')", "dem: stress given a string")
check.eq(type(s:measure("energy", {})), "table", "an empty table is no option")

local m = mpm.scene{ cells = { 8, 8 }, size = { 1e-3, 1e-3 } }
check.errors(function() m:measure("enrgy") end,
  "bad argument #1 to 'measure' (invalid option 'enrgy'; did you mean 'energy'? Valid options: 'energy', 'momentum', 'columns', 'shear')",
  "mpm measure")
check.errors(function() m:measure("energy", { foo = 1 }) end,
  "bad argument #2 to 'measure' (unknown field 'foo'; measure('energy') takes no options)", "mpm: energy takes none")
check.errors(function() m:measure("columns", true) end, "(nothing ('columns' takes no options) expected, got true)",
  "mpm: columns given a boolean")
check.errors(function() m:field("presure") end,
  "bad argument #1 to 'field' (invalid option 'presure'; did you mean 'pressure'? Valid options: 'vx',",
  "mpm field")

local d = dsmc.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, cells = { 4, 4 }, radius = 0.01 }
check.errors(function() d:measure("temprature") end,
  "bad argument #1 to 'measure' (invalid option 'temprature'; did you mean 'temperature'? Valid options: 'temperature', 'a2', 'fields', 'histogram', 'stats', 'profile', 'validity')",
  "dsmc measure")
check.errors(function() d:measure("temp") end, "did you mean 'temperature'?", "dsmc: unique prefix")
check.errors(function() d:measure("stats", { foo = 1 }) end,
  "bad argument #2 to 'measure' (unknown field 'foo'; measure('stats') takes no options)", "dsmc: stats takes none")
check.errors(function() d:measure("histogram", { bin = 10 }) end,
  "(unknown field 'bin'; did you mean 'bins'? Valid fields for 'histogram': bins, range, quantity)", "dsmc: misspelt option")
check.done()
