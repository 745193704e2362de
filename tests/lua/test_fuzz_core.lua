-- Generated bad-input test of grainlab.* (C and Lua parts) and grainlab.pack.* (see
-- fuzz_driver.lua): every field and argument gets every bad-value class; only the classes
-- declared below are accepted, everything else must end in an error naming the call and the
-- field. Files go to a temporary path, removed at the end.
local fuzz = dofile("../lua/lib/fuzz_driver.lua")
local check = grainlab.check
local tmp = os.tmpname()

local OPT = { "nil" }
local TEXT = { "nil", "string" }
local ALL = {}
for _, c in ipairs(fuzz.scalar) do ALL[#ALL + 1] = c[1] end
-- any value at all, including the array-derived classes (pretty prints whatever it is given)
local ANY = { "short", "long", "entry_nan", "entry_inf", "entry_huge", "entry_string", "entry_table" }
for _, c in ipairs(ALL) do ANY[#ANY + 1] = c end
local function self(ctx) return ctx end

local function scene()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.02, 0.02 } }, gravity = { 0, -9.81 } }
  s:contact{ normal = "hertz", damping = "viscous" }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:add_wall{ point = { 0, 0 }, normal = { 1, 0 } }
  s:add_wall{ point = { 0.02, 0 }, normal = { -1, 0 } }
  return s
end
local quartz = grainlab.material{ density = 2650, young = 1e8 }

local calls = {
  ["grainlab.clock"] = {},
  ["grainlab.cpu_clock"] = {},
  ["grainlab.elapsed"] = {},
  ["grainlab.threads"] = { args = function() return { 1 } end, pos = { OPT } },
  ["grainlab.rng"] = {
    args = function() return { { seed = 3, stream = 2 } } end, opts = 1, opts_optional = true,
    accept = { seed = { "nil", "zero" }, stream = { "nil", "zero" } },
  },
  ["grainlab.progress"] = {
    args = function() return { { label = "x", total = 10, unit = "steps" } } end, opts = 1,
    accept = { label = TEXT, total = { "nil", "zero" }, unit = TEXT },
  },
  ["grainlab.write_file"] = {
    args = function() return { tmp, "data" } end, pos = { { "string" }, { "string" } },
    strings = { tmp, "text" },
  },
  ["grainlab.doc"] = {
    args = function() return { function() end, { name = "f", usage = "f()", doc = "d", fields = { "a" } } } end,
    opts = 2, pos = { { "function", "empty", "nested", "keyed" } },
    accept = { name = { "string" }, usage = TEXT, doc = TEXT, fields = { "nil", "empty", "short", "long", "entry_string" } },
  },
  ["grainlab.doc_of"] = { args = function() return { print } end, pos = { ALL } },
  ["grainlab.material"] = {
    args = function() return { { name = "q", density = 2650, young = 1e9, poisson = 0.2, friction = 0.5,
                                 restitution = 0.5, rolling_friction = 0.1,
                                 work_of_adhesion = 0.05 } } end,
    opts = 1,
    accept = { name = TEXT, density = {}, young = {}, poisson = { "nil", "zero" },
               friction = { "nil", "zero" }, restitution = OPT, rolling_friction = { "nil", "zero" },
               work_of_adhesion = { "nil", "zero" } },
  },
  ["grainlab.pack.random"] = {
    setup = scene, args = function(s) return { s, { n = 2, radius = 1e-3, region = { { 0, 0 }, { 0.02, 0.02 } },
                                                    seed = 1, material = quartz, max_tries = 1000, speed = 0.1 } } end,
    opts = 2, pos = { {} },
    accept = { n = {}, radius = OPT, region = OPT, seed = { "nil", "zero" }, material = OPT,
               max_tries = OPT, speed = { "nil", "zero" } },
  },
  ["grainlab.pack.clumps"] = {
    setup = scene, args = function(s)
      local T = dem.clump_template{ members = { { offset = { 0, 0 }, radius = 1e-3 }, { offset = { 1e-3, 0 }, radius = 1e-3 } } }
      return { s, { n = 2, template = T, region = { { 0, 0 }, { 0.02, 0.02 } }, seed = 1, material = quartz,
                    max_tries = 1000, speed = 0.1 } }
    end,
    opts = 2, pos = { {} },
    accept = { n = {}, template = {}, region = OPT, seed = { "nil", "zero" }, material = OPT,
               max_tries = OPT, speed = { "nil", "zero" } },
  },
  ["grainlab.pack.deposit"] = {
    setup = scene, args = function(s) return { s, { n = 2, radius = 1e-3, region = { { 0, 0 }, { 0.02, 0.02 } },
                                                    seed = 1, material = quartz, relax_steps = 0, drag = 1 } } end,
    opts = 2, pos = { {} },
    accept = { n = {}, radius = OPT, region = OPT, seed = { "nil", "zero" }, material = OPT,
               relax_steps = { "nil", "zero" }, drag = { "nil", "zero" } },
  },
  ["grainlab.pack.settle"] = {
    setup = function()
      local s = scene()
      s:add_disk{ pos = { 0.01, 0.001 }, radius = 0.001 }
      return s
    end,
    args = function(s) return { s, { max_steps = 10, check_steps = 5, final_steps = 2, min_steps = 0,
                                     quiet = 1e-5, v_floor = 0.01, collapse = 0, collapse_drag = 20,
                                     collapse_quiet = 1e-4, verbose = false, drag = 10 } } end,
    opts = 2, opts_optional = true, pos = { {} },
    accept = { soften = OPT, drag = { "nil", "zero" }, quiet = OPT, min_steps = { "nil", "zero" },
               max_steps = OPT, ramp_stages = OPT, ramp_steps = OPT, final_steps = { "nil", "zero" },
               dt_final = OPT, verbose = { "nil", "boolean" }, dt = OPT, v_floor = OPT,
               check_steps = OPT, collapse = { "nil", "zero" }, collapse_drag = { "nil", "zero" },
               collapse_quiet = OPT },
  },
  ["grainlab.pack.slab"] = {
    args = function() return { { size = 1, n = 12, diameter = { 0.1, 0.15, 0.2 }, seed = 1,
                                 width = 1.8, margin = 0 } } end,
    opts = 1,
    -- nil n (369 such disks) and nil diameter (the paper's 31-250 um disks in 1 m) are refused
    -- at entry: more than random placement fits, and a slab too sparse to be a packing
    accept = { size = {}, n = {}, diameter = {}, seed = { "nil", "zero" }, width = OPT,
               margin = { "nil", "zero" } },
  },
  ["grainlab.pretty"] = {
    args = function() return { { 1, 2 }, { depth = 2, items = 5, fields = 5, width = 80, string = 10 } } end,
    pos = { ANY }, opts = 2, opts_optional = true,
    accept = { depth = { "nil", "zero" }, items = { "nil", "zero" }, fields = { "nil", "zero" },
               width = { "nil", "zero" }, string = { "nil", "zero" } } },
  ["grainlab.show"] = { args = function() return { 1 } end, pos = { ALL } },
  ["grainlab.rng:uniform"] = {
    setup = function() return grainlab.rng{ seed = 1 } end, self = self,
    args = function() return { 0, 1 } end, pos = { { "nil", "zero", "negative" }, { "nil", "zero" } },
  },
  ["grainlab.rng:normal"] = {
    setup = function() return grainlab.rng{ seed = 1 } end, self = self,
    args = function() return { 0, 1 } end, pos = { { "nil", "zero", "negative" }, { "nil", "zero" } },
  },
  ["grainlab.rng:integer"] = {
    setup = function() return grainlab.rng{ seed = 1 } end, self = self,
    args = function() return { 1, 6 } end, pos = { { "zero", "negative" }, {} },
  },
  ["grainlab.rng:raw"] = { setup = function() return grainlab.rng{ seed = 1 } end, self = self },
  ["grainlab.progress:update"] = {
    setup = function() return grainlab.progress{ total = 10 } end, self = self,
    args = function() return { 5 } end, pos = { { "zero" } },
  },
  ["grainlab.progress:finish"] = {
    setup = function() return grainlab.progress{ total = 10 } end, self = self,
    args = function() return { 5 } end, pos = { { "nil", "zero" } },
  },
}

-- grainlab.mpi (lua_mpi.c): on one rank, as the fuzz tests run. bcast sends any value but a
-- function (or userdata); root is a rank: 0 here.
calls["grainlab.mpi.rank"] = {}
calls["grainlab.mpi.size"] = {}
calls["grainlab.mpi.barrier"] = {}
calls["grainlab.mpi.stats"] = {}
calls["grainlab.mpi.reset_stats"] = {}
local SENDABLE = {}
for _, c in ipairs(ALL) do if c ~= "function" then SENDABLE[#SENDABLE + 1] = c end end
for _, c in ipairs{ "short", "long", "entry_nan", "entry_inf", "entry_huge", "entry_string", "entry_table" } do
  SENDABLE[#SENDABLE + 1] = c
end
calls["grainlab.mpi.bcast"] = { args = function() return { { 1, 2 }, 0 } end,
  pos = { SENDABLE, { "nil", "zero" } } }

-- grainlab.vtk.series (lua_vtk.c): the options are checked at creation, nothing is written.
calls["grainlab.vtk.series"] = {
  args = function() return { "r.pvd", { contacts = true, walls = true, grid = true, cells = true,
                                        clumps = true } } end,
  opts = 2, opts_optional = true, pos = { {} },
  accept = { contacts = { "nil", "boolean" }, walls = { "nil", "boolean" }, grid = { "nil", "boolean" },
             cells = { "nil", "boolean" }, clumps = { "nil", "boolean" } },
}

-- grainlab.report (report.lua): one report per run, so each case starts from a fresh module
-- state (and the failed checks the accepted cases count are forgotten at the end).
local R = require("grainlab.report")
local function fresh_report() R.written, R.failed = nil, 0 end
-- a figure: a finite number, a string, a boolean, or a JSON-shaped table of them
local FIGURE = { "nil", "string", "boolean", "negative", "zero", "huge", "empty", "nested", "keyed",
                 "short", "long", "entry_huge", "entry_string", "entry_table" }
local NUMBER_OR_NAN = { "nan", "inf", "-inf", "negative", "zero", "huge" } -- a NaN or inf fails the check
calls["grainlab.report"] = {
  setup = function() fresh_report(); return {} end, opts = 1,
  args = function() return { { scenario = "fuzz", params = { n = 3, name = "x", flags = { 1, 2 } },
    metrics = { wall_s = 0.5, steps = 2 },
    checks = { { name = "ok", value = 1, limit = 2, op = "<=" }, { name = "flag", pass = true } } } } end,
  nested = { params = { "n", "name", "flags" }, metrics = { "wall_s" },
             ["checks.1"] = { "name", "value", "limit", "op", "pass" } },
  any_keys = { params = "the scenario's own parameter names", metrics = "the scenario's own metric names" },
  accept = { scenario = { "string" }, params = { "nil", "empty", "keyed" }, metrics = { "nil", "empty", "keyed" },
             checks = { "nil", "empty", "short" },
             ["params.n"] = FIGURE, ["params.name"] = FIGURE, ["params.flags"] = FIGURE,
             ["metrics.wall_s"] = FIGURE,
             ["checks[1].name"] = { "string" }, ["checks[1].value"] = NUMBER_OR_NAN,
             ["checks[1].limit"] = NUMBER_OR_NAN, ["checks[1].op"] = OPT, ["checks[1].pass"] = { "nil", "boolean" } },
}

-- grainlab.recorder (recorder.lua): files go to a scratch directory.
local recdir = os.tmpname()
os.remove(recdir)
os.execute("mkdir -p '" .. recdir .. "'")
local function zero() return 0 end
local REC = { file = { "nil", "string" }, order = OPT, units = { "nil", "empty" },
              flush = { "nil", "zero", "huge", "inf" }, ["units.t"] = TEXT }
calls["grainlab.recorder"] = {
  -- columns as an array ({ name, fn } or a bare name filled by rec:add)
  { opts = 1, strings = { file = recdir .. "/s.csv" }, nested = { units = { "t" } },
    args = function() return { { file = recdir .. "/r.csv", columns = { { "t", zero }, "e" },
      units = { t = "s" }, flush = 10 } } end,
    accept = { file = REC.file, columns = { "short" }, order = OPT, units = REC.units, flush = REC.flush,
               ["units.t"] = REC["units.t"] } },
  -- columns as a map name -> fn, in the order `order` gives
  { opts = 1, strings = { file = recdir .. "/s.csv" }, nested = { units = { "t" } },
    args = function() return { { file = recdir .. "/r.csv", columns = { t = zero, e = zero },
      order = { "t", "e" }, units = { t = "s" } } } end,
    accept = { file = REC.file, columns = {}, order = {}, units = REC.units, flush = REC.flush,
               ["units.t"] = REC["units.t"] } },
}
-- the recorder's methods, on a recorder of two columns and two rows (positive: log axes plot them)
local function rec2()
  local k = 0
  local function count() k = k + 1; return k end
  local rec = grainlab.recorder{ file = recdir .. "/m.csv", columns = { { "t", count }, { "e", count } },
                                 units = { t = "s" }, flush = false }
  rec:sample(0)
  rec:sample(0)
  return rec
end
calls["grainlab.recorder:sample"] = { setup = rec2, self = self, args = function() return { 0 } end, pos = { ALL } }
calls["grainlab.recorder:add"] = {
  -- the keys are the column names (no fixed fields): the table is fuzzed whole
  setup = function() return grainlab.recorder{ columns = { "a", "b" } } end, self = self,
  args = function() return { { a = 1, b = 2 } } end, pos = { {} } }
calls["grainlab.recorder:column"] = { setup = rec2, self = self, args = function() return { "t" } end, pos = { {} } }
calls["grainlab.recorder:names"] = { setup = rec2, self = self }
calls["grainlab.recorder:write"] = { setup = rec2, self = self, args = function() return { recdir .. "/w.csv" } end,
  pos = { { "nil", "string" } }, strings = { recdir .. "/w.csv" } }
calls["grainlab.recorder:plot"] = {
  setup = rec2, self = self, opts = 1, strings = { file = recdir .. "/p.png" },
  args = function() return { { file = recdir .. "/p.png", x = "t", y = "e", labels = { "E" }, title = "T",
    xlabel = "x", ylabel = "y", xlog = false, ylog = false, width = 240, height = 160, style = "line" } } end,
  accept = { file = { "string" }, x = OPT, y = OPT, labels = { "nil", "entry_string" }, title = TEXT, xlabel = TEXT, ylabel = TEXT,
             xlog = { "nil", "boolean" }, ylog = { "nil", "boolean" }, width = OPT, height = OPT, style = OPT } }
-- grainlab.vtk.series's methods: frames of a small DEM scene into the scratch directory
local function series() return grainlab.vtk.series(recdir .. "/s.pvd") end
calls["grainlab.vtk.series:add"] = {
  setup = function() return { series = series(), s = scene() } end, self = function(ctx) return ctx.series end,
  args = function(ctx) return { ctx.s, 0.5 } end, pos = { {}, { "nil", "negative", "zero" } } }
calls["grainlab.vtk.series:info"] = { setup = series, self = self }

local skip = {}
local grainlab_fns = {}
for k, v in pairs(grainlab) do
  if type(v) == "function" then grainlab_fns[k] = v end
end
-- report's table goes to io.stdout: hundreds of them would drown the failures
local stdout = io.stdout
io.stdout = { write = function(f) return f end, flush = function(f) return f end }
local ok, err = pcall(fuzz.run, {
  modules = { grainlab = grainlab_fns, ["grainlab.pack"] = grainlab.pack, ["grainlab.vtk"] = grainlab.vtk,
              ["grainlab.mpi"] = grainlab.mpi },
  types = { ["grainlab.rng"] = grainlab.rng{}, ["grainlab.progress"] = grainlab.progress{ total = 1 },
            ["grainlab.recorder"] = grainlab.recorder{ columns = { "a" } },
            ["grainlab.vtk.series"] = series() },
  calls = calls, skip = skip })
io.stdout = stdout
os.remove(tmp)
fresh_report()
collectgarbage() -- the recorders write their last rows before their directory goes
os.execute("rm -rf '" .. recdir .. "'")
if not ok then error(err, 0) end

-- A grainlab.material is read-only: an assignment is refused, naming the field, and
-- the value does not change -- for a field that exists as for one that does not.
local q = grainlab.material{ density = 2650, young = 30e9 }
check.errors(function() q.density = -5 end,
  "a grainlab.material is read-only: field 'density' cannot be set", "material read-only")
check.eq(q.density, 2650, "density unchanged")
check.errors(function() q.colour = "red" end,
  "a grainlab.material is read-only: field 'colour' cannot be set", "material read-only (new field)")
local n = 0
for k, v in pairs(q) do n = n + 1; check.eq(q[k], v, "pairs gives the fields") end
check.eq(n, 7, "pairs over a material (name absent)")
-- grainlab.pack errors name the public call and point at the caller's line.
local msg = check.errors(function() grainlab.pack.deposit(scene(), { n = -3 }) end,
  "bad field 'n' in argument #2 to 'grainlab.pack.deposit' (integer in [1, 10000000] expected, got -3)", "deposit n")
check.contains(msg, "test_fuzz_core.lua:", "at the caller's line")
check.errors(function() grainlab.pack.settle(nil) end,
  "bad argument #1 to 'grainlab.pack.settle' (dem.scene expected, got nil)", "settle without a scene")
check.done()
