-- The render module's contract: pixels read back through render.image (disk area, colour map
-- values, title text), identical PNGs for identical scenes, frame patterns, plots, and every bad
-- argument refused with a message naming the call, the field and the value — leaving no file.
local check = grainlab.check

local dir = os.tmpname()
os.remove(dir)
assert(os.execute("mkdir -p '" .. dir .. "'"))
local function files()
  local p = io.popen("ls -A '" .. dir .. "'")
  local list = {}
  for name in p:lines() do list[#list + 1] = name end
  p:close()
  table.sort(list)
  return list
end
local function read(path)
  local f = assert(io.open(path, "rb"))
  local data = f:read("a")
  f:close()
  return data
end

local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } }
s:add_disk{ pos = { 0.5, 0.5 }, radius = 0.1 }

-- ---- a black disk on white: coverage sums to pi r^2 within 1% ------------------------------
local img = render.image(s, { width = 400, height = 400, color = { 0 }, colormap = "gray",
                              range = { 0, 1 }, show = {} })
local w, h = img:size()
check.eq(w, 400, "width")
check.eq(h, 400, "height")
local cover = 0
for y = 1, h do
  for x = 1, w do
    local r = img:pixel(x, y)
    cover = cover + (255 - r) / 255
  end
end
-- 1 m of box over the 400 px less two margins of 0.8 font sizes (font: 400/60 px -> 7, min 9)
local scale = 400 - 2 * math.floor(0.8 * 9 + 0.5)
check.near(cover, math.pi * (0.1 * scale) ^ 2, 0.01, "disk area from coverage")
check.eq(select(1, img:pixel(200, 200)), 0, "disk centre is black")
check.eq(select(1, img:pixel(3, 3)), 255, "corner is white")
check.errors(function() img:pixel(0, 1) end,
  "bad argument #1 to 'pixel' (pixel in [1, 400] x [1, 400] expected, got (0, 1))", "pixel outside")

-- ---- colour map through a scene: value 0.5 on [0, 1] is viridis(0.5) = #21918c ----------------
img = render.image(s, { width = 64, height = 64, color = { 0.5 }, range = { 0, 1 }, show = {} })
local r, g, b = img:pixel(32, 32)
check.near_abs(r, 0x21, 2, "viridis(0.5) red")
check.near_abs(g, 0x91, 2, "viridis(0.5) green")
check.near_abs(b, 0x8c, 2, "viridis(0.5) blue")

-- ---- a title draws ink in the top band, none without it -------------------------------------
local function ink_in_top_band(im)
  local n = 0
  local W = im:size()
  for y = 1, 30 do
    for x = 1, W // 2 do
      if im:pixel(x, y) < 128 then n = n + 1 end
    end
  end
  return n
end
check.gt(ink_in_top_band(render.image(s, { width = 600, title = "Title Wg" })), 40, "title ink")
check.eq(ink_in_top_band(render.image(s, { width = 600 })), 0, "no title, no ink")

-- ---- identical scenes give identical files; frame patterns count -----------------------------
for i = 1, 30 do s:add_disk{ pos = { 0.1 + 0.027 * i, 0.85 }, radius = 0.012, vel = { 0, i * 0.1 } } end
local opts = { width = 320, color = "speed", title = "same", stamp = true, show = { "colorbar", "box", "rotation" } }
check.eq(render.png(s, dir .. "/a.png", opts), dir .. "/a.png", "png returns the file name")
render.png(s, dir .. "/b.png", opts)
check.is_true(read(dir .. "/a.png") == read(dir .. "/b.png"), "identical PNG bytes")
check.eq(read(dir .. "/a.png"):sub(2, 4), "PNG", "a PNG signature")
check.eq(render.png(s, dir .. "/f_%03d.png"), dir .. "/f_000.png", "first frame")
check.eq(render.png(s, dir .. "/f_%03d.png"), dir .. "/f_001.png", "second frame")
check.eq(render.png(s, dir .. "/f_%03d.png", { frame = 17 }), dir .. "/f_017.png", "given frame")
check.eq(table.concat(files(), " "), "a.png b.png f_000.png f_001.png f_017.png", "files written")

-- ---- argument errors: the house grammar, and nothing written -------------------------------
local out = dir .. "/bad.png"
local function bad(o, text, what)
  check.errors(function() render.png(s, out, o) end, text, what)
end
bad({ colormap = "jet" },
  "bad field 'colormap' in argument #3 to 'png' (one of 'viridis', 'gray' expected, got 'jet')", "colormap")
bad({ width = 0 }, "bad field 'width' in argument #3 to 'png' (integer in [16, 8192] expected, got 0)", "zero width")
bad({ width = 100000 },
  "bad field 'width' in argument #3 to 'png' (integer in [16, 8192] expected, got 100000)", "huge width")
bad({ height = -5 }, "bad field 'height' in argument #3 to 'png' (integer in [16, 8192] expected, got -5)",
  "negative height")
bad({ colour = "speed" }, "bad argument #3 to 'png' (unknown field 'colour'; valid fields:", "unknown field")
bad({ color = "texture" },
  "bad field 'color' in argument #3 to 'png' (one of 'grain', 'speed', 'rotation', 'material' or an array of numbers expected, got 'texture')",
  "unknown colour")
bad({ color = { 1, 2 } }, "bad field 'color' in argument #3 to 'png' (array of 31 finite numbers (one per grain) expected",
  "short value array")
bad({ show = "chains" }, "bad field 'show' in argument #3 to 'png' (one or an array of 'force_chains', 'rotation'",
  "unknown show")
bad({ range = { 1, 0 } }, "bad field 'range' in argument #3 to 'png' ({lo, hi} with lo < hi expected, got table)",
  "decreasing range")
bad({ stamp = 3 }, "bad field 'stamp' in argument #3 to 'png' (boolean or string expected, got 3)", "stamp")
bad({ walls = { { point = { 0, 0 } } } }, "bad field 'walls' in argument #3 to 'png'", "wall without normal")
bad("big", "bad argument #3 to 'png' (table expected, got string)", "options not a table")
check.errors(function() render.png(nil, out) end, "bad argument #1 to 'png' (dem.scene expected, got nil)", "no scene")
check.errors(function() render.png(s) end, "bad argument #2 to 'png' (string expected, got nil)", "no file")
check.errors(function() render.png(s, dir .. "/f_%s.png") end, "one %d, %5d or %05d-style frame number", "bad pattern")
check.errors(function() render.png(s, dir .. "/missing/x.png") end, "png: cannot write '" .. dir .. "/missing/x.png'",
  "unwritable path")
check.errors(function() render.png(s, out, { show = "displacement" }) end,
  "png: no reference state: call set_reference first", "arrows without a reference")
s:set_reference()
check.errors(function() render.png(s, out, { show = "displacement", displacement = { scale = -1 } }) end,
  "bad field 'displacement.scale' in argument #3 to 'png' (non-negative number expected, got", "arrow scale")
check.errors(function() render.png(s, out, { show = "displacement", displacement = { affine = { 1, 2 } } }) end,
  "bad field 'displacement.affine' in argument #3 to 'png' (2 x 2 array of finite numbers", "affine")
local s3 = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } } }
s3:add_sphere{ pos = { 0.5, 0.5, 0.5 }, radius = 0.2 }
check.errors(function() render.png(s3, out, { show = "force_chains" }) end,
  "png: force chains, rotation markers, arrows and walls are drawn in 2D scenes only", "chains in 3D")
check.errors(function() render.png(s3, out, { camera = { fov = 120 } }) end,
  "bad field 'camera.fov' in argument #3 to 'png' (number in (0, 90) expected, got 120)", "camera fov")
check.errors(function() render.png(s3, out, { camera = { projection = "fisheye" } }) end,
  "bad field 'camera.projection' in argument #3 to 'png' (one of 'orthographic', 'perspective' expected, got 'fisheye')",
  "camera projection")
check.errors(function() render.png(s3, out, { camera = { zoom = 2 } }) end,
  "bad field 'camera' in argument #3 to 'png' (table { azimuth =, elevation =, projection =", "camera key")
check.eq(table.concat(files(), " "), "a.png b.png f_000.png f_001.png f_017.png", "no file from failed calls")

-- ---- a 3D sphere is shaded: lit from the upper left -----------------------------------------
local im3 = render.image(s3, { width = 200, height = 200, show = {}, color = { 0.5 }, colormap = "gray",
                               range = { 0, 1 }, camera = { azimuth = -90, elevation = 0 } })
check.gt(im3:pixel(85, 85), im3:pixel(115, 115) + 60, "sphere shading")

-- ---- displacement arrows: a grain moved right by 0.05 m draws red ink to its right ----------
local sa = dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } }, gravity = { 0, 0 } }
sa:add_disk{ pos = { 0.3, 0.5 }, radius = 0.05 }
sa:set_reference()
sa:set_velocity(1, { 1, 0 })
sa:run{ steps = 50, dt = 1e-3, force = true }
local ima = render.image(sa, { width = 200, height = 200, show = { "displacement" } })
local red, xsum = 0, 0
for yy = 25, 200 do
  for xx = 1, 200 do
    local rr, gg, bb = ima:pixel(xx, yy)
    if rr > 150 and gg < 80 and bb < 80 then red, xsum = red + 1, xsum + xx end
  end
end
check.gt(red, 20, "arrow pixels")
check.gt(xsum / red, 14.5 + 0.35 * 171, "the arrow starts at the grain (x = 0.35) and points right")

-- ---- plots ---------------------------------------------------------------------------------
local x, y = {}, {}
for i = 1, 20 do x[i], y[i] = i, i * i end
check.eq(render.plot{ file = dir .. "/p.png", title = "squares", xlabel = "n", ylabel = "n^2",
                      series = { { x = x, y = y, label = "n^2", style = "both" } } }, dir .. "/p.png", "plot file")
local pim = render.plot{ width = 300, height = 200, xlog = true, ylog = true, series = { { x = x, y = y } } }
check.eq(select(2, pim:size()), 200, "plot image height")
local function pbad(def, text, what)
  check.errors(function() render.plot(def) end, text, what)
end
pbad({ series = {} }, "bad field 'series' in argument #1 to 'plot' (non-empty array of", "no series")
pbad({ series = { { x = { 1, 2 }, y = { 1 } } } },
  "bad field 'series[1].y' in argument #1 to 'plot' (array as long as series[1].x (2) expected", "lengths differ")
pbad({ series = { { x = { 1 }, y = { 1 }, style = "dots" } } },
  "bad field 'series[1].style' in argument #1 to 'plot' (one of 'line', 'points', 'both' expected, got 'dots')", "style")
pbad({ series = { { x = { 1 }, y = { 1 }, colour = "red" } } }, "bad field 'series[1]' in argument #1 to 'plot' (unknown key 'colour'",
  "unknown series key")
pbad({ ylog = true, series = { { x = { 1, 2 }, y = { 1, 0 } } } },
  "plot: series 1 point 2: y = 0 cannot be shown on a log axis", "log of zero")
pbad({ width = 0, series = { { x = { 1 }, y = { 1 } } } },
  "bad field 'width' in argument #1 to 'plot' (integer in [16, 8192] expected, got 0)", "plot width")
pbad({ file = dir .. "/missing/p.png", series = { { x = { 1 }, y = { 1 } } } }, "plot: cannot write", "plot path")

os.execute("rm -rf '" .. dir .. "'")

-- ---- colour by material; the scene's walls are drawn by default --------------------------------
do
  local sm = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.04, 0.01 } } }
  local ma = grainlab.material{ density = 2650, young = 1e7 }
  local mb = grainlab.material{ density = 2650, young = 1e7, name = "b" }
  sm:add_disk{ pos = { 0.005, 0.005 }, radius = 0.004, material = ma }
  sm:add_disk{ pos = { 0.015, 0.005 }, radius = 0.004, material = ma }
  sm:add_disk{ pos = { 0.025, 0.005 }, radius = 0.004, material = mb }
  sm:add_wall{ point = { 0.035, 0 }, normal = { -1, 0 } }
  local im = render.image(sm, { width = 400, height = 100, color = "material", show = { "walls" } })
  local function rgb(x, y) local r, g, b = im:pixel(x, y); return r * 65536 + g * 256 + b end
  check.eq(rgb(50, 50), rgb(150, 50), "same material, same colour")
  check.is_true(rgb(50, 50) ~= rgb(250, 50), "different materials, different colours")
  -- a dark vertical line somewhere right of the last disk (the frame's margins shift columns)
  local rows = 0
  for y = 20, 80 do
    local hit = false
    for x = 300, 390 do local r = im:pixel(x, y); if r < 100 then hit = true end end
    if hit then rows = rows + 1 end
  end
  check.ge(rows, 55, "the scene's wall at x = 0.035 is drawn without opts.walls")
end
check.done()
