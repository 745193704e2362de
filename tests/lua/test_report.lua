-- grainlab.report in-process: validation errors first (they leave the run without a report),
-- then one passing report whose returned record is inspected, then the one-report rule.
-- The JSON encoder's output is compared with hand-written JSON.
local check = grainlab.check
local json = require "grainlab.json"

-- JSON: sorted keys, integers vs floats, shortest round-trip numbers, escapes, null for NaN.
check.eq(json.encode({ b = 1, a = { 0.1, 1/3, 2^53, -0.0 }, c = "q\"\\\n\1", d = 0/0, e = {} }),
  '{\n  "a": [\n    0.1,\n    0.3333333333333333,\n    9007199254740992,\n    -0\n  ],\n' ..
  '  "b": 1,\n  "c": "q\\"\\\\\\n\\u0001",\n  "d": null,\n  "e": []\n}\n', "json encoding")
check.errors(function() json.encode({ f = print }) end, "cannot encode a function (at value.f)", "json function")
local cyc = {}
cyc.self = cyc
check.errors(function() json.encode(cyc) end, "contains itself", "json cycle")

-- Validation.
local function rep(t) return function() grainlab.report(t) end end
check.errors(rep(nil), "bad argument #1 to 'report' (table expected, got nil)", "no table")
check.errors(rep{ metrics = {} }, "bad field 'scenario' in argument #1 to 'report' (non-empty string expected, got nil)", "no scenario")
check.errors(rep{ scenario = "s", metric = {} }, "(unknown field 'metric'; did you mean 'metrics'? Valid fields: checks, metrics, params, scenario)", "typo")
check.errors(rep{ scenario = "s", metrics = { WallTime = 1 } }, "snake_case metric names", "metric name")
check.errors(rep{ scenario = "s", metrics = { x = print } }, "bad field 'metrics.x' in argument #1 to 'report' (number, string, boolean or table expected, got function)", "metric value")
check.errors(rep{ scenario = "s", checks = { { name = "a", value = 1 } } }, "bad field 'checks[1].limit' in argument #1 to 'report' (number (or give pass=) expected, got nil)", "missing limit")
check.errors(rep{ scenario = "s", checks = { { name = "a", value = 1, limit = 2, op = "=<" } } }, "bad field 'checks[1].op'", "bad op")
check.errors(rep{ scenario = "s", checks = { { name = "a", pass = true }, { name = "a", pass = true } } }, "bad field 'checks[2].name' in argument #1 to 'report' (unique name expected, got 'a')", "duplicate")
check.errors(rep{ scenario = "s", checks = { { name = "a", pass = "yes" } } }, "bad field 'checks[1].pass' in argument #1 to 'report' (boolean expected", "pass type")
check.errors(rep{ scenario = "s", checks = { { name = "a", vale = 1, limit = 1 } } }, "bad field 'checks[1]' in argument #1 to 'report' (unknown field 'vale'", "check typo")
check.contains(check.errors(rep(5), "table expected"), "test_report.lua:", "position of the caller")
-- Figures JSON cannot hold are refused at the call, before anything is printed or written (they
-- used to print, then become null, or fail in the encoder after the table was out).
check.errors(rep{ scenario = "s", metrics = { e = 0/0 } }, "bad field 'metrics.e' in argument #1 to 'report' (finite number (a NaN or infinite figure belongs in a check, where it fails) expected, got nan)", "NaN metric")
check.errors(rep{ scenario = "s", metrics = { e = -1/0 } }, "bad field 'metrics.e'", "infinite metric")
check.errors(rep{ scenario = "s", params = { k = 1/0 } }, "bad field 'params.k'", "infinite param")
check.errors(rep{ scenario = "s", metrics = { series = { 1, 2, 0/0 } } }, "bad field 'metrics.series.3'", "NaN in a series")
check.errors(rep{ scenario = "s", metrics = { t = { [true] = 1 } } }, "bad field 'metrics.t' in argument #1 to 'report' (array 1..n or table with string keys (found key true) expected, got table)", "boolean key")
check.errors(rep{ scenario = "s", metrics = { t = { 1, x = 2 } } }, "(not both)", "mixed table")
local loop = {}
loop.again = loop
check.errors(rep{ scenario = "s", metrics = { t = loop } }, "bad field 'metrics.t.again' in argument #1 to 'report' (table that does not contain itself", "cycle")

-- The scenario names the run in JSON and in file names: letters, digits, '_', '.', '-'.
local SCENARIO = "(scenario name of letters, digits, '_', '.' and '-' (starting with a letter or digit, at most 64) expected, got "
check.errors(rep{ scenario = "my run! /x" }, "bad field 'scenario' in argument #1 to 'report' " .. SCENARIO .. "'my run! /x')", "spaces and punctuation")
check.errors(rep{ scenario = "../up" }, SCENARIO .. "'../up')", "a path")
check.errors(rep{ scenario = "-x" }, SCENARIO .. "'-x')", "a leading dash")
check.errors(rep{ scenario = string.rep("a", 65) }, SCENARIO, "65 characters")
check.errors(rep{ scenario = "a\0b" }, SCENARIO, "a NUL byte")

-- One passing report.
local passed, r = grainlab.report{
  scenario = "report_selftest",
  params = { e = 0.9 },
  metrics = { wall_s = 0.5, steps = 10 },
  checks = { { name = "err", value = 1e-5, limit = 1e-3 }, { name = "big", value = 5, limit = 5, op = ">=" },
             { name = "exact", value = 2, limit = 2, op = "==" } },
}
check.eq(passed, true, "report passed")
check.eq(r.scenario, "report_selftest", "record scenario")
check.eq(#r.checks, 3, "record checks")
check.eq(r.checks[1].op, "<=", "default op")
-- wall_s is the run's own clock: between 0 and the process's elapsed time (no timing limit).
check.is_true(r.wall_s >= 0 and r.wall_s <= grainlab.elapsed() + 1e-3, "wall_s")
check.errors(rep{ scenario = "again" }, "already reported scenario 'report_selftest'", "one report per run")
check.done()
