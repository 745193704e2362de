-- DSMC through the Lua binding: conservation at e = 1, the collision frequency with the chi the
-- code applies (free volume: chi = 1/(1 - nu/nu_rcp)), measurements that must add up (fields,
-- histogram, profile), a vibrating wall that feeds energy in, and the validity warnings.
local check = grainlab.check
local R, N, nu = 1e-3, 4000, 0.03
local L = math.sqrt(N * math.pi * R * R / nu)
local s = dsmc.scene{ dim = 2, size = { L, L }, cells = { 14, 14 }, radius = R, restitution = 1, seed = 3 }
s:fill{ n = N, speed = 1, seed = 2 }
local m = s:info().mass
local t0 = s:measure("temperature")

-- Kinetic theory, derived again: omega = n sigma <|g|> chi with sigma = 4R (2D cross-section),
-- <|g|> = sqrt(pi T/m) for two Maxwellian disks, n = (N - 1)/V the partners of a particle.
local chi = 1 / (1 - nu / 0.82)
local n = (N - 1) / (L * L)
local function omega(t_over_m) return n * 4 * R * math.sqrt(math.pi * t_over_m) * chi end
check.near(s:info().chi, chi, 1e-12, "chi of the free-volume correction")
check.near(t0.collision_frequency, omega(t0.t_over_m), 1e-12, "kinetic-theory omega")

local dt = 0.2 / omega(t0.t_over_m)
s:run{ steps = 100, dt = dt, warn = false } -- 20 collisions per particle: Maxwell-Boltzmann
s:reset_stats()
s:run{ steps = 400, dt = dt, warn = false }
local t1 = s:measure("temperature")
check.near(t1.kinetic_energy, t0.kinetic_energy, 1e-12, "energy conserved at e = 1")
for k = 1, 2 do
  check.near_abs(t1.momentum[k], t0.momentum[k], 1e-12 * m * N, "momentum conserved at e = 1")
end
local st = s:measure("stats")
-- The per-cell free volume is nonlinear in the cell's count, so Poisson fluctuations raise the
-- mean rate over chi(nu) by about 2 v_b / (V_c nu_rcp) relative (0.5% here); 2% covers it and
-- the statistical error (~0.3%).
check.near(st.collision_frequency, omega(t1.t_over_m), 0.02, "measured collision frequency")
check.near(st.collisions_per_particle_per_step, omega(t1.t_over_m) * dt / 2, 0.02, "omega tau / 2")
check.near(st.particle_moves, 400 * N, 1e-12, "particle moves")
check.is_true(st.attempts >= st.collisions and st.acceptance > 0.2 and st.acceptance <= 1, "acceptance")

-- Enskog's chi in 2D (Henderson): (1 - 7 nu/16)/(1 - nu)^2 multiplies Eq. 1 per cell
local en = dsmc.scene{ dim = 2, size = { L, L }, cells = { 14, 14 }, radius = R, seed = 4, excluded_volume = "enskog" }
en:fill{ n = N, temperature = m, seed = 6 }
local chi_e = (1 - 7 * nu / 16) / (1 - nu)^2
check.near(en:info().chi, chi_e, 1e-12, "Enskog chi")
local t_e = en:measure("temperature")
en:run{ steps = 50, dt = dt, warn = false }
en:reset_stats()
en:run{ steps = 300, dt = dt, warn = false }
local w_e = omega(en:measure("temperature").t_over_m) / chi * chi_e
check.near(en:measure("stats").collision_frequency, w_e, 0.02, "collision frequency with Enskog's chi")
check.near(t_e.collision_frequency, omega(t_e.t_over_m) / chi * chi_e, 1e-12, "kinetic-theory omega with Enskog's chi")

-- fields, histogram, profile add up
local f = s:measure("fields")
local cnt, ux = 0, 0
for i = 1, #f.count do cnt = cnt + f.count[i]; ux = ux + f.count[i] * f.ux[i] end
check.eq(cnt, N, "cell counts add up to N")
check.near_abs(ux / N, t1.mean_velocity[1], 1e-12, "cell velocities average to the mean")
check.eq(f.nx, 14, "field size")
local h = s:measure("histogram", { bins = 60 })
local area = 0
for i = 1, #h.pdf do area = area + h.pdf[i] * (h.centers[2] - h.centers[1]) end
check.near(area + h.outside / h.samples, 1, 1e-12, "histogram pdf normalised")
check.eq(h.samples, 2 * N, "one sample per component")
local p = s:measure("profile", { axis = 2, bins = 7 })
local pc = 0
for i = 1, 7 do pc = pc + p.count[i] end
check.eq(pc, N, "profile counts add up")

-- A vibrating bottom wall keeps an inelastic gas under gravity hot; a fixed one lets it cool,
-- and then collapse: DSMC keeps no distance between particles, and the run stops once a cell
-- holds more than fit in it (here 38 where 37 fit: 5 mm cells, R = 0.5 mm, packing limit 0.82).
local function bed(amplitude)
  local b = dsmc.scene{ dim = 2, size = { 0.05, 0.1 }, cells = { 10, 20 }, periodic = { true, false },
                        gravity = { 0, -9.81 }, radius = 5e-4, restitution = 0.9, seed = 1 }
  b:fill{ n = 100, temperature = b:info().mass * 0.05, region = { { 0, 0 }, { 0.05, 0.03 } } }
  if amplitude > 0 then b:wall{ side = "bottom", amplitude = amplitude, frequency = 50 } end
  b:run{ time = 0.3, dt = 2e-4, warn = false }
  return b:measure("temperature").t_over_m, b:measure("stats").wall_hits, b
end
local hot, hits = bed(1e-3)
local cold, _, cb = bed(0)
check.is_true(hits > 0, "particles hit the bottom wall")
check.gt(hot, 10 * cold, "vibration feeds energy in")
check.errors(function() cb:run{ time = 0.5, dt = 2e-4, force = true, warn = false } end,
  "holds 38 particles, a packing fraction of 1.19 where at most 37 fit at the packing limit 0.82: " ..
  "a state past close packing", "a collapsing bed stops the run past close packing")

-- validity: cells larger than the mean free path are reported with their numbers
local v = s:measure("validity", { dt = dt })
check.is_true(v.cells_ok == (v.mean_free_path > v.cell_size), "condition ii")
check.is_true(v.dt_ok, "dt below the collision time")
local dense = dsmc.scene{ dim = 2, size = { 0.1, 0.1 }, cells = { 5, 5 }, radius = 1e-3 }
dense:fill{ n = 500, temperature = 1e-6 }
local vd = dense:measure("validity", { dt = 1 })
check.is_true(not vd.cells_ok and not vd.dt_ok, "a dense gas with coarse cells and a huge dt violates ii and iii")

-- ... and s:run warns each violated condition with its numbers (on stderr, so run a child)
local exe = arg[-1]
for i = -2, -10, -1 do if arg[i] then exe = arg[i] else break end end
local chunk = "local d = dsmc.scene{ dim = 2, size = { 0.1, 0.1 }, cells = { 5, 5 }, radius = 1e-3 }; " ..
              "d:fill{ n = 500, temperature = 1e-6 }; pcall(d.run, d, { steps = 1, dt = 1, force = true }); " ..
              "local q = dsmc.scene{ dim = 2, size = { 0.1, 0.1 }, cells = { 5, 5 }, radius = 1e-3 }; " ..
              "q:fill{ n = 500, temperature = 1e-6 }; q:run{ steps = 1, dt = 1, force = true, warn = false }"
local pipe = io.popen(exe .. " -e '" .. chunk .. "' 2>&1")
local out = pipe:read("a")
pipe:close()
check.contains(out, "dsmc run: warning: cells larger than the mean free path (condition ii): cell side 0.02 m >= mean free path 0.00", "warning ii")
check.contains(out, "dsmc run: warning: time step above the mean collision time (condition iii): dt 1 s >= 1/omega = ", "warning iii")
local _, count = out:gsub("%(condition ii%)", "")
check.eq(count, 1, "warn = false silences the warnings")
check.contains(out, "over the limit of 100 per particle", "the second run ran (and stopped at the cap)")
local _, stops = out:gsub("over the limit of 100 per particle", "")
check.eq(stops, 1, "only the second run's error reaches stderr")
check.done()
