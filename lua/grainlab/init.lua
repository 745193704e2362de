-- Completes the grainlab table with its Lua-side parts (report, check) and defines help().
local grainlab = grainlab

grainlab.report = require("grainlab.report").report
grainlab.check = require("grainlab.check")
grainlab.material = require("grainlab.material")
grainlab.pack = require("grainlab.pack")
grainlab.biax = require("grainlab.biax")
grainlab.recorder = require("grainlab.recorder").new
local pretty = require("grainlab.pretty")
grainlab.pretty, grainlab.show = pretty.pretty, pretty.show
help = require("grainlab.help")
require("grainlab.docs")

grainlab.doc(grainlab, { name = "grainlab",
  doc = [[Core: report, check, material, pack, biax, recorder, pretty, show, rng, progress, clock, elapsed, threads, write_file, doc, version.]] })
grainlab.doc(params, { name = "params",
  doc = [[Command-line pairs: `grainlab FILE.lua n=100 name=run1` gives params.n == 100 and
params.name == "run1" (numbers converted, true/false as booleans, other text kept as strings).]] })
return grainlab
