-- grainlab demo: a granular column collapsing on a rough floor (DEM, rendered headlessly).
--
-- A tall column of polydisperse disks is deposited in a narrow bay against the left wall, the
-- gate that holds it is removed, and the column slumps and spreads along the floor until it
-- comes to rest (the 2D column collapse of Lube et al. 2005 and Lajeunesse et al. 2005). The
-- script writes frames coloured by grain, a force-chain frame, a speed frame with a colour bar
-- and two plots into images/ (README.md shows them), frames for a movie into out/frames/ (800 px,
-- one per 5 ms from the gate's opening to rest; the report's metric movie_frames counts them),
-- the time series of the collapse as out/demo_series.csv (param `csv`), and one report. Only the
-- default run publishes into images/; a run with any other n, seed, aspect, young, mu, frame_dt
-- or width writes those images into out/ (grainlab.figures).
--
-- Choices and why:
--  * Grains: n disks (default 1500), radii uniform in [0.5, 1] mm, density 2650 kg/m^3,
--    Poisson 0.3, Coulomb friction mu = 0.5 (grain-grain, grain-floor and grain-wall); 2D disks
--    moving in the plane with sphere masses. There is no rolling resistance: disks roll freely,
--    so they spread about twice as far as sand in laboratory channels (runout of order 1.2 a W0
--    at aspect ratio a; here ~5 W0 at a = 2) and the deposit ends in a thin tail.
--  * Contact law: Hertz normal force (f = 4/3 E* sqrt(R) d^1.5), Brilliantov viscoelastic damping
--    with restitution 0.5 at 1 m/s (inelastic enough for the flow to stop), Cundall-Strack
--    tangential spring capped at mu f_n (kt = 2/7 of the normal tangent stiffness).
--  * Soft grains: Young's modulus 5 MPa (param `young`) instead of quartz's ~30 GPa. The Hertz
--    contact time goes like E^(-2/5), so the time step is ~30x longer than for quartz and the
--    whole demo runs in ~20 s. The price is the overlap, relative to the smaller radius of the
--    pair: ~3.5% at rest under the column (on the 0.5 mm floor disks; at 1 MPa it would be ~8%)
--    and up to ~9% in the hardest impacts of the collapse (overlap_max_over_r), small enough
--    not to change how the pile flows and stops.
--  * Time step: the engine's automatic dt (1/50 of the Hertz contact time of the lightest pair)
--    at impact speed sqrt(2 g H0) = the fastest free fall from the top of the column, fixed for
--    the collapse. The preparation (grains at rest, pushed by a drag) runs at the engine's
--    stability limit (1/10 of that contact time).
--  * Geometry: the floor is a row of fixed disks (radius 0.5 mm, tops at y = 0) so the flow has a
--    rough base, as in laboratory collapses; a plane wall below them keeps anything from falling
--    through. The column is W0 wide (left wall at x = 0, the gate at x = W0) and filled to
--    H0 ~ aspect * W0 (aspect 2: 41 x 86 mm for 1500 disks). An end wall at x = L = (1 + 3.5 a)
--    W0 keeps the odd far-rolling grain in the domain; the deposit's front stays well clear of
--    it (a check).
--  * Preparation: grainlab.pack.deposit (2D drop-and-roll into the bay), then 0.1 s with a
--    background drag of 20/s and 0.02 s without it at the full contact law.
--  * Collapse: the gate is removed at t = 0; the run goes on in slices of `frame_dt` until, after
--    at least 0.4 s, the fastest grain is below v_rest (5 mm/s), at most T_max (1.5 s).
--  * Measured (every slice): front = x + r of the 99th-percentile grain in x (a few grains that
--    roll ahead of the deposit do not count), runout = front - W0; height = the top (y + r) of
--    the highest grain over the old footprint x < W0; kinetic + rotational energy; total
--    energy (kinetic, rotational, elastic, potential).
--  * Checks: the total energy never rises (between slices) by more than 1e-3 of the energy the
--    collapse releases (measured: < 2e-7); the final kinetic energy is below 1e-4 of it (~1e-7);
--    every grain centre still in the domain; the front more than 20 mm from the end wall; the
--    runout larger than the initial width (measured ~5 W0 over seeds 1-3) and the final
--    height lower than the initial (~0.41 H0); the grains at rest (v_max < v_rest).
--
--   grainlab scripts/demo.lua [n=1500] [seed=1] [aspect=2] [young=5e6] [mu=0.5]
--       [frame_dt=0.005] [movie=true] [width=1000] [csv=out/demo_series.csv]
-- Movie (pad: yuv420p needs even sizes):
--   ffmpeg -framerate 25 -i out/frames/frame_%04d.png -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' -pix_fmt yuv420p demo.mp4

local function int(v) return type(v) == "number" and math.tointeger(v) or nil end
local n = int(params.n or 1500)
local seed = int(params.seed or 1)
local aspect = params.aspect or 2
local young = params.young or 5e6
local mu = params.mu or 0.5
local frame_dt = params.frame_dt or 0.005
local movie = params.movie ~= false
local width = int(params.width or 1000)
local csv = params.csv or "out/demo_series.csv"
assert(n and n >= 100, "n must be an integer >= 100")
assert(seed and seed >= 0, "seed must be a non-negative integer")
assert(width and width >= 100 and width <= 4000, "width must be an integer in [100, 4000]")
for name, v in pairs { aspect = aspect, young = young, frame_dt = frame_dt } do
  assert(type(v) == "number" and v > 0, name .. " must be a positive number")
end
assert(type(mu) == "number" and mu >= 0, "mu must be a non-negative number")

-- The column, its floor, walls, gate, packing and preparation: scripts/lib/dem_column.lua, shared
-- with scripts/column_two_scales.lua.
local dem_column = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/dem_column.lua")
local rmax, v_rest = dem_column.radius_max, dem_column.v_rest
local nu, rho, rmin, e_rest = dem_column.poisson, dem_column.density, dem_column.radius_min, dem_column.restitution

local t_start = grainlab.clock()
local col = dem_column.new{ n = n, seed = seed, aspect = aspect, young = young, mu = mu, frame_dt = frame_dt }
local s, W0, L, walls, gate_def = col.s, col.W0, col.L, col.walls, col.gate_def
local st0 = col:prepare()
local dt = col.dt
local overlap0 = col:overlap_max()
local prep_wall = grainlab.clock() - t_start
print(string.format("demo: %d disks, column %.1f x %.1f mm (aspect %.2f), floor %.0f mm, E = %g Pa, dt = %.3g s; prepared in %.1f s",
                    n, W0 * 1e3, st0.height * 1e3, st0.height / W0, L * 1e3, young, dt, prep_wall))

-- images/ only for the run README.md shows (the defaults); movie=false changes no image.
local figures = require("grainlab.figures")
local published = figures.published({ n = n, seed = seed, aspect = aspect, young = young, mu = mu,
                                      frame_dt = frame_dt, width = width },
                                    { n = 1500, seed = 1, aspect = 2, young = 5e6, mu = 0.5,
                                      frame_dt = 0.005, width = 1000 })
local fig_dir = figures.dir{ published = published }
os.execute("mkdir -p out/frames")
local function stamp(t) return string.format("t = %.3f s", t) end
local base = { width = width, walls = walls, show = { "walls", "box" } }
local function opts(extra)
  local o = {}
  for k, v in pairs(base) do o[k] = v end
  for k, v in pairs(extra) do o[k] = v end
  return o
end
local frame_no = 0
local function snap(t, title)
  render.png(s, fig_dir .. "/demo_frame_%02d.png", opts{ frame = frame_no, color = "grain", title = title,
             stamp = stamp(t) })
  frame_no = frame_no + 1
end
local movie_no = 0
local function movie_frame(t, with_gate)
  if not movie then return end
  local w = {}
  for k, v in ipairs(walls) do w[k] = v end
  if with_gate then w[#w + 1] = gate_def end
  render.png(s, "out/frames/frame_%04d.png", opts{ frame = movie_no, color = "grain", walls = w,
             title = "granular column collapse", stamp = stamp(t), width = 800 })
  movie_no = movie_no + 1
end

local gate_walls = { walls[1], walls[2], walls[3], gate_def }
render.png(s, fig_dir .. "/demo_frame_%02d.png", opts{ frame = 0, color = "grain", walls = gate_walls,
           title = string.format("%d disks deposited behind a gate", n), stamp = stamp(0) })
frame_no = 1
movie_frame(0, true)

-- Collapse.
local E0 = st0.total
col:release()
local series = grainlab.recorder{ file = csv, columns = { "t", "runout", "height", "kinetic", "total" },
                                  units = { t = "s", runout = "mm", height = "mm", kinetic = "J", total = "J" } }
series:add{ t = 0, runout = 0, height = st0.height * 1e3, kinetic = st0.ke, total = E0 }
local snaps = { { 0.05, "the gate is gone: the column fails" }, { 0.1, "collapsing" }, { 0.2, "spreading" } }
local speed_at, chains_at = 0.12, 0.1
local E_min, rise_max, overlap_run = E0, 0, overlap0
local t, st = col:collapse(function(t, st)
  series:add{ t = t, runout = (st.front - W0) * 1e3, height = st.height * 1e3, kinetic = st.ke, total = st.total }
  overlap_run = math.max(overlap_run, col:overlap_max())
  rise_max = math.max(rise_max, st.total - E_min)
  E_min = math.min(E_min, st.total)
  movie_frame(t)
  for _, sn in ipairs(snaps) do
    if math.abs(t - sn[1]) < frame_dt / 2 then snap(t, sn[2]) end
  end
  if math.abs(t - chains_at) < frame_dt / 2 then
    render.png(s, fig_dir .. "/demo_force_chains.png", opts{ color = "grain", show = { "force_chains", "walls", "box" },
               title = "force chains: the static core carries the weight, the flowing skin does not",
               stamp = stamp(t) })
  end
  if math.abs(t - speed_at) < frame_dt / 2 then
    render.png(s, fig_dir .. "/demo_speed.png", opts{ color = "speed", colormap = "viridis", range = { 0, 1 },
               show = { "walls", "box", "colorbar" }, label = "speed (m/s)",
               title = "grain speed", stamp = stamp(t) })
  end
end)
local steps, run_wall = col.steps, col.run_wall
local released = E0 - st.total
snap(t, "at rest")

series:write()
series:plot{ file = fig_dir .. "/demo_runout.png", width = 1000, height = 560,
             title = string.format("column collapse: %d disks, aspect %.1f, mu %.2f", n, aspect, mu),
             xlabel = "time after the gate opens (s)", ylabel = "mm", y = { "runout", "height" },
             labels = { "runout: front - W0", "height over the column's footprint" } }
series:plot{ file = fig_dir .. "/demo_energy.png", width = 1000, height = 560, ylog = true, -- 0 J: a gap
             title = "kinetic energy (translation + rotation)",
             xlabel = "time after the gate opens (s)", ylabel = "J", y = "kinetic", labels = { "kinetic" } }

local wall_s = grainlab.clock() - t_start
local runout = st.front - W0
print(string.format("demo: at rest after %.3f s: runout %.1f mm (%.2f W0), height %.1f mm (%.2f H0), %d steps, %.3g particle-steps/s",
                    t, runout * 1e3, runout / W0, st.height * 1e3, st.height / st0.height, steps,
                    n * steps / run_wall))
if movie then print(string.format("demo: %d movie frames in out/frames/", movie_no)) end
print("demo: time series in " .. csv)

grainlab.report{
  scenario = "demo_column_collapse",
  params = { n = n, seed = seed, aspect = aspect, young_pa = young, poisson = nu, friction = mu,
             density_kg_per_m3 = rho, radius_min_m = rmin, radius_max_m = rmax, restitution = e_rest,
             frame_dt_s = frame_dt, movie = movie },
  metrics = {
    column_width_m = W0, column_height_m = st0.height, floor_length_m = L,
    runout_m = runout, runout_over_width = runout / W0, front_m = st.front, farthest_grain_m = st.xmax,
    final_height_m = st.height, final_height_over_initial = st.height / st0.height,
    collapse_time_s = t, dt_s = dt, steps = steps, energy_released_j = released,
    overlap_max_over_r_initial = overlap0, overlap_max_over_r = overlap_run,
    particle_steps_per_s = n * steps / run_wall, collapse_wall_s = run_wall, wall_s = wall_s,
    movie_frames = movie_no,
  },
  checks = {
    { name = "energy_rise_over_released", value = rise_max / released, limit = 1e-3 },
    { name = "final_kinetic_over_released", value = st.ke / released, limit = 1e-4 },
    { name = "grains_in_domain", value = st.inside, limit = n, op = ">=" },
    { name = "front_clear_of_end_wall_m", value = st.front, limit = L - 20 * rmax, op = "<" },
    { name = "runout_over_initial_width", value = runout / W0, limit = 1, op = ">" },
    { name = "final_over_initial_height", value = st.height / st0.height, limit = 1, op = "<" },
    { name = "at_rest_v_max_m_per_s", value = st.vmax, limit = v_rest, op = "<" },
  },
}
