-- help() and the REPL's completion candidates, read as text.
local check = grainlab.check

local captured = dofile("../lua/lib/captured.lua")

local text = captured(help)
check.contains(text, "grainlab " .. grainlab.version, "overview")
check.contains(text, "Modules:", "overview lists modules")
check.contains(text, "grainlab       Core: report", "overview lists grainlab")
text = captured(help, grainlab)
check.contains(text, "rng            A random stream", "module fields with their first doc line")
check.contains(text, "version        string: " .. grainlab.version, "plain fields")
text = captured(help, grainlab.rng{ seed = 1 })
check.contains(text, "methods:", "userdata methods")
check.contains(text, "uniform        A uniform number in [a, b).", "method doc")
check.contains(captured(help, "grainlab.check"), "check.near(a, b, rtol, what)", "help by name")
check.contains(captured(help, "no.such.thing"), "help: no API object named 'no.such.thing'", "unknown name")
check.contains(captured(help, function() end), "no documentation for this function", "undocumented")
grainlab.doc(captured, { name = "captured", usage = "captured(fn, ...)", doc = "Runs fn, returns what it printed." })
check.contains(captured(help, captured), "captured(fn, ...)\n  Runs fn, returns what it printed.", "grainlab.doc")

local complete = require "grainlab.complete"
local function same(list, want, what) check.eq(table.concat(list, " "), want, what) end
same(complete("grainlab.rep"), "grainlab.report(", "unique function gets (")
same(complete("grainl"), "grainlab.", "unique table gets .")
same(complete("grainlab.c"), "grainlab.check grainlab.clock grainlab.cpu_clock", "several candidates, sorted")
obj = setmetatable({}, { __index = { add_disk = function() end, add_wall = function() end, n = 3 } })
same(complete("obj:add_"), "obj:add_disk obj:add_wall", "methods through __index")
same(complete("obj:"), "obj:add_disk obj:add_wall", "only functions after ':'")
same(complete("whi"), "while", "keywords")
same(complete("no_such_global.x"), "", "unknown path")
local called = false
trap = setmetatable({}, { __index = function() called = true end })
complete("trap.x")
check.eq(called, false, "completion never runs __index functions")
check.done()
