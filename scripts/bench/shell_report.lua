-- The report of a shell benchmark (vs_lammps.sh, march_bits.sh, before_after.sh): reads the
-- figures the script collected, one a line,
--   param NAME VALUE      metric NAME VALUE      check NAME true|false
-- (a VALUE that reads as a number is one; the rest of the line is the value), and reports them
-- with the machine's facts (common.lua; the script exports GRAINLAB_BENCH_START at its start so
-- that the load and steal are those of its whole run).
--   grainlab --report FILE.json scripts/bench/shell_report.lua scenario=NAME figures=PATH
local bench = dofile((arg[0]:match("^(.*)/") or ".") .. "/common.lua")
local scenario, path = params.scenario, params.figures
if type(scenario) ~= "string" or type(path) ~= "string" then
  error("shell_report.lua: scenario=NAME figures=PATH expected", 0)
end
local f = assert(io.open(path, "r"))
local p, metrics, checks = {}, {}, {}
for line in f:lines() do
  local kind, name, value = line:match("^(%a+)%s+([%w_]+)%s+(.-)%s*$")
  if kind == "param" or kind == "metric" then
    local t = kind == "param" and p or metrics
    t[name] = tonumber(value) or value
  elseif kind == "check" then
    checks[#checks + 1] = { name = name, pass = value == "true" }
  elseif line:match("%S") then
    error(string.format("shell_report.lua: %s: not 'param|metric|check NAME VALUE': %s", path, line), 0)
  end
end
f:close()
grainlab.report{ scenario = scenario, params = p, metrics = bench.metrics(metrics), checks = checks }
