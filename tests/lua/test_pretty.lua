-- grainlab.pretty, the REPL's printer of results: exact strings for the shapes it must handle.
local check = grainlab.check
local P = grainlab.pretty

check.eq(P{}, "{}", "empty")
check.eq(P{ 1, 2.5, "a" }, '{1, 2.5, "a"}', "array in order, strings quoted")
check.eq(P{ 3, 1, zeta = 1, alpha = 2, [10] = 0, [true] = 1, ["two words"] = 3, ["end"] = 4 },
  '{3, 1, alpha = 2, ["end"] = 4, ["two words"] = 3, zeta = 1, [10] = 0, [true] = 1}',
  "mixed keys: array part, then string keys sorted, then numbers, then the rest")
check.eq(P{ a = { b = { c = { d = 1 } } } }, "{a = {b = {c = {…}}}}", "depth limit 3")
check.eq(P({ a = { b = 1 } }, { depth = 1 }), "{a = {…}}", "depth option")

local c = { name = "loop" }
c.self, c.kids = c, { c, { c } }
check.eq(P(c), '{kids = {<cycle>, {<cycle>}}, name = "loop", self = <cycle>}', "cycles")
local shared = { 1 }
check.eq(P{ shared, shared }, "{{1}, {1}}", "a shared table is not a cycle")

local long = {}
for i = 1, 2000 do long[i] = 0.001 + (i - 1) * 1e-4 end
check.eq(P(long), "{0.001, 0.0011, 0.0012, 0.0013, 0.0014, 0.0015, 0.0016, 0.0017, 0.0018, 0.0019, …(1990 more)}",
  "long array elided")
check.eq(P(long, { items = 2 }), "{0.001, 0.0011, …(1998 more)}", "items option")

check.eq(P{ 0 / 0, 1 / 0, -1 / 0, -0.0, 43.0, 1 / 3, 2 ^ 63, 1e-300, 7, math.mininteger },
  "{nan, inf, -inf, -0.0, 43.0, 0.333333, 9.22337e+18, 1e-300, 7, -9223372036854775808}",
  "numbers: %.6g, floats keep .0, nan and inf readable, integers exact")
check.eq(P{ s = "line\nbreak \"q\"" }, [[{s = "line\nbreak \"q\""}]], "escapes")
check.eq(P(("x"):rep(100), { string = 5 }), '"xxxxx…"', "long strings cut")
check.eq(P{ "\xff\0" }, [[{"\xff\0"}]], "bytes of a non-UTF-8 string escaped")
check.eq(P("ééééé", { string = 3 }), '"ééé…"', "UTF-8 cut at a character")

local fields = {}
for i = 1, 5 do fields["k" .. i] = i end
check.eq(P(fields, { fields = 3 }), "{k1 = 1, k2 = 2, k3 = 3, …(2 more fields)}", "fields option")

local obj = setmetatable({ hidden = 1 }, { __tostring = function() return "<obj>" end })
check.eq(P{ obj = obj }, "{obj = <obj>}", "__tostring of tables")
local trap = setmetatable({ 1 }, { __index = function() error("ran __index") end,
                                    __pairs = function() error("ran __pairs") end })
check.eq(P(trap), "{1}", "raw walk: no __index, no __pairs")
check.contains(P{ f = io.stdout }, "{f = file (0x", "userdata through tostring")

-- Past the width, a table breaks: array elements fill lines, each field on its own line.
check.eq(P({ x = { 1, 2, 3, 4, 5, 6 }, y = 2 }, { width = 26 }),
  "{\n  x = {1, 2, 3, 4, 5, 6},\n  y = 2\n}", "broken into lines")
check.eq(P({ 1, 2, 3, 4, 5, 6, 7, 8 }, { width = 13 }), "{\n  1, 2, 3, 4,\n  5, 6, 7, 8\n}",
  "array elements fill lines")

check.errors(function() P({}, { depht = 2 }) end,
  "bad argument #2 to 'pretty' (unknown field 'depht'; did you mean 'depth'? Valid fields: depth, items, fields, width, string)", "typo in an option")
check.errors(function() P({}, { depth = -1 }) end,
  "bad field 'depth' in argument #2 to 'pretty' (non-negative integer expected, got -1)", "bad option value")

-- show prints like the REPL: tables pretty, other values as print has them, tab-separated.
local lines, real = {}, print
print = function(...)
  local t = table.pack(...)
  for i = 1, t.n do t[i] = tostring(t[i]) end
  lines[#lines + 1] = table.concat(t, "\t", 1, t.n)
end
grainlab.show({ a = 1 }, "text", 2.0, nil)
print = real
check.eq(lines[1], "{a = 1}\ttext\t2.0\tnil", "show")
check.done()
