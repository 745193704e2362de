-- Random streams from Lua: the same numbers as the C generator (reference values derived
-- independently in Python from the published xoshiro256** and splitmix64), reproducible, with
-- the expected statistics.
local check = grainlab.check

check.eq(grainlab.rng{ seed = 42 }:raw(), 0x15780b2e0c2ec716, "seed 42, first output")
local s1 = grainlab.rng{ seed = 42, stream = 1 }
check.eq(s1:raw(), 0x50086ef83cbf4f4a, "seed 42, stream 1, first output")
check.eq(s1:raw(), 0xba285ec21347d703, "seed 42, stream 1, second output (negative as a Lua integer)")
check.eq(grainlab.rng():raw(), grainlab.rng{ seed = 0 }:raw(), "default seed is 0")
check.eq(grainlab.rng(nil):raw(), grainlab.rng{}:raw(), "nil means defaults")

local a, b = grainlab.rng{ seed = 7 }, grainlab.rng{ seed = 7 }
for i = 1, 100 do check.eq(a:normal(), b:normal(), "same seed, same normals " .. i) end

-- integer(lo, hi): inclusive, every face of a die within 5 standard errors of n/6.
local die, counts, n = grainlab.rng{ seed = 3 }, {}, 60000
for _ = 1, n do
  local k = die:integer(1, 6)
  counts[k] = (counts[k] or 0) + 1
end
local sd = math.sqrt(n * (1 / 6) * (5 / 6))
for k = 1, 6 do check.near_abs(counts[k], n / 6, 5 * sd, "die face " .. k) end
check.eq(die:integer(5, 5), 5, "degenerate range")
local full = die:integer(math.mininteger, math.maxinteger)
check.eq(math.type(full), "integer", "full 64-bit range")

-- normal(mean, sd) and uniform(a, b) moments; standard errors for n = 10^5.
local g, m, v = grainlab.rng{ seed = 5 }, 0, 0
n = 100000
for _ = 1, n do
  local x = g:normal(10, 2)
  m = m + x
  v = v + (x - 10) ^ 2
end
check.near_abs(m / n, 10, 5 * 2 / math.sqrt(n), "normal mean")
check.near_abs(v / n, 4, 5 * 4 * math.sqrt(2 / n), "normal variance")
local u, lo, hi = grainlab.rng{ seed = 6 }, math.huge, -math.huge
for _ = 1, 10000 do
  local x = u:uniform(-1, 3)
  lo, hi = math.min(lo, x), math.max(hi, x)
end
check.is_true(lo >= -1 and hi < 3 and lo < -0.99 and hi > 2.99, "uniform(-1, 3) covers its range")
check.done()
