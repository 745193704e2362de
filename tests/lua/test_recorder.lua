-- grainlab.recorder: the CSV byte for byte, the exact round trip of %.17g, the plot, the refusals
-- with their messages, and that a run which dies still leaves the CSV of what it sampled.
local check = grainlab.check

local tmp = os.tmpname()
os.remove(tmp)
local dir = tmp .. "_rec"
local function slurp(path) -- the file's bytes, or nil when it does not exist
  local f <close> = io.open(path, "rb")
  return f and f:read("a")
end

-- ---- the CSV, exactly: header with units, integers as %d, floats as %.17g, nan, order kept ----
local rec = grainlab.recorder{ file = dir .. "/sub/a.csv", flush = false,
  columns = { { "step" }, { "t" }, { "kinetic" } }, units = { t = "s", kinetic = "J" } }
check.eq(slurp(dir .. "/sub/a.csv"), "step,t (s),kinetic (J)\n", "the header is written at once (directory made)")
rec:add{ step = 0, t = 0.0, kinetic = 0.1 }
rec:add{ step = 100, t = 1 / 3, kinetic = 0 / 0 }
rec:add{ step = 200, t = 2.5e-7, kinetic = -math.huge }
check.eq(#rec, 3, "#rec counts samples")
check.eq(slurp(dir .. "/sub/a.csv"), "step,t (s),kinetic (J)\n", "flush = false: nothing more before write()")
check.eq(rec:write(), dir .. "/sub/a.csv", "write() returns the path")
check.eq(slurp(dir .. "/sub/a.csv"),
  "step,t (s),kinetic (J)\n0,0,0.10000000000000001\n100,0.33333333333333331,nan\n200,2.4999999999999999e-07,-inf\n",
  "the CSV, byte for byte")
check.eq(table.concat(rec:names(), " "), "step t kinetic", "names() in CSV order")
local t = rec:column("t")
check.eq(#t, 3, "column() length")
t[1] = 99
check.eq(rec:column("t")[1], 0.0, "column() is a copy")
check.eq(grainlab.doc_of(rec).name, "grainlab.recorder", "help(rec) answers with the type's text")
check.eq(tostring(rec), "grainlab.recorder(step, t, kinetic; 3 samples -> " .. dir .. "/sub/a.csv)", "tostring")

-- ---- %.17g reads back to the same double, for awkward values --------------------------------
local values = { 0.1, 1 / 3, math.pi, 1e-300, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308,
                 -0.0, 2 ^ 53 + 2, 123456789.123456789, 6.02214076e23, -1.5e-17 }
local rt = grainlab.recorder{ file = dir .. "/rt.csv", columns = { "i", "v" } }
for i, v in ipairs(values) do rt:add{ i = i, v = v } end
rt:write()
local n = 0
for line in slurp(dir .. "/rt.csv"):gmatch("[^\n]+") do
  local i, v = line:match("^(%d+),(.+)$")
  if i then
    n = n + 1
    local x = tonumber(v:find("[eE]") and v or v .. "e0") -- a float even for "-0" and "1"
    check.eq(string.format("%a", x), string.format("%a", values[tonumber(i)]), "round trip of value " .. i)
  end
end
check.eq(n, #values, "every value read back")

-- ---- map + order, sampling functions, and rec(s) as a run's on_step ---------------------------
local mat = grainlab.material{ density = 2650, young = 1e7, poisson = 0.3 }
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.01, 0.01 } }, gravity = { 0, -9.81 } }
s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
s:add_disk{ pos = { 0.005, 0.002 }, radius = 1e-3, material = mat }
local ts = grainlab.recorder{ file = dir .. "/run.csv", order = { "t", "y" },
  columns = { y = function(sc) return sc:particles().y[1] end, t = function(sc) return sc:info().time end } }
local r = s:run{ steps = 500, dt = 1e-5, every = 100, on_step = ts }
check.eq(r.steps, 500, "the run with the recorder as on_step")
check.eq(#ts, 5, "one sample every 100 steps")
check.near(ts:column("t")[5], 500 * 1e-5, 1e-12, "t sampled from the scene")
check.lt(ts:column("y")[5], 0.002, "the disk fell")
ts:sample(s) -- explicit form
check.eq(#ts, 6, "rec:sample(s)")

-- ---- the plot --------------------------------------------------------------------------------
local png = ts:plot{ file = dir .. "/fig/run.png", x = "t", y = "y", title = "falling disk" }
check.eq(png, dir .. "/fig/run.png", "plot returns the file")
check.eq((slurp(png) or ""):sub(1, 4), "\137PNG", "the plot is a PNG")
ts:write()
check.eq(select(2, slurp(dir .. "/run.csv"):gsub("\n", "")), 7, "header + 6 rows")
local png2 = rec:plot{ file = dir .. "/log.png", x = "step", y = { "t", "kinetic" }, ylog = true }
check.eq((slurp(png2) or ""):sub(1, 4), "\137PNG", "log plot: zeros, NaN and -inf are gaps, not errors")

-- ---- refusals, at construction or at the first sample, naming the call and the field ---------
local function R(t) return grainlab.recorder(t) end
check.errors(R, "bad argument #1 to 'recorder' (table expected, got nil)", "no table")
check.errors(R, "unknown field 'colums'; did you mean 'columns'? Valid fields: columns, file, flush, order, units", "typo", { colums = { "a" } })
check.errors(R, "bad field 'columns' in argument #1 to 'recorder' (non-empty table of columns expected, got nil)", "no columns", {})
check.errors(R, "bad field 'columns[2]' in argument #1 to 'recorder' (column name (text without , \" or a line break) expected, got 'a,b')",
             "comma in a name", { columns = { "x", "a,b" } })
check.errors(R, "bad field 'columns[1]'", "newline in a name", { columns = { "a\nb" } })
check.errors(R, "bad field 'columns[1][2]' in argument #1 to 'recorder' (function(s) returning a number expected, got 42)",
             "fn not a function", { columns = { { "a", 42 } } })
check.errors(R, "bad field 'columns' in argument #1 to 'recorder' (distinct column names expected, got 'a')",
             "duplicate", { columns = { "a", "a" } })
check.errors(R, "bad field 'order' in argument #1 to 'recorder' (array of the column names", "map without order",
             { columns = { a = function() return 1 end } })
check.errors(R, "bad field 'order' in argument #1 to 'recorder' (array naming every column expected, got 'b')",
             "order missing a column", { columns = { a = print, b = print }, order = { "a" } })
check.errors(R, "bad field 'order[2]' in argument #1 to 'recorder' (name of one of the 'columns' expected, got 'c')",
             "order naming no column", { columns = { a = print }, order = { "a", "c" } })
check.errors(R, "bad field 'units' in argument #1 to 'recorder' (names of the 'columns' expected, got 'z')",
             "unit of no column", { columns = { "a" }, units = { z = "m" } })
check.errors(R, "bad field 'units.a'", "comma in a unit", { columns = { "a" }, units = { a = "m,s" } })
check.errors(R, "bad field 'flush' in argument #1 to 'recorder' (seconds >= 0 or false expected, got -1)",
             "flush", { columns = { "a" }, flush = -1 })
check.errors(R, "bad field 'file' in argument #1 to 'recorder' (writable path", "unwritable file",
             { columns = { "a" }, file = "/proc/no/such/dir/x.csv" })
local bad = grainlab.recorder{ columns = { { "t", function() return 1 end }, { "e", function() return nil end } } }
check.errors(bad.sample, "bad value of column 'e' in 'sample' (number expected, got nil)", "non-number at the first sample", bad, s)
check.eq(#bad, 0, "no half row kept")
local named = grainlab.recorder{ columns = { "a" } }
check.errors(named.sample, "bad column 'a' in 'sample' (no function to sample it", "sample needs functions", named, s)
check.errors(named.add, "bad argument #1 to 'add' (unknown column 'b'; columns: a)", "add: unknown", named, { a = 1, b = 2 })
check.errors(named.add, "bad field 'a' in argument #1 to 'add' (number expected, got '1')", "add: a string", named, { a = "1" })
check.errors(named.add, "bad field 'a' in argument #1 to 'add' (number expected, got nil)", "add: missing", named, {})
check.errors(named.column, "bad argument #1 to 'column' (column name expected, got 'b'; columns: a)", "column: unknown", named, "b")
check.errors(named.write, "bad argument #1 to 'write' (file name expected, got nil; the recorder has no file)", "write without file", named)
check.errors(named.plot, "bad self to 'plot' (the recorder holds no samples yet)", "empty plot", named, { file = dir .. "/x.png" })
named:add{ a = 1 }
check.errors(named.plot, "bad argument #1 to 'plot' (unknown field 'ylgo'", "plot: typo", named, { file = dir .. "/x.png", ylgo = true })
check.errors(named.plot, "bad field 'y[1]' in argument #1 to 'plot' (column name (a) expected, got 'b')", "plot: y", named,
             { file = dir .. "/x.png", y = "b" })
check.errors(named.plot, "bad field 'file' in argument #1 to 'plot' (file name expected, got nil)", "plot: file", named, {})
check.errors(rec.sample, "bad self to 'sample' (grainlab.recorder expected, got table)", "dot call", {}, s)

-- ---- a run that dies ------------------------------------------------------------------------
-- flush = 0 rewrites at every sample: the on_step error stops the run and the CSV on disk holds
-- exactly the rows sampled before it.
local k = 0
local dying = grainlab.recorder{ file = dir .. "/dying.csv", flush = 0,
  columns = { { "n", function() k = k + 1; return k end },
              { "boom", function() if k == 3 then error("instability at sample 3") end return 0.5 end } } }
local ok, err = pcall(s.run, s, { steps = 1000, dt = 1e-5, every = 100, on_step = dying })
check.eq(ok, false, "the run failed")
check.contains(err, "instability at sample 3", "with the callback's error")
check.eq(slurp(dir .. "/dying.csv"), "n,boom\n1,0.5\n2,0.5\n", "the CSV of the two complete samples")

-- With periodic writes off, the rows still reach the file when the recorder is collected ...
local gone = grainlab.recorder{ file = dir .. "/gone.csv", flush = false, columns = { "x" } }
gone:add{ x = 1 }
gone:add{ x = 2 }
gone = nil
collectgarbage()
collectgarbage()
check.eq(slurp(dir .. "/gone.csv"), "x\n1\n2\n", "collected: the last rows written")

-- ... at the end of a <close> scope ...
do
  local scoped <close> = grainlab.recorder{ file = dir .. "/scoped.csv", flush = false, columns = { "x" } }
  scoped:add{ x = 0.25 }
end
check.eq(slurp(dir .. "/scoped.csv"), "x\n0.25\n", "<close>: the rows written")

-- ... and when a script dies with an error: Lua closes and the recorder writes what it has.
local exe = arg and arg[-1]
check.is_true(type(exe) == "string", "the binary's path is arg[-1]")
local script = dir .. "/dies.lua"
local f = assert(io.open(script, "w"))
f:write(string.format([[
local rec = grainlab.recorder{ file = %q, flush = false, columns = { "i", "sq" } }
for i = 1, 4 do rec:add{ i = i, sq = i * i * 0.5 } end
error("the run died at hour 3")
]], dir .. "/died.csv"))
f:close()
local p = io.popen(string.format("'%s' --quiet '%s' 2>&1; echo \"rc=$?\"", exe, script))
local out = p:read("a")
p:close()
check.contains(out, "the run died at hour 3", "the script failed")
check.contains(out, "rc=1", "with a non-zero exit")
check.eq(slurp(dir .. "/died.csv"), "i,sq\n1,0.5\n2,2\n3,4.5\n4,8\n", "its CSV holds every sampled row")

os.execute("rm -rf '" .. dir .. "'")
check.done()
