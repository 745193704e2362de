-- Fills a DEM scene from the inserter just added to it, and lets the grains settle: advance(T)
-- (the script's own run of T seconds) in steps of 0.1 s until the inserter has placed or given
-- up on `n` grains (at most 2 s), an error if more than 1 % found no place, then 0.3 s with a
-- background drag of 20 /s and 0.2 s without. Returns s:flow() after the filling.
-- Shared by silo.lua and brazil_nut.lua:
--   local pour = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/pour.lua")
--   pour(s, n, advance, "silo")
return function(s, n, advance, who)
  local poured = 0
  repeat
    advance(0.1)
    poured = poured + 0.1
  until s:flow().inserted + s:flow().skipped >= n or poured > 2
  local f = s:flow()
  assert(f.skipped <= 0.01 * n, string.format("%s: %d grains found no place to enter", who, f.skipped))
  s:drag(20)
  advance(0.3)
  s:drag(0)
  advance(0.2)
  return f
end
