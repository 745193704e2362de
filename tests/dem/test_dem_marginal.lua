-- Angle of marginal stability (Herrmann Sec. 3), small and fast: the procedure of
-- scripts/marginal_stability.lua (scripts/lib/heap_box.lua) with 200 disks. The closed box is tilted
-- in steps until at least a tenth of the grains move by more than a diameter in one hold; the
-- search then restarts from the last stable state, loaded from a checkpoint, in finer steps.
-- Checks: mu = 0.5 holds its surface above the angle of repose of the same packing (the wall
-- removed), and below 45 deg; nearly frictionless disks (mu = 0.02) give way at a much smaller
-- angle; after the first coarse failure the search goes on from the last stable state in fine
-- steps.
local check = grainlab.check
grainlab.threads(1) -- 200 particles: threads only add synchronisation
local heap_box = dofile("../../scripts/lib/heap_box.lua")
local ckpt = os.tmpname()

local function marginal(mu)
  local b = heap_box.new{ n = 200, mu = mu, seed = 1 }
  local tilts = {}
  local theta_m, after, tilt = b:marginal{ checkpoint = ckpt, on_hold = function(t) tilts[#tilts + 1] = t end }
  return theta_m, after, tilt, tilts
end

local m5, after5, tilt5, tilts5 = marginal(0.5)
local r5 = heap_box.new{ n = 200, mu = 0.5, seed = 1 }:collapse(3)
local m0 = marginal(0.02)
print(string.format("mu 0.5: theta_m %.2f (tilt %.2f, left at %.2f), theta_r %.2f; mu 0.02: theta_m %.2f",
                    m5, tilt5, after5, r5.theta, m0))
check.gt(m5, r5.theta, "mu = 0.5: theta_m above theta_r of the same packing")
check.lt(m5, 45, "mu = 0.5: theta_m below 45 deg")
check.lt(m0, m5 - 5, "mu = 0.02 gives way well before mu = 0.5")
check.gt(m0, 0, "mu = 0.02: a positive angle")
-- after the first coarse failure (2 deg steps) the search goes on from the last stable coarse
-- tilt, restored, in 0.5 deg steps
local coarse_fail, first_fine
for k = 2, #tilts5 do
  if tilts5[k] < tilts5[k - 1] then coarse_fail, first_fine = tilts5[k - 1], tilts5[k] break end
end
check.is_true(coarse_fail ~= nil, "mu = 0.5: a coarse failure, then the fine search")
check.near_abs(first_fine, coarse_fail - 1.5, 1e-9, "the fine search starts a fine step above the last stable tilt")
check.near_abs((tilt5 - first_fine) / 0.5 % 1, 0, 1e-9, "the fine search goes in 0.5 deg steps")
os.remove(ckpt)
check.done()
