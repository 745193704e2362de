-- grainlab DEM: the angle of repose of piles of clumps (dimers, trimers) against disks (2D).
--
-- The pile of scripts/repose.lua (scripts/lib/heap_box.lua: grains settle in a box, its gate is
-- removed, the pile left in the box is fitted by a line; the procedure and its reasons are in
-- repose.lua's header), filled with three shapes in turn, several packings (seeds) each:
--   disk    repose.lua's disks, radii uniform in [0.5, 1] mm (grainlab.pack.deposit);
--   dimer   rigid clumps (docs/dem.md "Clumps") of two equal disks of radius r, centres r apart
--           (length 3r over width 2r: aspect ratio 1.5);
--   trimer  three equal disks of radius r at the corners of a triangle of side r.
-- The clumps' member radius r takes six values evenly over [0.5, 1] mm (a template each, drawn at
-- random), so members are the size of the disks; a dimer holds 1.61 and a trimer 1.86 disks'
-- area. Equal pile size rather than equal number of grains: every shape fills the same box
-- (width W from N disks) with the same solid area, N disks' worth of clumps (N/1.61 dimers,
-- N/1.86 trimers), so that the pile is the same number of member diameters tall and wide and
-- the surface fit sees the same bins; only the grains' shape changes. The clumps are poured by
-- random sequential addition (grainlab.pack.clumps) into a region 2.7 h0 tall, fall under a drag
-- of 20/s onto the rough floor and settle as the disks do.
--
-- Law: repose.lua's (Hertz + Brilliantov damping, e = 0.5 at 1 m/s, Cundall-Strack spring
-- capped at mu f_n), mu = 0.5 grain-grain and grain-wall, no rolling resistance: a disk rolls
-- freely, a clump cannot roll without lifting its centre, so the shape alone supplies the
-- resistance to rolling. The box is taller than repose.lua's (aspect 0.7 against 0.5): a line
-- from the foot of the gate to the top of the left wall then makes atan(0.7) = 35 deg; at 0.5
-- (26.6 deg) a dimer pile keeps its whole initial surface and the fit returns the box's own
-- diagonal. The disks' angle does not depend on the box's aspect within the scatter.
--
-- What the literature says, and what is compared. Non-round grains pile steeper than round
-- ones: elongated and angular grains interlock and cannot roll (Pohlman et al. 2006, PRE 73,
-- 031304; Zhou et al. 2002, Powder Technol. 125, 45: the angle rises with rolling friction,
-- which a clump's shape stands in for; Matuttis, Luding & Herrmann 2000, Powder Technol. 109,
-- 278: heaps of 2D polygons steeper than of round grains), and simulations of multi-sphere and
-- disk clumps find piles several degrees steeper than those of their round members, rising with
-- the aspect ratio and the number of members. 2D clumps in a box of ~45 diameters are no
-- particular material: what is compared is the sign and rough size (several degrees).
--
-- Output: one grainlab.report: theta_r per shape (mean and sd over the packings), and checks:
-- the disks' theta_r within twice the standard error of repose.lua's measured value (its
-- parameters: n = 2000, mu = 0.5, E = 1e6); dimers and trimers steeper than disks by more than
-- `steeper_se` combined standard errors (sqrt(sd1^2/n1 + sd2^2/n2)); per shape: theta_r in
-- (0, 60) deg, the fit rms below `rms_limit` mean diameters, the pile at rest, the basin heap below
-- the box floor, the largest overlap in the pile below 10 % of the smaller radius. A CSV and a
-- PNG of theta_r by shape with +- one sd bars and a picture of one dimer pile coloured by clump
-- (images/repose_clumps.png, images/repose_clumps_pile.png for the default run, out/ else).
--
-- Against it: the clumps stand 7.6 (dimer) and 6.6 (trimer)
-- deg steeper than the disks: the sign and the size of "several degrees". Olson et al. 2002
-- (Europhys. Lett. 57, 904: 2D monomer, dimer and trimer beads, experiment and simulation) find
-- dimers steepest and trimers below them; here the trimers' mean is 0.9 deg below the dimers',
-- within the scatter (the dimers' packings spread over 23.9-29.1 deg). Their monomers are
-- monodisperse and crystallise; the disks here are polydisperse and do not.
--
-- Measured (default run: n = 2000 disks' area, mu = 0.5, aspect 0.7, seeds 1-4):
--     shape    grains   theta_r (seeds 1 / 2 / 3 / 4)       mean +- sd     left in the box
--     disk      2000    18.35 / 19.02 / 18.70 / 17.87       18.49 +- 0.50       27 %
--     dimer     1244    23.86 / 25.53 / 29.11 / 25.71       26.05 +- 2.20       43 %
--     trimer     976    25.18 / 23.69 / 26.89 / 24.66       25.10 +- 1.34       39 %
--   Disks within 0.64 deg of repose.lua's 19.13 (limit: twice the standard error, 1.59); dimers
--   steeper than disks by 6.7 combined standard errors, trimers by 9.3. The largest overlap in
--   the pile: 7.4 % of the smaller radius (disks), 7.8 % (dimers), 9.0 % (trimers; a clump's
--   weight rests on fewer contacts). About 6-10 min on one core (12 runs, 18-48 s each).
--
--   grainlab scripts/repose_clumps.lua [n=2000] [mu=0.5] [shapes=disk,dimer,trimer] [seed=1]
--       [seeds=4] [young=1e6] [aspect=0.7] [v_rest=5e-3] [T_max=4] [rms_limit=1]
--       [steeper_se=2] [csv=out/repose_clumps.csv] [png=FILE] [pile_png=FILE] [verbose=false]

local function int(v) return type(v) == "number" and math.tointeger(v) or nil end
local n = int(params.n or 2000)
local mu = params.mu or 0.5
local seed = int(params.seed or 1)
local seeds = int(params.seeds or 4)
local young = params.young or 1e6
local aspect = params.aspect or 0.7
local v_rest = params.v_rest or 5e-3
local T_max = params.T_max or 4
local rms_limit = params.rms_limit or 1
local steeper_se = params.steeper_se or 2
local csv = params.csv or "out/repose_clumps.csv"
local verbose = params.verbose == true
assert(n and n >= 50, "n must be an integer >= 50")
assert(type(mu) == "number" and mu >= 0, "mu must be a non-negative number")
assert(seed and seed >= 0, "seed must be a non-negative integer")
assert(seeds and seeds >= 2, "seeds must be an integer >= 2 (the scatter between packings)")
for name, v in pairs { young = young, aspect = aspect, v_rest = v_rest, T_max = T_max,
                       rms_limit = rms_limit, steeper_se = steeper_se } do
  assert(type(v) == "number" and v > 0, name .. " must be a positive number")
end
assert(type(csv) == "string", "csv must be a path")
local shapes = {}
for v in tostring(params.shapes or "disk,dimer,trimer"):gmatch("[^,]+") do
  assert(v == "disk" or v == "dimer" or v == "trimer", "shapes must list disk, dimer, trimer")
  shapes[#shapes + 1] = v
end
local heap_box = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/heap_box.lua")
local figures = require("grainlab.figures")
local published = figures.published({ n = n, mu = mu, seed = seed, seeds = seeds, young = young,
                                      aspect = aspect, v_rest = v_rest, T_max = T_max,
                                      shapes = table.concat(shapes, ",") },
                                    { n = 2000, mu = 0.5, seed = 1, seeds = 4, young = 1e6,
                                      aspect = 0.7, v_rest = 5e-3, T_max = 4,
                                      shapes = "disk,dimer,trimer" })
local png = params.png or figures.path("repose_clumps.png", { published = published })
local pile_png = params.pile_png
                 or figures.path("repose_clumps_pile.png", { published = published })

-- repose.lua's measured angle at mu = 0.5 (its header: seeds 1-4, n = 2000, E = 1e6).
local ref = { theta = 19.13, sd = 1.51, packings = 4 }
local same_as_repose = n == 2000 and mu == 0.5 and young == 1e6 and v_rest == 5e-3 and T_max == 4

-- The largest overlap of the pile's contacts (a grain in the box) over the smaller radius.
local function worst_overlap(b)
  local P, nf = b.s:particles(), b.nf
  local function in_pile(i) return i > nf and P.x[i] < b.W and P.y[i] > 0 end
  local c, worst = b.s:measure("contacts"), 0
  for q = 1, #c.i do
    local i, j = c.i[q], c.j[q]
    if in_pile(i) or (j > 0 and in_pile(j)) then
      local rr = j > 0 and math.min(P.radius[i], P.radius[j]) or P.radius[i]
      worst = math.max(worst, c.overlap[q] / rr)
    end
  end
  return worst
end

local shown = false
local function run_one(k, sd)
  local c0 = grainlab.clock()
  local b = heap_box.new{ n = n, mu = mu, seed = sd, young = young, aspect = aspect,
                          v_rest = v_rest, shape = shapes[k] }
  local r = b:collapse(T_max)
  r.overlap = worst_overlap(b)
  r.grains, r.members = b.grains, b.members
  r.fraction_left = r.left / b.members
  r.wall_s = grainlab.clock() - c0
  if shapes[k] == "dimer" and not shown then
    shown = true
    render.png(b.s, pile_png, { color = "clump", width = 1160, height = 1000,
                                 title = string.format("a dimer pile at rest (seed %d), one "
                                                       .. "colour per clump", sd) })
  end
  if verbose then
    io.stderr:write(string.format("%s seed %d: theta %.2f deg, rms %.2f d, %.3f left, at rest "
                                  .. "after %.2f s, max overlap %.3f r, %.1f s\n", shapes[k], sd,
                                  r.theta, r.rms, r.fraction_left, r.t, r.overlap, r.wall_s))
  end
  return r
end

os.execute("mkdir -p out")
local keys = {}
for k = 1, #shapes do keys[k] = k end
print(string.format("repose_clumps: %d disks' area, mu = %g, aspect %g, %d packings per shape",
                    n, mu, aspect, seeds))
local results = heap_box.sweep{ label = "repose_clumps", mus = keys, seed = seed, seeds = seeds,
                                run = run_one, mean = { "theta", "fraction_left", "points" },
                                max = { "rms", "vmax", "t", "basin_top", "overlap", "grains",
                                        "members" },
                                sum = { "wall_s" } }

local metrics, checks, by = {}, {}, {}
local rows = { "shape,grains,theta_r_deg,theta_r_sd_deg,packings,fraction_left,fit_points" }
print(string.format("%7s %6s %9s %6s %7s %7s %7s %9s %7s", "shape", "grains", "theta_r", "sd",
                    "left", "points", "rms/d", "overlap/r", "wall s"))
local rf = heap_box.new{ n = n, aspect = aspect, geometry_only = true }.rf
for _, r in ipairs(results) do
  local id = shapes[r.mu]
  r.id, by[id] = id, r
  print(string.format("%7s %6d %9.2f %6.2f %7.3f %7.1f %7.3f %9.3f %7.1f", id, r.grains, r.theta,
                      r.theta_sd, r.fraction_left, r.points, r.rms, r.overlap, r.wall_s))
  rows[#rows + 1] = string.format("%s,%d,%.4f,%.4f,%d,%.4f,%.1f", id, r.grains, r.theta,
                                  r.theta_sd, seeds, r.fraction_left, r.points)
  metrics["theta_r_deg_" .. id] = r.theta
  metrics["theta_r_sd_deg_" .. id] = r.theta_sd
  metrics["grains_" .. id] = r.grains
  metrics["fraction_left_" .. id] = r.fraction_left
  metrics["fit_rms_over_d_" .. id] = r.rms
  metrics["max_overlap_over_r_" .. id] = r.overlap
  metrics["wall_s_" .. id] = r.wall_s
  checks[#checks + 1] = { name = "theta_r_in_0_60_deg_" .. id, pass = r.theta > 0 and r.theta < 60 }
  heap_box.pile_checks(checks, id, r, rms_limit, v_rest, rf)
  checks[#checks + 1] = { name = "max_overlap_over_r_" .. id, value = r.overlap, limit = 0.1 }
end
local disk = by.disk
if disk and same_as_repose then
  local se = math.sqrt(disk.theta_sd ^ 2 / seeds + ref.sd ^ 2 / ref.packings)
  metrics.theta_r_repose_lua_deg = ref.theta
  checks[#checks + 1] = { name = "disk_theta_r_minus_repose_lua_deg",
                          value = math.abs(disk.theta - ref.theta), limit = 2 * se }
end
for _, id in ipairs { "dimer", "trimer" } do
  local r = by[id]
  if disk and r then
    local se = math.sqrt((r.theta_sd ^ 2 + disk.theta_sd ^ 2) / seeds)
    metrics["steeper_than_disk_deg_" .. id] = r.theta - disk.theta
    metrics["steeper_than_disk_se_" .. id] = (r.theta - disk.theta) / se
    checks[#checks + 1] = { name = id .. "_steeper_than_disk_over_se",
                            value = (r.theta - disk.theta) / se, limit = steeper_se, op = ">" }
  end
end

local dir = csv:match("^(.*)/[^/]*$")
if dir and dir ~= "" and dir ~= "out" then
  os.execute("mkdir -p '" .. dir:gsub("'", "'\\''") .. "'")
end
assert(grainlab.write_file(csv, table.concat(rows, "\n") .. "\n"))
print("wrote " .. csv)
do -- theta_r by shape (1 disk, 2 dimer, 3 trimer members): means, +- one sd, the packings
  local mx, my, ex, ey, px, py = {}, {}, {}, {}, {}, {}
  local members = { disk = 1, dimer = 2, trimer = 3 }
  for _, r in ipairs(results) do
    local x = members[r.id]
    mx[#mx + 1], my[#my + 1] = x, r.theta
    local lo, hi, gap = r.theta - r.theta_sd, r.theta + r.theta_sd, { 0 / 0, 0 / 0 }
    for _, p in ipairs { { x, lo }, { x, hi }, gap, { x - 0.05, lo }, { x + 0.05, lo }, gap,
                         { x - 0.05, hi }, { x + 0.05, hi }, gap } do
      ex[#ex + 1], ey[#ey + 1] = p[1], p[2]
    end
    for _, q in ipairs(r.runs) do px[#px + 1], py[#py + 1] = x + 0.12, q.theta end
  end
  render.plot{ file = png, width = 900, height = 560,
               title = string.format("angle of repose by shape, mu = %g (mean +- sd of %d "
                                     .. "packings)", mu, seeds),
               xlabel = "members per grain (1 disk, 2 dimer, 3 trimer)",
               ylabel = "theta_r (degrees)",
               series = { { x = mx, y = my, label = "theta_r mean", style = "points" },
                          { x = ex, y = ey, label = "+- one sd", style = "line" },
                          { x = px, y = py, label = "each packing", style = "points" } } }
  print("wrote " .. png)
end

grainlab.report{
  scenario = "repose_clumps",
  params = { n = n, mu = mu, seed = seed, seeds = seeds, shapes = shapes, young_pa = young,
             aspect = aspect, v_rest_m_per_s = v_rest, t_max_s = T_max, rms_limit = rms_limit,
             steeper_se = steeper_se, csv = csv },
  metrics = metrics,
  checks = checks,
}
