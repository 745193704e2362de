-- grainlab.progress refuses amounts that would print nonsense ("nan%", a bar running backwards
-- from NaN): update and finish take finite numbers >= 0; the output itself is tested in
-- tests/core/test_progress.c and tests/cli/.
local check = grainlab.check
local p = grainlab.progress{ label = "t", total = 10 }
check.errors(function() p:update(0/0) end, "bad argument #1 to 'update' (finite non-negative number expected, got ", "NaN")
check.errors(function() p:update(1/0) end, "got inf)", "infinity")
check.errors(function() p:update(-1) end, "got -1)", "negative")
check.errors(function() p:update("x") end, "number expected, got string", "string")
p:update(4)
check.errors(function() p:finish(0/0) end, "bad argument #1 to 'finish' (finite non-negative number expected", "finish NaN")
p:finish(10)
check.errors(function() p:update(5) end, "already finished", "after finish")
check.errors(function() grainlab.progress{ total = 0/0 } end, "bad field 'total' in argument #1 to 'progress'", "NaN total")
check.done()
