-- Eight disks closing in on a 60 x 60 grid (periodic in y), one of them prescribed, a no-slip
-- wall on the left and a moving friction wall on the right, run for 25 steps: the scene of the
-- tests that compare frictional contact's code paths bit for bit (test_mpm_contact_paths.lua,
-- isa_bits_scenes.lua). case: update, shape, pic, wall_gap, plane (a friction plane at the
-- right), contact (options added to { model = "friction", mu = 0.4 }). Returns { run = function(case)
-- returning the scene after its run, cases = the three frictional option sets both tests use }.
local mat = mpm.material{ model = "vonmises", density = 3000, shear = 2.5e6, bulk = 10e6, yield = 2e4 }
local function run(case)
  local m = mpm.scene{ cells = { 60, 60 }, size = { 6, 6 }, gravity = { 0.5, -9.8 }, periodic = { false, true },
                       update = case.update, shape = case.shape, pic = case.pic, wall_gap = case.wall_gap,
                       walls = { left = "noslip", right = { kind = "friction", mu = 0.3, velocity = { 0, 0.2 } } } }
  local ids = {}
  for k = 0, 7 do
    -- columns 1.3 apart and rows 1.25 apart (radius 0.62: gaps under a cell), the last column
    -- reaching the right wall's nodes
    ids[k] = m:add_disk{ center = { 1.4 + 1.3 * (k % 4), 1.5 + 1.25 * (k // 4) }, radius = 0.62, material = mat,
                         points_per_cell = 3,
                         velocity = { (k % 2 == 0) and 1 or -1, (k // 4 == 0) and 0.5 or -0.5 } }
  end
  m:prescribe(ids[5], { -0.5, -0.5 })
  if case.plane then m:plane{ point = { 5.95, 0 }, normal = { 1, 0.2 }, kind = "friction", mu = 0.4 } end
  local c = { model = "friction", mu = 0.4 }
  for k, v in pairs(case.contact) do c[k] = v end
  if c.model == "noslip" then c.mu = nil end
  m:contact(c)
  m:run{ steps = 25, cfl = 0.3, progress = false }
  return m
end

-- B-spline shapes with the strain cap, separation and conserve (MUSL); a friction plane with the
-- gap test and the grains' own normals (USF: the force sums); linear normals with a PIC blend
-- (USL, no remap).
local cases = {
  { name = "musl, bspline, cap, separation, conserve", update = "musl", shape = "bspline",
    contact = { strain_cap = 0.05, separation = 0.2, conserve = true } },
  { name = "usf, friction plane with gap test, own normals", update = "usf", plane = true, wall_gap = 0.5,
    contact = { normals = "own", conserve = true } },
  { name = "usl, linear normals, pic", update = "usl", pic = 0.3, contact = { normals = "linear" } },
}

return { run = run, cases = cases }
