-- Exactness of coarse-graining (Weinhart, Thornton, Luding & Bokhove 2012; Goldhirsch 2010):
-- every kernel integrates to 1, so the fields integrate to the particles' totals whatever the
-- width: the mass, the momentum, and the stress plus rho V (x) V to the virial sum
-- sum_contacts b (x) f plus the momentum flux sum_i m_i v_i (x) v_i (the kinetic stress is
-- M - rho V V by definition, so its integral is not a sum over particles by itself). The
-- reference sums come from the scene, not from the coarse-graining: the pairs' virial from
-- s:measure('stress') (the DEM's own loop), the walls' from s:measure('contacts') (frictionless
-- walls: r_i f_n n (x) n). The floor's force density integrates to its force.
-- The integrals are midpoint sums over a grid of spacing w / 2 that holds every kernel's support
-- (one period on periodic axes). With the Gaussian cut at 8 w (phi there is e^-32 = 1.3e-14 of its
-- peak) the fields are smooth to round-off, and the sums integrate them to round-off (spectral
-- accuracy); with the default cut at 3 w the jump at the cut leaves ~1e-4.
-- Scenes (falling and colliding grains, so that the kinetic part is not nil): a 2D bed periodic in
-- x on a frictionless floor; a 3D bed periodic in x and y; an MPM disk moving on a grid.
--   grainlab scripts/cg_exactness.lua [n2=70] [n3=60]
local check_tol = 1e-11
local depth = 1e-3

local function bed2(n)
  local W = 0.01
  local s = dem.scene{ dim = 2, box = { { 0, 0 }, { W, 0.012 } }, gravity = { 0, -9.81 },
                       periodic = { true, false }, thickness = depth }
  s:add_wall{ point = { 0, 0 }, normal = { 0, 1 }, friction = 0 }
  local m = grainlab.material{ density = 2650, young = 5e7, poisson = 0.3, friction = 0.5, restitution = 0.6 }
  grainlab.pack.random(s, { n = n, radius = { 0.3e-3, 0.45e-3 }, seed = 5, material = m, speed = 0.05,
                            region = { { 0, 0 }, { W, 0.008 } } })
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.6, impact_velocity = 1, tangential = "spring" }
  s:run{ time = 0.04, progress = false }
  return s, W
end

local function bed3(n)
  local L = 0.006
  local s = dem.scene{ dim = 3, box = { { 0, 0, 0 }, { L, L, L } }, gravity = { 0, 0, -9.81 }, periodic = { true, true, false } }
  s:add_wall{ point = { 0, 0, 0 }, normal = { 0, 0, 1 }, friction = 0 }
  local m = grainlab.material{ density = 2650, young = 5e7, poisson = 0.3, friction = 0.5, restitution = 0.6 }
  grainlab.pack.random(s, { n = n, radius = { 0.5e-3, 0.6e-3 }, seed = 2, material = m, speed = 0.05 })
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.6, impact_velocity = 1, tangential = "spring" }
  s:run{ time = 0.1, progress = false }
  return s, L
end

local function integral(F, f)
  local t = 0
  for i = 1, F.n do t = t + f(i) end
  return t * F.cell_volume
end

-- The scene's own totals: mass, momentum, flux, virial (pairs from s:measure, walls r fn n n).
local function totals(s)
  local P, dim = s:particles(), s:info().dim
  local ax = dim == 2 and { "x", "y" } or { "x", "y", "z" }
  local mass, mom, flux = 0, {}, {}
  for a = 1, dim do mom[a] = 0; flux[a] = {}; for b = 1, dim do flux[a][b] = 0 end end
  for i = 1, P.count do
    mass = mass + P.mass[i]
    for a = 1, dim do
      local va = P["v" .. ax[a]][i]
      mom[a] = mom[a] + P.mass[i] * va
      for b = 1, dim do flux[a][b] = flux[a][b] + P.mass[i] * va * P["v" .. ax[b]][i] end
    end
  end
  local sig = s:measure("stress", { volume = 1 })
  local vir = {}
  for a = 1, dim do vir[a] = {}; for b = 1, dim do vir[a][b] = sig[ax[a] .. ax[b]] end end
  local C = s:measure("contacts")
  local nk = { C.nx, C.ny, C.nz }
  local floor = 0
  for k = 1, #C.i do
    if C.j[k] < 0 then
      local r = P.radius[C.i[k]]
      floor = floor + C.fn[k]
      for a = 1, dim do for b = 1, dim do vir[a][b] = vir[a][b] + r * C.fn[k] * nk[a][k] * nk[b][k] end end
    end
  end
  return { mass = mass, mom = mom, flux = flux, vir = vir, ax = ax, floor = floor, contacts = #C.i }
end

-- Relative errors of the grid integrals against the totals (scale: depth in 2D, 1 in 3D).
local function errors(s, F, scale)
  local T = totals(s)
  local dim = #T.ax
  local e = { mass = math.abs(integral(F, function(i) return F.density[i] end) * scale / T.mass - 1) }
  local em, es = 0, 0
  local ref = math.abs(T.vir[1][1]) + math.abs(T.vir[dim][dim]) + math.abs(T.flux[1][1]) + math.abs(T.flux[dim][dim])
  local pref = 0
  for a = 1, dim do pref = pref + math.abs(T.mom[a]) end
  for a = 1, dim do
    local V = F.velocity[T.ax[a]]
    local got = integral(F, function(i) return F.density[i] > 0 and F.density[i] * V[i] or 0 end) * scale
    em = math.max(em, math.abs(got - T.mom[a]) / pref)
    for b = 1, dim do
      local S, Vb = F.stress[T.ax[a] .. T.ax[b]], F.velocity[T.ax[b]]
      local st = integral(F, function(i)
        return S[i] + (F.density[i] > 0 and F.density[i] * V[i] * Vb[i] or 0)
      end) * scale
      es = math.max(es, math.abs(st - (T.vir[a][b] + T.flux[a][b])) / ref)
    end
  end
  e.momentum, e.stress = em, es
  if F.traction and T.floor > 0 then
    local up = integral(F, function(i) return F.traction[T.ax[dim]][i] end) * scale
    e.floor = math.abs(up / T.floor - 1)
  end
  e.kinetic_share = (math.abs(T.flux[1][1]) + math.abs(T.flux[dim][dim])) / ref
  e.contacts = T.contacts
  return e
end

local metrics, checks = {}, {}
local function record(tag, e)
  for k, v in pairs(e) do metrics[tag .. "_" .. k] = v end
  for _, k in ipairs{ "mass", "momentum", "stress", "floor" } do
    if e[k] then checks[#checks + 1] = { name = tag .. "_" .. k, value = e[k], limit = check_tol } end
  end
end

-- 2D: one period in x, beyond every support in y; w = 0.4 mm cut at 8 w, h = w / 2
local s2, W = bed2(params.n2 or 70)
local w = 0.4e-3
local F2 = analysis.coarse_grain(s2, { width = w, cutoff = 8 * w, cells = { 50, 90 },
                                       region = { { 0, -4e-3 }, { W, 0.0152 } } })
record("dem2d", errors(s2, F2, depth))
-- the same with the default cut at 3 w: the jump's quadrature error, reported
local F2c = analysis.coarse_grain(s2, { width = w, cells = { 50, 90 }, region = { { 0, -4e-3 }, { W, 0.0152 } } })
metrics.dem2d_cut3w_mass = errors(s2, F2c, depth).mass

-- 3D: one period in x and y; w = 0.6 mm cut at 8 w
local s3, L = bed3(params.n3 or 60)
local w3 = 0.6e-3
local F3 = analysis.coarse_grain(s3, { width = w3, cutoff = 8 * w3, cells = { 20, 20, 40 },
                                       region = { { 0, 0, -5e-3 }, { L, L, L + 5e-3 } } })
record("dem3d", errors(s3, F3, 1))

-- MPM: a disk of elastic points moving across a grid (per unit depth)
local mm = mpm.scene{ cells = { 24, 24 }, size = { 0.024, 0.024 }, gravity = { 0, -9.81 } }
local mat = mpm.material{ model = "elastic", density = 2000, shear = 1e6, bulk = 2e6 }
mm:add_disk{ center = { 0.012, 0.012 }, radius = 0.005, material = mat, points_per_cell = 4, velocity = { 0.1, 0 } }
mm:run{ steps = 50, cfl = 0.2, progress = false }
local Fm = analysis.coarse_grain(mm, { width = 1e-3, cutoff = 8e-3, cells = { 96, 96 },
                                       region = { { -0.012, -0.012 }, { 0.036, 0.036 } } })
local pts = mm:points()
local mass, px, sxx, syy = 0, 0, 0, 0
for i = 1, #pts.x do
  mass = mass + pts.mass[i]
  px = px + pts.mass[i] * pts.vx[i]
  sxx = sxx - pts.volume[i] * pts.sxx[i] + pts.mass[i] * pts.vx[i] ^ 2
  syy = syy - pts.volume[i] * pts.syy[i] + pts.mass[i] * pts.vy[i] ^ 2
end
local e = {
  mass = math.abs(integral(Fm, function(i) return Fm.density[i] end) / mass - 1),
  momentum = math.abs(integral(Fm, function(i) return Fm.density[i] > 0 and Fm.density[i] * Fm.velocity.x[i] or 0 end) / px - 1),
  stress = math.max(
    math.abs(integral(Fm, function(i) return Fm.stress.xx[i] + (Fm.density[i] > 0 and Fm.density[i] * Fm.velocity.x[i] ^ 2 or 0) end) / sxx - 1),
    math.abs(integral(Fm, function(i) return Fm.stress.yy[i] + (Fm.density[i] > 0 and Fm.density[i] * Fm.velocity.y[i] ^ 2 or 0) end) / syy - 1)),
}
record("mpm", e)

grainlab.report{
  scenario = "cg_exactness",
  params = { kernel = "gauss", cutoff_w = 8, grid_spacing_w = 0.5 },
  metrics = metrics,
  checks = checks,
}
