-- A run failing inside grainlab.pack.deposit (the pile has a floor but no side walls): the error
-- is reported at line 6, the traceback shows this script's lines only.
local s = dem.scene{ dim = 2, box = { { 0, 0 }, { 0.03, 0.04 } }, gravity = { 0, -9.81 } }
s:add_wall{ point = { 0, 0 }, normal = { 0, 1 } }
local sand = grainlab.material{ density = 2650, young = 5e6, poisson = 0.3, friction = 0.5 }
grainlab.pack.deposit(s, { n = 100, radius = { 0.5e-3, 1e-3 }, seed = 7, material = sand })
