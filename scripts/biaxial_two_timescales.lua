-- grainlab DEM: Padbidri's two-timescales comparison (Sec. 2.4-2.6, Table 2.1) rerun on the
-- biaxial sample of scripts/biaxial.lua (grainlab.biax: Jodrey-Tory deposit, 100 kPa on the
-- Delaunay boundary, Table 3.1 materials) under the direct-pressure boundary condition (rigid
-- plates + pressure on the lateral Delaunay edges), as in the paper's Ch. 2.
--   III  velocity Verlet, dt = delta t = Delta t / 50 (the benchmark)
--   I    velocity Verlet, dt = Delta t = 1e-5 s (Table 3.1)
--   II   two timescales m(n + q) with the small step delta t: 2(20+5), 2(15+10), 2(10+15), 5(5+5)
-- Every run starts from the same plate-loaded state (biax.start on the large step) and updates
-- its Delaunay boundary every 250 large steps of simulated time (12500 small steps). Measured:
-- CPU time of the runs (one thread) and force evaluations, the speed-ups against III and the
-- theory N_S / (m (1 + q)) (shared/VALIDATION.md), the volumetric strain path (Bagi-Satake,
-- summed increments every 0.01% strain) and its rms and final difference from III, and the mean
-- |slip velocity| / v_R. Scale: III needs 50 steps per large step, so the default is a smaller
-- sample (n = 600, `scale` of the biaxial sample's 3300) to 0.2% axial strain; the paper's
-- comparison went to 10%.
--   grainlab scripts/biaxial_two_timescales.lua [n=600] [strain=0.002] [seed=1]
--       [png=images/biaxial_two_timescales] [runs=1,2,...] [plot=1] [out=out/biaxial_tt]
-- Only n=3300 strain=0.01 seed=1 (the documented run) writes images/biaxial_two_timescales.png;
-- plot=1 takes the same n, strain and seed as the runs.
-- runs = a subset of the six (1 = III, 2 = I, 3-6 = II in the order above) saves each run to
-- <out>_<k>.lua (split the runs over processes to use several cores: CPU time is per run, so
-- the speed-ups do not depend on the split); plot=1 then reads the six files and reports.
local biax = grainlab.biax
local n = params.n or 600
local strain = params.strain or 0.002
local seed = params.seed or 1
-- The published figure (images/, shown in docs/analysis.md) is the documented run, n = 3300 to
-- 1 % strain, seed 1; any other run, the small default included, writes its figure to out/ and
-- keeps its run files apart (out/biaxial_tt_reduced_<k>.lua), so plot=1 of the full run never
-- draws a reduced run's data (grainlab.figures).
local figures = require("grainlab.figures")
local published = figures.published({ n = n, strain = strain, seed = seed }, { n = 3300, strain = 0.01, seed = 1 })
local png = params.png or figures.path("biaxial_two_timescales", { published = published })
local NS = 50
local outp = params.out or (published and "out/biaxial_tt" or "out/biaxial_tt_reduced")
local only = nil
if params.runs then
  only = {}
  for k in tostring(params.runs):gmatch("%d+") do only[tonumber(k)] = true end
end
grainlab.threads(1)
os.execute("mkdir -p out")
local c = biax.config{}
local dt_large = c.dt
local dt_small = dt_large / NS
local st = not params.plot and biax.prepared{ n = n, seed = seed } or nil

local runs = {
  { name = "III", integrator = "velocity_verlet", dt = dt_small, per = 1, theory = 1 },
  { name = "I", integrator = "velocity_verlet", dt = dt_large, per = NS, theory = NS },
  { name = "II 2(20+5)", integrator = "two_timescales", m = 2, n = 20, q = 5 },
  { name = "II 2(15+10)", integrator = "two_timescales", m = 2, n = 15, q = 10 },
  { name = "II 2(10+15)", integrator = "two_timescales", m = 2, n = 10, q = 15 },
  { name = "II 5(5+5)", integrator = "two_timescales", m = 5, n = 5, q = 5 },
}
local total_small = math.floor(strain / (c.rate * dt_small) / (NS * 20) + 0.5) * NS * 20
local sample_small = math.max(NS * 20, math.floor(0.0001 / (c.rate * dt_small) / (NS * 20) + 0.5) * NS * 20)
for _, r in ipairs(runs) do
  if r.integrator == "two_timescales" then
    r.dt, r.theory = dt_small, NS / (r.m * (1 + r.q))
    r.engine_per_macro = r.m * (1 + r.q) -- engine steps per N_S small steps
  else
    r.engine_per_macro = NS / r.per
  end
  r.every = 250 * r.engine_per_macro -- 250 large steps of time between boundary updates
end

local function save_run(k, r)
  local rows = {}
  for _, row in ipairs(r.rows) do rows[#rows + 1] = string.format("{%.17g,%.17g}", row.ea, row.ev) end
  grainlab.write_file(string.format("%s_%d.lua", outp, k), string.format(
    "return { n = %d, strain = %.17g, seed = %d, cpu = %.17g, evals = %.17g, slip = %.17g, ev = %.17g, servo_b = %.17g, servo_t = %.17g, servo_steps = %d, rows = {%s} }\n",
    n, strain, seed, r.cpu, r.evals, r.slip, r.ev, r.servo_b, r.servo_t, r.servo_steps, table.concat(rows, ",")))
end

local metrics, checks = {}, {}
for k, r in ipairs(runs) do
 if params.plot then
  local d = dofile(string.format("%s_%d.lua", outp, k))
  if d.n and (d.n ~= n or d.strain ~= strain or d.seed ~= seed) then
    error(string.format("%s_%d.lua holds a run with n=%d strain=%g seed=%d: plot with the run's parameters",
                        outp, k, d.n, d.strain, d.seed))
  end
  r.cpu, r.evals, r.slip, r.ev = d.cpu, d.evals, d.slip, d.ev
  r.servo_b, r.servo_t, r.servo_steps = d.servo_b, d.servo_t, d.servo_steps
  r.rows = {}
  for _, row in ipairs(d.rows) do r.rows[#r.rows + 1] = { ea = row[1], ev = row[2] } end
 elseif not only or only[k] then
  local s, lab = biax.setup(st, "pressure", c)
  r.servo_b, r.servo_t = biax.start(lab) -- identical for every run (large steps)
  r.servo_steps = lab.servo_steps
  s:boundary{ pressure = c.pressure, every = r.every, alpha = c.alpha, sides = "lateral" }
  local mesh = analysis.delaunay(s, { ids = lab.ids })
  r.rows = {}
  local ev, slip_sum, slip_n = 0, 0, 0
  local cpu, f0, done = 0, s:info().force_evaluations, 0
  while done < total_small do
    local steps = r.integrator == "two_timescales" and sample_small or sample_small // r.per
    local c0 = grainlab.cpu_clock()
    s:run{ steps = steps, dt = r.dt, integrator = r.integrator, m = r.m, n = r.n, q = r.q,
           impact_velocity = 1e-3, progress = false }
    cpu = cpu + grainlab.cpu_clock() - c0
    done = done + sample_small
    local e = mesh:strain(s).coarse
    ev = ev + e.xx + e.yy
    local sl = s:measure("slip")
    slip_sum, slip_n = slip_sum + sl, slip_n + 1
    r.rows[#r.rows + 1] = { ea = biax.axial(lab), ev = ev }
    mesh = analysis.delaunay(s, { ids = lab.ids })
  end
  r.cpu, r.evals = cpu, s:info().force_evaluations - f0
  r.slip = slip_sum / slip_n / c.v_r
  r.ev = ev
  io.stderr:write(string.format("%-12s cpu %.1f s, %d force evaluations, eps_v %.3e\n", r.name, cpu, r.evals, ev))
  s = nil
  collectgarbage()
  if only then save_run(k, r) end
 end
end
if only then return end
local III = runs[1]
print(string.format("%-12s %8s %8s %8s %11s %10s %10s %8s", "run", "theory", "evals", "cpu",
                    "eps_v", "|d eps_v|", "rms d ev", "slip/vR"))
local series = {}
for _, r in ipairs(runs) do
  local s2, m = 0, math.min(#r.rows, #III.rows)
  for k = 1, m do s2 = s2 + (r.rows[k].ev - III.rows[k].ev) ^ 2 end
  r.rms = math.sqrt(s2 / math.max(1, m))
  r.su_evals, r.su_cpu = III.evals / r.evals, III.cpu / r.cpu
  print(string.format("%-12s %8.4f %8.4f %8.4f %11.3e %10.3e %10.3e %8.3f", r.name, r.theory, r.su_evals,
                      r.su_cpu, r.ev, math.abs(r.ev - III.ev), r.rms, r.slip))
  local id = r.name:lower():gsub("[^%w]+", "_"):gsub("_$", "")
  metrics[id .. "_speedup_theory"] = r.theory
  metrics[id .. "_speedup_force_evals"] = r.su_evals
  metrics[id .. "_speedup_cpu"] = r.su_cpu
  metrics[id .. "_cpu_s"] = r.cpu
  metrics[id .. "_eps_v_final"] = r.ev
  metrics[id .. "_eps_v_rms_diff"] = r.rms
  metrics[id .. "_slip_over_v_r"] = r.slip
  local x, y = {}, {}
  for _, row in ipairs(r.rows) do x[#x + 1], y[#y + 1] = 100 * row.ea, 100 * row.ev end
  series[#series + 1] = { x = x, y = y, label = r.name, style = "line" }
  if r ~= III then
    checks[#checks + 1] = { name = id .. "_force_eval_ratio", value = math.abs(r.su_evals / r.theory - 1), limit = 0.02 }
  end
end
render.plot{ file = png .. ".png", width = 900, height = 560,
             title = string.format("Two timescales on the biaxial sample (%d disks, direct pressure)", n),
             xlabel = "axial strain (%)", ylabel = "volumetric strain (%)", series = series }
grainlab.report{
  scenario = "biaxial_two_timescales",
  params = { n = n, strain = strain, seed = seed, dt_large = dt_large, dt_small = dt_small, N_S = NS,
             plate_stress_start_bottom = III.servo_b, plate_stress_start_top = III.servo_t,
             servo_steps = III.servo_steps },
  metrics = metrics,
  checks = checks,
}
