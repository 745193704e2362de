-- Herrmann & Mueller's Fig. 2 gas, shared by scaling.lua and largest.lua:
--   local fig2_gas = dofile((arg[0]:match("^(.*)/") or ".") .. "/fig2_gas.lua")
--   local s, nc = fig2_gas(n)
-- n disks (R = 1 mm) in 2D at volume fraction nu = 0.1, e = 0.9, a periodic square, cells one mean
-- free path wide (lambda = 1 / (2 sqrt 2 n_A 2R chi), Henderson's 2D Enskog chi, as dsmc uses:
-- 0.7 particles per cell), Maxwellian at T/m = 1 m^2/s^2. Returns the scene and the cells per side.
return function(n)
  local nu, R = 0.1, 1e-3
  local L = math.sqrt(n * math.pi * R * R / nu)
  local chi = (1 - 7 / 16 * nu) / (1 - nu) ^ 2
  local lambda = 1 / (2 * math.sqrt(2) * (n / (L * L)) * 2 * R * chi)
  local nc = math.ceil(L / lambda)
  local s = dsmc.scene{ dim = 2, size = { L, L }, cells = { nc, nc }, radius = R, restitution = 0.9, seed = 3 }
  s:fill{ n = n, temperature = s:info().mass * 1.0, seed = 5 }
  return s, nc
end
