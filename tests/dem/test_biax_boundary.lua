-- The biaxial laboratory on a small assembly (150 disks, Table 3.1 materials): the Christoffersen
-- stress of a confined assembly at rest equals the applied pressure (2%); the minimal boundary
-- conditions hold a prescribed pure-shear strain rate (5%) with a penalty force summing to zero;
-- the mesh gives an affine strain exactly; bad input is refused with clear messages.
local check = grainlab.check
local biax = grainlab.biax
local c = biax.config{}

-- ---- confined at rest: Christoffersen = p ----------------------------------------------------
local st, rep = biax.prepare{ n = 150, seed = 3, ramp_steps = 10000, hold_steps = 5000,
                               friction_steps = 2000, rest_steps = 3000 }
print(string.format("prepared 150 disks in %.2f s: <p> = %.1f Pa (applied %.0f), kinetic %.2e J",
                    rep.seconds, rep.pressure, c.pressure, rep.kinetic))
check.near(rep.pressure, c.pressure, 0.02, "Christoffersen pressure at rest")
-- A circle of 150 leaves the short recipe more than 2% off (breathing); the settling rounds
-- (drag, then drag-free rest, until within settle_tol) bring it to the pressure.
do
  local _, rc = biax.prepare{ n = 150, seed = 3, shape = "circle", ramp_steps = 10000,
                              hold_steps = 5000, friction_steps = 2000, rest_steps = 3000,
                              settle_tol = 0.005 }
  print(string.format("circle of 150: <p> = %.1f Pa after %d settling rounds", rc.pressure,
                      rc.settle_rounds))
  check.near(rc.pressure, c.pressure, 0.005, "settled circle pressure")
  check.ge(rc.settle_rounds, 1, "settling rounds taken")
end

-- ---- affine displacement: exact per cell and on the boundary (Eq. 3.1) -----------------------
do
  local mesh = analysis.delaunay({ x = st.x, y = st.y, radius = st.r }, { alpha = 1.5 })
  local G = { { 0.011, -0.004 }, { 0.009, -0.023 } }
  local x, y = {}, {}
  for i = 1, #st.x do
    x[i] = st.x[i] + G[1][1] * st.x[i] + G[1][2] * st.y[i] + 1e-4
    y[i] = st.y[i] + G[2][1] * st.x[i] + G[2][2] * st.y[i] - 3e-4
  end
  local e = mesh:strain{ x = x, y = y }
  local worst = 0
  for k = 1, #e.xx do
    worst = math.max(worst, math.abs(e.xx[k] - G[1][1]), math.abs(e.yy[k] - G[2][2]),
                     math.abs(e.xy[k] - 0.5 * (G[1][2] + G[2][1])))
  end
  check.le(worst, 1e-12, "affine strain in every cell")
  check.near_abs(e.coarse_gradient.xy, G[1][2], 1e-12, "boundary integral xy")
  check.near_abs(e.coarse_gradient.yx, G[2][1], 1e-12, "boundary integral yx")
  check.near_abs(e.volumetric, G[1][1] + G[2][2], 1e-12, "boundary integral trace")
  check.near_abs(e.mean_gradient.yy, e.coarse_gradient.yy, 1e-12, "cell mean = boundary integral")
  print(string.format("affine: %d cells, worst |strain - G| = %.2e", #e.xx, worst))
end

-- ---- MBC: pure shear at eps = 0.05/s to 1% ----------------------------------------------------
-- The default penalty (dt given: K capped at half the explicit limit, integral term tau = 1000
-- dt) is checked; the paper's rate penalty alone (tau = 0) is printed for comparison.
local function pure_shear(tau)
  local eps = 0.05
  local s = biax.scene(st, c)
  biax.contact(s, c, false)
  local info = s:boundary{ pressure = c.pressure,
                           mbc = { strain_rate = { { eps, 0 }, { 0, -eps } }, dt = c.dt, tau = tau } }
  local sum_xx, sum_yy, T, worst_sum, max_pen = 0, 0, 0, 0, 0
  local mesh, t = analysis.delaunay(s), s:info().time
  for k = 1, 20 do
    s:run{ steps = 1000, dt = c.dt, impact_velocity = 1e-3, progress = false }
    local e, now = mesh:strain(s).coarse, s:info().time
    if k > 1 then -- after the initial transient (0.05%)
      sum_xx, sum_yy, T = sum_xx + e.xx, sum_yy + e.yy, T + (now - t)
    end
    local bi = s:boundary_info()
    worst_sum = math.max(worst_sum, math.abs(bi.penalty_sum[1]), math.abs(bi.penalty_sum[2]))
    max_pen = math.max(max_pen, bi.penalty_max)
    mesh, t = analysis.delaunay(s), now
  end
  return s, info, sum_xx / (eps * T), sum_yy / (-eps * T), worst_sum, max_pen
end
do
  local s, info, rxx, ryy, worst_sum, max_pen = pure_shear(nil)
  check.gt(info.K, 0, "automatic K")
  print(string.format("MBC pure shear: K = %.3g, actual/imposed xx %.4f yy %.4f; penalty sum %.2e N, max %.3g N",
                      info.K, rxx, ryy, worst_sum, max_pen))
  check.near(rxx, 1, 0.05, "MBC strain rate xx / imposed")
  check.near(ryy, 1, 0.05, "MBC strain rate yy / imposed")
  check.gt(max_pen, 0, "the penalty acts")
  check.le(worst_sum, 1e-12 * max_pen, "penalty forces sum to zero")
  -- The band triangulation used by the boundary updates finds the loop of the full one.
  s:run{ steps = 250, dt = c.dt, impact_velocity = 1e-3, progress = false }
  local E, loop = s:boundary_edges(), analysis.delaunay(s):boundary()
  local same = #E.a == #loop
  local start
  for k = 1, #loop do if loop[k] == E.a[1] then start = k end end
  for k = 1, #E.a do same = same and start and E.a[k] == loop[(start + k - 2) % #loop + 1] end
  check.is_true(same, "band triangulation gives the full triangulation's boundary loop")
  -- Too stiff a penalty for the step is refused, naming the limit.
  s:boundary{ pressure = c.pressure, mbc = { strain_rate = { { 0.05, 0 }, { 0, -0.05 } }, K = info.K * 10 } }
  check.errors(function() s:run{ steps = 10, dt = c.dt, impact_velocity = 1e-3, progress = false } end,
               "is too stiff for dt", "stiff penalty")
  local _, info0, r0xx, r0yy = pure_shear(0)
  print(string.format("  rate penalty alone (tau = 0, same K %.3g): xx %.4f yy %.4f", info0.K, r0xx, r0yy))
end

-- ---- bad input ---------------------------------------------------------------------------------
check.errors(function() analysis.delaunay{ x = { 0, 1, 2 }, y = { 0, 1, 2 } } end,
  "delaunay: all 3 particle centres are collinear", "collinear")
check.errors(function() analysis.delaunay{ x = { 0, 1 }, y = { 0, 1 } } end,
  "delaunay: a Delaunay triangulation needs at least 3 particles, got 2", "two particles")
check.errors(function() analysis.delaunay{ x = { 0, 1, 0, 1 }, y = { 0, 0, 1, 0 } } end,
  "delaunay: particles 2 and 4 have the same position", "duplicates")
check.errors(function() analysis.delaunay{ x = { 0, 1, 0 }, y = { 0, 0 } } end,
  "bad field 'y' in argument #1 to 'delaunay' (array of 3 finite numbers expected", "short y")
check.errors(function() analysis.delaunay({ x = { 0, 1, 0 }, y = { 0, 0, 1 } }, { alpha = -1 }) end,
  "bad field 'alpha' in argument #2 to 'delaunay' (non-negative number expected, got -1)", "alpha")
check.errors(function() analysis.delaunay({ x = { 0, 1, 0 }, y = { 0, 0, 1 } }, { alhpa = 1 }) end,
  "unknown field 'alhpa'", "typo")
local s = biax.scene(st, c)
check.errors(function() s:boundary{ pressure = -1 } end,
  "bad field 'pressure' in argument #1 to 'boundary' (non-negative number expected, got -1)", "negative pressure")
check.errors(function() s:boundary{ pressure = 1e5, mode = "plates" } end, "bad field 'mode'", "bad mode")
check.errors(function() s:boundary{ pressure = 1e5, mbc = { strain_rate = { { 1, 2 }, { 3, 4 } } } } end,
  "must be symmetric", "asymmetric strain rate")
check.errors(function() s:boundary{ pressure = 1e5, mbc = { strain_rate = { { 0, 0 }, { 0, -1 } }, gradient = { { 0, 0 }, { 0, 0 } } } } end,
  "exactly one of strain_rate and gradient", "both targets")
check.errors(function() s:springs{ i = { 1 }, j = { 1 }, k = 1e4 } end, "ids must be distinct", "self spring")
check.errors(function() s:springs{ i = { 1 }, j = { 2 }, k = 0 } end,
  "bad field 'k' in argument #1 to 'springs' (positive number expected, got 0)", "zero spring")
check.errors(function() s:tie{ ids = { 1 }, wall = 3 } end, "wall 3 does not exist", "tie to no wall")
check.errors(function() s:boundary{ mode = "edges", pressure = 1, edges = { a = { 1, 2, 3 }, b = { 2, 3, 5 } }, closed = true } end,
  "closed boundary needs the edges in loop order", "open loop")
-- A prescribed spin holds its value through a run; the translation stays free.
do
  local sp = biax.scene(st, c)
  biax.contact(sp, c, false)
  sp:boundary{ pressure = c.pressure }
  sp:spin{ id = 7, omega = 0.03 }
  sp:run{ steps = 200, dt = c.dt, impact_velocity = 1e-3, progress = false }
  local a0 = sp:particles().angle[7]
  sp:run{ steps = 300, dt = c.dt, impact_velocity = 1e-3, progress = false }
  local P = sp:particles()
  check.near(P.omega[7], 0.03, 1e-12, "prescribed spin")
  -- the integrated rotation: exactly omega t for a held spin
  check.near(P.angle[7] - a0, 0.03 * 300 * c.dt, 1e-9, "angle of a held spin")
  check.errors(function() sp:spin{ id = 0, omega = 1 } end, "bad field 'id' in argument #1 to 'spin'", "spin id")
  local bare = biax.scene(st, c)
  bare:contact{ normal = "hertz" }
  check.errors(function() bare:spin{ id = 1, omega = 1 } end, "no rotations", "spin without rotations")
end
local s3 = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { 1, 1, 1 } } }
check.errors(function() s3:boundary{ pressure = 1 } end, "2D only", "3D scene")
check.done()
