-- Driver of test_checkpoint.sh: one step of a checkpoint round trip per process.
--   mode=full  : build, run n + m steps, print the state
--   mode=save  : build, run n steps, save to file
--   mode=onstep: build, run n + m steps saving to file from on_step at step n, print the state
--   mode=load  : load file, run m steps, print the state
-- dim=2|3, integ=velocity_verlet|position_verlet|gear|two_timescales, bnd=true: the 2D scene with
-- boundary conditions
local C = dofile("../lua/ckpt_dem_case.lua")
local p = params
local dim, integ, n, m = p.dim or 2, p.integ or "velocity_verlet", p.n or 300, p.m or 300
local build = p.bnd and function() return C.build_boundary() end or C.build
if p.mode == "full" then
  local s = build(dim)
  C.run(s, integ, n + m)
  print(C.dump(s))
elseif p.mode == "save" then
  local s = build(dim)
  C.run(s, integ, n)
  s:save(p.file)
elseif p.mode == "onstep" then
  local s = build(dim)
  C.run(s, integ, n + m, 50, function(sc)
    if sc:info().steps == n then sc:save(p.file) end
  end)
  print(C.dump(s))
elseif p.mode == "load" then
  local s = dem.load(p.file)
  C.run(s, integ, m)
  print(C.dump(s))
else
  error("mode must be full, save, onstep or load")
end
