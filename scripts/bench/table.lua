-- Renders docs/performance.md's figures, and README.md's headline rows of them, from the reports of
-- one benchmark run (a directory of report JSON, as run_all.sh writes it).
--   grainlab scripts/bench/table.lua dir=DIR [page=docs/performance.md] [readme=README.md]
--   grainlab scripts/bench/table.lua dir=DIR print=true      (print the generated text only)
-- The page's generated part lies between the lines "<!-- begin: bench table -->" and
-- "<!-- end: bench table -->", README's between "<!-- begin: bench headline -->" and
-- "<!-- end: bench headline -->"; the text around them is left as it is.
-- The set is refused, and nothing is written, when a benchmark's report is missing, a report is
-- not one of the set or appears twice, the reports come from different runs (run_all.sh gives
-- every report of a run the same id: GRAINLAB_BENCH_RUN), or a report's checks failed.

-- ---- reading reports -------------------------------------------------------------------------
-- A JSON reader for the reports grainlab.report writes (objects, arrays, strings, numbers,
-- booleans, null).
local function decode(text, name)
  local pos = 1
  local function fail(what)
    error(string.format("table.lua: %s: %s at byte %d", name, what, pos), 0)
  end
  local function ws() pos = text:find("[^ \t\r\n]", pos) or #text + 1 end
  local value
  local escapes = { b = "\b", f = "\f", n = "\n", r = "\r", t = "\t", ['"'] = '"', ["\\"] = "\\", ["/"] = "/" }
  local function str()
    local out = {}
    pos = pos + 1
    while true do
      local c = text:sub(pos, pos)
      if c == "" then fail("unterminated string") end
      if c == '"' then pos = pos + 1; return table.concat(out) end
      if c == "\\" then
        local e = text:sub(pos + 1, pos + 1)
        if e == "u" then
          local hex = text:sub(pos + 2, pos + 5)
          if not hex:match("^%x%x%x%x$") then fail("bad \\u escape") end
          out[#out + 1] = utf8.char(tonumber(hex, 16))
          pos = pos + 6
        elseif escapes[e] then
          out[#out + 1] = escapes[e]
          pos = pos + 2
        else
          fail("bad escape")
        end
      else
        local s, e = text:find('^[^"\\]+', pos)
        out[#out + 1] = text:sub(s, e)
        pos = e + 1
      end
    end
  end
  function value()
    ws()
    local c = text:sub(pos, pos)
    if c == "{" then
      local t = {}
      pos = pos + 1
      ws()
      if text:sub(pos, pos) == "}" then pos = pos + 1; return t end
      while true do
        ws()
        if text:sub(pos, pos) ~= '"' then fail("object key expected") end
        local k = str()
        ws()
        if text:sub(pos, pos) ~= ":" then fail("':' expected") end
        pos = pos + 1
        t[k] = value()
        ws()
        local d = text:sub(pos, pos)
        pos = pos + 1
        if d == "}" then return t end
        if d ~= "," then fail("',' or '}' expected") end
      end
    elseif c == "[" then
      local t = {}
      pos = pos + 1
      ws()
      if text:sub(pos, pos) == "]" then pos = pos + 1; return t end
      while true do
        t[#t + 1] = value()
        ws()
        local d = text:sub(pos, pos)
        pos = pos + 1
        if d == "]" then return t end
        if d ~= "," then fail("',' or ']' expected") end
      end
    elseif c == '"' then
      return str()
    elseif text:find("^true", pos) then pos = pos + 4; return true
    elseif text:find("^false", pos) then pos = pos + 5; return false
    elseif text:find("^null", pos) then pos = pos + 4; return nil
    else
      local s, e = text:find("^-?%d+%.?%d*[eE]?[-+]?%d*", pos)
      if not s then fail("value expected") end
      pos = e + 1
      return tonumber(text:sub(s, e))
    end
  end
  local v = value()
  ws()
  if pos <= #text then fail("text after the value") end
  return v
end

local function read(path)
  local f, msg = io.open(path, "r")
  if not f then error("table.lua: " .. msg, 0) end
  local text = f:read("a")
  f:close()
  return text
end

-- ---- numbers as the docs write them ----------------------------------------------------------
local SUP = { ["0"] = "⁰", ["1"] = "¹", ["2"] = "²", ["3"] = "³", ["4"] = "⁴", ["5"] = "⁵",
              ["6"] = "⁶", ["7"] = "⁷", ["8"] = "⁸", ["9"] = "⁹", ["-"] = "⁻" }

local function commas(s)
  local int, rest = s:match("^(%d+)(.*)$")
  if not int or #int <= 4 then return s end
  return int:reverse():gsub("(%d%d%d)", "%1,"):reverse():gsub("^,", "") .. rest
end

-- x to `sig` significant digits: 2.04·10⁷ from 10⁵ up and below 10⁻³, otherwise plain (20,000;
-- 999; 5.63; 0.923)
local function num(x, sig)
  sig = sig or 3
  if x == 0 then return "0" end
  local neg = x < 0
  local a = math.abs(x)
  local e = math.floor(math.log(a, 10) + 1e-12)
  local m = tonumber(string.format("%." .. (sig - 1) .. "e", a):match("^([%d.]+)"))
  e = tonumber(string.format("%." .. (sig - 1) .. "e", a):match("e([-+]%d+)$"))
  local s
  if e >= 5 or e < -3 then
    s = string.format("%." .. (sig - 1) .. "f", m) .. "·10" .. tostring(e):gsub(".", SUP)
  else
    local decimals = math.max(0, sig - 1 - e)
    s = commas(string.format("%." .. decimals .. "f", a))
  end
  return (neg and "−" or "") .. s
end

local function count(x) -- an integer count: 74,047; 2·10⁸ and 10⁶ when round
  if x >= 1e6 and x % 10 ^ math.floor(math.log(x, 10) + 1e-12) == 0 then
    return (num(x, 1):gsub("^1·", ""))
  end
  return commas(string.format("%d", math.floor(x + 0.5)))
end

local function pct(x) return (string.format("%+.1f %%", 100 * x):gsub("^%-", "−")) end

-- ---- the benchmarks and their rows -----------------------------------------------------------
-- Each benchmark: the reports it needs (the first is its own: its load is shown), what it
-- measures, and rows { figure, threads, value, headline }. get(scenario) returns a report's
-- metrics, m(scenario, name) one metric (refusing a report without it).
local BENCH = {}
local reports_file -- the file of a scenario's report, set by render
local function bench(t) BENCH[#BENCH + 1] = t end

bench{
  name = "DEM pile", script = "dem_dense.lua", needs = { "bench_dem_dense", "bench_dem_dense_callgrind" },
  measures = "DEM steps of a settled pile of polydisperse disks in a closed box under gravity " ..
             "(Hertz, Brilliantov damping, Cundall–Strack springs, dt = 0.1 µs), prepared untimed; " ..
             "the instructions are callgrind's count of the same steps on one thread",
  scene = function(m)
    return string.format("%s disks, %s contacts per particle", count(m("bench_dem_dense", "disks")),
                         num(m("bench_dem_dense", "contacts_per_particle")))
  end,
  rows = function(m)
    return {
      { "particle-steps/s", "1", num(m("bench_dem_dense", "particle_steps_per_s_1_threads")), true },
      { "particle-steps/s", "2", num(m("bench_dem_dense", "particle_steps_per_s_2_threads")), true },
      { "instructions per particle-step", "1",
        num(m("bench_dem_dense_callgrind", "instructions_per_particle_step")), true },
    }
  end,
}

bench{
  name = "DEM against LAMMPS", script = "vs_lammps.sh", needs = { "bench_vs_lammps" },
  measures = "the same pile in grainlab and in Debian's LAMMPS (`pair_style granular`: Hertz, " ..
             "viscoelastic damping at the mean pair, Mindlin tangential springs of grainlab's " ..
             "stiffness), runs alternated; first the per-particle forces of both codes from the same " ..
             "state, as rms difference over rms force",
  scene = function(m, p)
    local g = num(m("bench_vs_lammps", "contacts_per_particle_end_grainlab"))
    local l = num(m("bench_vs_lammps", "contacts_per_particle_end_lammps"))
    return string.format("%s disks, %s → %s particle–particle contacts per particle (%s)",
                         count(p("bench_vs_lammps", "n")), num(m("bench_vs_lammps", "contacts_per_particle_start")),
                         g, g == l and "both codes" or ("grainlab; LAMMPS: " .. l))
  end,
  rows = function(m)
    return {
      { "speed, grainlab / LAMMPS", "1 core", num(m("bench_vs_lammps", "ratio_1_cores")), true },
      { "speed, grainlab / LAMMPS", "2 cores", num(m("bench_vs_lammps", "ratio_2_cores")), true },
      { "LAMMPS particle-steps/s", "1 rank", num(m("bench_vs_lammps", "lammps_rate_1_cores")) },
      { "LAMMPS particle-steps/s", "2 ranks", num(m("bench_vs_lammps", "lammps_rate_2_cores")) },
      { "forces: Hertz, walls, gravity", "—", num(m("bench_vs_lammps", "forces_elastic_rms_rel"), 2) },
      { "forces: with damping (one damping time)", "—", num(m("bench_vs_lammps", "forces_damped_rms_rel"), 2) },
      { "forces: after 100 steps of tangential springs", "—", num(m("bench_vs_lammps", "forces_springs_rms_rel"), 2) },
    }
  end,
}

local function mpm_rows(sc, m, headline)
  return {
    { "point-steps/s", "1", num(m(sc, "particle_steps_per_s_1_threads")) },
    { "point-steps/s", "2", num(m(sc, "particle_steps_per_s_2_threads")), headline },
    { "full shear (25,124 cycles), projected", "2",
      string.format("%s s", num(m(sc, "projected_full_run_s_2_threads"))), headline },
    { "instructions per point-step", "1", num(m(sc .. "_callgrind", "instructions_per_point_step")), headline },
  }
end
bench{
  name = "MPM shear", script = "mpm_shear.lua", needs = { "bench_mpm_shear", "bench_mpm_shear_callgrind" },
  measures = "the shear problem of Bardenhagen et al. (1998): von Mises grains sheared between " ..
             "walls at 100 m/s, frictional contact μ = 0.3, the paper's time step; timed from a " ..
             "prepared scene (200 cycles in), so the projection is from the early shear",
  scene = function(m)
    return string.format("%s points in %d grains, %d per cell, frictional contact",
                         count(m("bench_mpm_shear", "points")), m("bench_mpm_shear", "grains"),
                         m("bench_mpm_shear", "points_per_cell"))
  end,
  rows = function(m) return mpm_rows("bench_mpm_shear", m, true) end,
}
bench{
  name = "MPM shear, no contact", script = "mpm_shear.lua model=noslip",
  needs = { "bench_mpm_shear_noslip", "bench_mpm_shear_noslip_callgrind" },
  measures = "the same shear with the single centre-of-mass field (no-slip, no contact " ..
             "algorithm): what the step costs without contact",
  scene = function(m)
    return string.format("%s points in %d grains, %d per cell", count(m("bench_mpm_shear_noslip", "points")),
                         m("bench_mpm_shear_noslip", "grains"), m("bench_mpm_shear_noslip", "points_per_cell"))
  end,
  rows = function(m) return mpm_rows("bench_mpm_shear_noslip", m, false) end,
}

local function continuum_scene(sc)
  return function(m)
    return string.format("%s points, %s cells across the column", count(m(sc, "points")),
                         m(sc, "cells_across_l0"))
  end
end
local function continuum_rows(sc, m)
  return {
    { "point-steps/s", "1", num(m(sc, "particle_steps_per_s_1_threads")) },
    { "point-steps/s", "2", num(m(sc, "particle_steps_per_s_2_threads")) },
    { "share of the step in the material update", "2",
      string.format("%.0f %%", 100 * m(sc, "stage_material_ns") / m(sc, "stage_total_ns")) },
  }
end
bench{
  name = "MPM continuum column", script = "continuum.lua", needs = { "bench_mpm_continuum" },
  measures = "the collapsing column of `column_collapse.lua` (μ(I) glass beads, a = 2, B-splines, " ..
             "2 × 2 points per cell) timed from its 200th step, as 8 side-by-side grains of one " ..
             "continuum; then the whole collapse of the demo's column both ways on one thread: " ..
             "1500 disks in DEM from the gate's removal to rest, and its continuum twin (10 cells " ..
             "across the column) until its front stops",
  scene = continuum_scene("bench_mpm_continuum"),
  rows = function(m)
    local c = "bench_mpm_continuum"
    local rows = continuum_rows(c, m)
    rows[#rows + 1] = { string.format("whole collapse, DEM: %s disk-steps", count(1500 * m(c, "whole_dem_steps"))),
                        "1", string.format("%s s", num(m(c, "whole_dem_wall_s"))) }
    rows[#rows + 1] = { string.format("whole collapse, continuum: %s point-steps",
                                      count(m(c, "whole_mpm_points") * m(c, "whole_mpm_steps"))),
                        "1", string.format("%s s", num(m(c, "whole_mpm_wall_s"))) }
    rows[#rows + 1] = { "whole collapse, DEM time / continuum time", "1", num(m(c, "whole_dem_over_mpm")), true }
    return rows
  end,
}
bench{
  name = "MPM continuum column, large", script = "continuum.lua cells=360 whole=false",
  needs = { "bench_mpm_continuum_large" },
  measures = "the same column on a finer grid",
  scene = continuum_scene("bench_mpm_continuum_large"),
  rows = function(m)
    local rows = continuum_rows("bench_mpm_continuum_large", m)
    rows[2][4] = true
    return rows
  end,
}

bench{
  name = "DSMC cooling", script = "dsmc_cooling.lua", needs = { "bench_dsmc_cooling", "bench_dsmc_cooling_callgrind" },
  measures = "a homogeneously cooling granular gas of disks (e = 0.9, a tenth of the mean " ..
             "collision time a step), periodic; memory from the particle and cell arrays; " ..
             "instructions on a tenth of the gas",
  scene = function(m)
    return string.format("%s disks, %s per cell, %s collisions per particle per step",
                         count(m("bench_dsmc_cooling", "particles")), num(m("bench_dsmc_cooling", "particles_per_cell"), 2),
                         num(m("bench_dsmc_cooling", "collisions_per_particle_per_step"), 2))
  end,
  rows = function(m)
    return {
      { "particle-steps/s", "1", num(m("bench_dsmc_cooling", "particle_steps_per_s_1_threads")) },
      { "particle-steps/s", "2", num(m("bench_dsmc_cooling", "particle_steps_per_s_2_threads")), true },
      { "bytes per particle (with the cells)", "—",
        string.format("%s (%s)", num(m("bench_dsmc_cooling", "bytes_per_particle")),
                      num(m("bench_dsmc_cooling", "bytes_per_particle_with_cells"))) },
      { string.format("instructions per particle-step (%s disks)",
                      count(m("bench_dsmc_cooling_callgrind", "particles"))), "1",
        num(m("bench_dsmc_cooling_callgrind", "instructions_per_particle_step")) },
    }
  end,
}

local function scaling_rows(e, m, headline)
  local s = "bench_scaling"
  return {
    { "particle-steps/s", "1 rank", num(m(s, e .. "_rate_1_rank")) },
    { "particle-steps/s", "2 ranks", num(m(s, e .. "_rate_2_ranks")) },
    { "particle-steps/s", "1 rank × 2 threads", num(m(s, e .. "_rate_2_threads")) },
    { "efficiency at 2 ranks", "2 ranks", num(m(s, e .. "_efficiency_2_ranks")), headline },
    { "2 ranks / 2 threads", "2", num(m(s, e .. "_ranks_over_threads")) },
    { string.format("speed-up at 512 ranks, N = %s, projected (this machine's / a cluster's network)",
                    count(m(s, e .. "_projection_n"))), "512 ranks",
      string.format("%s / %s", num(m(s, e .. "_speedup_512")), num(m(s, e .. "_speedup_512_cluster"))) },
  }
end
bench{
  name = "MPI scaling, DEM", script = "scaling.lua", needs = { "bench_scaling" },
  measures = "the DEM pile on 1 rank, 2 ranks and 1 rank with 2 threads, alternated (medians); " ..
             "a communication model fitted to the traffic at 2 and 4 ranks and a ping-pong, " ..
             "projected to 512 ranks (a model, not a measurement)",
  scene = function(m)
    return string.format("%s disks, %s contacts per particle", count(m("bench_scaling", "dem_particles")),
                         num(m("bench_scaling", "dem_contacts_per_particle")))
  end,
  rows = function(m) return scaling_rows("dem", m, true) end,
}
bench{
  name = "MPI scaling, DSMC", script = "scaling.lua", needs = { "bench_scaling" },
  measures = "Herrmann & Müller's Fig. 2 gas (ν = 0.1, cells one mean free path wide), the same way",
  scene = function(m)
    return string.format("%s disks, %s per cell, %s collisions per particle per step",
                         count(m("bench_scaling", "dsmc_particles")), num(m("bench_scaling", "dsmc_particles_per_cell"), 2),
                         num(m("bench_scaling", "dsmc_collisions_per_particle_per_step"), 2))
  end,
  rows = function(m) return scaling_rows("dsmc", m, true) end,
}

bench{
  name = "Largest run, DSMC", script = "largest.lua engine=dsmc", needs = { "largest_dsmc" },
  measures = "how much memory a particle costs at scale: the peak resident set less the " ..
             "process's size before the particles were made, over N",
  scene = function(m)
    return string.format("Fig. 2's gas, %s disks, %s per cell", count(m("largest_dsmc", "particles")),
                         num(m("largest_dsmc", "particles_per_cell"), 2))
  end,
  rows = function(m)
    return {
      { "bytes per particle (cells included)", "—", num(m("largest_dsmc", "bytes_per_particle")), true },
      { "peak resident set", "—", string.format("%s GiB", num(m("largest_dsmc", "peak_resident_gib"))) },
      { "particle-steps/s", tostring(m("largest_dsmc", "threads")), num(m("largest_dsmc", "particle_steps_per_s")) },
    }
  end,
}
bench{
  name = "Largest run, DEM", script = "largest.lua engine=dem", needs = { "largest_dem" },
  measures = "the same for DEM: disks on a periodic lattice, each pressing on its four neighbours, " ..
             "the pile's laws",
  scene = function(m)
    return string.format("%s disks, %s contacts per particle", count(m("largest_dem", "particles")),
                         num(m("largest_dem", "contacts_per_particle")))
  end,
  rows = function(m)
    return {
      { "bytes per particle", "—", num(m("largest_dem", "bytes_per_particle")), true },
      { "peak resident set", "—", string.format("%s GiB", num(m("largest_dem", "peak_resident_gib"))) },
      { "particle-steps/s", tostring(m("largest_dem", "threads")), num(m("largest_dem", "particle_steps_per_s")) },
    }
  end,
}

bench{
  name = "Rendering", script = "render.lua", needs = { "bench_render" },
  measures = "one frame of disks coloured by speed, with colour bar, title and stamp, rendered " ..
             "headlessly (OSMesa) and written as PNG; the median of several frames after the first",
  scene = function(m, p)
    return string.format("%s disks, %d × %d pixels", count(m("bench_render", "disks")),
                         p("bench_render", "width"), p("bench_render", "height"))
  end,
  rows = function(m)
    return {
      { "seconds per frame, to PNG", "—", string.format("%s s", num(m("bench_render", "frame_s"), 2)), true },
      { "of which PNG encoding", "—", string.format("%s s", num(m("bench_render", "png_s"), 2)) },
    }
  end,
}

bench{
  name = "Coarse-graining", script = "cg.lua", needs = { "bench_cg" },
  measures = "`analysis.coarse_grain` of a square lattice of disks, each touching its four " ..
             "neighbours, the contacts loaded by a few DEM steps: the fields of one call with the " ..
             "Gaussian kernel (cut at 3 w) and with Lucy's, the fastest of several calls, and one " ..
             "sample of a time average (`avg:add`: the same sums, no Lua tables); then DEM steps " ..
             "sampling a Gaussian average against the same steps without, the time added over " ..
             "the samples' own time",
  scene = function(m)
    local c = "bench_cg"
    local g = m(c, "grid")
    return string.format("%s disks, %s contacts per particle, %d × %d cells of %s d, w = %g d",
                         count(m(c, "particles")), num(m(c, "contacts_per_particle")), g[1], g[2],
                         num(m(c, "cell_over_d")), m(c, "width_over_d"))
  end,
  rows = function(m, p)
    local c, rows = "bench_cg", {}
    for _, k in ipairs { { "gauss", "Gaussian" }, { "lucy", "Lucy" } } do
      for _, t in ipairs { 1, 2 } do
        local call = m(c, string.format("%s_seconds_%dt", k[1], t))
        local sample = m(c, string.format("%s_sample_seconds_%dt", k[1], t))
        rows[#rows + 1] = { "seconds per call (per sample of an average), " .. k[2], tostring(t),
                            string.format("%s s (%s s)", num(call, 2), num(sample, 2)) }
      end
    end
    rows[#rows + 1] = {
      string.format("a run sampling an average (%d samples in %d steps): time added / the samples' own time",
                    m(c, "average_samples"), p(c, "steps")),
      "auto", num(m(c, "added_per_sample_over_sample")) }
    return rows
  end,
}

bench{
  name = "Biaxial boundary conditions", script = "biaxial.lua", needs = { "bench_biaxial" },
  measures = "what each boundary condition of the biaxial laboratory costs over plain DEM steps " ..
             "of the same sample under the same load (CPU time, one thread)",
  scene = function(m, p)
    return string.format("%s disks, %s contacts per particle (plain), %s (minimal BC)",
                         count(p("bench_biaxial", "n")), num(m("bench_biaxial", "plain_contacts_per_particle")),
                         num(m("bench_biaxial", "mbc_contacts_per_particle")))
  end,
  rows = function(m)
    local s = "bench_biaxial"
    return {
      { "particle-steps/s, plain", "1", num(m(s, "plain_particle_steps_per_s")) },
      { "cost over plain: direct pressure", "1", pct(m(s, "pressure_overhead_vs_plain")) },
      { "cost over plain: membrane", "1", pct(m(s, "membrane_overhead_vs_plain")) },
      { "cost over plain: minimal BC", "1", pct(m(s, "mbc_overhead_vs_plain")) },
      { "minimal BC: share in the triangulation", "1", string.format("%.1f %%", 100 * m(s, "mbc_triangulation_share")) },
    }
  end,
}

bench{
  name = "Shared machine", script = "contended.lua", needs = { "bench_contended" },
  measures = "each engine's step on one thread, on two fixed threads and in auto mode (the " ..
             "default), with and without a busy loop on one core; ratios of particle-steps/s",
  scene = function(m)
    local l = m("bench_contended", "dem_load")
    local p = m("bench_contended", "mpm_load")
    local d = m("bench_contended", "dsmc_load")
    return string.format("DEM %s disks (%s contacts per particle), MPM %s points, DSMC %s disks",
                         count(l.disks), num(l.contacts_per_particle), count(p.points), count(d.disks))
  end,
  rows = function(m)
    local rows = {}
    for _, e in ipairs { { "dem", "DEM" }, { "mpm", "MPM" }, { "dsmc", "DSMC" } } do
      local k = "bench_contended"
      rows[#rows + 1] = { e[2] .. ", one core busy: 2 fixed threads / 1 thread", "2",
                          num(m(k, e[1] .. "_contended_all_per_s") / m(k, e[1] .. "_contended_one_per_s")) }
      rows[#rows + 1] = { e[2] .. ", one core busy: auto / 1 thread", "auto", num(m(k, e[1] .. "_contended_auto_over_one")) }
      rows[#rows + 1] = { e[2] .. ", no busy loop: auto / 2 fixed threads", "auto", num(m(k, e[1] .. "_quiet_auto_over_all")) }
    end
    return rows
  end,
}

bench{
  name = "Instruction sets", script = "march_bits.sh", needs = { "bench_march_bits" },
  measures = "three builds of the same code on the DEM pile, the MPM shear and a gas of 10⁵ disks: " ..
             "the portable baseline (SSE2), the default build (hot kernels also compiled for AVX2, " ..
             "picked at run time) and a build for x86-64-v3; every final state compared byte for byte",
  scene = function(m)
    return string.format("%s disks (%s contacts per particle), %s points, 10⁵ disks",
                         count(m("bench_march_bits", "dem_particles")), num(m("bench_march_bits", "dem_contacts_per_particle")),
                         count(m("bench_march_bits", "mpm_points")))
  end,
  rows = function(m, p, checks)
    local k, rows = "bench_march_bits", {}
    -- a failed comparison refuses the set (as any failed check), so here they all passed
    local same = 0
    for _, c in ipairs(checks(k)) do if c.name:match("^same_bits_") and c.pass then same = same + 1 end end
    if same == 0 then error("table.lua: " .. reports_file(k) .. " compares no states", 0) end
    rows[1] = { "the same bits, all three builds", "1, 2", string.format("yes (%d comparisons)", same) }
    for _, b in ipairs { { "default", "speed, default / baseline" }, { "march", "speed, x86-64-v3 / baseline" } } do
      for _, t in ipairs { 1, 2 } do
        local parts = {}
        for _, e in ipairs { { "dem", "DEM" }, { "mpm", "MPM" }, { "dsmc", "DSMC" } } do
          local base = m(k, string.format("%s_rate_baseline_%d_threads", e[1], t))
          local v = m(k, string.format("%s_rate_%s_%d_threads", e[1], b[1], t))
          parts[#parts + 1] = string.format("%s %s", e[2], num(v / base, 3))
        end
        rows[#rows + 1] = { b[2], tostring(t), table.concat(parts, ", ") }
      end
    end
    return rows
  end,
}

-- ---- the set of one run ----------------------------------------------------------------------
local function refuse(problems)
  io.stderr:write("table.lua: refused, nothing written:\n  ", table.concat(problems, "\n  "), "\n")
  os.exit(1)
end

local function load_set(dir)
  local reports, problems, files = {}, {}, {}
  local ls = io.popen("ls -1 '" .. dir:gsub("'", "'\\''") .. "' 2>/dev/null")
  for name in ls:lines() do
    if name:match("%.json$") then files[#files + 1] = name end
  end
  ls:close()
  if #files == 0 then refuse { "no report (*.json) in " .. dir } end
  local needed, order = {}, {}
  for _, b in ipairs(BENCH) do
    for _, sc in ipairs(b.needs) do
      if not needed[sc] then needed[sc] = b; order[#order + 1] = sc end
    end
  end
  local run_of = {}
  for _, name in ipairs(files) do
    local path = dir .. "/" .. name
    local r = decode(read(path), path)
    if type(r) ~= "table" or type(r.scenario) ~= "string" or type(r.metrics) ~= "table" then
      problems[#problems + 1] = name .. ": not a grainlab report"
    elseif not needed[r.scenario] then
      problems[#problems + 1] = string.format("%s: scenario '%s' is not one of this set", name, r.scenario)
    elseif reports[r.scenario] then
      problems[#problems + 1] = string.format("two reports of '%s': %s and %s", r.scenario,
                                              reports[r.scenario].file, name)
    else
      r.file = name
      reports[r.scenario] = r
      local mach = r.metrics.machine
      local run = type(mach) == "table" and mach.run or ""
      if run == "" then
        problems[#problems + 1] = name .. ": no run id (a report not written by run_all.sh)"
      else
        run_of[#run_of + 1] = { run = run, file = name }
      end
      for _, c in ipairs(r.checks or {}) do
        if not c.pass then problems[#problems + 1] = string.format("%s: check '%s' failed", name, c.name) end
      end
    end
  end
  for _, sc in ipairs(order) do
    if not reports[sc] then
      problems[#problems + 1] = string.format("incomplete: no report of '%s' (scripts/bench/%s)", sc,
                                              needed[sc].script)
    end
  end
  for i = 2, #run_of do
    if run_of[i].run ~= run_of[1].run then
      problems[#problems + 1] = string.format("the reports mix runs: %s is of run %s, %s of run %s",
                                              run_of[1].file, run_of[1].run, run_of[i].file, run_of[i].run)
      break
    end
  end
  if #problems > 0 then refuse(problems) end
  return reports
end

-- ---- rendering -------------------------------------------------------------------------------
local function render(reports)
  local problems = {}
  local function m(sc, name)
    local v = reports[sc].metrics[name]
    if v == nil then error(string.format("table.lua: %s has no metric '%s'", reports[sc].file, name), 0) end
    return v
  end
  local function p(sc, name)
    local v = (reports[sc].params or {})[name]
    if v == nil then error(string.format("table.lua: %s has no param '%s'", reports[sc].file, name), 0) end
    return v
  end
  local function checks(sc) return reports[sc].checks or {} end
  reports_file = function(sc) return reports[sc].file end

  -- the machine, from every report (they must agree)
  local first = reports[BENCH[1].needs[1]].metrics.machine
  local lo, hi, steal = math.huge, -math.huge, 0
  for sc, r in pairs(reports) do
    local mach = r.metrics.machine
    for _, k in ipairs { "cpu_model", "cores", "kernels", "version", "commit", "mode" } do
      if mach[k] ~= first[k] then
        problems[#problems + 1] = string.format("the reports disagree on the machine: %s has %s = %s, %s has %s",
                                                r.file, k, tostring(mach[k]), reports[BENCH[1].needs[1]].file, tostring(first[k]))
      end
    end
    lo = math.min(lo, mach.load_start, mach.load_end)
    hi = math.max(hi, mach.load_start, mach.load_end)
    steal = math.max(steal, mach.steal_share or 0)
    local _ = sc
  end
  if #problems > 0 then refuse(problems) end

  local function load_of(r)
    local mach = r.metrics.machine
    return string.format("%.1f → %.1f", mach.load_start, mach.load_end)
  end

  local desc, rows, head = {}, {}, {}
  local header = { "| benchmark | scene and load | figure | threads | value | load average |",
                   "|---|---|---|---|---:|---|" }
  for _, b in ipairs(BENCH) do
    local own = reports[b.needs[1]]
    local cmds = {}
    for _, sc in ipairs(b.needs) do
      cmds[#cmds + 1] = "`" .. reports[sc].metrics.command .. "`"
    end
    desc[#desc + 1] = string.format("- **%s** (`scripts/bench/%s`): %s. Run as %s.", b.name,
                                    b.script:match("^%S+"), b.measures, table.concat(cmds, " and "))
    local scene = b.scene(m, p)
    local first_row = true
    for _, row in ipairs(b.rows(m, p, checks)) do
      local line = string.format("| %s | %s | %s | %s | %s | %s |", first_row and b.name or "",
                                 first_row and scene or "", row[1], row[2], row[3],
                                 first_row and load_of(own) or "")
      rows[#rows + 1] = line
      if row[4] then
        local named = head.last ~= b.name
        head[#head + 1] = string.format("| %s | %s | %s | %s | %s |", named and b.name or "",
                                        named and scene or "", row[1], row[2], row[3])
        head.last = b.name
      end
      first_row = false
    end
  end

  local machine = string.format(
    "Measured on %s, %d cores, %.0f GiB, by grainlab %s%s (kernels: %s), in one %srun of " ..
    "`scripts/bench/run_all.sh`; the machine's 1-minute load average lay between %.1f and %.1f " ..
    "during the run%s.",
    first.cpu_model, first.cores, first.memory_gib, first.version,
    (first.commit or "") ~= "" and (" at commit " .. first.commit) or "", first.kernels,
    first.mode == "quick" and "quick " or "", lo, hi,
    steal > 0.01 and string.format(", and the hypervisor took up to %.0f %% of its CPU time", 100 * steal) or "")

  local page = { machine, "" }
  for _, d in ipairs(desc) do page[#page + 1] = d end
  page[#page + 1] = ""
  for _, l in ipairs(header) do page[#page + 1] = l end
  for _, l in ipairs(rows) do page[#page + 1] = l end

  local readme = { machine:gsub("`scripts/bench/run_all.sh`", "[`scripts/bench/run_all.sh`](docs/performance.md)"), "",
                   "| benchmark | scene and load | figure | threads | value |", "|---|---|---|---|---:|" }
  for _, l in ipairs(head) do readme[#readme + 1] = l end
  return table.concat(page, "\n"), table.concat(readme, "\n")
end

local function splice(path, key, text)
  local doc = read(path)
  local b = "<!-- begin: bench " .. key .. " -->"
  local e = "<!-- end: bench " .. key .. " -->"
  local s1, e1 = doc:find(b, 1, true)
  local s2 = doc:find(e, 1, true)
  if not s1 or not s2 or s2 < e1 then
    error(string.format("table.lua: %s has no lines '%s' ... '%s'", path, b, e), 0)
  end
  return doc:sub(1, e1) .. "\n" .. text .. "\n" .. doc:sub(s2)
end

-- ---- main --------------------------------------------------------------------------------------
local dir = params.dir
if type(dir) ~= "string" or dir == "" then
  error("table.lua: dir=DIR expected (the reports of one run, as run_all.sh writes them)", 0)
end
local reports = load_set(dir)
local page_text, readme_text = render(reports)
if params.print then
  print(page_text)
  print()
  print(readme_text)
  return
end
local page_path = params.page or "docs/performance.md"
local readme_path = params.readme or "README.md"
-- both files spliced before either is written: a missing marker writes nothing
local new_page = splice(page_path, "table", page_text)
local new_readme = splice(readme_path, "headline", readme_text)
for _, w in ipairs { { page_path, new_page }, { readme_path, new_readme } } do
  local ok, msg = grainlab.write_file(w[1], w[2])
  if not ok then error("table.lua: " .. msg, 0) end
end
local n = 0
for _ in pairs(reports) do n = n + 1 end
print(string.format("table.lua: %d reports of run %s -> %s, %s", n, reports.bench_dem_dense.metrics.machine.run,
                    page_path, readme_path))
