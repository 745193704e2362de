-- Benchmark: what each boundary condition of the biaxial laboratory costs over plain DEM steps.
-- The biaxial sample of Padbidri Table 3.1 (3300 disks, r in [0.5, 1] mm, quartz scaled x 1e5,
-- Hertz + Brilliantov + regularised Coulomb, dt = 1e-5 s) between the same plates under:
--   plain     the same lateral load as fixed external forces (no boundary machinery: what the
--             others are measured against)
--   pressure  direct pressure on the lateral Delaunay edges, rebuilt every 250 steps
--   membrane  frictionless membrane chains on 10 N/mm springs carrying the pressure
--   mbc       pressure on the Delaunay loop + the minimal-boundary penalty (Eqs. 3.2-3.5)
-- Each is set up from the same prepared sample (grainlab.biax.prepared, cached in out/), given
-- `warm` untimed steps, then `steps` steps are timed (CPU time, one thread).
--   grainlab scripts/bench/biaxial.lua [n=3300] [steps=5000] [warm=250] [seed=1] [cache=path]
-- Report bench_biaxial: <bc>_particle_steps_per_s, <bc>_contacts_per_particle, and for each
-- boundary condition the overhead over plain (per particle of the sample: membrane disks are
-- extra particles, counted as cost), the share of time in the triangulation (the boundary update
-- calls qhull through analysis.delaunay) and in applying the boundary forces.
local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
local biax = grainlab.biax
local n = params.n or 3300
local steps = params.steps or 5000
local warm = params.warm or 250
local seed = params.seed or 1
grainlab.threads(1)
local c = biax.config{}

local t0 = grainlab.clock()
local st, rep, cached = biax.prepared{ n = n, seed = seed, cache = params.cache }
io.stderr:write(string.format("sample of %d disks %s in %.1f s\n", n, cached and "loaded" or "prepared",
                              grainlab.clock() - t0))

local metrics, checks, rows = {}, {}, {}
local function measure(bc)
  local s, lab
  if bc == "plain" then
    -- The same plates and the same lateral load, as fixed external forces: the pressure BC's
    -- edge forces at the start (p depth L/2 on each end of each loaded edge), then no boundary.
    s, lab = biax.setup(st, "pressure", c)
    local E, P = s:boundary_edges(), s:particles()
    local fx, fy, order = {}, {}, {}
    for k = 1, #E.a do
      if E.loaded[k] then
        local a, b = E.a[k], E.b[k]
        local hx, hy = 0.5 * (P.y[b] - P.y[a]), -0.5 * (P.x[b] - P.x[a])
        for _, i in ipairs{ a, b } do
          if not fx[i] then fx[i], fy[i] = 0, 0; order[#order + 1] = i end
          fx[i] = fx[i] - c.pressure * c.thickness * hx
          fy[i] = fy[i] - c.pressure * c.thickness * hy
        end
      end
    end
    s:boundary{ mode = "none" }
    local ax, ay = {}, {}
    for k, i in ipairs(order) do ax[k], ay[k] = fx[i], fy[i] end
    s:set_forces{ ids = order, fx = ax, fy = ay }
  else
    s, lab = biax.setup(st, bc, c)
  end
  s:run{ steps = warm, dt = c.dt, impact_velocity = 1e-3, progress = false }
  local b0 = bc ~= "plain" and s:boundary_info() or nil
  local cpu0, w0 = grainlab.cpu_clock(), grainlab.clock()
  s:run{ steps = steps, dt = c.dt, impact_velocity = 1e-3, progress = false }
  local cpu, wall = grainlab.cpu_clock() - cpu0, grainlab.clock() - w0
  local np = s:info().count
  local r = { bc = bc, cpu = cpu, wall = wall, rate = np * steps / cpu, particles = np,
              z = s:measure("coordination").z }
  if b0 then
    local b1 = s:boundary_info()
    r.tri = (b1.update_seconds - b0.update_seconds) / cpu -- CPU time in both
    r.apply = (b1.apply_seconds - b0.apply_seconds) / cpu
    r.updates = b1.updates - b0.updates
  end
  return r
end

for _, bc in ipairs{ "plain", "pressure", "membrane", "mbc" } do
  rows[#rows + 1] = measure(bc)
  collectgarbage()
end
local plain = rows[1]
print(string.format("%-9s %9s %9s %12s %8s %8s %9s", "bc", "particles", "cpu s", "p-steps/s",
                    "tri %", "apply %", "overhead"))
for _, r in ipairs(rows) do
  -- per simulated particle of the sample: membrane disks are extra particles, counted as cost
  r.overhead = (r.cpu / plain.cpu) * (plain.particles / n) - 1
  print(string.format("%-9s %9d %9.2f %12.4g %8s %8s %+8.1f%%", r.bc, r.particles, r.cpu, r.rate,
                      r.tri and string.format("%.2f", 100 * r.tri) or "-",
                      r.apply and string.format("%.2f", 100 * r.apply) or "-", 100 * r.overhead))
  metrics[r.bc .. "_particle_steps_per_s"] = r.rate
  metrics[r.bc .. "_cpu_s"] = r.cpu
  metrics[r.bc .. "_wall_s"] = r.wall
  metrics[r.bc .. "_contacts_per_particle"] = r.z
  if r.bc ~= "plain" then
    metrics[r.bc .. "_triangulation_share"] = r.tri
    metrics[r.bc .. "_apply_share"] = r.apply
    metrics[r.bc .. "_boundary_updates"] = r.updates
    metrics[r.bc .. "_overhead_vs_plain"] = r.overhead
  end
end
metrics.projected_full_run_h_per_bc = plain.cpu / steps * (0.20 / c.rate / c.dt) / 3600
print(string.format("a full run (20%% strain at %.3g/s, dt %g s = %.3g steps) projects to %.1f h per BC at the plain rate",
                    c.rate, c.dt, 0.20 / c.rate / c.dt, metrics.projected_full_run_h_per_bc))
grainlab.report{
  scenario = "bench_biaxial",
  params = { n = n, steps = steps, warm = warm, seed = seed, dt = c.dt, every = c.every },
  metrics = bench.metrics(metrics),
  checks = checks,
}
