-- The help() records of the Lua-side library's functions (grainlab.pack.*, grainlab.check.*,
-- grainlab.biax.*), in the registry the C bindings fill, so help(grainlab.pack.deposit) answers
-- directly. tests/lua/test_help_all.lua walks every module and fails on an undocumented function.
local grainlab = grainlab

-- grainlab.pack's module doc lists each function as an entry: a usage line (continued while its
-- brackets are open) at two spaces, the text at four. Each entry becomes that function's record,
-- so the text is written once, next to the code in pack.lua.
local function split_entries(module_doc, prefix)
  local entries, cur, open = {}, nil, 0
  for line in (module_doc .. "\n"):gmatch("([^\n]*)\n") do
    local name = line:match("^  " .. prefix .. "%.([%a_][%w_]*)[%({]")
    if name then
      cur = { usage = line:sub(3), doc = {} }
      entries[name] = cur
      open = select(2, line:gsub("[%({]", "")) - select(2, line:gsub("[%)}]", ""))
    elseif cur and open > 0 then
      cur.usage = cur.usage .. " " .. line:gsub("^%s+", "")
      open = open + select(2, line:gsub("[%({]", "")) - select(2, line:gsub("[%)}]", ""))
    elseif cur and line:match("^    ") then
      cur.doc[#cur.doc + 1] = line:sub(5)
    else
      cur = nil
    end
  end
  return entries
end

local pack_doc = grainlab.doc_of(grainlab.pack)
for name, e in pairs(split_entries(pack_doc and pack_doc.doc or "", "pack")) do
  local fn = grainlab.pack[name]
  if type(fn) == "function" then
    grainlab.doc(fn, { name = "grainlab.pack." .. name, usage = "grainlab." .. e.usage,
                       doc = table.concat(e.doc, "\n") })
  end
end

-- Breaks text into lines of at most `width` characters at spaces.
local function wrap(text, width)
  local lines, cur = {}, ""
  for word in text:gmatch("%S+") do
    if cur ~= "" and #cur + 1 + #word > width then
      lines[#lines + 1] = cur
      cur = word
    else
      cur = cur == "" and word or cur .. " " .. word
    end
  end
  lines[#lines + 1] = cur
  return table.concat(lines, "\n")
end

-- records: name = { usage, text[, fields] } (fields: the keys of its options table, as checked).
local function document(module, prefix, records)
  for name, r in pairs(records) do
    assert(type(module[name]) == "function", prefix .. name .. " is not a function")
    grainlab.doc(module[name], { name = prefix .. name, usage = prefix .. r[1], doc = wrap(r[2], 92),
                                 fields = r[3] })
  end
end

document(grainlab.check, "grainlab.check.", {
  near = { "near(a, b, rtol, what)", "Passes when |a - b| <= rtol |b|; else raises an error naming what, both values and the relative error." },
  near_abs = { "near_abs(a, b, atol, what)", "Passes when |a - b| <= atol; else raises an error naming what, both values and the error." },
  eq = { "eq(a, b, what)", "Passes when a == b (raw equality); else raises an error naming what and both values." },
  is_true = { "is_true(v, what)", "Passes when v is neither nil nor false." },
  le = { "le(a, b, what)", "Passes when a <= b (numbers)." },
  lt = { "lt(a, b, what)", "Passes when a < b (numbers)." },
  ge = { "ge(a, b, what)", "Passes when a >= b (numbers)." },
  gt = { "gt(a, b, what)", "Passes when a > b (numbers)." },
  contains = { "contains(s, text, what)", "Passes when the string s contains text literally (no patterns)." },
  errors = { "errors(fn, text, what, ...)", "Calls fn(...), which must raise an error containing text literally; returns the message." },
  done = { "done()", "Prints the closing line of a test, \"N passed, 0 failed\" (a failed check has already raised)." },
})

grainlab.doc(grainlab.biax, { name = "grainlab.biax", doc = [[The biaxial laboratory of Padbidri Ch. 3: sample preparation and three boundary conditions
(plates + lateral pressure, plates + membrane, minimal boundary) over dem.scene:boundary and the
Delaunay continuum. biax.defaults holds Table 3.1 (E 30 GPa, nu 0.3, p 100 kPa, density x 1e5
mass scaling, mu 0.45, rate 5e-3/s, dt 1e-5 s, membrane 10 N/mm). scripts/biaxial.lua uses it.]] })

document(grainlab.biax, "grainlab.biax.", {
  config = { "config(opts)", "biax.defaults overridden by opts, with v_r = (rmin + rmax) rate (Eq. 3.A2) unless given." },
  save = { "save(s)", "The state {x, y, r} of a scene's particles (for biax.scene and biax.setup)." },
  scene = { "scene(state, cfg)", "A gravity-free, mass-scaled dem.scene holding the state's disks (membrane disks frictionless). Returns the scene and the grain and membrane materials." },
  contact = { "contact(s, cfg, frictionless)", "Sets App. A's contact laws on s: Hertz with Brilliantov damping, and (unless frictionless) the regularised Coulomb law with v_R = d rate." },
  prepare = { "prepare{ n = 400, seed = 1, method = 'deposit'|'random', shape = 'square'|'circle', width =, ramp_steps =, hold_steps =, friction_steps =, rest_steps =, settle_tol = 0.02, settle_rounds = 6, ... }",
    "A confined sample: deposited (grainlab.pack.deposit) or randomly placed disks, copied into a gravity-free, mass-scaled scene, the pressure ramped on the Delaunay boundary with frictionless contacts and drag, then friction on and a drag-free rest. Any field of biax.defaults may be overridden. Returns the state {x, y, r} and a report table." },
  prepared = { "prepared{ ..., cache = 'out/biax_<n>_<seed>.lua' | false }",
    "biax.prepare cached in a file: the same n, seed and preparation give the same sample, so scripts share it (cache = false always prepares). Returns the state, the report and whether it came from the cache." },
  setup = { "setup(state, bc, cfg)",
    "A scene from a prepared state with one boundary condition bc: 'pressure' (plates + pressure on the lateral Delaunay edges), 'membrane' (plates + chains of frictionless membrane disks on springs), 'mbc' (pressure on all sides + minimal-boundary penalty). Returns the scene and a table {ids, plates, membrane, H0, info, ...}." },
  plate_forces = { "plate_forces(lab)", "The normal forces (bottom, top) the plates exert on the sample: contacts and the tied membrane ends." },
  start = { "start(lab, max_steps = 30000, tol = 0.05)",
    "Plates: brings each plate onto the sample under force control (s:wall_servo) until it carries p W t within tol, then moves the plates at the imposed strain rate. No-op for 'mbc'. Returns the plate stress / p (bottom, top) before the compression starts." },
  axial = { "axial(lab)", "The imposed axial strain now (compression positive): from the plate gap, or rate x time for 'mbc'." },
})

local recorder = require("grainlab.recorder")
grainlab.doc(grainlab.recorder, { name = "grainlab.recorder", fields = recorder.fields,
  usage = "grainlab.recorder{ file = 'out/x.csv', columns = { { 't', fn }, ... } | { name = fn, ... }, order = { names }, units = { name = 'unit' }, flush = 10 }",
  doc = wrap("A time series: each sample is one row, one number per column. A column is { name, fn } " ..
    "(fn(s) returns a number; the row comes from rec:sample(s), or rec(s) as on_step) or a bare name " ..
    "(the rows come from rec:add{...}); columns given as a map name -> fn need `order`. The CSV (header " ..
    "'name (unit)', integers as %d, floats as %.17g, NaN as nan) is written whole (temporary file + " ..
    "rename): its header at once, then every `flush` seconds while samples arrive (false: only at " ..
    "write/close), at rec:write(), and when the recorder is closed or collected (also after a script's " ..
    "error). Methods: sample, add, column, names, write, plot; #rec is the number of samples.", 92) })
grainlab.doc(recorder.type, { name = "grainlab.recorder", doc = wrap("A time series made by " ..
  "grainlab.recorder{...}. Methods: rec:sample(s) (or rec(s), e.g. as a run's on_step), " ..
  "rec:add{ name = value, ... }, rec:column(name), rec:names(), rec:write([path]), rec:plot{...}; " ..
  "#rec is the number of samples. help(grainlab.recorder) tells more.", 92) })
document(recorder.methods, "rec:", {
  sample = { "sample(s)", "Appends a row: each column's fn(s). A non-number is refused naming the column. rec(s) is the same, so the recorder can be a run's on_step." },
  add = { "add{ name = value, ... }", "Appends a row given by value; every column must be named, and nothing else." },
  names = { "names()", "The column names, in CSV order." },
  column = { "column(name)", "A copy of the column's values, in sampling order." },
  write = { "write([path])", "Writes the whole CSV to path (default: the recorder's file), temporary file + rename. Returns the path." },
  plot = { "plot{ file =, x = first column, y = other columns | name | { names }, labels =, title =, xlabel =, ylabel =, xlog =, ylog =, width =, height =, style = 'line' }",
    "Draws y against x with render.plot. Axis labels default to the column names with their units; on a log axis values <= 0 are gaps. Returns the file.",
    recorder.plot_fields },
})
