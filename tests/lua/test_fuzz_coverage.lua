-- The generated bad-input tests (test_fuzz_*.lua, test_lammps_fuzz.lua) cover every function of
-- the API that takes options: the list comes from the help registry (grainlab.doc_of), never from
-- a hand-made list. Each fuzz test runs here in list mode (fuzz_driver.lua records what its calls
-- cover and runs no case); then, for every documented function and method:
--   - one whose record lists the keys of an options table (`fields`) has a fuzz entry with that
--     table, and one with per-mode keys (`modes`, s:measure('stress', {...})) an entry per mode,
--     in some test (a `skip` elsewhere does not count);
--   - one whose usage line shows an options table ({ name = ...}, opts, cfg) records its keys,
--     so that the first rule sees it (a table whose keys are the user's own names is listed
--     below with its reason);
--   - every function is visited by some fuzz test (fuzzed or skipped with a reason there), but
--     for the few listed below with theirs.
local check = grainlab.check

-- Usage lines that show a table whose keys are not a fixed list of options.
local OWN_KEYS = {
  ["grainlab.recorder:add"] = "one row: the keys are the recorder's column names (test_recorder.lua)",
}
-- Functions no fuzz test visits.
local NOT_VISITED = {
  help = "prints the documentation of any value",
}
for _, k in ipairs{ "contains", "done", "eq", "errors", "ge", "gt", "is_true", "le", "lt", "near",
                    "near_abs" } do
  NOT_VISITED["grainlab.check." .. k] = "assertions of test scripts: any value is an argument they judge"
end

-- The registry: every documented function reachable from the global modules, and the methods of
-- every documented userdata type (their named metatables), as test_help_all.lua walks them.
local api, seen = {}, {}
local function walk(path, t, sep)
  if seen[t] then return end
  seen[t] = true
  for k, v in pairs(t) do
    if type(k) == "string" then
      local p = path .. sep .. k
      if type(v) == "function" and grainlab.doc_of(v) then
        api[p] = grainlab.doc_of(v)
      elseif type(v) == "table" and grainlab.doc_of(v) then
        walk(p, v, ".")
      end
    end
  end
end
for name, v in pairs(_G) do
  if type(v) == "table" and v ~= _G and grainlab.doc_of(v) then walk(name, v, ".") end
  if type(v) == "function" and grainlab.doc_of(v) then api[name] = grainlab.doc_of(v) end
end
for name, mt in pairs(debug.getregistry()) do
  if type(name) == "string" and type(mt) == "table" and type(rawget(mt, "__index")) == "table" and
     grainlab.doc_of(mt) then
    walk(name, rawget(mt, "__index"), ":")
  end
end

-- The fuzz tests (every test file, in any folder of tests/, that loads fuzz_driver.lua), in list
-- mode.
FUZZ_COVERAGE = { covered = {}, skipped = {} }
local files = {}
for f in io.popen([[grep -lF 'dofile("../lua/lib/fuzz_driver.lua")' ../*/test_*.lua]]):lines() do
  if f ~= "../lua/test_fuzz_coverage.lua" then files[#files + 1] = f end
end
table.sort(files)
check.is_true(#files >= 8, "the fuzz tests are found (" .. table.concat(files, ", ") .. ")")
local real_print, real_stdout = print, io.stdout
print = function() end -- their own reports and check.done lines
for _, f in ipairs(files) do
  local ok, err = pcall(dofile, f)
  print, io.stdout = function() end, real_stdout
  if not ok then
    print = real_print
    error(f .. " in list mode: " .. tostring(err), 0)
  end
end
print = real_print
local covered, skipped = FUZZ_COVERAGE.covered, FUZZ_COVERAGE.skipped
FUZZ_COVERAGE = nil

local function shows_options(usage)
  return usage:find("{%s*[%a_][%w_]*%s*=") or usage:find("[(,]%s*opts%s*[),]") or
    usage:find("[(,]%s*cfg%s*[),]")
end

local problems, names, with_options = {}, {}, 0
for name in pairs(api) do names[#names + 1] = name end
table.sort(names)
for _, name in ipairs(names) do
  local d, c = api[name], covered[name]
  if d.fields or d.modes then with_options = with_options + 1 end
  if d.fields and not (c and c.opts) then
    problems[#problems + 1] = name .. ": takes an options table (fields " .. table.concat(d.fields, ", ") ..
      ") that no fuzz test covers" .. (skipped[name] and " (skipped: " .. skipped[name] .. ")" or "")
  end
  for mode in pairs(d.modes or {}) do
    if not (c and c.modes[mode]) then
      problems[#problems + 1] = name .. ": mode '" .. mode .. "' takes options that no fuzz test covers"
    end
  end
  if not d.fields and not d.modes and shows_options(d.usage) and not OWN_KEYS[name] then
    problems[#problems + 1] = name .. ": its usage shows an options table (" .. d.usage ..
      ") but its doc record lists no fields (grainlab.doc{ fields = }, bind_register_fields)"
  end
  if not c and not skipped[name] and not NOT_VISITED[name] then
    problems[#problems + 1] = name .. ": no fuzz test visits it"
  end
end
for name in pairs(OWN_KEYS) do
  if not api[name] then problems[#problems + 1] = "OWN_KEYS lists '" .. name .. "', not in the registry" end
end
for name in pairs(NOT_VISITED) do
  if not api[name] then problems[#problems + 1] = "NOT_VISITED lists '" .. name .. "', not in the registry" end
  if covered[name] then problems[#problems + 1] = "NOT_VISITED lists '" .. name .. "', which a fuzz test covers" end
end
table.sort(problems)
check.eq(table.concat(problems, "\n"), "", "functions with options the fuzz tests do not cover")
check.gt(#names, 150, "functions in the registry")
check.gt(with_options, 60, "functions with options")
-- The rule sees the modes of s:measure (one list per mode, empty for a mode without options).
check.is_true(api["dem.scene:measure"].modes and api["dem.scene:measure"].modes.energy, "dem measure's modes recorded")
check.eq(#api["dem.scene:measure"].modes.energy, 0, "energy takes no options")
check.done()
