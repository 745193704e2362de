-- What every benchmark's report carries beside its own figures, and instruction counts by callgrind.
--   local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
--   ...
--   grainlab.report{ scenario = "bench_x", params = {…}, metrics = bench.metrics(metrics), … }
-- bench.metrics adds metrics.command (how the benchmark was run) and metrics.machine: the CPU
-- model, cores, memory and the kernels' instruction set; the 1-minute load average when this file
-- was loaded and when the report is made; the share of the machine's CPU time the hypervisor gave
-- to other guests in between (steal); and the run the report belongs to (GRAINLAB_BENCH_RUN,
-- GRAINLAB_BENCH_MODE and GRAINLAB_BENCH_COMMIT, set by run_all.sh), so that table.lua can refuse
-- a set of reports that mixes runs.
-- bench.instructions(fn) runs fn and returns the instructions it executed when the process runs
-- under `valgrind --tool=callgrind --instr-atstart=no` (nil otherwise).
local M = {}

local function read(path)
  local f = io.open(path, "r")
  if not f then return nil end
  local text = f:read("a")
  f:close()
  return text
end

local function load1()
  return tonumber((read("/proc/loadavg") or ""):match("^(%S+)")) or -1
end

-- total and steal jiffies of all processors (/proc/stat's first line)
local function cpustat()
  local line = (read("/proc/stat") or ""):match("^cpu%s+([^\n]*)") or ""
  local total, k, steal = 0, 0, 0
  for v in line:gmatch("%d+") do
    k = k + 1
    if k <= 8 then total = total + tonumber(v) end
    if k == 8 then steal = tonumber(v) end
  end
  return total, steal
end

local function command(cmd)
  local f = io.popen(cmd .. " 2>/dev/null")
  if not f then return "" end
  local out = f:read("a") or ""
  f:close()
  return out
end

-- A shell driver that reports through shell_report.lua exports GRAINLAB_BENCH_START="load total
-- steal" (its /proc/loadavg and /proc/stat at its start), so that its report covers its whole run.
local start_load = load1()
local start_total, start_steal = cpustat()
do
  local l, t, s = (os.getenv("GRAINLAB_BENCH_START") or ""):match("^(%S+) (%d+) (%d+)$")
  if l then start_load, start_total, start_steal = tonumber(l), tonumber(t), tonumber(s) end
end

-- The facts are read once; the load and steal are taken at each call.
local facts
function M.machine()
  if not facts then
    local cpuinfo = read("/proc/cpuinfo") or ""
    local version = command("'" .. (arg[-1] or "grainlab"):gsub("'", "'\\''") .. "' --version")
    facts = {
      cpu_model = cpuinfo:match("model name%s*:%s*([^\n]+)") or "unknown",
      cores = tonumber(command("nproc"):match("%d+")) or select(2, cpuinfo:gsub("\nprocessor%s*:", "")),
      memory_gib = (tonumber((read("/proc/meminfo") or ""):match("MemTotal:%s*(%d+)")) or 0) / 1048576,
      kernels = version:match("kernels: ([^)]+)") or "unknown",
      version = grainlab.version,
      run = os.getenv("GRAINLAB_BENCH_RUN") or "",
      mode = os.getenv("GRAINLAB_BENCH_MODE") or "",
      commit = os.getenv("GRAINLAB_BENCH_COMMIT") or "",
    }
  end
  local total, steal = cpustat()
  local t = {}
  for k, v in pairs(facts) do t[k] = v end
  t.load_start = start_load
  t.load_end = load1()
  t.steal_share = total > start_total and (steal - start_steal) / (total - start_total) or 0
  return t
end

-- The command that ran the benchmark: a shell driver's own (GRAINLAB_BENCH_COMMAND, which it
-- exports), or this script's with its arguments (under valgrind when callgrind= is given).
local function command_line()
  local own = os.getenv("GRAINLAB_BENCH_COMMAND")
  if own and own ~= "" then return own end
  local words = { "grainlab", arg[0] }
  for i = 1, #arg do words[#words + 1] = arg[i] end
  local cmd = table.concat(words, " ")
  if params.callgrind then cmd = "valgrind --tool=callgrind --instr-atstart=no " .. cmd end
  return cmd
end

-- metrics with the machine's facts and the command added (the table is changed and returned)
function M.metrics(metrics)
  metrics.machine = M.machine()
  metrics.command = command_line()
  return metrics
end

M.load1 = load1

-- Instructions executed by fn(): under callgrind with --instr-atstart=no, collection is switched
-- on for fn alone and dumped, and the dump's total is read back. out is the run's
-- --callgrind-out-file (its %p the process id; default callgrind.out.%p, in the working
-- directory). Returns nil when not under callgrind (no dump appears).
function M.instructions(fn, out)
  local pid = command("echo $PPID"):match("%d+")
  local ctl = "callgrind_control %s " .. pid .. " >/dev/null 2>&1"
  os.execute(ctl:format("-z") .. "; " .. ctl:format("-i on"))
  fn()
  os.execute(ctl:format("-i off") .. "; " .. ctl:format("-d"))
  local base = (type(out) == "string" and out or "callgrind.out.%p"):gsub("%%p", pid)
  -- the newest dump: <base>.<n>
  local name = command("ls -t '" .. base:gsub("'", "'\\''") .. "'.*"):match("[^\n]+")
  local text = name and read(name)
  return text and tonumber(text:match("\ntotals:%s*(%d+)"))
end

return M
