-- Coarse-grained fields of a distributed DEM run: every field equals the one-process field, bit
-- for bit (the scene is gathered to every rank before the sums, which then run in particle and
-- contact order). A 2D bed periodic in x with a frictional floor, 600 steps sampled by an
-- average every 100, then the fields now; every value written with %a (rank 0 writes the file).
--   compare_np.sh --np "0 2 3" --file cg_dump.txt grainlab cg_same.lua out=cg_dump.txt
local W = 0.012
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { W, 0.012 } }, gravity = { 0, -9.81 },
                     periodic = { true, false }, thickness = 1e-3 }
s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
local m = grainlab.material{ density = 2650, young = 5e7, poisson = 0.3, friction = 0.5, restitution = 0.6 }
grainlab.pack.random(s, { n = 100, radius = { 0.3e-3, 0.45e-3 }, seed = 4, material = m, speed = 0.05,
                          region = { { 0, 0 }, { W, 0.009 } } })
s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.6, impact_velocity = 1, tangential = "spring" }
s:run{ time = 0.01, progress = false }
local opts = { kernel = "gauss", width = 0.8e-3, cells = { 24, 18 }, region = { { 0, -2e-3 }, { W, 0.012 } } }
local avg = analysis.cg_average(s, opts)
s:run{ steps = 600, dt = 2e-6, every = 100, progress = false, on_step = function(sc) avg:add(sc) end }
local F = analysis.coarse_grain(s, opts)
local A = avg:fields()
local out = assert(io.open(params.out or "cg_dump.txt", "w"))
for i = 1, F.n do
  out:write(string.format("%a %a %a %a %a %a %a %a\n", F.density[i], F.stress.xx[i], F.stress.xy[i],
                          F.stress.yy[i], F.fabric.xx[i], F.traction.y[i], A.density[i], A.stress.yy[i]))
end
out:close()
if grainlab.mpi.size() > 1 then -- the run was decomposed: the fields are gathered ones
  local dist = assert(s:info().distributed, "the run was not distributed")
  assert(dist.ranks == grainlab.mpi.size() and dist.rebuilds > 0, "decomposed over every rank")
end
print(string.format("samples %d, contacts %d", A.samples, s:measure("coordination").z * 100 // 1))
