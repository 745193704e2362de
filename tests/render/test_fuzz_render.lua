-- Generated bad-input test of the render module (see fuzz_driver.lua): every field of every
-- render function and image method gets every bad-value class; only the classes declared below
-- are accepted, everything else must end in an error naming the call and the field. Files go to
-- a temporary path, removed at the end.
local fuzz = dofile("../lua/lib/fuzz_driver.lua")
local tmp = os.tmpname()
local png = tmp .. ".png"

local function scene()
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } }
  s:add_disk{ pos = { 0.5, 0.5 }, radius = 0.1 }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  s:set_reference()
  return s
end
local function self(ctx) return ctx end
local OPT = { "nil" }
local BOOL = { "nil", "boolean" }
local TEXT = { "nil", "string" }

local function scene_opts()
  return { width = 128, height = 128, color = "speed", colormap = "gray", range = { 0, 1 },
           show = { "walls", "box", "displacement" }, title = "t", stamp = true, label = "l",
           walls = { { point = { 0, 0 }, normal = { 0, 1 } } }, frame = 1, camera = { azimuth = 10 },
           displacement = { scale = 1 } }
end
local scene_accept = { width = OPT, height = OPT, color = OPT, colormap = OPT, range = OPT,
  show = { "nil", "empty", "short", "long" }, title = TEXT, stamp = { "nil", "boolean", "string" }, label = TEXT,
  walls = { "nil", "boolean", "empty", "short", "long" }, frame = { "nil", "zero" }, camera = { "nil", "empty" },
  displacement = { "nil", "empty" } }

local calls = {
  ["render.png"] = {
    setup = scene, args = function(s) return { s, png, scene_opts() } end, opts = 3, opts_optional = true,
    pos = { {}, { "string" } }, strings = { [2] = png }, accept = scene_accept,
  },
  ["render.image"] = {
    setup = scene, args = function(s) return { s, scene_opts() } end, opts = 2, opts_optional = true,
    pos = { {} }, accept = scene_accept,
  },
  ["render.plot"] = {
    args = function() return { { file = png, width = 320, height = 240, title = "t", xlabel = "x", ylabel = "y",
                                 xlog = false, ylog = false,
                                 series = { { x = { 1, 2 }, y = { 1, 2 }, label = "a", style = "line" } } } } end,
    opts = 1, strings = { file = png },
    accept = { file = { "nil", "string" }, width = OPT, height = OPT, title = TEXT, xlabel = TEXT, ylabel = TEXT,
               xlog = BOOL, ylog = BOOL, series = { "long" } },
  },
  ["render.field"] = {
    args = function() return { { file = png, frame = 1, width = 128, height = 128, values = { 1, 2, 3, 4 },
                                 nx = 2, ny = 2, extent = { { 0, 0 }, { 1, 1 } },
                                 mask = { true, true, false, true }, background = { 0, 0, 0 },
                                 interpolation = "nearest", colormap = "gray", range = { 0, 5 },
                                 colorbar = true, box = true, title = "t", stamp = "s", label = "l",
                                 arrows = { u = { 1, 0, 0, 1 }, v = { 0, 1, 1, 0 } } } } end,
    opts = 1,
    strings = { file = png },
    accept = { file = { "nil", "string" }, frame = { "nil", "zero" }, width = OPT, height = OPT,
               values = { "nil", "entry_nan" }, nx = {}, ny = {}, extent = OPT, mask = OPT, background = OPT, interpolation = OPT,
               colormap = OPT, range = OPT, colorbar = BOOL, box = BOOL, title = TEXT, stamp = TEXT,
               label = TEXT, arrows = OPT },
  },
  ["render.points"] = {
    args = function() return { { file = png, frame = 1, width = 128, height = 128, x = { 0, 1 }, y = { 0, 1 },
                                 values = { 1, 2 }, size = 3, extent = { { 0, 0 }, { 1, 1 } },
                                 colormap = "gray", range = { 0, 5 }, colorbar = true, box = true,
                                 title = "t", stamp = "s", label = "l" } } end,
    opts = 1,
    strings = { file = png },
    accept = { file = { "nil", "string" }, frame = { "nil", "zero" }, width = OPT, height = OPT,
               x = {}, y = {}, values = { "nil", "entry_nan" }, size = OPT, extent = OPT, colormap = OPT, range = OPT, colorbar = BOOL,
               box = BOOL, title = TEXT, stamp = TEXT, label = TEXT },
  },
  ["render.image:size"] = { setup = function() return render.image(scene(), { width = 128, height = 128 }) end, self = self },
  ["render.image:pixel"] = {
    setup = function() return render.image(scene(), { width = 128, height = 128 }) end, self = self,
    args = function() return { 2, 3 } end, pos = { {}, {} },
  },
  ["render.image:save"] = {
    setup = function() return render.image(scene(), { width = 128, height = 128 }) end, self = self,
    args = function() return { png } end, pos = { { "string" } }, strings = { png },
  },
}

local ok, err = pcall(fuzz.run, { modules = { render = render },
  types = { ["render.image"] = render.image(scene(), { width = 128, height = 128 }) }, calls = calls,
  skip = { ["render.coarse_grain"] = "fuzzed by test_fuzz_coarse_grain.lua" } })
os.remove(tmp)
os.remove(png)
if not ok then error(err, 0) end
