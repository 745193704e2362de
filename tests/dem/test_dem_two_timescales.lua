-- Padbidri's two-timescales algorithm (Sec. 2.4, Table 2.1) on a small biaxial compression: 150
-- disks under a confining pressure applied as forces on the outermost particles, rigid plates at
-- a constant strain rate. The force evaluations of II: m(n+q) against III (one small step at a
-- time) must give N_S / (m(1+q)) (shared/VALIDATION.md "Two-timescales speed-up"; I gives N_S);
-- and II must stay near III where the single large step I does not: I's mean slip velocity is
-- well above III's (the rotations, fast variables, are not resolved by the large step). For
-- 2(10+15) and 5(5+5) (the paper's best), the mean slip velocity is within 5% of III's and the
-- volumetric strain within a quarter of I's distance from III's. The coarsest, 2(20+5) and
-- 2(15+10), are only timed: in a sample this small their deviations depend on single events.
-- The sample, its confining forces and its preparation are the script's own
-- (scripts/lib/confined_disks.lua); scripts/two_timescales.lua has the full version, its
-- parameters and the reasoning behind them (same material, laws, mass scaling, Delta t = 5e-5 s,
-- delta t = Delta t / 50, eps_rate 0.01/s; here 150 disks and 0.1% axial strain).
local check = grainlab.check
grainlab.threads(1)

local NS, p, rate, dt_large = 50, 1e5, 0.01, 5e-5
local dt_small = dt_large / NS
local v_R = 2 * rate * 0.75e-3
local v_imp = 1e-3 -- impact velocity of the stability check (m/s): ~4 v_0 of the test
local quartz = grainlab.material{ density = 2650, young = 30e9, poisson = 0.3, friction = 0.45 }

-- The script's sample, boundary and preparation (scripts/lib/confined_disks.lua) with 150 disks.
local confined = assert(loadfile("../../scripts/lib/confined_disks.lua")){
  n = 150, rmin = 0.5e-3, rmax = 1e-3, thickness = 1.5e-3, material = quartz, seed = 1,
  mass_scale = 1e5, damping_time = 0.002, v_r = v_R, exponent = 10, impact_velocity = v_imp }
local confine = confined.confine
local prepared, _, sb, st = confined.prepare(p)
check.near(sb, 1, 0.3, "bottom plate carries p W t after the preparation")
check.near(st, 1, 0.3, "top plate carries p W t after the preparation")

-- ---- compression: 0.1% axial strain -----------------------------------------------------------
local runs = {
  { name = "III", integrator = "velocity_verlet", dt = dt_small, theory = 1 },
  { name = "I", integrator = "velocity_verlet", dt = dt_large, theory = NS },
  { name = "II 2(20+5)", integrator = "two_timescales", dt = dt_small, m = 2, n = 20, q = 5 },
  { name = "II 2(15+10)", integrator = "two_timescales", dt = dt_small, m = 2, n = 15, q = 10 },
  { name = "II 2(10+15)", integrator = "two_timescales", dt = dt_small, m = 2, n = 10, q = 15,
    near = true },
  { name = "II 5(5+5)", integrator = "two_timescales", dt = dt_small, m = 5, n = 5, q = 5, near = true },
}
local total, sample, update = 100000, 500, 2500 -- small-step equivalents
local H0 = prepared.ytop - prepared.ybot
for _, run in ipairs(runs) do
  if run.m then run.theory = NS / (run.m * (1 + run.q)) end
  local s = confined.build(prepared, true)
  local W0_ = confine(s, p, true)
  s:wall_velocity(1, { 0, 0.5 * rate * H0 })
  s:wall_velocity(2, { 0, -0.5 * rate * H0 })
  local per = run.dt == dt_large and NS or 1
  local f0 = s:info().force_evaluations
  local slip, ns, W = 0, 0, W0_
  s:run{ steps = total // per, dt = run.dt, integrator = run.integrator, m = run.m, n = run.n,
         q = run.q, impact_velocity = v_imp, every = sample // per, progress = false,
         on_step = function(sc)
           ns = ns + 1
           slip = slip + sc:measure("slip")
           if ns % (update // sample) == 0 then
             W = confine(sc, p, true)
           end
         end }
  local H = s:wall_point(2)[2] - s:wall_point(1)[2]
  check.near(1 - H / H0, total * dt_small * rate, 1e-6, run.name .. ": axial strain")
  run.evals = s:info().force_evaluations - f0 -- boundary updates cost no evaluation
  run.ev = H * W / (H0 * W0_) - 1
  run.slip = slip / ns / v_R
end

local III, I = runs[1], runs[2]
for k = 2, #runs do
  local r = runs[k]
  check.near(III.evals / r.evals, r.theory, 0.01, r.name .. ": force evaluations III / run = N_S/(m(1+q))")
end
check.gt(I.slip, 1.5 * III.slip, "I: the large step inflates the mean slip velocity")
for k = 3, #runs do
  local r = runs[k]
  if r.near then
    check.near(r.slip, III.slip, 0.05, r.name .. ": mean slip velocity near III's")
    check.lt(math.abs(r.ev - III.ev), 0.25 * math.abs(I.ev - III.ev),
             r.name .. ": volumetric strain much closer to III than I's")
  end
end
check.done()
