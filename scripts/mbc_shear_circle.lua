-- grainlab DEM: the minimal boundary conditions impose any strain-rate tensor on any cell
-- shape (Padbidri Sec. 3.2, Fig. 3.4: a circular assembly after 20% shear strain).
-- A circular sample (grainlab.biax.prepared{ shape = "circle" }, Table 3.1 materials, 100 kPa on
-- the Delaunay boundary) is sheared by the MBC penalty alone, target strain rate E_xy = E_yx =
-- gamma_rate / 2 (engineering shear rate gamma_rate; E_xx = E_yy = 0 held too), to engineering
-- shear `gamma` (20%). The coarse strain of the sample (Bagi-Satake, Eq. 3.1, summed over mesh
-- windows of 0.5%) is compared with the imposed one; the deformed assembly is drawn with the
-- displacement field (Fig. 3.4). Scale: n = 400 and gamma_rate = 0.05/s by default (phi stays
-- << 1), i.e. 4e5 steps; the paper's assembly is larger.
--   grainlab scripts/mbc_shear_circle.lua [n=400] [gamma=0.2] [gamma_rate=0.05] [seed=1]
--       [png=images/mbc_shear_circle.png]
local biax = grainlab.biax
local n = params.n or 400
local gamma = params.gamma or 0.2
local gamma_rate = params.gamma_rate or 0.05
local seed = params.seed or 1
-- images/ only from the default run (docs/analysis.md shows it); any other run writes to out/.
local figures = require("grainlab.figures")
local png = params.png or figures.path("mbc_shear_circle.png", {
  published = figures.published({ n = n, gamma = gamma, gamma_rate = gamma_rate, seed = seed },
                                { n = 400, gamma = 0.2, gamma_rate = 0.05, seed = 1 }) })
grainlab.threads(1)
os.execute("mkdir -p out")
local c = biax.config{}
local st = biax.prepared{ n = n, seed = seed, shape = "circle" }
local s = biax.scene(st, c)
biax.contact(s, c, false)
local h = 0.5 * gamma_rate
local info = s:boundary{ pressure = c.pressure, every = c.every, alpha = c.alpha,
                         mbc = { strain_rate = { { 0, h }, { h, 0 } }, rate = h, dt = c.dt } }
s:set_reference()
local total = math.floor(gamma / gamma_rate / c.dt + 0.5)
local window = math.floor(0.005 / gamma_rate / c.dt + 0.5)
local exy, exx, eyy, done = 0, 0, 0, 0
local mesh = analysis.delaunay(s)
local progress = grainlab.progress{ label = "mbc shear", total = total, unit = "steps" }
while done < total do
  local k = math.min(window, total - done)
  s:run{ steps = k, dt = c.dt, impact_velocity = 1e-3, progress = false }
  done = done + k
  local e = mesh:strain(s).coarse
  exy, exx, eyy = exy + e.xy, exx + e.xx, eyy + e.yy
  mesh = analysis.delaunay(s)
  progress:update(done)
end
progress:finish()
local imposed = 0.5 * gamma_rate * total * c.dt
render.png(s, png, { width = 800, color = "speed", show = { "displacement", "box", "colorbar" },
                     displacement = { scale = 1 }, label = "|v| (m/s)",
                     title = string.format("Fig. 3.4: %d disks after %.0f%% shear under the minimal BC (arrows: displacement)",
                                           n, 200 * imposed) })
local bi = s:boundary_info()
print(string.format("coarse E_xy %.4f (imposed %.4f), E_xx %.2e, E_yy %.2e; penalty K %.3g", exy, imposed, exx, eyy, info.K))
grainlab.report{
  scenario = "mbc_shear_circle",
  params = { n = n, gamma = gamma, gamma_rate = gamma_rate, seed = seed, dt = c.dt },
  metrics = { coarse_exy = exy, imposed_exy = imposed, coarse_exx = exx, coarse_eyy = eyy,
              ratio_exy = exy / imposed, penalty_k = info.K, boundary_updates = bi.updates },
  checks = { { name = "shear_strain_within_5pct", value = math.abs(exy / imposed - 1), limit = 0.05 } },
}
