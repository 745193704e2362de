-- grainlab.recorder{…}: a time series sampled from a run's on_step (or added row by row), kept as
-- columns, written as CSV (whole: temporary file + rename) and drawn with render.plot, so a script
-- needs no CSV loop of its own.
--
-- When the CSV is written: at construction (the header: a bad path fails before the run), then
-- again at most every `flush` seconds of wall clock while samples arrive (default 10, and never
-- more often than 20x the time the last write took, so rewriting a long file costs < 5% of the
-- run; flush = 0: at every sample, flush = false: not during the run), at rec:write(), at the end of a `<close>` scope, and when the recorder is collected or
-- Lua closes — which a script that dies with an error or Ctrl-C still reaches. A run killed
-- outright (SIGKILL, a node's time limit) loses at most the last `flush` seconds of samples; the
-- file on disk is always a complete CSV of the rows sampled before its last write.
local grainlab = grainlab
local args = require("grainlab.args")

local M = {} -- the methods; the instance metatable is below
local MT = { __index = M, __name = "grainlab.recorder" }

local function describe(v)
  if type(v) == "string" then return "'" .. v:gsub("\0", "\\0") .. "'" end
  if type(v) == "number" or type(v) == "boolean" then return tostring(v) end
  return type(v)
end

local function bad_field(call, field, expected, got, level)
  error(string.format("bad field '%s' in argument #1 to '%s' (%s expected, got %s)", field, call,
                      expected, describe(got)), level + 1)
end

-- A column name or unit lands in the CSV header unquoted: no separators, quotes or line breaks.
local function clean_text(s) return type(s) == "string" and s ~= "" and not s:find('[,"\r\n]') end

-- Exact text of a value: integers as integers, floats with 17 significant digits (they read back
-- to the same double), NaN as `nan` whatever its sign bit (C prints -nan for some NaNs).
local function fmt(v)
  if math.type(v) == "integer" then return string.format("%d", v) end
  if v ~= v then return "nan" end
  return string.format("%.17g", v)
end

local function mkdir_for(path)
  local dir = path:match("^(.*)/[^/]*$")
  if dir and dir ~= "" then os.execute("mkdir -p '" .. dir:gsub("'", "'\\''") .. "' 2>/dev/null") end
end

local FIELDS = { file = true, columns = true, order = true, units = true, flush = true }
local FIELD_NAMES = { "columns", "file", "flush", "order", "units" }

-- A file name: non-empty, and without a NUL byte (the C side would end the name there).
local function file_expected(v)
  return type(v) == "string" and v ~= "" and "file name without NUL bytes" or "file name"
end

-- Reads `columns` (+ `order`) into an array of { name =, fn = } in CSV order.
local function read_columns(t)
  local cols = t.columns
  if type(cols) ~= "table" or next(cols) == nil then
    bad_field("recorder", "columns", "non-empty table of columns", cols, 3)
  end
  local out = {}
  if #cols > 0 then -- an array: { "name" } (filled by rec:add) or { "name", fn }
    if t.order ~= nil then
      bad_field("recorder", "order", "nil (the 'columns' array already gives the order)", t.order, 3)
    end
    for k in pairs(cols) do
      if math.type(k) ~= "integer" or k < 1 or k > #cols then
        bad_field("recorder", "columns", "array of { name, fn } (no other keys)", k, 3)
      end
    end
    for i, c in ipairs(cols) do
      local where = "columns[" .. i .. "]"
      local name, fn = c, nil
      if type(c) == "table" then
        for k in pairs(c) do
          if k ~= 1 and k ~= 2 then bad_field("recorder", where, "{ name, fn }", k, 3) end
        end
        name, fn = c[1], c[2]
      end
      if not clean_text(name) then
        bad_field("recorder", where, "column name (text without , \" or a line break)", name, 3)
      end
      if fn ~= nil and type(fn) ~= "function" then
        bad_field("recorder", where .. "[2]", "function(s) returning a number", fn, 3)
      end
      out[i] = { name = name, fn = fn }
    end
  else -- a map name -> fn, in the order `order` gives
    if type(t.order) ~= "table" then
      bad_field("recorder", "order",
                "array of the column names (the 'columns' given by name have no order of their own)", t.order, 3)
    end
    local seen = {}
    for i, name in ipairs(t.order) do
      if cols[name] == nil then
        bad_field("recorder", "order[" .. i .. "]", "name of one of the 'columns'", name, 3)
      end
      seen[name] = true
      out[i] = { name = name, fn = cols[name] }
    end
    for name, fn in pairs(cols) do
      if not clean_text(name) then
        bad_field("recorder", "columns", "column name (text without , \" or a line break)", name, 3)
      end
      if type(fn) ~= "function" then
        bad_field("recorder", "columns." .. name, "function(s) returning a number", fn, 3)
      end
      if not seen[name] then bad_field("recorder", "order", "array naming every column", name, 3) end
    end
  end
  local names = {}
  for i, c in ipairs(out) do
    -- in the map form a name can only repeat in `order`
    if names[c.name] then
      bad_field("recorder", #cols > 0 and "columns" or "order", "distinct column names", c.name, 3)
    end
    names[c.name] = i
  end
  return out, names
end

-- grainlab.recorder{ file =, columns =, order =, units =, flush = 10 }
local function new(t)
  if type(t) ~= "table" then
    error("bad argument #1 to 'recorder' (table expected, got " .. describe(t) .. ")", 2)
  end
  for k in pairs(t) do
    if not FIELDS[k] then
      error("bad argument #1 to 'recorder' " .. args.unknown(k, FIELD_NAMES), 2)
    end
  end
  if t.file ~= nil and not args.is_path(t.file) then
    bad_field("recorder", "file", file_expected(t.file), t.file, 2)
  end
  local flush = t.flush
  if flush == nil then flush = 10 end
  if flush ~= false and (type(flush) ~= "number" or not (flush >= 0)) then
    bad_field("recorder", "flush", "seconds >= 0 or false", flush, 2)
  end
  local cols, index = read_columns(t)
  local units = t.units or {}
  if type(units) ~= "table" then bad_field("recorder", "units", "table name -> unit", units, 2) end
  for name, u in pairs(units) do
    if not index[name] then bad_field("recorder", "units", "names of the 'columns'", name, 2) end
    if not clean_text(u) then
      bad_field("recorder", "units." .. name, "unit text without , \" or a line break", u, 2)
    end
  end
  local head = {}
  for i, c in ipairs(cols) do
    c.unit = units[c.name]
    c.data = {}
    head[i] = c.unit and (c.name .. " (" .. c.unit .. ")") or c.name
  end
  local rec = setmetatable({
    _cols = cols, _index = index, _n = 0, _lines = {}, _header = table.concat(head, ","),
    _file = t.file, _flush = flush, _written = 0, _last = 0, _cost = 0,
  }, MT)
  local d = grainlab.doc_of(MT) -- help(rec) answers with the type's text (docs.lua writes it)
  if d then grainlab.doc(rec, { name = d.name, usage = d.usage, doc = d.doc }) end
  if rec._file then
    mkdir_for(rec._file)
    local ok, err = grainlab.write_file(rec._file, rec._header .. "\n")
    if not ok then bad_field("recorder", "file", "writable path (" .. tostring(err) .. ")", t.file, 2) end
    rec._last = grainlab.clock()
  end
  return rec
end

local function csv(rec)
  if rec._n == 0 then return rec._header .. "\n" end
  return rec._header .. "\n" .. table.concat(rec._lines, "\n", 1, rec._n) .. "\n"
end

local function write(rec, path)
  local t0 = grainlab.clock()
  local ok, err = grainlab.write_file(path, csv(rec))
  local t1 = grainlab.clock()
  if path == rec._file and ok then
    rec._written, rec._last, rec._cost = rec._n, t1, t1 - t0
  end
  return ok, err
end

-- Stores one row of checked values; the periodic write follows.
local function append(rec, row)
  local n = rec._n + 1
  local parts = {}
  for i, c in ipairs(rec._cols) do
    c.data[n] = row[i]
    parts[i] = fmt(row[i])
  end
  rec._lines[n] = table.concat(parts, ",")
  rec._n = n
  if rec._file and rec._flush then
    local now = grainlab.clock()
    -- flush = 0 asks for every sample; otherwise a long file is not rewritten more often than
    -- 20x the time its last write took (< 5% of the run spent writing)
    if rec._flush == 0 or now - rec._last >= math.max(rec._flush, 20 * rec._cost) then
      local ok, err = write(rec, rec._file)
      if not ok then error("recorder: " .. tostring(err), 3) end
    end
  end
end

local function check_self(rec, call)
  if getmetatable(rec) ~= MT then
    error(string.format("bad self to '%s' (grainlab.recorder expected, got %s): call it as rec:%s(...)",
                        call, describe(rec), call), 3)
  end
end

-- rec:sample(s): one row, each column's fn(s).
function M.sample(rec, s)
  check_self(rec, "sample")
  local row = {}
  for i, c in ipairs(rec._cols) do
    if not c.fn then
      error(string.format("bad column '%s' in 'sample' (no function to sample it: give { '%s', fn } or fill the rows with rec:add{...})",
                          c.name, c.name), 2)
    end
    local v = c.fn(s)
    if type(v) ~= "number" then
      error(string.format("bad value of column '%s' in 'sample' (number expected, got %s)", c.name,
                          describe(v)), 2)
    end
    row[i] = v
  end
  append(rec, row)
end

-- rec:add{ name = value, ... }: one row given by value, every column named.
function M.add(rec, values)
  check_self(rec, "add")
  if type(values) ~= "table" then
    error("bad argument #1 to 'add' (table name -> number expected, got " .. describe(values) .. ")", 2)
  end
  for k in pairs(values) do
    if not rec._index[k] then
      local near = args.closest(k, M.names(rec))
      error(string.format("bad argument #1 to 'add' (unknown column %s; %scolumns: %s)", describe(k),
                          near and ("did you mean '" .. near .. "'? ") or "",
                          table.concat(M.names(rec), ", ")), 2)
    end
  end
  local row = {}
  for i, c in ipairs(rec._cols) do
    local v = values[c.name]
    if type(v) ~= "number" then bad_field("add", c.name, "number", v, 2) end
    row[i] = v
  end
  append(rec, row)
end

-- rec:names(): the column names in CSV order.
function M.names(rec)
  check_self(rec, "names")
  local out = {}
  for i, c in ipairs(rec._cols) do out[i] = c.name end
  return out
end

local function column_of(rec, name, call, argn)
  local i = rec._index[name]
  if not i then
    error(string.format("bad argument #%d to '%s' (column name expected, got %s; columns: %s)", argn,
                        call, describe(name), table.concat(M.names(rec), ", ")), 3)
  end
  return rec._cols[i]
end

-- rec:column(name): a copy of the column's values, in sampling order.
function M.column(rec, name)
  check_self(rec, "column")
  local c = column_of(rec, name, "column", 1)
  return table.move(c.data, 1, rec._n, 1, {})
end

-- rec:write([path]): the whole CSV to path (default: the recorder's file).
function M.write(rec, path)
  check_self(rec, "write")
  path = path or rec._file
  if not args.is_path(path) then
    error("bad argument #1 to 'write' (" .. file_expected(path) .. " expected, got " .. describe(path) ..
          (rec._file and ")" or "; the recorder has no file)"), 2)
  end
  mkdir_for(path)
  local ok, err = write(rec, path)
  if not ok then error("write: " .. tostring(err), 2) end
  return path
end

-- rec:plot's options, checked at its entry (render.plot would name its own fields: series[1]).
local SIZE = { "integer", min = 16, max = 8192 } -- render's image sizes
local PLOT = {
  file = { required = true, check = function(v) return args.is_path(v), file_expected(v) end },
  x = { "string" },
  y = { check = function(v) return type(v) == "string" or type(v) == "table", "column name or array of names" end },
  labels = { "table" }, title = { "string" }, xlabel = { "string" }, ylabel = { "string" },
  xlog = { "boolean" }, ylog = { "boolean" }, width = SIZE, height = SIZE,
  style = { "option", values = { "line", "points", "both", "none" } },
}

-- On a log axis a value <= 0 has no place: it becomes a gap (NaN), as a zero kinetic energy at rest.
local function plotted(data, n, log)
  local out = table.move(data, 1, n, 1, {})
  if log then
    for k = 1, n do if out[k] <= 0 then out[k] = 0 / 0 end end
  end
  return out
end

-- rec:plot{ file =, x = first column, y = the others (name or names), labels =, title =, xlabel =,
-- ylabel =, xlog =, ylog =, width =, height =, style = 'line' }
function M.plot(rec, o)
  check_self(rec, "plot")
  args.check("plot", 1, o, PLOT)
  if rec._n == 0 then error("bad self to 'plot' (the recorder holds no samples yet)", 2) end
  local xc = rec._cols[1]
  if o.x ~= nil then
    if not rec._index[o.x] then bad_field("plot", "x", "column name (" .. table.concat(M.names(rec), ", ") .. ")", o.x, 2) end
    xc = rec._cols[rec._index[o.x]]
  end
  local ys = o.y
  if ys == nil then
    ys = {}
    for _, c in ipairs(rec._cols) do if c ~= xc then ys[#ys + 1] = c.name end end
  elseif type(ys) == "string" then
    ys = { ys }
  end
  if type(ys) ~= "table" or #ys == 0 then bad_field("plot", "y", "column name or array of names", o.y, 2) end
  for i in pairs(ys) do
    if math.type(i) ~= "integer" or i < 1 or i > #ys then
      bad_field("plot", "y", "column name or array of names", o.y, 2)
    end
  end
  if o.labels ~= nil and (type(o.labels) ~= "table" or #o.labels ~= #ys) then
    bad_field("plot", "labels", "array of " .. #ys .. " labels (one per y column)", o.labels, 2)
  end
  for i, label in pairs(o.labels or {}) do
    if math.type(i) ~= "integer" or i < 1 or i > #ys or type(label) ~= "string" then
      bad_field("plot", "labels", "array of " .. #ys .. " labels (one per y column)", o.labels, 2)
    end
  end
  local x = plotted(xc.data, rec._n, o.xlog)
  local series, unit = {}, nil
  for i, name in ipairs(ys) do
    local k = rec._index[name]
    if not k then
      bad_field("plot", "y[" .. i .. "]", "column name (" .. table.concat(M.names(rec), ", ") .. ")", name, 2)
    end
    local c = rec._cols[k]
    if i == 1 then unit = c.unit elseif unit ~= c.unit then unit = nil end
    local label = o.labels and o.labels[i] or (#ys > 1 and name or nil)
    series[i] = { x = x, y = plotted(c.data, rec._n, o.ylog), label = label, style = o.style }
  end
  local xlabel = o.xlabel or (xc.unit and (xc.name .. " (" .. xc.unit .. ")") or xc.name)
  local ylabel = o.ylabel or (#ys == 1 and (unit and (ys[1] .. " (" .. unit .. ")") or ys[1]) or unit)
  mkdir_for(o.file)
  return render.plot{ file = o.file, series = series, title = o.title, xlabel = xlabel,
                      ylabel = ylabel, xlog = o.xlog, ylog = o.ylog, width = o.width, height = o.height }
end

MT.__call = M.sample
MT.__len = function(rec) return rec._n end
MT.__tostring = function(rec)
  return string.format("grainlab.recorder(%s; %d samples%s)", table.concat(M.names(rec), ", "), rec._n,
                       rec._file and (" -> " .. rec._file) or "")
end
-- The last rows reach the file when the recorder goes away: at the end of a `<close>` scope, when
-- it is collected, and when Lua closes after a script's error.
local function finish(rec)
  if rec._file and rec._written ~= rec._n then
    local ok, err = write(rec, rec._file)
    if not ok then io.stderr:write("grainlab.recorder: ", tostring(err), "\n") end
  end
end
MT.__close = finish
MT.__gc = finish

-- Registered as a named type (as luaL_newmetatable does for the C types), so help and
-- tests/lua/test_help_all.lua find its methods the way they find dem.scene's.
debug.getregistry()["grainlab.recorder"] = MT

-- The fields of grainlab.recorder{...} and rec:plot{...} (for help and the generated test,
-- test_fuzz_core.lua).
local fields = {}
for k in pairs(FIELDS) do fields[#fields + 1] = k end
table.sort(fields)

return { new = new, methods = M, type = MT, fields = fields, plot_fields = args.fields(PLOT) }
