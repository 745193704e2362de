-- Argument checking for the Lua-side API (grainlab.pack, grainlab.biax, ...), in the grammar of
-- the C bindings: "bad field 'n' in argument #2 to 'grainlab.pack.deposit' (positive integer
-- expected, got -3)". A public function checks everything at its entry, so an error names the
-- call the user made, never an internal one (add_disk, rng, uniform) nor "attempt to index".
--
--   local args = require("grainlab.args")
--   local SPEC = { n = { "integer", min = 1, max = 1e7, required = true },
--                  radius = { "positive" }, mode = { "option", values = { "a", "b" } } }
--   args.check("grainlab.pack.deposit", 2, opts, SPEC)   -- unknown keys refused too
--   args.fields(SPEC)                                     -- sorted names, for grainlab.doc
-- Kinds: number (finite), positive, nonneg, range (lo, hi, open_lo, open_hi), integer (min,
-- max), boolean, string, path (a file name: non-empty, no NUL byte), option (values), function,
-- table, and custom: { check = function(v) return ok, expected end }. Numbers above 1e100 in
-- magnitude are refused, as in the C bindings. An unknown key names the closest valid one.
local args = {}

local MAX = 1e100

local function describe(v)
  if type(v) == "string" then
    v = v:gsub("\0", "\\0") -- a NUL byte shown, as the C bindings show it
    return "'" .. (#v > 40 and v:sub(1, 37) .. "..." or v) .. "'"
  end
  if type(v) == "number" or type(v) == "boolean" or v == nil then return tostring(v) end
  return type(v)
end
args.describe = describe

-- The error is raised at the user's call: the first frame above the grainlab.* Lua modules (so
-- the library's functions may call each other freely), and above the C functions they call
-- (xpcall in grainlab.entry).
-- A C caller (pcall) gets no position, as with the C bindings.
local function library(info) return info and info.short_src:find("grainlab/[%w_]+%.lua$") end
local function user_level()
  local level = 3 -- 1: user_level's caller's error call site is level 2 of raise
  while true do
    local info = debug.getinfo(level, "S")
    if not info then return 1 end
    if not (library(info) or info.what == "C" and library(debug.getinfo(level + 1, "S"))) then
      return level - 1
    end
    level = level + 1
  end
end

local function raise(msg) error(msg, user_level()) end
args.raise = raise

function args.fail(call, argn, field, expected, got)
  raise(string.format("bad field '%s' in argument #%d to '%s' (%s expected, got %s)", field, argn,
                      call, expected, describe(got)))
end

function args.arg_fail(call, argn, expected, got)
  raise(string.format("bad argument #%d to '%s' (%s expected, got %s)", argn, call, expected,
                      describe(got)))
end

-- Optimal string alignment distance (edits and adjacent swaps), as src/lua/args.c computes it.
local function distance(a, b)
  local d = {}
  for i = 0, #a do d[i] = { [0] = i } end
  for j = 0, #b do d[0][j] = j end
  for i = 1, #a do
    for j = 1, #b do
      local best = math.min(d[i - 1][j - 1] + (a:byte(i) == b:byte(j) and 0 or 1),
                            d[i - 1][j] + 1, d[i][j - 1] + 1)
      if i > 1 and j > 1 and a:byte(i) == b:byte(j - 1) and a:byte(i - 1) == b:byte(j) then
        best = math.min(best, d[i - 2][j - 2] + 1)
      end
      d[i][j] = best
    end
  end
  return d[#a][#b]
end

-- The name of `names` closest to s, or nil: a unique prefix of at least two letters ("temp"),
-- else one that differs only in case, else the nearest of three letters or more within a third
-- of its length, at least one edit (bind_closest_name's rule).
function args.closest(s, names)
  if type(s) ~= "string" or #s > 32 then return nil end
  local prefix, nprefix = nil, 0
  for _, name in ipairs(names) do
    if #s >= 2 and name:sub(1, #s) == s then prefix, nprefix = name, nprefix + 1 end
  end
  if nprefix == 1 then return prefix end
  for _, name in ipairs(names) do
    if name:lower() == s:lower() then return name end
  end
  local best, best_d
  for _, name in ipairs(names) do
    local d = #name >= 3 and distance(s, name)
    if d and d <= math.max(1, #name // 3) and (not best_d or d < best_d) then best, best_d = name, d end
  end
  return best
end

-- "(unknown field 'raduis'; did you mean 'radius'? Valid fields: a, b)" for key k of a table
-- whose keys are `names` (sorted).
function args.unknown(k, names)
  local near = args.closest(k, names)
  return string.format("(unknown field %s; %s: %s)", describe(k),
                       near and ("did you mean '" .. near .. "'? Valid fields") or "valid fields",
                       table.concat(names, ", "))
end

-- A file name that crosses into C intact: a non-empty string without NUL bytes (the C side
-- would end the name at the first NUL: "a\0b.txt" written as "a").
function args.is_path(v) return type(v) == "string" and v ~= "" and not v:find("\0", 1, true) end

local function finite(v) return type(v) == "number" and v == v and v >= -MAX and v <= MAX end

local function number_expected(base, v)
  if type(v) == "number" and v == v and v ~= math.huge and v ~= -math.huge and not finite(v) then
    return base .. " of magnitude at most 1e+100"
  end
  return base
end

-- ok, expected for value v against field spec f.
local function validate(f, v)
  local kind = f[1]
  if f.check then return f.check(v) end
  if kind == "number" then return finite(v), number_expected("finite number", v) end
  if kind == "positive" then return finite(v) and v > 0, number_expected("positive number", v) end
  if kind == "nonneg" then return finite(v) and v >= 0, number_expected("non-negative number", v) end
  if kind == "range" then
    local ok = finite(v) and (f.open_lo and v > f.lo or not f.open_lo and v >= f.lo)
      and (f.open_hi and v < f.hi or not f.open_hi and v <= f.hi)
    return ok, string.format("number in %s%g, %g%s", f.open_lo and "(" or "[", f.lo, f.hi,
                             f.open_hi and ")" or "]")
  end
  if kind == "integer" then
    local lo, hi = f.min or -math.maxinteger, f.max or math.maxinteger
    local expected = (lo == 1 and not f.max) and "positive integer"
      or (lo == 0 and not f.max) and "non-negative integer"
      or string.format("integer in [%d, %d]", lo, math.tointeger(hi) or hi)
    return math.type(v) == "integer" and v >= lo and v <= hi, expected
  end
  if kind == "boolean" then return type(v) == "boolean", "boolean" end
  if kind == "string" then return type(v) == "string", "string" end
  if kind == "path" then
    return args.is_path(v), type(v) == "string" and "non-empty file path without NUL bytes" or "file path (string)"
  end
  if kind == "function" then return type(v) == "function", "function" end
  if kind == "table" then return type(v) == "table", "table" end
  if kind == "option" then
    local names = {}
    for i, name in ipairs(f.values) do
      if v == name then return true end
      names[i] = "'" .. name .. "'"
    end
    return false, "one of " .. table.concat(names, ", ")
  end
  error("grainlab.args: unknown kind " .. tostring(kind), 2)
end

function args.fields(spec)
  local names = {}
  for name in pairs(spec) do names[#names + 1] = name end
  table.sort(names)
  return names
end

-- Checks the options table opts (argument #argn of call) against spec; nil is {} when
-- optional is true. Returns opts. Errors are raised at the caller of the public function.
function args.check(call, argn, opts, spec, optional)
  if opts == nil and optional then return {} end
  if type(opts) ~= "table" then args.arg_fail(call, argn, "table", opts) end
  for k in pairs(opts) do
    if type(k) ~= "string" or not spec[k] then
      raise(string.format("bad argument #%d to '%s' %s", argn, call, args.unknown(k, args.fields(spec))))
    end
  end
  for _, name in ipairs(args.fields(spec)) do
    local f, v = spec[name], opts[name]
    if v == nil then
      if f.required then args.fail(call, argn, name, select(2, validate(f, nil)) or f[1], nil) end
    else
      local ok, expected = validate(f, v)
      if not ok then args.fail(call, argn, name, expected, v) end
    end
  end
  return opts
end

-- The object at argument #argn has the userdata type tname (its metatable's __name).
function args.object(call, argn, v, tname)
  local mt = type(v) == "userdata" and getmetatable(v)
  if not (type(mt) == "table" and mt.__name == tname) then
    args.arg_fail(call, argn, tname, v)
  end
  return v
end

-- Field kinds shared by the packers.
function args.material(v)
  local mt = getmetatable(v)
  return type(v) == "table" and type(mt) == "table" and mt.__name == "grainlab.material",
    "grainlab.material"
end

-- {{lower corner}, {upper corner}} of dim finite numbers each, upper above lower.
function args.box(dim)
  return function(v)
    local ok = type(v) == "table" and #v == 2 and type(v[1]) == "table" and type(v[2]) == "table"
      and #v[1] == dim and #v[2] == dim
    for d = 1, dim do
      ok = ok and finite(v[1][d]) and finite(v[2][d]) and v[2][d] > v[1][d]
    end
    return ok, string.format("{{lower corner}, {upper corner}} with %d finite numbers each, upper above lower", dim)
  end
end

return args
