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
bad({ colour = "speed" }, "bad argument #3 to 'png' (unknown field 'colour'; did you mean 'color'? Valid fields:", "unknown field")
bad({ color = "texture" },
  "bad field 'color' in argument #3 to 'png' (one of 'grain', 'speed', 'rotation', 'material', 'clump' or an array of numbers expected, got 'texture')",
  "unknown colour")
bad({ color = { 1, 2 } }, "bad field 'color' in argument #3 to 'png' (array of 31 finite numbers (one per grain) expected",
  "short value array")
bad({ show = { "chains" } }, "bad field 'show' in argument #3 to 'png' (array of 'force_chains', 'rotation'",
  "unknown show")
bad({ show = "chains" }, "bad field 'show' in argument #3 to 'png' (array of 'force_chains', 'rotation'",
  "show: an unknown name alone")
-- a single name is a list of one written without its braces: refused, the braces shown (it also
-- drops the default box and colour bar, which a list says openly)
bad({ show = "walls" }, "bad field 'show' in argument #3 to 'png' (array of names (show = { 'walls' }) expected, got 'walls')",
  "show: one name without a list")
-- 'walls' in show with walls = false: one of the two would be ignored
bad({ show = { "walls" }, walls = false }, "bad field 'walls' in argument #3 to 'png' (true when show has 'walls' expected, got false)",
  "show 'walls' against walls = false")
bad({ range = { 1, 0 } }, "bad field 'range' in argument #3 to 'png' ({lo, hi} with lo < hi expected, got table)",
  "decreasing range")
bad({ stamp = 3 }, "bad field 'stamp' in argument #3 to 'png' (boolean or string expected, got 3)", "stamp")
bad({ walls = { { point = { 0, 0 } } } }, "bad field 'walls' in argument #3 to 'png'", "wall without normal")
bad("big", "bad argument #3 to 'png' (table expected, got string)", "options not a table")
check.errors(function() render.png(nil, out) end, "bad argument #1 to 'png' (dem.scene expected, got nil)", "no scene")
check.errors(function() render.png(s) end, "bad argument #2 to 'png' (file path (string) expected, got nil)", "no file")
check.errors(function() render.png(s, dir .. "/f_%s.png") end, "one %d, %5d or %05d-style frame number", "bad pattern")
check.errors(function() render.png(s, dir .. "/missing/x.png") end, "png: cannot write '" .. dir .. "/missing/x.png'",
  "unwritable path")
check.errors(function() render.png(s, out, { show = { "displacement" } }) end,
  "png: no reference state: call set_reference first", "arrows without a reference")
s:set_reference()
check.errors(function() render.png(s, out, { show = { "displacement" }, displacement = { scale = -1 } }) end,
  "bad field 'displacement.scale' in argument #3 to 'png' (non-negative number expected, got", "arrow scale")
check.errors(function() render.png(s, out, { show = { "displacement" }, displacement = { affine = { 1, 2 } } }) end,
  "bad field 'displacement.affine' in argument #3 to 'png' (2 x 2 array of finite numbers", "affine")
local s3 = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } } }
s3:add_sphere{ pos = { 0.5, 0.5, 0.5 }, radius = 0.2 }
check.errors(function() render.png(s3, out, { show = { "force_chains" } }) end,
  "png: force chains, rotation markers and arrows are drawn in 2D scenes only", "chains in 3D")
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
-- A 'none' series widens the axes and draws nothing (no marker, no legend entry): the orange of
-- the second series appears with style 'points' and not at all with 'none'.
do
  local function orange_pixels(style)
    local im = render.plot{ width = 200, height = 160, series = {
      { x = { 0, 1 }, y = { 0, 1 }, label = "line" },
      { x = { -2, 3 }, y = { -2, 3 }, label = "extent", style = style } } }
    local w, h = im:size()
    local count = 0
    for py = 1, h do
      for px = 1, w do
        local r, g, b = im:pixel(px, py)
        if r > 200 and g > 90 and g < 160 and b < 60 then count = count + 1 end
      end
    end
    return count
  end
  check.gt(orange_pixels("points"), 20, "points series drawn")
  check.eq(orange_pixels("none"), 0, "none series not drawn")
end
local function pbad(def, text, what)
  check.errors(function() render.plot(def) end, text, what)
end
pbad({ series = {} }, "bad field 'series' in argument #1 to 'plot' (non-empty array of", "no series")
pbad({ series = { { x = { 1, 2 }, y = { 1 } } } },
  "bad field 'series[1].y' in argument #1 to 'plot' (array as long as series[1].x (2) expected", "lengths differ")
pbad({ series = { { x = { 1 }, y = { 1 }, style = "dots" } } },
  "bad field 'series[1].style' in argument #1 to 'plot' (one of 'line', 'points', 'both', 'none' expected, got 'dots')", "style")
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

-- ---- the scene's walls: by default whatever `show` says, where they are now, removed ones not ---
do
  local sw = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.1, 0.1 } }, gravity = { 0, 0 } }
  sw:add_disk{ pos = { 0.02, 0.02 }, radius = 0.005 }
  local moving = sw:add_wall{ point = { 0.08, 0 }, normal = { -1, 0 } }
  local removed = sw:add_wall{ point = { 0, 0.06 }, normal = { 0, -1 } }
  sw:remove_wall(removed)
  sw:wall_velocity(moving, { -0.1, 0 })
  sw:run{ time = 0.2, progress = false } -- the wall moves from x = 0.08 to 0.06
  check.near_abs(sw:wall_point(moving)[1], 0.06, 1e-6, "the wall moved")
  local function image(opts)
    opts.width, opts.height = 400, 400
    return render.image(sw, opts)
  end
  local function darkest(im, y)
    local best, at = 256, nil
    for x = 1, 400 do local r = im:pixel(x, y); if r < best then best, at = r, x end end
    return best, at
  end
  -- the box's outline (walls off) gives the frame: first and last grey column and row
  local frame = image{ show = { "box" }, walls = false }
  local left, right, top, bottom = 400, 1, 400, 1
  for i = 1, 400 do
    if frame:pixel(i, 200) < 250 then left, right = math.min(left, i), math.max(right, i) end
    if frame:pixel(200, i) < 250 then top, bottom = math.min(top, i), math.max(bottom, i) end
  end
  check.gt(right - left, 300, "box found")
  local plain = image{ show = { "force_chains" } } -- no 'walls' in show: walls still drawn
  local off = image{ show = { "force_chains" }, walls = false }
  local v, x = darkest(plain, 200)
  check.lt(v, 120, "walls drawn by default, whatever show lists")
  check.eq((darkest(off, 200)), 255, "walls = false: no wall")
  check.near_abs((x - left) / (right - left), 0.6, 0.02, "the moving wall drawn where it is now (x = 0.06)")
  -- the removed wall (y = 0.06) leaves its rows clean
  local row = math.floor(top + 0.4 * (bottom - top))
  local clean = true
  for yy = row - 4, row + 4 do
    for xx = left + 60, left + 200 do if plain:pixel(xx, yy) < 250 then clean = false end end
  end
  check.is_true(clean, "a removed wall is not drawn")
  check.errors(function() image{ walls = 1 } end,
    "bad field 'walls' in argument #2 to 'image' (false, true or an array of", "walls type")

  -- 3D: the walls' outlines are drawn by default, not with walls = false
  local s3w = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } }, gravity = { 0, 0, -9.81 } }
  s3w:add_sphere{ pos = { 0.5, 0.5, 0.5 }, radius = 0.1 }
  s3w:add_wall{ point = { 0, 0, 0.25 }, normal = { 0, 0, 1 } }
  local a = render.image(s3w, { width = 200, height = 200, show = {} })
  local b = render.image(s3w, { width = 200, height = 200, show = {}, walls = false })
  local diff = 0
  for yy = 1, 200 do for xx = 1, 200 do if a:pixel(xx, yy) ~= b:pixel(xx, yy) then diff = diff + 1 end end end
  check.gt(diff, 200, "3D: the floor wall's outline is drawn")
end
-- ---- walls beyond planes: polylines and circles along their surface, where they are now --------
do
  -- a drum (circle, R = 0.04) and a baffle turning at 2 rad/s about the centre: after 0.4 s the
  -- baffle lies at 0.8 rad; one grain at rest in the middle, away from both
  local sd = dem.scene{ dim = 2, box = { { -0.05, -0.05 }, { 0.05, 0.05 } }, gravity = { 0, 0 } }
  sd:add_disk{ pos = { 0, -0.01 }, radius = 0.003 }
  sd:add_cylinder{ center = { 0, 0 }, radius = 0.04, omega = 2 }
  sd:add_polyline{ points = { { 0.015, 0 }, { 0.035, 0 } }, center = { 0, 0 }, omega = 2 }
  sd:run{ time = 0.4, progress = false }
  local function image(opts)
    opts.width, opts.height = 400, 400
    return render.image(sd, opts)
  end
  local frame = image{ show = { "box" }, walls = false }
  local left, right, top, bottom = 400, 1, 400, 1
  for i = 1, 400 do
    if frame:pixel(i, 200) < 250 then left, right = math.min(left, i), math.max(right, i) end
    if frame:pixel(200, i) < 250 then top, bottom = math.min(top, i), math.max(bottom, i) end
  end
  check.gt(right - left, 300, "shapes: box found")
  local with, without = image{ show = {} }, image{ show = {}, walls = false }
  -- the darkest pixel within 2 px of the image of (x, y)
  local function dark(im, x, y)
    local px = left + (x + 0.05) / 0.1 * (right - left)
    local py = top + (0.05 - y) / 0.1 * (bottom - top)
    local best = 255
    for yy = math.floor(py) - 2, math.floor(py) + 2 do
      for xx = math.floor(px) - 2, math.floor(px) + 2 do best = math.min(best, (im:pixel(xx, yy))) end
    end
    return best
  end
  local on, off = 0, 0
  for k = 0, 35 do -- every 10 degrees around the circle
    local a = math.rad(10 * k)
    if dark(with, 0.04 * math.cos(a), 0.04 * math.sin(a)) < 120 then on = on + 1 end
    if dark(without, 0.04 * math.cos(a), 0.04 * math.sin(a)) < 250 then off = off + 1 end
  end
  check.eq(on, 36, "shapes: the circle is drawn all round")
  check.eq(off, 0, "shapes: walls = false draws no circle")
  local now, before = 0, 0
  for k = 0, 10 do -- along the baffle, where it is now (0.8 rad) and where it started (0 rad)
    local rr = 0.015 + 0.002 * k
    if dark(with, rr * math.cos(0.8), rr * math.sin(0.8)) < 120 then now = now + 1 end
    if dark(with, rr, 0) < 250 then before = before + 1 end
  end
  check.eq(now, 11, "shapes: the turning polyline is drawn where it is now")
  check.eq(before, 0, "shapes: and not where it was")
  -- 3D: a mesh's edges and a cylinder's rims are drawn, not with walls = false
  local s3 = dem.scene{ dim = 3, box = { { -1, -1, -1 }, { 1, 1, 1 } } }
  s3:add_sphere{ pos = { 0, 0, 0.5 }, radius = 0.05 }
  s3:add_mesh{ triangles = { { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } } } }
  local a = render.image(s3, { width = 200, height = 200, show = {} })
  local b = render.image(s3, { width = 200, height = 200, show = {}, walls = false })
  local function diff(u, v)
    local n = 0
    for yy = 1, 200 do for xx = 1, 200 do if u:pixel(xx, yy) ~= v:pixel(xx, yy) then n = n + 1 end end end
    return n
  end
  check.gt(diff(a, b), 150, "3D: a triangle's edges are drawn")
  s3:add_cylinder{ center = { 0, 0, 0 }, radius = 0.8, axis = { 0, 0, 1 }, length = 1 }
  local c = render.image(s3, { width = 200, height = 200, show = {} })
  check.gt(diff(c, a), 400, "3D: a cylinder's rims are drawn")
end
-- ---- grid fields and point clouds on plain arrays (MPM, DSMC) ----------------------------------
do
  local fdir = os.tmpname()
  os.remove(fdir)
  assert(os.execute("mkdir -p '" .. fdir .. "'"))
  local function ls()
    local p = io.popen("ls -A '" .. fdir .. "'")
    local list = {}
    for name in p:lines() do list[#list + 1] = name end
    p:close()
    table.sort(list)
    return table.concat(list, " ")
  end
  -- 4 x 2 cells over [0, 4] x [0, 2], value i + 4 j (first row at the bottom), grey: white = large
  local flat = { 0, 1, 2, 3, 4, 5, 6, 7 }
  local rows = { { 0, 1, 2, 3 }, { 4, 5, 6, 7 } }
  local opts = { values = flat, nx = 4, ny = 2, extent = { { 0, 0 }, { 4, 2 } }, colormap = "gray",
                 width = 200, height = 120, colorbar = false, box = false }
  local a = render.field(opts)
  opts.values, opts.nx, opts.ny = rows, nil, nil
  local b = render.field(opts)
  local W, H = a:size()
  local same = true
  for y = 1, H, 3 do for x = 1, W, 3 do
    local r1, g1, b1 = a:pixel(x, y)
    local r2, g2, b2 = b:pixel(x, y)
    same = same and r1 == r2 and g1 == g2 and b1 == b2
  end end
  check.is_true(same, "a flat array and an array of rows draw the same field")
  -- margins 7 px (font 9), scale min(186 / 4, 106 / 2) = 46.5 px per unit, centred: column of
  -- cell 3 (x in [3, 4]) ends at the right margin, the top row (j = 1) at the top
  local ox, oy = math.floor(7 + (186 - 4 * 46.5) / 2 + 0.5), math.floor(7 + (106 - 2 * 46.5) / 2 + 0.5)
  local function cell(im, i, j)
    return im:pixel(ox + math.floor((i + 0.5) * 46.5) + 1, oy + math.floor((2 - j - 0.5) * 46.5) + 1)
  end
  check.eq(cell(a, 3, 1), 255, "largest value white")
  check.eq(cell(a, 0, 0), 0, "smallest value black")
  check.gt(cell(a, 2, 1), cell(a, 1, 1), "grey grows with the value")
  check.gt(cell(a, 1, 1), cell(a, 3, 0), "the top row holds the larger values")
  -- NaN and masked cells show the background
  local nan = { 0, 0 / 0, 2, 3, 4, 5, 6, 7 }
  local c = render.field{ values = nan, nx = 4, ny = 2, extent = { { 0, 0 }, { 4, 2 } }, width = 200, height = 120,
                          colorbar = false, box = false, mask = { true, true, true, true, true, true, false, true },
                          background = { 0, 0, 255 } }
  check.eq(select(3, cell(c, 1, 0)), 255, "NaN cell: background blue")
  check.eq(select(1, cell(c, 1, 0)), 0, "NaN cell: background blue, no red")
  check.eq(select(3, cell(c, 2, 1)), 255, "masked cell: background")
  -- arrows only: a uniform field to the right draws red ink right of a cell centre
  local u, v = {}, {}
  for k = 1, 25 do u[k], v[k] = 1, 0 end
  local d = render.field{ nx = 5, ny = 5, extent = { { 0, 0 }, { 1, 1 } }, arrows = { u = u, v = v, scale = 0.1, every = 1 },
                          width = 200, height = 200 }
  local red = 0
  for y = 1, 200 do for x = 1, 200 do
    local r, g, bb = d:pixel(x, y)
    if r > 150 and g < 80 and bb < 80 then red = red + 1 end
  end end
  check.gt(red, 25 * 10, "arrow ink")
  -- a point lights its pixel; files, patterns and identical bytes
  local p = render.points{ x = { 0.25 }, y = { 0.75 }, values = { 1 }, range = { 0, 1 }, size = 10,
                           extent = { { 0, 0 }, { 1, 1 } }, width = 100, height = 100, colorbar = false }
  -- scale 86 px per unit from (7, 7): the point at pixel (7 + 21.5, 7 + 21.5)
  local r, g, bb = p:pixel(29, 29)
  check.near_abs(r, 0xfd, 2, "point: viridis(1) red")
  check.near_abs(bb, 0x25, 2, "point: viridis(1) blue")
  check.eq(select(1, p:pixel(40, 29)), 255, "beside the point")
  local big = {}
  for k = 1, 300 do big[k] = math.sin(k) end
  local fopts = { file = fdir .. "/f.png", values = big, nx = 20, ny = 15, title = "field", label = "s",
                  interpolation = "bilinear", arrows = { u = big, v = big, unit = "m/s" } }
  check.eq(render.field(fopts), fdir .. "/f.png", "field returns the file name")
  fopts.file = fdir .. "/g.png"
  render.field(fopts)
  local function read(path) local f = assert(io.open(path, "rb")); local s = f:read("a"); f:close(); return s end
  check.is_true(read(fdir .. "/f.png") == read(fdir .. "/g.png"), "identical field PNGs")
  check.eq(render.points{ file = fdir .. "/p_%02d.png", x = big, y = big }, fdir .. "/p_00.png", "points frame pattern")
  check.eq(render.points{ file = fdir .. "/p_%02d.png", x = big, y = big, frame = 7 }, fdir .. "/p_07.png", "given frame")

  local function fbad(o, text, what) check.errors(function() render.field(o) end, text, what) end
  local function pbad(o, text, what) check.errors(function() render.points(o) end, text, what) end
  local out = fdir .. "/bad.png"
  fbad({ file = out, values = flat, nx = 0, ny = 2 },
    "bad field 'nx' in argument #1 to 'field' (positive integer expected, got 0)", "nx zero")
  fbad({ file = out, values = flat, nx = 4 },
    "bad field 'ny' in argument #1 to 'field' (positive integer (with a flat array of cells) expected, got nil)", "ny missing")
  fbad({ file = out, values = flat, nx = 3, ny = 2 },
    "bad field 'values' in argument #1 to 'field' (nx * ny = 6 numbers expected, got 8)", "flat length")
  fbad({ file = out, values = { { 1, 2 }, { 3 } } },
    "bad field 'values' in argument #1 to 'field' (rows of 2 numbers expected, got 1 at row 2)", "ragged rows")
  fbad({ file = out, values = rows, nx = 3 },
    "bad field 'values' in argument #1 to 'field' (rows of 3 entries expected, got 4 at row 1)", "rows against nx")
  fbad({ file = out, values = { 1, "x", 3, 4 }, nx = 2, ny = 2 },
    "bad field 'values' in argument #1 to 'field' (numbers (NaN for no value) expected, got 'x' at entry 2)", "a string")
  fbad({ file = out, values = { 1, 2, 1 / 0, 4 }, nx = 2, ny = 2 },
    "bad field 'values' in argument #1 to 'field' (numbers (NaN for no value) expected, got inf at entry 3)", "infinity")
  fbad({ file = out, nx = 2, ny = 2 },
    "bad field 'values' in argument #1 to 'field' (array of numbers, or array of rows (or arrows) expected, got nil)", "nothing")
  fbad({ file = out, values = rows, mask = { { true, 1, true, true }, { true, true, true, true } } },
    "bad field 'mask' in argument #1 to 'field' (booleans expected, got 1 at row 1, entry 2)", "mask")
  fbad({ file = out, values = rows, extent = { { 0, 0 }, { 0, 1 } } },
    "bad field 'extent' in argument #1 to 'field' ({{x0, y0}, {x1, y1}} with x0 < x1 and y0 < y1 expected, got table)", "extent")
  fbad({ file = out, values = rows, range = { 1, 1 } },
    "bad field 'range' in argument #1 to 'field' ({lo, hi} with lo < hi expected, got table)", "range")
  fbad({ file = out, values = rows, colormap = "jet" },
    "bad field 'colormap' in argument #1 to 'field' (one of 'viridis', 'gray' expected, got 'jet')", "colormap")
  fbad({ file = out, values = rows, interpolation = "cubic" },
    "bad field 'interpolation' in argument #1 to 'field' (one of 'nearest', 'bilinear' expected, got 'cubic')", "interpolation")
  fbad({ file = out, values = rows, width = 8 },
    "bad field 'width' in argument #1 to 'field' (integer in [16, 8192] expected, got 8)", "width")
  fbad({ file = out, values = rows, background = { 0, 0, 300 } },
    "bad field 'background' in argument #1 to 'field' ({r, g, b} with integers in [0, 255] expected, got table)", "background")
  fbad({ file = out, values = rows, colour = "gray" },
    "bad argument #1 to 'field' (unknown field 'colour'; valid fields:", "unknown field")
  fbad({ file = out, values = rows, arrows = { u = rows } },
    "bad field 'arrows.v' in argument #1 to 'field' (array of numbers, or array of rows expected, got nil)", "arrows without v")
  fbad({ file = out, values = rows, arrows = { u = rows, v = rows, scale = 0 } },
    "bad field 'arrows.scale' in argument #1 to 'field' (positive number expected, got 0)", "arrow scale")
  fbad({ file = out, values = rows, arrows = { u = rows, v = rows, every = 0 } },
    "bad field 'arrows.every' in argument #1 to 'field' (positive integer expected, got 0)", "arrow spacing")
  fbad({ file = out, values = rows, arrows = { u = rows, v = rows, w = rows } },
    "bad field 'arrows' in argument #1 to 'field' (unknown key 'w'; valid keys: u, v, scale, every, unit)", "arrow key")
  fbad({ file = out, values = rows, arrows = { u = { { 1 } }, v = rows } },
    "bad field 'arrows.u' in argument #1 to 'field' (2 rows expected, got 1 rows)", "arrows shape")
  fbad({ file = fdir .. "/missing/f.png", values = rows }, "field: cannot write '" .. fdir .. "/missing/f.png'", "field path")
  fbad("x", "bad argument #1 to 'field' (table expected, got string)", "not a table")
  pbad({ file = out, x = { 1, 2 }, y = { 1 } },
    "bad field 'y' in argument #1 to 'points' (array as long as 'x' (2) expected, got table)", "lengths")
  pbad({ file = out, x = { 1, 0 / 0 }, y = { 1, 2 } },
    "bad field 'x' in argument #1 to 'points' (finite numbers expected, got", "NaN position")
  pbad({ file = out, x = { 1 }, y = { 1 }, size = 0 },
    "bad field 'size' in argument #1 to 'points' (diameter in (0, 8192] pixels expected, got 0)", "size")
  pbad({ file = out, x = { 1 }, y = { 1 }, values = { 1, 2 } },
    "bad field 'values' in argument #1 to 'points' (array as long as 'x' (1) expected, got table)", "values length")
  pbad({ file = out, y = { 1 } }, "bad field 'x' in argument #1 to 'points' (array of finite numbers expected, got nil)", "no x")
  pbad({ file = out, x = { 1 }, y = { 1 }, height = 100000 },
    "bad field 'height' in argument #1 to 'points' (integer in [16, 8192] expected, got 100000)", "height")
  pbad({ file = out, x = { 1 }, y = { 1 }, extent = { 0, 1 } }, "bad field 'extent' in argument #1 to 'points'", "extent")
  check.eq(ls(), "f.png g.png p_00.png p_07.png", "no file from failed calls")
  os.execute("rm -rf '" .. fdir .. "'")
end
check.done()
