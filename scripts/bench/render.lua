-- Benchmark: one frame of n disks (default 100,000) at 1920 x 1080, rendered headlessly to PNG.
--   A 16:9 box filled with a jittered triangular lattice of polydisperse disks (no physics run),
--   coloured by speed through viridis with a colour bar, title and stamp; written as PNG.
--   grainlab scripts/bench/render.lua [n=100000] [width=1920] [height=1080] [repeat=5] [out=FILE]
-- Report bench_render: frame_s (median wall time of render.png over `repeat` frames, the
-- first frame, which also starts the GL context and compiles the shaders, excluded), image_s
-- (render.image, no PNG), png_s (the difference), first_frame_s, png_bytes.
local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
local n = params.n or 100000
local width, height = params.width or 1920, params.height or 1080
local reps = params["repeat"] or 5
local out = params.out or os.tmpname() .. ".png"

-- Lattice: rows of disks spaced 2 R_max, rows 2 R_max sqrt(3)/2 apart, filling a 16:9 box.
local Wb = 0.16
local Hb = Wb * height / width
local cols = math.ceil(math.sqrt(n * (Wb / Hb) * math.sqrt(3) / 2))
local d = Wb / (cols + 0.5)
local rows = math.ceil(n / cols)
local Hbox = math.max(Hb, (rows + 1) * d * math.sqrt(3) / 2)
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { Wb, Hbox } }, gravity = { 0, 0 } }
local rng = grainlab.rng{ seed = 4 }
local k = 0
for j = 0, rows - 1 do
  for i = 0, cols - 1 do
    if k == n then break end
    k = k + 1
    local x = (i + 0.5 + 0.5 * (j % 2)) * d
    local y = (j + 0.5) * d * math.sqrt(3) / 2 + d * 0.25
    s:add_disk{ pos = { x, y }, radius = d * rng:uniform(0.3, 0.5),
                vel = { rng:normal(0, 0.1), rng:normal(0, 0.1) } }
  end
end

local opts = { width = width, height = height, color = "speed", title = "100,000 disks", stamp = true }
local function median(t)
  table.sort(t)
  local m = #t
  return m % 2 == 1 and t[(m + 1) / 2] or 0.5 * (t[m / 2] + t[m / 2 + 1])
end
local t0 = grainlab.clock()
render.png(s, out, opts)
local first = grainlab.clock() - t0
local full, image = {}, {}
for r = 1, reps do
  t0 = grainlab.clock()
  render.png(s, out, opts)
  full[r] = grainlab.clock() - t0
  t0 = grainlab.clock()
  local img = render.image(s, opts)
  image[r] = grainlab.clock() - t0
  img = nil
  collectgarbage()
end
local f = assert(io.open(out, "rb"))
local bytes = f:seek("end")
f:close()
if not params.out then os.remove(out) end
local t_full, t_image = median(full), median(image)

grainlab.report{
  scenario = "bench_render",
  params = { n = n, width = width, height = height, ["repeat"] = reps },
  metrics = bench.metrics{ frame_s = t_full, image_s = t_image, png_s = t_full - t_image,
                           first_frame_s = first, png_bytes = bytes, disks = n, pixels = width * height },
  checks = { { name = "png_written", value = bytes, limit = 0, op = ">" } },
}
