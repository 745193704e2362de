-- grainlab.pretty(v [, opts]): a readable, bounded rendering of a Lua value, which the REPL uses
-- for the tables that expressions return (s:measure(...), s:info(), run results).
-- Written in Lua rather than C: it is all string building, key sorting and recursion, which Lua
-- does in a few lines, and its cost is bounded by the limits below, not by the table's size.
-- Tables are walked with next/rawget only, so printing never runs a __index or __pairs.
local M = {}

local DEFAULTS = { depth = 3, items = 10, fields = 40, width = 100, string = 80 }

local function number(v)
  if math.type(v) == "integer" then return string.format("%d", v) end
  if v ~= v then return "nan" end
  if v == math.huge then return "inf" end
  if v == -math.huge then return "-inf" end
  local s = string.format("%.6g", v)
  -- a float stays visibly a float, as Lua prints it (43.0, not 43)
  if not s:find("[.eni]") then s = s .. ".0" end
  return s
end

-- Quoted and escaped as Lua would read it back; cut after max characters (bytes if the string
-- is not UTF-8, whose bytes above 127 are then shown as \xNN).
local function quote(s, max)
  local utf = utf8.len(s) ~= nil
  local cut = (utf and utf8.len(s) or #s) > max
  if cut then s = s:sub(1, (utf and utf8.offset(s, max + 1) or max + 1) - 1) end
  s = string.format("%q", s):gsub("\\\n", "\\n"):gsub("\\13", "\\r")
  if not utf then s = s:gsub("[\128-\255]", function(c) return string.format("\\x%02x", c:byte()) end) end
  if cut then s = s:sub(1, -2) .. "…\"" end
  return s
end

local function plain(v)
  local ok, s = pcall(tostring, v)
  return ok and s or "<" .. type(v) .. ">"
end

local KEYWORDS = {}
for w in ("and break do else elseif end false for function goto if in local nil not or repeat " ..
          "return then true until while"):gmatch("%a+") do KEYWORDS[w] = true end

-- Order of the non-array keys: strings sorted, then numbers ascending, then the rest by type.
local RANK = { string = 1, number = 2, boolean = 3 }
local function key_less(a, b)
  local ta, tb = type(a), type(b)
  local ra, rb = RANK[ta] or 4, RANK[tb] or 4
  if ra ~= rb then return ra < rb end
  if ta == "string" or ta == "number" then
    if a ~= a then return false end -- NaN cannot be a key, but keep the order total
    return a < b
  end
  if ta == "boolean" then return (not a) and b end
  return plain(a) < plain(b)
end

local format

-- Columns a string takes: characters for UTF-8, bytes otherwise (binary strings).
local function len(s) return utf8.len(s) or #s end

local function key_text(k, o, path)
  if type(k) == "string" and k:match("^[%a_][%w_]*$") and not KEYWORDS[k] then return k end
  return "[" .. format(k, o, path, 1, 0, 0) .. "]"
end

-- path: the tables being printed above this one (a table met again on it is a cycle); indent:
-- of the lines of a broken table; col: where this value starts on its line.
function format(v, o, path, level, indent, col)
  local t = type(v)
  if t == "number" then return number(v) end
  if t == "string" then return quote(v, o.string) end
  if t ~= "table" then return plain(v) end
  local mt = getmetatable(v)
  if type(mt) == "table" and rawget(mt, "__tostring") then return plain(v) end
  if path[v] then return "<cycle>" end
  if next(v) == nil then return "{}" end
  if level > o.depth then return "{…}" end
  path[v] = true

  local parts = {}
  local n = 0
  while rawget(v, n + 1) ~= nil do n = n + 1 end
  for i = 1, math.min(n, o.items) do parts[#parts + 1] = format(rawget(v, i), o, path, level + 1, indent + 2, indent + 2) end
  if n > o.items then parts[#parts + 1] = string.format("…(%d more)", n - o.items) end
  local npos = #parts

  local keys = {}
  for k in next, v do
    if not (math.type(k) == "integer" and k >= 1 and k <= n) then keys[#keys + 1] = k end
  end
  table.sort(keys, key_less)
  for j = 1, math.min(#keys, o.fields) do
    local k = keys[j]
    local kt = key_text(k, o, path) .. " = "
    parts[#parts + 1] = kt .. format(rawget(v, k), o, path, level + 1, indent + 2, indent + 2 + len(kt))
  end
  if #keys > o.fields then parts[#parts + 1] = string.format("…(%d more fields)", #keys - o.fields) end
  path[v] = nil

  local line = "{" .. table.concat(parts, ", ") .. "}"
  if col + len(line) <= o.width and not line:find("\n", 1, true) then return line end
  -- Broken: array elements fill lines up to the width, each other field has its own line.
  local pad = string.rep(" ", indent + 2)
  local lines, cur = {}, nil
  for j, p in ipairs(parts) do
    local packable = j <= npos and not p:find("\n", 1, true)
    if cur and packable and #pad + len(cur) + 2 + len(p) + 1 <= o.width then -- "," too
      cur = cur .. ", " .. p
    else
      if cur then lines[#lines + 1] = cur end
      cur = p
    end
    if not packable then lines[#lines + 1] = cur; cur = nil end
  end
  if cur then lines[#lines + 1] = cur end
  return "{\n" .. pad .. table.concat(lines, ",\n" .. pad) .. "\n" .. string.rep(" ", indent) .. "}"
end

local OPTS = { "depth", "items", "fields", "width", "string" }

local function pretty(v, opts)
  local o = {}
  for k, d in pairs(DEFAULTS) do o[k] = d end
  o.width = math.type(M.width) == "integer" and M.width or o.width -- the REPL's terminal
  if opts ~= nil then
    if type(opts) ~= "table" then
      error("bad argument #2 to 'pretty' (table expected, got " .. type(opts) .. ")", 2)
    end
    for k, x in pairs(opts) do
      if DEFAULTS[k] == nil then
        error("bad argument #2 to 'pretty' " .. require("grainlab.args").unknown(k, OPTS), 2)
      end
      if math.type(x) ~= "integer" or x < 0 then
        error(string.format("bad field '%s' in argument #2 to 'pretty' (non-negative integer expected, got %s)",
          k, type(x) == "string" and "'" .. x .. "'" or tostring(x)), 2)
      end
      o[k] = x
    end
  end
  return format(v, o, {}, 1, 0, 0)
end

-- The REPL's printing: tables (without __tostring) pretty, everything else as print shows it,
-- all through the global print so a redefined print still applies.
local function show(...)
  local out = table.pack(...)
  for i = 1, out.n do
    local v = out[i]
    if type(v) == "table" then out[i] = pretty(v) end
  end
  print(table.unpack(out, 1, out.n))
end

M.pretty, M.show = pretty, show

local fields = table.move(OPTS, 1, #OPTS, 1, {})
table.sort(fields)
grainlab.doc(pretty, { name = "grainlab.pretty", fields = fields,
  usage = "grainlab.pretty(v, { depth = 3, items = 10, fields = 40, width = 100, string = 80 })",
  doc = [[A readable string of v, as the REPL prints results: arrays in order, then string keys
sorted (then other keys); tables nested deeper than `depth` as {…}; arrays past `items`
elements and more than `fields` other keys elided with …(N more); strings quoted (cut after
`string` bytes); numbers %.6g (integers as integers, floats keep a .0, nan, inf); a table seen
again inside itself as <cycle>; tables with __tostring and userdata through tostring. Lines
longer than `width` (in the REPL: the terminal's) break, array elements filling lines, other
fields one per line. print(t) itself is unchanged.]] })
grainlab.doc(show, { name = "grainlab.show", usage = "grainlab.show(...)",
  doc = [[Prints its arguments as the REPL prints results: tables through grainlab.pretty, other
values as print shows them, separated by tabs.]] })
return M
