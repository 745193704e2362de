-- grainlab.report{…}: the one way a scenario hands its figures to people, tests and benchmarks.
-- Prints a readable table; with --report FILE.json (or GRAINLAB_REPORT=FILE) also writes
--   {"scenario", "params", "metrics", "checks": [{"name","value","limit","op","pass"}], "wall_s"}
-- whole (temporary file, then rename). Failed checks make the process exit non-zero.
local json = require "grainlab.json"
local args = require "grainlab.args"

local M = { failed = 0, written = nil }

local OPS = {
  ["<="] = function(v, l) return v <= l end,
  ["<"]  = function(v, l) return v < l end,
  [">="] = function(v, l) return v >= l end,
  [">"]  = function(v, l) return v > l end,
  ["=="] = function(v, l) return v == l end,
}

local function describe(v)
  if type(v) == "string" then return "'" .. v .. "'" end
  if v ~= v then return "nan" end
  if type(v) == "number" or type(v) == "boolean" then return tostring(v) end
  return type(v)
end

-- Validation errors are raised without a position here; report() re-raises them at the caller.
local function bad(field, expected, got)
  error(string.format("bad field '%s' in argument #1 to 'report' (%s expected, got %s)",
                      field, expected, describe(got)), 0)
end

local function only(t, where, allowed)
  for k in pairs(t) do
    if not allowed[k] then
      local names = {}
      for name in pairs(allowed) do names[#names + 1] = name end
      table.sort(names)
      local unknown = args.unknown(k, names)
      if where then
        error(string.format("bad field '%s' in argument #1 to 'report' %s", where, unknown), 0)
      end
      error("bad argument #1 to 'report' " .. unknown, 0)
    end
  end
end

local function is_name(s) return type(s) == "string" and s:match("^[a-z][a-z0-9_]*$") ~= nil end

-- A scenario names the run in the JSON and in the file names tools derive from it: letters,
-- digits, '_', '.' and '-', starting with a letter or digit, at most 64 characters.
local SCENARIO = "scenario name of letters, digits, '_', '.' and '-' (starting with a letter or digit, at most 64)"
local function is_scenario(s)
  return type(s) == "string" and #s <= 64 and s:match("^[A-Za-z0-9][A-Za-z0-9_.-]*$") ~= nil
end

-- A figure is a finite number, a string, a boolean, or a table of figures that JSON can hold
-- (an array 1..n, or string keys), checked here at the call so that nothing is printed or
-- written before the whole report is known to be valid. NaN and infinities have no JSON form
-- (they would turn into null unnoticed): a figure that can be NaN belongs in a check, which a NaN
-- value fails.
local function check_value(v, field, seen)
  local tv = type(v)
  if tv == "number" then
    if v ~= v or v == math.huge or v == -math.huge then
      bad(field, "finite number (a NaN or infinite figure belongs in a check, where it fails)", v)
    end
    return
  end
  if tv == "string" or tv == "boolean" then return end
  if tv == "table" then
    seen = seen or {}
    if seen[v] then bad(field, "table that does not contain itself", v) end
    seen[v] = true
    local n, strings, others = #v, 0, 0
    for k in pairs(v) do
      if type(k) == "string" then strings = strings + 1
      elseif math.type(k) == "integer" and k >= 1 and k <= n then others = others + 1
      else bad(field, "array 1..n or table with string keys (found key " .. describe(k) .. ")", v) end
    end
    if strings > 0 and others > 0 then
      bad(field, "array 1..n or table with string keys (not both)", v)
    end
    for k, x in pairs(v) do check_value(x, field .. "." .. tostring(k), seen) end
    seen[v] = nil
    return
  end
  bad(field, "number, string, boolean or table", v)
end

local function fmt(v)
  if math.type(v) == "integer" then return string.format("%d", v) end
  if type(v) == "number" then return string.format("%.6g", v) end
  if type(v) == "table" then
    local n = 0
    for _ in pairs(v) do n = n + 1 end
    return string.format("(table of %d)", n)
  end
  return tostring(v)
end

local function sorted_keys(t)
  local keys = {}
  for k in pairs(t) do keys[#keys + 1] = k end
  table.sort(keys, function(a, b) return tostring(a) < tostring(b) end)
  return keys
end

local function normalise_checks(list)
  if list == nil then return {} end
  if type(list) ~= "table" then bad("checks", "array of checks", list) end
  local out, names = {}, {}
  for i, c in ipairs(list) do
    local where = "checks[" .. i .. "]"
    if type(c) ~= "table" then bad(where, "table {name=, value=, limit=}", c) end
    only(c, where, { name = true, value = true, limit = true, op = true, pass = true })
    if not is_name(c.name) then bad(where .. ".name", "snake_case name", c.name) end
    if names[c.name] then bad(where .. ".name", "unique name", c.name) end
    names[c.name] = true
    local op = c.op or "<="
    if not OPS[op] then bad(where .. ".op", "one of '<=', '<', '>=', '>', '=='", op) end
    local pass = c.pass
    if pass ~= nil and type(pass) ~= "boolean" then bad(where .. ".pass", "boolean", pass) end
    if c.value ~= nil and type(c.value) ~= "number" then bad(where .. ".value", "number", c.value) end
    if c.limit ~= nil and type(c.limit) ~= "number" then bad(where .. ".limit", "number", c.limit) end
    if pass == nil then
      if c.value == nil then bad(where .. ".value", "number (or give pass=)", nil) end
      if c.limit == nil then bad(where .. ".limit", "number (or give pass=)", nil) end
      -- NaN compares false with everything, so a NaN value always fails.
      pass = OPS[op](c.value, c.limit)
    end
    out[i] = { name = c.name, value = c.value, limit = c.limit, op = op, pass = pass }
  end
  for k in pairs(list) do
    if math.type(k) ~= "integer" or k < 1 or k > #list then
      bad("checks", "array of checks (found key " .. describe(k) .. ")", list)
    end
  end
  return out
end

local function print_table(r)
  local w = 24
  for _, section in ipairs { r.params, r.metrics } do
    for k in pairs(section) do w = math.max(w, #tostring(k)) end
  end
  for _, c in ipairs(r.checks) do w = math.max(w, #c.name) end
  local lines = { string.format("== %s ==%s", r.scenario,
                                string.rep(" ", math.max(1, w + 8 - #r.scenario)) ..
                                string.format("wall %.3g s", r.wall_s)) }
  for _, sec in ipairs { { "params", r.params }, { "metrics", r.metrics } } do
    if next(sec[2]) then
      lines[#lines + 1] = sec[1]
      for _, k in ipairs(sorted_keys(sec[2])) do
        lines[#lines + 1] = string.format("  %-" .. w .. "s  %s", k, fmt(sec[2][k]))
      end
    end
  end
  if #r.checks > 0 then
    local failed = 0
    lines[#lines + 1] = "checks"
    for _, c in ipairs(r.checks) do
      if not c.pass then failed = failed + 1 end
      local cond = ""
      if c.value ~= nil and c.limit ~= nil then
        cond = string.format("%s %s %s", fmt(c.value), c.op, fmt(c.limit))
      elseif c.value ~= nil then
        cond = fmt(c.value)
      end
      lines[#lines + 1] = string.format("  %-4s  %-" .. w .. "s  %s", c.pass and "ok" or "FAIL",
                                        c.name, cond)
    end
    lines[#lines + 1] = string.format("%d passed, %d failed", #r.checks - failed, failed)
  end
  io.stdout:write(table.concat(lines, "\n"), "\n")
  io.stdout:flush()
end

local function report_impl(t)
  if type(t) ~= "table" then
    error("bad argument #1 to 'report' (table expected, got " .. type(t) .. ")", 0)
  end
  only(t, nil, { scenario = true, params = true, metrics = true, checks = true })
  if type(t.scenario) ~= "string" or t.scenario == "" then bad("scenario", "non-empty string", t.scenario) end
  if not is_scenario(t.scenario) then bad("scenario", SCENARIO, t.scenario) end
  if M.written then
    error("report: this run already reported scenario '" .. M.written ..
          "' (one report per run; put all figures in one call)", 0)
  end
  local params = t.params or {}
  if type(params) ~= "table" then bad("params", "table", params) end
  for k, v in pairs(params) do
    if type(k) ~= "string" then bad("params", "table with string keys", k) end
    check_value(v, "params." .. k)
  end
  local metrics = t.metrics or {}
  if type(metrics) ~= "table" then bad("metrics", "table", metrics) end
  for k, v in pairs(metrics) do
    if not is_name(k) then bad("metrics", "snake_case metric names (e.g. wall_s)", k) end
    check_value(v, "metrics." .. k)
  end
  local r = { scenario = t.scenario, params = params, metrics = metrics,
              checks = normalise_checks(t.checks), wall_s = grainlab.elapsed(),
              version = grainlab.version }
  -- Encoded before anything is printed: a report is refused whole or reported whole.
  local path = grainlab.options.report or os.getenv("GRAINLAB_REPORT")
  local text = path and path ~= "" and json.encode(r)

  local failed = 0
  for _, c in ipairs(r.checks) do if not c.pass then failed = failed + 1 end end
  M.failed = M.failed + failed
  M.written = t.scenario
  print_table(r)
  if text then
    local ok, msg = grainlab.write_file(path, text)
    if not ok then error("report: " .. msg, 0) end
  end
  return failed == 0, r
end

local function report(t)
  local ok, passed, r = pcall(report_impl, t)
  if not ok then error(passed, 2) end
  return passed, r
end

M.report = report
grainlab.doc(report, {
  name = "grainlab.report", fields = { "checks", "metrics", "params", "scenario" },
  usage = "grainlab.report{ scenario = 'name', params = {…}, metrics = {…}, checks = {{ name =, value =, limit =, op = '<=' }, …} }",
  doc = [[Reports a scenario's figures: prints a readable table and, with --report FILE.json or
GRAINLAB_REPORT=FILE, writes them as JSON (written whole; keys sorted):
  {"scenario", "params", "metrics", "checks": [{"name","value","limit","op","pass"}], "wall_s", "version"}
The scenario is a name of letters, digits, '_', '.' and '-' (starting with a letter or digit,
at most 64 characters). Metric and check names are snake_case with the unit in the name where
useful (wall_s, particle_steps_per_s). A check passes when `value op limit` holds (op defaults to '<='; a NaN
value fails), or give pass = true/false directly. Metrics and params are finite numbers, strings,
booleans, or tables of them (arrays, or string keys); anything else (NaN, infinity, a function,
a mixed or self-containing table, a name that is not snake_case) is refused at the call, before
anything is printed or written. Any failed check makes grainlab exit with
status 1 at the end of the run. One report per run. Returns all_passed, record.]] })

return M
