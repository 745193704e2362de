-- grainlab MPM: speed against accuracy for a granular column collapse as a continuum.
--
-- The column of scripts/column_collapse.lua (glass beads, L0 = 5 cm, half column against a slip
-- wall, friction floor 0.6, B-splines; scripts/lib/mpm_column.lua) at aspect ratio `a` (default
-- 2, the experiments' break), for both continua (drucker_prager and mu_i). One knob at a time is
-- swept from the base of 10 cells across L0 and 2 x 2 points per cell:
--   cells across L0: 5, 10, 20, 40 (`cells=` a comma list; the last is the reference);
--   points per cell (per axis): 1, 2, 3, 4 at 10 cells.
-- Each run reports the runout (L_inf - L0) / L0 and the final height over L0, their relative
-- errors against the finest grid's (40 cells, 2 x 2 points), its points, steps and CPU time
-- (os.clock). The runout is read when the front stops (mpm_column.lua's c:collapse).
-- Output: a table, out/study_column.csv (csv=), images/study_column.png (png=): |runout error|
-- against CPU time, one line per knob and model (images/ from the default run only, else out/).
-- Checks: the error falls from the coarsest grid to the next finer but one (5 to 20 cells), for
-- each model; the reference run ends with its front at rest (how each run ended is reported: on
-- the coarsest grid the front may still creep at 8 t_c).
--   grainlab scripts/study_column.lua [a=2] [cells=5,10,20,40] [ppcs=1,2,3,4] [csv=...] [png=...]
local a = tonumber(params.a or 2)
local cells_s = tostring(params.cells or "5,10,20,40")
local ppcs_s = tostring(params.ppcs or "1,2,3,4")
local csv_path = params.csv or "out/study_column.csv"
local figures = require("grainlab.figures")
local png = params.png or figures.path("study_column.png", {
  published = figures.published({ a = a, cells = cells_s, ppcs = ppcs_s },
                                { a = 2, cells = "5,10,20,40", ppcs = "1,2,3,4" }) })
local function list(s)
  local t = {}
  for v in s:gmatch("[^,]+") do t[#t + 1] = assert(math.tointeger(tonumber(v)), "cells and ppcs: integers") end
  return t
end
local cell_list, ppc_list = list(cells_s), list(ppcs_s)
table.sort(cell_list)

local mpm_column = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/mpm_column.lua")
local L0 = 0.05
local beads = { density = 0.6 * 2450, grain_density = 2450, grain_diameter = 5e-4, i0 = 0.279,
                mu_s = math.tan(math.rad(20.9)), mu_2 = math.tan(math.rad(32.76)), shear = 1e6, bulk = 2e6 }

local function run(model, cells, ppc)
  local c = mpm_column.new{ material = mpm_column.material(model, beads), L0 = L0, H0 = a * L0, cells = cells,
                            ppc = ppc, shape = "bspline", floor_mu = 0.6, length = L0 * (2 + 3.2 * a ^ 0.85) }
  local r = c:collapse{ t_max = 8, slice = 0.1, rest = 1e-3, stall = 0.005 }
  return { runout = (r.state.front - L0) / L0, height = r.state.height / L0, cpu = r.cpu, points = r.points,
           steps = r.steps, reason = r.reason }
end

local lines = { "model,knob,cells,points_per_cell,points,steps,cpu_s,runout,height_over_l0,err_runout,err_height,end" }
local rows, series, metrics, checks = {}, {}, {}, {}
local base_cells = 10
for _, model in ipairs({ "drucker_prager", "mu_i" }) do
  local key = model == "drucker_prager" and "dp" or "mu_i"
  local done = {}
  local function get(cells, ppc)
    local k = cells .. "x" .. ppc
    if not done[k] then done[k] = run(model, cells, ppc) end
    return done[k]
  end
  local ref = get(cell_list[#cell_list], 2)
  checks[#checks + 1] = { name = "reference_front_at_rest_" .. key, pass = ref.reason ~= "cap" }
  local sweeps = { { knob = "cells", values = cell_list, at = function(v) return v, 2 end },
                   { knob = "points_per_cell", values = ppc_list, at = function(v) return base_cells, v end } }
  for _, sw in ipairs(sweeps) do
    local xs, ys = {}, {}
    for _, v in ipairs(sw.values) do
      local cells, ppc = sw.at(v)
      local r = get(cells, ppc)
      local er, eh = r.runout / ref.runout - 1, r.height / ref.height - 1
      lines[#lines + 1] = string.format("%s,%s,%d,%d,%d,%d,%.4f,%.6f,%.6f,%.6f,%.6f,%s", model, sw.knob, cells, ppc,
                                        r.points, r.steps, r.cpu, r.runout, r.height, er, eh, r.reason)
      rows[#rows + 1] = string.format("%-14s %-15s %2d  %6d points %6d steps %8.2f s   runout %6.3f (%+6.1f%%)   H/L0 %5.3f (%+6.1f%%)  %s",
                                      model, sw.knob, v, r.points, r.steps, r.cpu, r.runout, 100 * er, r.height,
                                      100 * eh, r.reason)
      metrics[string.format("runout_%s_%s_%d", key, sw.knob, v)] = r.runout
      metrics[string.format("err_runout_%s_%s_%d", key, sw.knob, v)] = er
      metrics[string.format("err_height_%s_%s_%d", key, sw.knob, v)] = eh
      metrics[string.format("cpu_s_%s_%s_%d", key, sw.knob, v)] = r.cpu
      metrics[string.format("points_%s_%s_%d", key, sw.knob, v)] = r.points
      metrics[string.format("end_%s_%s_%d", key, sw.knob, v)] = r.reason
      if not (cells == cell_list[#cell_list] and ppc == 2) then -- the reference: no error to plot
        xs[#xs + 1], ys[#ys + 1] = math.max(r.cpu, 1e-3), math.max(math.abs(er), 1e-4)
      end
    end
    series[#series + 1] = { x = xs, y = ys, style = "both",
                            label = string.format("%s, %s (%s)", key, sw.knob, table.concat(sw.values, ", ")) }
  end
  if #cell_list >= 3 then
    local e1 = math.abs(get(cell_list[1], 2).runout / ref.runout - 1)
    local e3 = math.abs(get(cell_list[#cell_list - 1], 2).runout / ref.runout - 1)
    checks[#checks + 1] = { name = "refinement_converges_" .. key, value = e3, limit = e1, op = "<" }
  end
end

print(table.concat(rows, "\n"))
if csv_path:find("/") then os.execute("mkdir -p '" .. csv_path:match("^(.*)/[^/]*$") .. "'") end
assert(grainlab.write_file(csv_path, table.concat(lines, "\n") .. "\n"))
render.plot{ file = png, width = 900, height = 600, xlog = true, ylog = true,
             title = string.format("Column collapse (a = %g): |runout error| against CPU time, one knob at a time", a),
             xlabel = "CPU time per run (s)", ylabel = "|runout / runout(finest) - 1|", series = series }
grainlab.report{
  scenario = "study_column",
  params = { a = a, cells = cells_s, ppcs = ppcs_s, base_cells = base_cells, base_points_per_cell = 2, csv = csv_path,
             png = png },
  metrics = metrics,
  checks = checks,
}
