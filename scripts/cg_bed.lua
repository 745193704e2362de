-- The static bed of the coarse-graining checks (scripts/cg_pile.lua, scripts/cg_width.lua), not a
-- scenario; load it with
--   local cg_bed = dofile((arg[0]:match("^(.*)/") or ".") .. "/cg_bed.lua")
-- cg_bed.get{ n =, width =, seed =, cache = } returns the scene of a settled 2D bed and its sizes:
--   box     x in [0, W] periodic (W = width mean diameters), a plane floor at y = 0 with the
--           grains' friction, open above; n disks of radius uniform in [0.4, 0.6] mm (d = 1 mm),
--           cylinders 1 mm thick (so the fields are per m^3 and stresses in Pa), density 2650.
--   law     Hertz (E = 1 GPa, nu = 0.3) + Brilliantov damping (restitution 0.5 at 1 m/s) +
--           Cundall-Strack spring, mu = 0.5 (grains and floor).
--   packing Jodrey-Tory deposition (grainlab.pack.deposit: every disk rests on two supports),
--           then grainlab.pack.settle with collapse (the grains the drag only held fail first):
--           a pile at rest, every grain's net force a small fraction of its weight.
-- The settled bed is cached as a checkpoint (cache = path, default out/cg_bed_<n>_<W>_<seed>.ckpt;
-- false: always prepare), so the scripts that share it prepare it once.
local cg_bed = {}

cg_bed.d, cg_bed.rho, cg_bed.g, cg_bed.depth = 1e-3, 2650, 9.81, 1e-3

function cg_bed.get(o)
  local n, wd, seed = o.n or 1200, o.width or 30, o.seed or 1
  local W = wd * cg_bed.d
  local path = o.cache
  if path == nil then path = string.format("out/cg_bed_%d_%d_%d.ckpt", n, wd, seed) end
  local f = path and io.open(path, "rb")
  if f then
    f:close()
    local s = dem.load(path)
    return s, { W = W, n = n, seed = seed, cached = true, prep_s = 0 }
  end
  local t0 = grainlab.clock()
  local H = 3 * n * math.pi * 0.25 * cg_bed.d ^ 2 / W -- room to drop into
  local s = dem.scene{ dim = 2, box = { { 0, -0.002 }, { W, H } }, gravity = { 0, -cg_bed.g },
                       periodic = { true, false }, thickness = cg_bed.depth }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
  local m = grainlab.material{ density = cg_bed.rho, young = 1e9, poisson = 0.3, friction = 0.5,
                               restitution = 0.5 }
  grainlab.pack.deposit(s, { n = n, radius = { 0.4e-3, 0.6e-3 }, seed = seed, material = m,
                             region = { { 0, 0 }, { W, H } }, relax_steps = 0 })
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
             tangential = "spring" }
  local settle = grainlab.pack.settle(s, { quiet = 1e-5, collapse = 0.5 })
  if path then
    os.execute("mkdir -p '" .. (path:match("^(.*)/[^/]*$") or ".") .. "'")
    s:save(path)
  end
  return s, { W = W, n = n, seed = seed, cached = false, prep_s = grainlab.clock() - t0,
              v_rms = settle.v_rms, v_max = settle.v_max }
end

-- Largest net force on a grain over its weight (how static the bed is), and the top of the bed.
function cg_bed.state(s)
  local P = s:particles()
  local worst, top = 0, 0
  for i = 1, P.count do
    local f = math.sqrt(P.fx[i] ^ 2 + P.fy[i] ^ 2)
    worst = math.max(worst, f / (P.mass[i] * cg_bed.g))
    top = math.max(top, P.y[i] + P.radius[i])
  end
  return worst, top
end

return cg_bed
