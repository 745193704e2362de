-- grainlab DEM: the angles of repose and of marginal stability against the rolling friction
-- mu_r, at a fixed Coulomb friction (Herrmann & Mueller Sec. 3; rolling resistance: docs/dem.md).
--
-- Without rolling resistance a pile of disks levels off near 20 deg however large mu is (the
-- disks roll once friction stops them sliding: scripts/repose.lua), where sand stands at 30-35
-- deg. Rolling resistance stands for the shape and contact width of real grains. Here mu = 0.8
-- and mu_r runs through `mus_r`; for each, on the same packings (scripts/lib/heap_box.lua):
--  * theta_r: the wall of the box removed, the pile left at rest fitted (scripts/repose.lua);
--  * theta_m: the closed box tilted in steps until the surface gives way
--    (scripts/marginal_stability.lua).
-- Law: Hertz + Brilliantov damping + Cundall-Strack spring, and the EPSD rolling law (Ai et al.
-- 2011, type C: a rolling spring k_r = k_t R_eff^2 capped at mu_r R_eff |F_n|, rolling damping
-- 0.3).
-- Checks: theta_r rises with mu_r over the range and reaches 30 deg (real sand's 30-35) at some
-- mu_r; theta_m >= theta_r at every mu_r; all angles in (0, 50) deg; the piles at rest.
--
-- Measured (default run, box aspect 1, one packing per mu_r): theta_r = 21.0, 27.0,
-- 28.2, 29.4, 36.5 deg and theta_m = 32.8, 38.2, 37.2, 39.8, 44.1 deg for mu_r = 0, 0.1, 0.2,
-- 0.3, 0.5: real sand's 30-35 deg lies between mu_r = 0.3 and 0.5. Three packings (seeds=3):
-- theta_r = 30.6 +- 1.6 deg at mu_r = 0.3 (29.4, 30.1, 32.4) and 35.8 +- 1.9 at 0.5 (36.5, 33.7,
-- 37.2): the scatter between packings, ~2 deg, is why one packing at 0.3 fell short. With strong
-- rolling resistance the tilted pile may only creep under the fine 0.5 deg steps: theta_m is then
-- the coarse 2 deg step's (heap_box:marginal's fifth value; mu_r = 0.2 here). In the half-full
-- box (aspect 0.5): 20.9, 25.7, 28.5, 27.5 deg for mu_r up to 0.3; at mu = 0.5 theta_r stays
-- near atan 0.5 = 26.6 deg (17.8, 25.0, 25.3, 27.7; 2 packings).
--   grainlab scripts/repose_rolling.lua [n=1000] [mu=0.8] [mus_r=0,0.1,0.2,0.3,0.5] [seed=1]
--       [seeds=1] [aspect=1] [csv=out/repose_rolling.csv] [verbose=false]
local heap_box = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/heap_box.lua")
local figures = require("grainlab.figures")

local n = math.tointeger(params.n or 1000)
local mu = params.mu or 0.8
local seed = math.tointeger(params.seed or 1)
local seeds = math.tointeger(params.seeds or 1)
-- A box filled to its width (aspect 1): a pile steeper than 30 deg needs the height; in the
-- half-full box of repose.lua (aspect 0.5) mu_r = 0.3 gave 29.2 deg where this one gives 33.3
-- (600 disks, one packing).
local aspect = params.aspect or 1
local csv = params.csv or "out/repose_rolling.csv"
local verbose = params.verbose == true
assert(n and n >= 50, "n must be an integer >= 50")
assert(type(mu) == "number" and mu >= 0, "mu must be a non-negative number")
assert(seed and seed >= 0, "seed must be a non-negative integer")
assert(seeds and seeds >= 1, "seeds must be a positive integer")
local mus_r = heap_box.mus(params.mus_r, { 0, 0.1, 0.2, 0.3, 0.5 })
local published = figures.published({ n = n, mu = mu, seed = seed, seeds = seeds, aspect = aspect,
                                      mus_r = table.concat(mus_r, ",") },
                                    { n = 1000, mu = 0.8, seed = 1, seeds = 1, aspect = 1,
                                      mus_r = "0,0.1,0.2,0.3,0.5" })
local png = params.png or figures.path("repose_rolling.png", { published = published })
local ckpt = os.tmpname()
local function say(fmt, ...) if verbose then io.stderr:write(string.format(fmt, ...) .. "\n") end end

local function run_one(mu_r, sd)
  local c0 = grainlab.clock()
  local r = heap_box.new{ n = n, mu = mu, mu_r = mu_r > 0 and mu_r or nil, seed = sd,
                          aspect = aspect }:collapse(4)
  -- tilted slowly from 4 deg (a first tilt of theta_r - 8 deg at once, tried to save time, gave
  -- 28.9 instead of 32.8 deg at mu_r = 0: the slow tilt's history matters)
  local theta_m, _, _, _, crept = heap_box.new{ n = n, mu = mu, mu_r = mu_r > 0 and mu_r or nil,
                                                seed = sd, aspect = aspect }
                                  :marginal{ checkpoint = ckpt, limit = 70 }
  say("mu_r %.2f seed %d: theta_r %.2f, theta_m %.2f%s, %.1f s", mu_r, sd, r.theta, theta_m,
      crept and " (coarse: crept under the fine steps)" or "", grainlab.clock() - c0)
  return { theta_r = r.theta, theta_m = theta_m, vmax = r.vmax, rms = r.rms, v_rest = 5e-3,
           crept = crept and 1 or 0, wall_s = grainlab.clock() - c0 }
end

print(string.format("repose with rolling resistance: n = %d, mu = %g, %d packing(s) per mu_r", n, mu, seeds))
local results = heap_box.sweep{ label = "repose_rolling", mus = mus_r, seed = seed, seeds = seeds,
                                run = run_one, mean = { "theta_r", "theta_m" }, max = { "vmax", "rms" },
                                sum = { "wall_s", "crept" } }
os.remove(ckpt)

local metrics, checks, rows = {}, {}, { "mu_r,theta_r_deg,theta_r_sd_deg,theta_m_deg,theta_m_sd_deg" }
print(string.format("%6s %9s %7s %9s %7s %7s", "mu_r", "theta_r", "sd", "theta_m", "sd", "wall s"))
local reached = false
for _, r in ipairs(results) do
  local id = string.format("mur%03d", math.floor(r.mu * 100 + 0.5))
  local sdr, sdm = r.theta_r_sd or 0 / 0, r.theta_m_sd or 0 / 0
  print(string.format("%6.2f %9.2f %7.2f %9.2f %7.2f %7.1f", r.mu, r.theta_r, sdr, r.theta_m, sdm, r.wall_s))
  rows[#rows + 1] = string.format("%g,%.4f,%.4f,%.4f,%.4f", r.mu, r.theta_r, sdr, r.theta_m, sdm)
  if r.theta_r == r.theta_r then metrics["theta_r_deg_" .. id] = r.theta_r end
  if r.theta_m == r.theta_m then metrics["theta_m_deg_" .. id] = r.theta_m end
  checks[#checks + 1] = { name = "avalanche_found_" .. id, pass = r.theta_m == r.theta_m }
  metrics["wall_s_" .. id] = r.wall_s
  checks[#checks + 1] = { name = "theta_r_in_0_50_deg_" .. id, pass = r.theta_r > 0 and r.theta_r < 50 }
  checks[#checks + 1] = { name = "theta_m_at_least_theta_r_deg_" .. id, value = r.theta_m - r.theta_r,
                          limit = 0, op = ">=" }
  checks[#checks + 1] = { name = "at_rest_v_max_m_per_s_" .. id, value = r.vmax, limit = 5e-3, op = "<" }
  if r.theta_r >= 30 then reached = true end
end
if #results > 1 then
  checks[#checks + 1] = { name = "theta_r_rise_over_mu_r_range_deg",
                          value = results[#results].theta_r - results[1].theta_r, limit = 5, op = ">=" }
  checks[#checks + 1] = { name = "theta_r_reaches_30_deg", pass = reached }
end
os.execute("mkdir -p out")
assert(grainlab.write_file(csv, table.concat(rows, "\n") .. "\n"))
print("wrote " .. csv)
do
  local x, yr, ym = {}, {}, {}
  for _, r in ipairs(results) do x[#x + 1], yr[#yr + 1], ym[#ym + 1] = r.mu, r.theta_r, r.theta_m end
  render.plot{ file = png, width = 900, height = 560,
               title = string.format("repose and marginal stability against rolling friction, mu = %g, %d disks", mu, n),
               xlabel = "rolling friction mu_r", ylabel = "angle (degrees)",
               series = { { x = x, y = ym, label = "theta_m (tilted box)", style = "both" },
                          { x = x, y = yr, label = "theta_r (wall removed)", style = "both" },
                          { x = { x[1], x[#x] }, y = { 30, 30 }, label = "30 deg", style = "line" } } }
  print("wrote " .. png)
end

grainlab.report{
  scenario = "repose_rolling",
  params = { n = n, mu = mu, mus_r = mus_r, seed = seed, seeds = seeds, aspect = aspect, csv = csv },
  metrics = metrics,
  checks = checks,
}
