-- The binding contract: bad arguments raise errors that name the call, the field and the value,
-- at the caller's line.
local check = grainlab.check

local msg = check.errors(function() return grainlab.rng{ seed = -1 } end,
  "bad field 'seed' in argument #1 to 'rng' (non-negative integer expected, got -1)", "negative seed")
check.contains(msg, "test_args.lua:5:", "error position is the caller's line")
check.errors(function() return grainlab.rng{ seed = 1.5 } end,
  "bad field 'seed' in argument #1 to 'rng' (non-negative integer expected, got 1.5)", "fractional seed")
check.errors(function() return grainlab.rng{ seed = "x" } end,
  "(non-negative integer expected, got 'x')", "string seed")
check.errors(function() return grainlab.rng{ sed = 1 } end,
  "bad argument #1 to 'rng' (unknown field 'sed'; did you mean 'seed'? Valid fields: seed, stream)", "typo in a field name")
check.errors(function() return grainlab.rng(5) end,
  "bad argument #1 to 'rng' (table expected, got number)", "not a table")
check.errors(function() return grainlab.rng{ stream = 1e9 } end,
  "bad field 'stream' in argument #1 to 'rng' (integer in [0, 1048576] expected, got 1000000000.0)", "stream range")

check.errors(function() return grainlab.progress{ total = -1 } end,
  "bad field 'total' in argument #1 to 'progress' (non-negative number expected, got -1)", "negative total")
check.errors(function() return grainlab.progress{ total = 0/0 } end,
  "bad field 'total' in argument #1 to 'progress' (non-negative number expected, got ", "NaN total")
check.errors(function() return grainlab.progress{ total = math.huge } end,
  "(non-negative number expected, got inf)", "infinite total")
check.errors(function() return grainlab.progress{ label = 3 } end,
  "bad field 'label' in argument #1 to 'progress' (string expected, got 3)", "label type")
check.errors(function() return grainlab.progress() end,
  "bad argument #1 to 'progress' (table expected, got no value)", "missing table")

check.errors(function() return grainlab.threads(0) end,
  "bad argument #1 to 'threads' (integer in [1, 4096] or \"auto\" expected, got 0)", "threads 0")
check.errors(function() return grainlab.threads("fast") end,
  "bad argument #1 to 'threads' (integer in [1, 4096] or \"auto\" expected, got 'fast')", "threads string")
-- a fixed count, then auto mode (all processors between runs; the tuner's counts)
local n, mode, st = grainlab.threads(1)
check.eq(n, 1, "fixed count")
check.eq(mode, "fixed", "fixed mode")
check.eq(math.type(st.probes), "integer", "tuner probes")
n, mode, st = grainlab.threads("auto")
check.eq(mode, "auto", "auto mode")
check.eq(n, select(1, grainlab.threads()), "auto: the count between runs")
check.eq(st.steps_one_thread + st.steps_all_threads >= 0, true, "tuner step counts")

-- Methods count arguments as the user sees them: self is not #1.
local r = grainlab.rng{ seed = 1 }
check.errors(function() return r:integer() end, "bad argument #1 to 'integer' (integer expected, got no value)", "method arg")
check.errors(function() return r:uniform(2, 1) end, "bad argument #2 to 'uniform' (upper bound below lower bound)", "bounds")
check.errors(function() return r.uniform(5) end, "bad argument #1 to 'uniform' (grainlab.rng expected, got number)", "bad self")
local p = grainlab.progress{ total = 1 }
p:finish()
check.errors(function() p:update(1) end, "progress reporter already finished", "use after finish")

-- File failures return nil, message like io.open.
local ok, err = grainlab.write_file("/nonexistent_dir/x.txt", "data")
check.eq(ok, nil, "write_file result")
check.eq(err, "cannot write '/nonexistent_dir/x.txt': No such file or directory", "write_file message")

check.errors(function() grainlab.doc(print, { nme = "x" }) end,
  "bad argument #2 to 'doc' (unknown field 'nme'; did you mean 'name'? Valid fields: name, usage, doc, fields)", "doc fields")
check.done()
