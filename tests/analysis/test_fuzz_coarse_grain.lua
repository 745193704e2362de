-- Generated bad-input test of analysis.coarse_grain, analysis.cg_average and the methods of the
-- average (see fuzz_driver.lua): on a grid and at points, the points' arrays fuzzed in place.
local fuzz = dofile("../lua/lib/fuzz_driver.lua")
local OPT = { "nil" }

local dir = os.tmpname()
os.remove(dir)
os.execute("mkdir -p '" .. dir .. "'")

local function scene()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, -9.81 }, thickness = 1e-3 }
  for _, p in ipairs{ { 0.2, 0.2 }, { 0.5, 0.2 }, { 0.35, 0.45 } } do s:add_disk{ pos = p, radius = 0.16 } end
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:set_reference()
  return s
end

local grid_accept = {
  kernel = OPT, width = {}, cutoff = OPT, cells = {}, region = OPT, points = OPT, depth = OPT,
  contacts = { "nil", "boolean" }, displacement = { "nil", "boolean" }, vtk = { "nil", "string" },
  csv = { "nil", "string" },
}
local points_accept = {
  kernel = OPT, width = {}, cutoff = OPT, cells = OPT, region = OPT, points = {}, depth = OPT,
  contacts = { "nil", "boolean" }, displacement = { "nil", "boolean" }, vtk = OPT, csv = { "nil", "string" },
  ["points.x"] = {}, ["points.y"] = {}, ["points.z"] = OPT,
}
local function without_files(t)
  local c = {}
  for k, v in pairs(t) do if k ~= "vtk" and k ~= "csv" then c[k] = v end end
  return c
end
local strings = { vtk = dir .. "/f.vti", csv = dir .. "/f.csv" }

local calls = {
  ["analysis.coarse_grain"] = {
    { setup = scene, args = function(s) return { s, { kernel = "gauss", width = 0.1, cutoff = 0.2,
        cells = { 4, 3 }, region = { { 0, 0 }, { 1, 1 } }, depth = 1e-3, contacts = true,
        displacement = false, vtk = dir .. "/g.vti", csv = dir .. "/g.csv" } } end,
      opts = 2, pos = { {} }, accept = grid_accept, strings = strings },
    { setup = scene, args = function(s) return { s, { width = 0.1, points = { x = { 0.3 }, y = { 0.3 } },
        csv = dir .. "/p.csv" } } end,
      opts = 2, pos = { {} }, nested = { points = { "x", "y", "z" } }, accept = points_accept,
      strings = strings },
  },
  ["analysis.cg_average"] = {
    { setup = scene, args = function(s) return { s, { kernel = "lucy", width = 0.1, cells = { 4, 3 },
        region = { { 0, 0 }, { 1, 1 } }, depth = 1e-3, contacts = true, displacement = false } } end,
      opts = 2, pos = { {} }, accept = without_files(grid_accept) },
    { setup = scene, args = function(s) return { s, { width = 0.1, points = { x = { 0.3 }, y = { 0.3 } } } } end,
      opts = 2, pos = { {} }, nested = { points = { "x", "y", "z" } }, accept = without_files(points_accept) },
  },
}
local function average()
  local s = scene()
  local avg = analysis.cg_average(s, { width = 0.1, cells = { 4, 3 } })
  avg:add(s)
  return { s = s, avg = avg }
end
local function the_avg(ctx) return ctx.avg end
calls["analysis.cg_average:add"] = { setup = average, self = the_avg, pos = { {} },
  args = function(ctx) return { ctx.s } end }
calls["analysis.cg_average:fields"] = { setup = average, self = the_avg, opts = 1, opts_optional = true,
  args = function() return { { vtk = dir .. "/a.vti", csv = dir .. "/a.csv" } } end,
  accept = { vtk = { "nil", "string" }, csv = { "nil", "string" } }, strings = strings }
calls["analysis.cg_average:reset"] = { setup = average, self = the_avg }
calls["analysis.cg_average:info"] = { setup = average, self = the_avg }

local skip = { ["analysis.delaunay"] = "fuzzed by test_fuzz_analysis.lua" }
local ok, err = pcall(fuzz.run, { modules = { analysis = analysis },
  types = { ["analysis.cg_average"] = average().avg }, calls = calls, skip = skip })
-- render.coarse_grain draws a fields table (the rest of render: test_fuzz_render.lua)
local png = dir .. "/f.png"
local fields = analysis.coarse_grain(scene(), { width = 0.1, cells = { 6, 5 } })
local BOOL, TEXT = { "nil", "boolean" }, { "nil", "string" }
if ok then
  ok, err = pcall(fuzz.run, { modules = { render = { coarse_grain = render.coarse_grain } }, calls = {
    ["render.coarse_grain"] = {
      args = function() return { fields, { file = png, show = "psd", tensor = "stress", glyphs = true,
        glyph_every = 1, arrows = "velocity", arrow_every = 1, colormap = "gray", interpolation = "bilinear",
        range = { 0, 1 }, width = 128, height = 128, title = "t", label = "l", colorbar = true, box = true } } end,
      opts = 2, pos = { {} }, strings = { file = png },
      accept = { file = { "string" }, show = OPT, tensor = OPT, glyphs = BOOL, glyph_every = { "nil", "zero" },
                 arrows = OPT, arrow_every = { "nil", "zero" }, colormap = OPT, interpolation = OPT,
                 range = OPT, width = OPT, height = OPT, title = TEXT, label = TEXT, colorbar = BOOL, box = BOOL },
    } } })
end
os.execute("rm -rf '" .. dir .. "'")
if not ok then error(err, 0) end
