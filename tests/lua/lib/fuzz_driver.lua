-- The generated binding test: every registered function of a module gets one valid base call
-- (declared in the test file), then every field of its options table -- the list the binding
-- itself checks, read from grainlab.doc_of(fn).fields (or .modes[mode]) -- is replaced, one at a
-- time, by every bad-value class, and every positional argument likewise. Each case must end in
-- a Lua error naming the call and the field (or argument), unless the test file declares that
-- class accepted for that field, in which case the call must succeed. The options table (and
-- each nested table) also gets a key that is no field, which must be refused naming the key,
-- and a misspelt field, which must be refused with "did you mean" and the field; the options
-- argument itself gets every value that is not an options table. Methods are also called with
-- '.' instead of ':'. A field or argument without a declaration fails the test, so a new field
-- cannot slip through; a registered function without a base call fails it too.
-- test_fuzz_coverage.lua runs every such test in list mode (the global FUZZ_COVERAGE set: run
-- records what each test covers and runs no case) and fails when a function of the registry
-- that takes options is covered by none.
--
-- Used by tests/*/test_fuzz_*.lua:
--   local fuzz = dofile("../lua/lib/fuzz_driver.lua")
--   fuzz.run{ modules = { dem = dem }, types = { ["dem.scene"] = scene }, calls = { ... } }
-- A call entry, keyed "module.fn" or "type:method" (type = the metatable's __name):
--   { setup = function() return ctx end,          -- fresh state for every case (optional)
--     args = function(ctx) return { ... } end,     -- the valid arguments (without self)
--     self = function(ctx) return obj end,         -- methods: the object
--     opts = k,                                    -- args[k] is the options table (optional)
--     mode = "stress",                             -- fields come from doc.modes[mode]
--     accept = { field = { "nil", "zero", ... } }, -- classes a field legitimately takes
--     pos = { [i] = { "nil", ... } },              -- positional args to fuzz and what they take
--     strings = { [i or field] = "..." },          -- the "string" class there (a file path)
--     slow = { field = { class = "why" } },        -- an accepted class printed, not run (cost)
--     nested = { mbc = { "K", ... } },            -- sub-tables args[opts].mbc (or a path such as
--                                                  --   "checks.1"): fields fuzzed in place, declared
--                                                  --   in accept as "mbc.K" ("checks[1].name")
--     any_keys = { params = "why" },               -- nested tables whose keys are the user's own
--                                                  --   names (no unknown-key case there)
--     no_opts = true,                              -- a variant without the options table
--     todo = { field = "why" },                    -- printed, not fuzzed (a fix pending elsewhere)
--     name = "add_disk" }                          -- the name errors use (default: the key's)
-- An entry may be a list of such tables (one per mode).
local M = {}

local nan = 0 / 0

-- Whole-value classes, for every field and positional argument.
M.scalar = {
  { "nil", nil }, { "string", "x" }, { "boolean", true }, { "function", function() end },
  { "nan", nan }, { "inf", math.huge }, { "-inf", -math.huge }, { "negative", -1 },
  { "zero", 0 }, { "huge", 1e300 }, { "empty", {} }, { "nested", { { {} } } },
  { "keyed", { a = { b = 1 } } },
}

local function copy(t)
  if type(t) ~= "table" then return t end
  local c = {}
  for k, v in pairs(t) do c[k] = copy(v) end
  return setmetatable(c, getmetatable(t))
end

-- Classes derived from an array-valued base (a vector, a box, a list of values).
local function derived(base)
  if type(base) ~= "table" or getmetatable(base) or #base == 0 then return {} end
  local out = {}
  local short = copy(base); short[#short] = nil
  out[#out + 1] = { "short", short }
  local long = copy(base); long[#long + 1] = copy(base[#base])
  out[#out + 1] = { "long", long }
  for _, c in ipairs{ { "entry_nan", nan }, { "entry_inf", math.huge }, { "entry_huge", 1e300 },
                      { "entry_string", "1" }, { "entry_table", { {} } } } do
    local v = copy(base)
    if type(base[1]) == "table" and not getmetatable(base[1]) and #base[1] > 0 then
      v[1][1] = c[2] -- a box or a list of points: garbage inside the first entry
    else
      v[1] = c[2]
    end
    out[#out + 1] = { c[1], v }
  end
  return out
end

local function describe(v)
  if type(v) == "table" then return "table" end
  return tostring(v)
end

local failures, cases = {}, 0
local function fail(what, msg) failures[#failures + 1] = what .. ": " .. msg end

local function set_of(list)
  local s = {}
  for _, c in ipairs(list or {}) do s[c] = true end
  return s
end

-- Calls as a user writes them -- m.fn(...), s:fn(...), or s.fn(...) by mistake -- so that error
-- messages see the call's name (a pcall of the bare function or a tail call would not). The
-- parentheses keep the call from being a tail call.
local wrappers = {}
local function wrapper(form, name)
  local code = form == ":" and "return function(s, ...) return (s:%s(...)) end"
    or "return function(s, ...) return (s.%s(...)) end"
  local k = form .. name
  wrappers[k] = wrappers[k] or assert(load(string.format(code, name)))()
  return wrappers[k]
end

local function try(e, self, args, n)
  return pcall(wrapper(e._form, e._fname), self, table.unpack(args, 1, n))
end

local function case(key, e, fn, what, mutate, accepted, names)
  cases = cases + 1
  local ctx = e.setup and e.setup() or {}
  local args = e.args and e.args(ctx) or {}
  local n = e.nargs or #args
  local self = e.self and e.self(ctx) or nil
  local label = mutate(args)
  if label and label > n then n = label end
  local ok, msg = try(e, self or e._module, args, n)
  if accepted then
    if not ok then fail(key .. " " .. what, "declared accepted, but refused: " .. tostring(msg)) end
    return
  end
  if ok then fail(key .. " " .. what, "accepted (a bad value must be refused)"); return end
  msg = tostring(msg)
  local call = e.name or key:match("[.:]([%w_]+)$")
  if not msg:find(call, 1, true) then
    fail(key .. " " .. what, "error does not name the call '" .. call .. "': " .. msg)
  end
  local named = false
  for _, nm in ipairs(names) do named = named or msg:find(nm, 1, true) ~= nil end
  if not named then
    fail(key .. " " .. what, "error does not name " .. table.concat(names, " or ") .. ": " .. msg)
  end
end

local function fuzz_entry(key, e, fn, doc)
  local fields
  if e.mode then
    fields = doc and doc.modes and doc.modes[e.mode]
    if not fields then fail(key, "no fields recorded for mode '" .. e.mode .. "'"); return end
  else
    fields = doc and doc.fields
  end
  if e.no_opts then fields = nil end
  if fields and not e.opts then
    fail(key, "the binding records fields but the entry has no opts"); return
  end
  if e.opts and not fields then fail(key, "the entry has opts but the binding records no fields"); return end
  -- The base call must succeed (else the cases below would test nothing).
  local before = #failures
  case(key, e, fn, "base call", function() end, true, {})
  if #failures > before then return end
  local accept = e.accept or {}
  for k in pairs(accept) do
    local known = false
    for _, f in ipairs(fields or {}) do known = known or f == k end
    for path, subs in pairs(e.nested or {}) do
      local label = path:gsub("%.(%d+)", "[%1]")
      for _, f in ipairs(subs) do known = known or k == label .. "." .. f end
    end
    if not known then fail(key, "declared field '" .. k .. "' is not a field of the binding") end
  end
  -- One field (or a nested field "parent.f" of a sub-table the entry lists in `nested`):
  -- every class, at the place get/set reach in the arguments.
  local function fuzz_field(f, get, set)
    if e.todo and e.todo[f] then
      print(key .. ": field '" .. f .. "' not fuzzed yet: " .. e.todo[f])
    elseif not accept[f] then
      fail(key, "field '" .. f .. "' has no declaration of the classes it accepts")
    else
      local ok_set = set_of(accept[f])
      local probe = e.args and e.args(e.setup and e.setup() or {}) or {}
      local base = get(probe)
      local classes = {}
      for _, c in ipairs(M.scalar) do classes[#classes + 1] = c end
      for _, c in ipairs(derived(base)) do classes[#classes + 1] = c end
      for _, c in ipairs(classes) do
        local cname, v = c[1], c[2]
        if cname == "string" and e.strings and e.strings[f] then v = e.strings[f] end
        local slow = e.slow and e.slow[f] and e.slow[f][cname]
        if slow then
          print(key .. ": field '" .. f .. "' = " .. cname .. " not run (accepted, but slow): " .. slow)
        else case(key, e, fn, "field '" .. f .. "' = " .. cname .. " (" .. describe(v) .. ")",
          function(args) set(args, copy(v)) end, ok_set[cname],
          { "'" .. f .. "'", "'" .. f .. ".", "'" .. f .. "[" })
        end
      end
    end
  end
  for _, f in ipairs(fields or {}) do
    fuzz_field(f, function(a) return a[e.opts] and a[e.opts][f] end,
      function(a, v) a[e.opts][f] = v end)
  end
  -- nested = { path = { fields } }: the sub-table args[opts].path must be in the base call (a path
  -- "mbc", or "checks.1" for an array entry); its fields are declared in accept under the name
  -- errors use: "mbc.K", "checks[1].name".
  for path, subs in pairs(e.nested or {}) do
    local steps = {}
    for part in path:gmatch("[^.]+") do steps[#steps + 1] = math.tointeger(tonumber(part)) or part end
    local label = steps[1]
    for i = 2, #steps do
      label = label .. (math.type(steps[i]) == "integer" and "[" .. steps[i] .. "]" or "." .. steps[i])
    end
    local known = false
    for _, f in ipairs(fields or {}) do known = known or f == steps[1] end
    if not known then fail(key, "nested table '" .. path .. "' is not in a field of the binding") end
    local function sub(a)
      local t = a[e.opts]
      for _, st in ipairs(steps) do t = type(t) == "table" and t[st] or nil end
      return t
    end
    for _, sf in ipairs(subs) do
      fuzz_field(label .. "." .. sf, function(a) local t = sub(a); return t and t[sf] end,
        function(a, v) sub(a)[sf] = v end)
    end
  end
  -- A key that is no field, and a misspelt field, in the options table and in each nested table:
  -- refused, naming the key (and, misspelt, the field meant). The misspelling is the longest field
  -- name with an 'x' appended (one edit from it, and from no other field).
  local function unknown_keys(where, names, label, get)
    local bogus = "zz_not_a_field"
    case(key, e, fn, where .. " unknown key '" .. bogus .. "'", function(args) get(args)[bogus] = 1 end,
      false, { "'" .. bogus .. "'" })
    local longest = ""
    for _, f in ipairs(names) do if #f > #longest then longest = f end end
    if #longest < 4 then return end
    for _, f in ipairs(names) do
      if f ~= longest and #f == #longest and f:sub(-1) == "x" then return end
    end
    local typo = longest .. "x"
    cases = cases + 1
    local ctx = e.setup and e.setup() or {}
    local args = e.args and e.args(ctx) or {}
    get(args)[typo] = 1
    local ok, msg = try(e, e.self and e.self(ctx) or e._module, args, e.nargs or #args)
    msg = tostring(msg)
    local what = key .. " " .. where .. " misspelt field '" .. typo .. "'"
    if ok then
      fail(what, "accepted (a misspelt field must be refused)")
    elseif not msg:find("did you mean '" .. longest .. "'", 1, true) then
      fail(what, "error does not suggest '" .. longest .. "': " .. msg)
    elseif label and not msg:find("'" .. label .. "'", 1, true) then
      fail(what, "error does not name the table '" .. label .. "': " .. msg)
    end
  end
  if e.opts and fields then
    unknown_keys("options:", fields, nil, function(a) a[e.opts] = a[e.opts] or {}; return a[e.opts] end)
  end
  for path, subs in pairs(e.nested or {}) do
    if not (e.any_keys and e.any_keys[path]) then
      local steps = {}
      for part in path:gmatch("[^.]+") do steps[#steps + 1] = math.tointeger(tonumber(part)) or part end
      local label = path:gsub("%.(%d+)", "[%1]")
      unknown_keys("'" .. label .. "':", subs, label, function(a)
        local t = a[e.opts]
        for _, st in ipairs(steps) do t = t[st] end
        return t
      end)
    end
  end
  for path in pairs(e.any_keys or {}) do
    if not (e.nested and e.nested[path]) then fail(key, "any_keys names '" .. path .. "', which is not nested") end
  end
  -- The options table itself and positional arguments.
  local pos = e.pos or {}
  local probe = e.args and e.args(e.setup and e.setup() or {}) or {}
  for i = 1, (e.nargs or #probe) do
    if i ~= e.opts and not pos[i] and not (e.mode and probe[i] == e.mode) then
      fail(key, "positional argument #" .. i .. " has no declaration of the classes it accepts")
    end
  end
  for i, acc in pairs(pos) do
    local ok_set = set_of(acc)
    local classes = {}
    for _, c in ipairs(M.scalar) do classes[#classes + 1] = c end
    for _, c in ipairs(derived(probe[i])) do classes[#classes + 1] = c end
    for _, c in ipairs(classes) do
      local cname, v = c[1], c[2]
      if cname == "string" and e.strings and e.strings[i] then v = e.strings[i] end
      case(key, e, fn, "argument #" .. i .. " = " .. cname .. " (" .. describe(v) .. ")",
        function(args) args[i] = copy(v); return i end, ok_set[cname],
        { "#" .. i, table.unpack(e.argnames and e.argnames[i] or {}) })
    end
  end
  if e.opts and not pos[e.opts] then
    for _, c in ipairs(M.scalar) do
      local cname, v = c[1], c[2]
      -- every value but an options table: {} may be one (all fields optional), { {{}} } and
      -- { a = ... } have keys that are no field
      if cname ~= "empty" and not (cname == "nil" and e.opts_optional) then
        case(key, e, fn, "options = " .. cname, function(args) args[e.opts] = copy(v); return e.opts end,
          false, { "#" .. e.opts })
      end
    end
  end
  -- A method called with '.' instead of ':'.
  if e.self then
    cases = cases + 1
    local ctx = e.setup and e.setup() or {}
    local args = e.args and e.args(ctx) or {}
    local ok, msg = pcall(wrapper(".", e._fname), e.self(ctx), table.unpack(args, 1, e.nargs or #args))
    local call = e.name or key:match("[.:]([%w_]+)$")
    if ok then
      fail(key .. " called with '.'", "accepted")
    elseif not tostring(msg):find(call, 1, true) then
      fail(key .. " called with '.'", "error does not name the call: " .. tostring(msg))
    end
  end
end

-- spec: { modules = { name = table }, types = { tname = object }, calls = { key = entry },
--         skip = { key = "why" } }
function M.run(spec)
  local listed = {}
  local cover = rawget(_G, "FUZZ_COVERAGE")
  local function visit(key, fn, module)
    listed[key] = true
    local e = spec.calls[key]
    if spec.skip and spec.skip[key] then
      if cover then cover.skipped[key] = spec.skip[key] end
      return
    end
    if not e then fail(key, "registered, but the test has no base call for it"); return end
    if cover then -- list mode: what this test covers, no case run
      local c = cover.covered[key] or { modes = {} }
      cover.covered[key] = c
      for _, v in ipairs(e[1] and e or { e }) do
        if v.opts and not v.no_opts then
          if v.mode then c.modes[v.mode] = true else c.opts = true end
        end
      end
      return
    end
    local doc = grainlab.doc_of(fn)
    local variants = e[1] and e or { e }
    local modes = {}
    local t0 = os.clock()
    for _, v in ipairs(variants) do
      v._fname, v._form, v._module = key:match("[.:]([%w_]+)$"), module and "." or ":", module
      if v.mode then modes[v.mode] = true end
      fuzz_entry(key, v, fn, doc)
    end
    if os.getenv("FUZZ_TIMES") then print(string.format("%-32s %.3f s", key, os.clock() - t0)) end
    for m in pairs(doc and doc.modes or {}) do
      if not modes[m] then fail(key, "mode '" .. m .. "' has fields but no base call") end
    end
  end
  local function names(t)
    local ks = {}
    for k, v in pairs(t) do if type(v) == "function" then ks[#ks + 1] = k end end
    table.sort(ks)
    return ks
  end
  local mods = {}
  for m in pairs(spec.modules or {}) do mods[#mods + 1] = m end
  table.sort(mods)
  for _, m in ipairs(mods) do
    for _, k in ipairs(names(spec.modules[m])) do visit(m .. "." .. k, spec.modules[m][k], spec.modules[m]) end
  end
  local tys = {}
  for t in pairs(spec.types or {}) do tys[#tys + 1] = t end
  table.sort(tys)
  for _, t in ipairs(tys) do
    local index = getmetatable(spec.types[t]).__index
    for _, k in ipairs(names(index)) do visit(t .. ":" .. k, index[k]) end
  end
  for key in pairs(spec.calls) do
    if not listed[key] then fail(key, "the test has a base call for a function that is not registered") end
  end
  collectgarbage()
  if cover then
    if #failures > 0 then error(table.concat(failures, "\n"), 0) end
    return
  end
  if #failures > 0 then
    for i = 1, math.min(#failures, 400) do io.stderr:write(failures[i], "\n") end
    error(string.format("%d of %d binding cases failed", #failures, cases), 0)
  end
  print(string.format("%d binding cases passed", cases))
end

-- The base calls of an engine's checkpoint pair, added to calls: name.scene:save(path) on a fresh
-- scene(), and name.load(path) of the file a fresh scene() saved there (path is the "string"
-- class of both).
function M.checkpoint_calls(calls, name, scene, path)
  calls[name .. ".scene:save"] = {
    setup = scene, self = function(ctx) return ctx end, args = function() return { path } end,
    pos = { { "string" } }, strings = { path },
  }
  calls[name .. ".load"] = {
    setup = function() scene():save(path) end, args = function() return { path } end,
    pos = { { "string" } }, strings = { path },
  }
end

return M
