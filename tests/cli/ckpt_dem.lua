-- Driver of test_checkpoint.sh: one step of a checkpoint round trip per process.
--   mode=full  : build, run n + m steps, print the state
--   mode=save  : build, run n steps, save to file
--   mode=onstep: build, run n + m steps saving to file from on_step at step n, print the state
--   mode=load  : load file, run m steps, print the state
-- dim=2|3, integ=velocity_verlet|position_verlet|gear|two_timescales, bnd=true: the 2D scene with
-- boundary conditions; delaunay=K: the 2D scene with Delaunay boundary variant K of
-- ckpt_dem_case.lua (its integrator, N and M unless given), the edges printed too
local C = dofile("../lua/lib/ckpt_dem_case.lua")
local p = params
local v = p.delaunay and assert(C.delaunay[p.delaunay], "no such Delaunay variant") or {}
local dim, integ = p.dim or 2, p.integ or v.integ or "velocity_verlet"
local n, m = p.n or v.n or 300, p.m or v.m or 300
local build = p.bnd and function() return C.build_boundary() end or C.build
if p.delaunay then build = function() return C.build_delaunay(p.delaunay) end end
local dump = C.dump
if p.delaunay then dump = function(s) return C.dump(s) .. "\n" .. C.dump_edges(s) end end
if p.mode == "full" then
  local s = build(dim)
  C.run(s, integ, n + m)
  print(dump(s))
elseif p.mode == "save" then
  local s = build(dim)
  C.run(s, integ, n)
  s:save(p.file)
elseif p.mode == "onstep" then
  local s = build(dim)
  C.run(s, integ, n + m, 50, function(sc)
    if sc:info().steps == n then sc:save(p.file) end
  end)
  print(dump(s))
elseif p.mode == "load" then
  local s = dem.load(p.file)
  C.run(s, integ, m)
  print(dump(s))
else
  error("mode must be full, save, onstep or load")
end
