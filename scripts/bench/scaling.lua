-- Strong scaling over MPI ranks, and a communication model projected to Herrmann & Mueller's 512
-- processors (the paper's Figs. 1 and 2).
--
--   grainlab scripts/bench/scaling.lua [engines=dem,dsmc] [reps=3] [dem_n=20000] [dem_steps=2000]
--                                      [dsmc_n=500000] [dsmc_steps=40] [pile=PATH.ckpt] [out=DIR]
--
-- Cases, each run alternately (1 rank, 2 ranks, 1 rank on 2 threads, …) `reps` times; medians:
--   dem   scripts/bench/dem_dense.lua's pile of dem_n disks (prepared once by that script's
--         export=, which leaves a checkpoint: the same state for every run; pile= names one
--         already made), its laws (Hertz, Brilliantov per pair, Cundall-Strack springs),
--         dt = 1e-7 s, 200 warm-up steps (the decomposition and the first rebuilds) then
--         dem_steps timed.
--   dsmc  Fig. 2's gas (fig2_gas.lua): dsmc_n disks, 2D, volume fraction 0.1, e = 0.9, cells one
--         mean free path wide (0.76 particles per cell), Maxwellian at T/m = 1 m^2/s^2, periodic
--         square, dt = a tenth of the mean collision time; 5 warm-up steps, dsmc_steps timed.
-- Traffic: every rank's bytes and messages per step and seconds inside communication per step
-- (grainlab.mpi.stats over the timed steps), at 2 ranks and, as counts only (oversubscribed: their
-- times mean nothing on 2 cores), at 4 ranks.
--
-- The model (Hockney): a message of b bytes costs alpha + beta b, alpha and beta fitted to a
-- ping-pong between two ranks (grainlab.mpi.bcast of 8 B to 4 MiB; its Lua serialisation is in
-- the figure, so beta is an upper bound for the engines' raw transfers). A rank's step on P ranks:
--   t(P) = (1 + eps) t1 / P  +  alpha m(P)  +  beta b(P)
-- t1: the 1-rank step. b(P): the bytes a rank sends per step, proportional to the length of its
-- subdomain's interior boundary (the halo, the migrants), c g(N, P), c fitted to the counts at 2
-- and 4 ranks. DEM cuts by recursive bisection: a subdomain is a square of side ~ sqrt(N / P)
-- with on average 4 (1 - 1 / sqrt P) interior sides (0 at 1 rank, ~1 at 2, 2 at 4, -> 4), so
-- g = sqrt(N / P) 4 (1 - 1 / sqrt P). DSMC cuts the cell index into ranges, slabs the width of
-- the box with on average 2 (1 - 1 / P) interior sides, so g = sqrt N 2 (1 - 1 / P): its traffic
-- per rank does not shrink with P, which caps its speed-up. m(P): the messages per step, the
-- count measured at 4 ranks plus 2 per doubling beyond (the tree of the per-step reductions).
-- eps: what the transfers leave unexplained of the measured 2-rank step (the ranks waiting for
-- each other at the step's synchronisations for the jitter and imbalance of their work, work a
-- rank does twice), as a fraction of the compute t1 / 2, kept for every P.
-- The projection to 512 ranks uses the measured alpha, beta (this machine's shared memory) and,
-- labelled as such, an assumed cluster network (alpha = 1.5 us, beta = 0.1 ns/B: 10 GB/s). The
-- figure plots the measured speed-ups, the ideal line and the projections (labelled so).
--
-- Report bench_scaling: per engine, <engine>_rate_1_rank, _rate_2_ranks, _rate_2_threads
-- (particle-steps per second), _efficiency_2_ranks, _ranks_over_threads, traffic, the model's
-- terms and _speedup_512 (this machine's network) and _speedup_512_cluster; alpha_s, beta_s_per_byte.
-- Writes scaling.png into images/ for the full run (the defaults), into out/ otherwise, and prints
-- the measured table.
local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
local figures = require("grainlab.figures")
local mpi = grainlab.mpi

local P = {
  engines = params.engines or "dem,dsmc", reps = params.reps or 3,
  dem_n = params.dem_n or 20000, dem_steps = params.dem_steps or 2000,
  dsmc_n = params.dsmc_n or 500000, dsmc_steps = params.dsmc_steps or 40,
}
local metrics = {}

-- ---- the cases (run by the driver below, under mpirun or not) --------------------------------
local function result(t)
  if mpi.rank() ~= 0 then return end
  local parts = {}
  for k, v in pairs(t) do parts[#parts + 1] = string.format("%s=%.17g", k, v) end
  table.sort(parts)
  print("SCALING " .. table.concat(parts, " "))
end

local function traffic(steps)
  -- every rank's counters, on every rank (bcast from each in turn); max over ranks per step
  local st = mpi.stats()
  local bytes, msgs, secs = 0, 0, 0
  for r = 0, mpi.size() - 1 do
    local x = mpi.bcast(st, r)
    bytes = math.max(bytes, x.bytes / steps)
    msgs = math.max(msgs, x.messages / steps)
    secs = math.max(secs, x.seconds / steps)
  end
  return bytes, msgs, secs
end

local function timed(s, run)
  mpi.barrier()
  mpi.reset_stats()
  local t0 = grainlab.clock()
  s:run(run)
  mpi.barrier()
  local wall = mpi.bcast(grainlab.clock() - t0) -- rank 0's clock decides
  return wall, traffic(run.steps)
end

local function case_dem()
  local s = dem.load(params.ckpt)
  local n = s:info().count
  s:run{ steps = 200, dt = 1e-7, progress = false }
  local wall, bytes, msgs, secs = timed(s, { steps = params.steps, dt = 1e-7, progress = false })
  local d = s:info().distributed or {}
  result{ n = n, steps = params.steps, wall = wall, rate = n * params.steps / wall, bytes = bytes,
          messages = msgs, comm_s = secs, rebuilds = d.rebuilds or 0,
          imbalance = d.owned_max and d.owned_max / (n / mpi.size()) or 1,
          z = s:measure("coordination").z }
end

local fig2_scene = dofile((arg[0]:match("^(.*)/") or ".") .. "/fig2_gas.lua")

local function case_dsmc()
  local n = params.n
  local s, nc = fig2_scene(n)
  local dt = 0.1 / s:measure("temperature").collision_frequency
  -- warn = false: at nu = 0.1 a cell one mean free path wide holds 0.7 particles, below the
  -- validity check's few per cell (the paper's case; the run is timed, not validated)
  s:run{ steps = 5, dt = dt, progress = false, warn = false }
  local wall, bytes, msgs, secs = timed(s, { steps = params.steps, dt = dt, progress = false, warn = false })
  result{ n = n, steps = params.steps, wall = wall, rate = n * params.steps / wall, bytes = bytes,
          messages = msgs, comm_s = secs, per_cell = n / (nc * nc),
          collisions = s:measure("stats").collisions_per_particle_per_step }
end

local function case_pingpong()
  -- alpha, beta between two ranks: a bcast from rank 0 to rank 1 of b bytes, repeated
  local sizes = { 8, 1024, 16384, 262144, 4194304 }
  local out = {}
  for k, b in ipairs(sizes) do
    local msg = string.rep("x", b)
    local reps = b >= 262144 and 20 or 200
    mpi.bcast(msg)
    mpi.barrier()
    local t0 = grainlab.clock()
    for _ = 1, reps do mpi.bcast(msg) end
    mpi.barrier()
    out["t" .. k] = mpi.bcast((grainlab.clock() - t0) / reps)
    out["b" .. k] = b
  end
  result(out)
end

if params.case then
  local cases = { dem = case_dem, dsmc = case_dsmc, pingpong = case_pingpong }
  local fn = cases[params.case]
  if not fn then error("scaling.lua: unknown case " .. tostring(params.case) .. " (dem, dsmc, pingpong)") end
  fn()
  return
end

-- ---- the driver ----------------------------------------------------------------------------------
assert(mpi.size() == 1, "scaling.lua starts its own mpirun runs: run it without mpirun")
local published = figures.published(P, { engines = "dem,dsmc", reps = 3, dem_n = 20000, dem_steps = 2000,
                                        dsmc_n = 500000, dsmc_steps = 40 })
local dir = figures.dir and figures.dir({ published = published, out = params.out })
  or (published and "images" or (params.out or "out"))
local work = "out/scaling"
os.execute("mkdir -p " .. work)
local exe = arg[-1] -- this grainlab
local mpirun = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe --bind-to none"

local function launch(ranks, threads, args)
  local cmd = string.format("%s %s --threads %d scripts/bench/scaling.lua %s 2>&1",
                            ranks > 1 and (mpirun .. " -np " .. ranks) or "", exe, threads, args)
  local f = assert(io.popen(cmd))
  local txt = f:read("a")
  f:close()
  local line = txt:match("SCALING ([^\n]*)")
  if not line then error("scaling.lua: no result from: " .. cmd .. "\n" .. txt) end
  local r = {}
  for k, v in line:gmatch("([%w_]+)=(%S+)") do r[k] = tonumber(v) end
  return r
end

local function median(xs)
  local c = {}
  for i, x in ipairs(xs) do c[i] = x end
  table.sort(c)
  return c[(#c + 1) // 2]
end

local function load1() -- the 1-minute load average
  local f = io.open("/proc/loadavg")
  local l = f and tonumber(f:read("a"):match("^(%S+)")) or 0
  if f then f:close() end
  return l
end

-- alpha, beta: least squares of t = alpha + beta b over the ping-pong sizes
local pp = launch(2, 1, "case=pingpong")
local sx, sy, sxx, sxy, k = 0, 0, 0, 0, 0
for i = 1, 5 do
  local b, t = pp["b" .. i], pp["t" .. i]
  sx, sy, sxx, sxy, k = sx + b, sy + t, sxx + b * b, sxy + b * t, k + 1
end
local beta = (k * sxy - sx * sy) / (k * sxx - sx * sx)
local alpha = math.max((sy - beta * sx) / k, pp.t1 - beta * 8)
print(string.format("ping-pong (2 ranks, shared memory): alpha = %.3g us, beta = %.3g ns/B (%.3g GB/s)",
                    alpha * 1e6, beta * 1e9, 1e-9 / beta))

local engines = {}
for e in P.engines:gmatch("[^,]+") do engines[#engines + 1] = e end
local rows, curves = {}, {}
for _, eng in ipairs(engines) do
  local args
  if eng == "dem" then
    local ckpt = params.pile
    if not ckpt then
      local data = string.format("%s/pile%d.data", work, P.dem_n)
      ckpt = data .. ".ckpt"
      if not io.open(ckpt) then
        assert(os.execute(string.format("%s scripts/bench/dem_dense.lua n=%d export=%s", exe, P.dem_n, data)))
      end
    end
    args = string.format("case=dem ckpt=%s steps=%d", ckpt, P.dem_steps)
  elseif eng == "dsmc" then
    args = string.format("case=dsmc n=%d steps=%d", P.dsmc_n, P.dsmc_steps)
  else
    error("scaling.lua: engines are dem and dsmc, got " .. eng)
  end
  local configs = { { 1, 1 }, { 2, 1 }, { 1, 2 } }
  local runs = { {}, {}, {} }
  local loads = {}
  for rep = 1, P.reps do
    for c, cfg in ipairs(configs) do
      loads[#loads + 1] = load1()
      local r = launch(cfg[1], cfg[2], args)
      runs[c][#runs[c] + 1] = r
      io.stderr:write(string.format("%s rep %d: %d rank(s) x %d thread(s): %.4g particle-steps/s\n",
                                    eng, rep, cfg[1], cfg[2], r.rate))
    end
  end
  local four = launch(4, 1, args) -- traffic counts only (4 ranks on 2 cores)
  local function med(c, key)
    local xs = {}
    for i, r in ipairs(runs[c]) do xs[i] = r[key] end
    return median(xs)
  end
  local r1, r2, rt = med(1, "rate"), med(2, "rate"), med(3, "rate")
  local N = runs[1][1].n
  local b2, m2, c2 = med(2, "bytes"), med(2, "messages"), med(2, "comm_s")
  local b4, m4 = four.bytes, four.messages
  local t1 = N / r1
  local function g_of(n, p) -- the interior boundary of a subdomain (see the header)
    if eng == "dsmc" then return math.sqrt(n) * 2 * (1 - 1 / p) end
    return math.sqrt(n / p) * 4 * (1 - 1 / math.sqrt(p))
  end
  -- c from the counts at 2 and 4 ranks (least squares through the origin)
  local x2, x4 = g_of(N, 2), g_of(N, 4)
  local cb = (b2 * x2 + b4 * x4) / (x2 * x2 + x4 * x4)
  local function m_of(p) return p <= 2 and m2 or (p <= 4 and m4 or m4 + 2 * (math.log(p, 2) - 2)) end
  local function transfer(p, n, a, b) return a * m_of(p) + b * cb * g_of(n, p) end
  -- What the transfers do not explain at 2 ranks (the ranks waiting for each other at the step's
  -- synchronisations for the jitter and imbalance of their work, and work a rank does twice):
  -- a fraction eps of the compute, fitted at 2 ranks, kept for every P.
  local t2 = N / r2
  local sync = math.max(0, t2 - (t1 / 2 + transfer(2, N, alpha, beta)))
  local eps = sync / (t1 / 2)
  local function t_of(p, n, a, b)
    if p == 1 then return t1 * (n / N) end
    return t1 * (n / N) / p * (1 + eps) + transfer(p, n, a, b)
  end
  local model2 = t1 / 2 + transfer(2, N, alpha, beta)
  rows[#rows + 1] = string.format(
    "| %s | %d | %.3g | %.3g | %.3g | %.2f | %.2f | %.0f / %.0f | %.1f / %.1f | %.3g | %.3g | %.3g | %.3g (%.2f) | %.1f–%.1f |",
    eng, N, r1, r2, rt, r2 / r1 / 2, r2 / rt, b2, b4, m2, m4, t2, model2, c2, sync, eps,
    math.min(table.unpack(loads)), math.max(table.unpack(loads)))
  local nproj = eng == "dsmc" and 500000 or 1000000
  local ps, ideal, meas, proj_sm, proj_cl = {}, {}, {}, {}, {}
  for e = 0, 9 do
    local p = 2 ^ e
    ps[#ps + 1] = p
    proj_sm[#proj_sm + 1] = t_of(1, nproj, alpha, beta) / t_of(p, nproj, alpha, beta)
    proj_cl[#proj_cl + 1] = t_of(1, nproj, 1.5e-6, 1e-10) / t_of(p, nproj, 1.5e-6, 1e-10)
  end
  local pre = eng .. "_"
  metrics[pre .. "particles"] = N
  metrics[pre .. "rate_1_rank"] = r1
  metrics[pre .. "rate_2_ranks"] = r2
  metrics[pre .. "rate_2_threads"] = rt
  metrics[pre .. "efficiency_2_ranks"] = r2 / r1 / 2
  metrics[pre .. "ranks_over_threads"] = r2 / rt
  metrics[pre .. "bytes_per_step_2_ranks"] = b2
  metrics[pre .. "bytes_per_step_4_ranks"] = b4
  metrics[pre .. "messages_per_step_2_ranks"] = m2
  metrics[pre .. "messages_per_step_4_ranks"] = m4
  metrics[pre .. "step_2_ranks_s"] = t2
  metrics[pre .. "step_2_ranks_model_s"] = model2
  metrics[pre .. "comm_s_per_step"] = c2
  metrics[pre .. "eps"] = eps
  metrics[pre .. "speedup_512"] = proj_sm[#proj_sm]
  metrics[pre .. "speedup_512_cluster"] = proj_cl[#proj_cl]
  metrics[pre .. "projection_n"] = nproj
  metrics[pre .. "load_min"] = math.min(table.unpack(loads))
  metrics[pre .. "load_max"] = math.max(table.unpack(loads))
  if eng == "dem" then metrics[pre .. "contacts_per_particle"] = runs[1][1].z end
  if eng == "dsmc" then
    metrics[pre .. "particles_per_cell"] = runs[1][1].per_cell
    metrics[pre .. "collisions_per_particle_per_step"] = runs[1][1].collisions
  end
  curves[#curves + 1] = { eng = eng, ps = ps, proj_sm = proj_sm, proj_cl = proj_cl, n = nproj,
                          meas_p = { 1, 2 }, meas_s = { 1, r2 / r1 }, s512_cl = proj_cl[#proj_cl],
                          s512_sm = proj_sm[#proj_sm] }
end

local md = {
  string.format("ping-pong between two ranks (shared memory): alpha = %.3g us, beta = %.3g ns/B", alpha * 1e6, beta * 1e9),
  "",
  "| engine | N | 1 rank (p-steps/s) | 2 ranks | 1 rank, 2 threads | efficiency at 2 ranks | 2 ranks / 2 threads | bytes per step per rank (2 / 4 ranks) | messages per step per rank (2 / 4 ranks) | step at 2 ranks, measured (s) | t1/2 + transfers, model (s) | in communication, measured (s per step) | residual (s; eps) | 1-min load |",
  "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
}
for _, r in ipairs(rows) do md[#md + 1] = r end
md[#md + 1] = ""
for _, c in ipairs(curves) do
  md[#md + 1] = string.format("projection, %s, N = %d: speed-up at 512 ranks %.0f (this machine's alpha, beta), %.0f (cluster network, assumed)",
                              c.eng, c.n, c.s512_sm, c.s512_cl)
end
print(table.concat(md, "\n"))

local series = {}
local ideal_x, ideal_y = {}, {}
for e = 0, 9 do ideal_x[#ideal_x + 1] = 2 ^ e; ideal_y[#ideal_y + 1] = 2 ^ e end
series[#series + 1] = { x = ideal_x, y = ideal_y, label = "ideal", style = "line" }
for _, c in ipairs(curves) do
  series[#series + 1] = { x = c.meas_p, y = c.meas_s, label = c.eng .. ", measured (N = " .. (c.eng == "dem" and P.dem_n or P.dsmc_n) .. ")", style = "both" }
  series[#series + 1] = { x = c.ps, y = c.proj_cl, label = c.eng .. ", projection N = " .. c.n .. ", cluster network", style = "line" }
  series[#series + 1] = { x = c.ps, y = c.proj_sm, label = c.eng .. ", projection N = " .. c.n .. ", this machine's network", style = "line" }
end
render.plot{ file = dir .. "/scaling.png", title = "Speed-up over MPI ranks: measured (1-2 ranks) and projected (model)",
             xlabel = "ranks", ylabel = "speed-up", xlog = true, ylog = true, series = series }
print("wrote " .. dir .. "/scaling.png")
metrics.alpha_s = alpha
metrics.beta_s_per_byte = beta
grainlab.report{
  scenario = "bench_scaling",
  params = { engines = P.engines, reps = P.reps, dem_n = P.dem_n, dem_steps = P.dem_steps,
             dsmc_n = P.dsmc_n, dsmc_steps = P.dsmc_steps },
  metrics = bench.metrics(metrics),
}
