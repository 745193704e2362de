-- The granular column of scripts/demo.lua (the DEM collapse), shared with
-- scripts/column_two_scales.lua, which runs the same column as a continuum. Not a scenario; load
-- it with
--   local dem_column = dofile((arg[0]:match("^(.*)/") or ".") .. "/lib/dem_column.lua")
-- The set-up and its reasons are in scripts/demo.lua's header.
--
-- dem_column.new{ n, seed, aspect, young, mu } builds the scene: the floor of fixed disks under
-- the column (radius rf, tops at y = 0), the walls (below the floor, x = 0, x = L) and the gate
-- (x = W0), n disks deposited behind the gate, the collapse's contact law. The returned column c
-- has c.s (the scene), c.nf (the floor disks under the column, the scene's first particles),
-- c.n, c.W0, c.H0 (the nominal height n area / W0), c.L, c.walls, c.gate_def, c.mat and the
-- constants below, and the methods:
--   c:prepare()          the preparation at the stability limit (drag, then none); sets c.dt
--                        and c.v_imp (the collapse's step and impact speed); returns c:state()
--   c:release()          removes the gate and lays the floor beyond it
--   c:collapse(on_slice) runs slices of c.frame_dt until, after at least T_min, the fastest grain
--                        is below v_rest (at most T_max); on_slice(t, state) after each slice;
--                        returns t and the last state; c.steps and c.run_wall (the wall time of
--                        the runs alone) count the collapse's steps
--   c:state()            front (x + r of the 99th-percentile grain in x), xmax, vmax, height (top
--                        of the highest grain over x < W0), inside (grains in the box), ke
--                        (kinetic + rotational), total energy
--   c:overlap_max()      the deepest overlap over the smaller radius of its pair
--   c:surface(x0, dx, k) the deposit's surface: for k bins of width dx from x0, the top (y + r) of
--                        the highest grain whose centre lies in the bin (0 where none)
local dem_column = {}
dem_column.__index = dem_column

local g, rho, nu = 9.81, 2650, 0.3
local rmin, rmax, rf = 0.5e-3, 1e-3, 0.5e-3
local e_rest, v_e = 0.5, 1.0
local v_rest, T_max, T_min = 5e-3, 1.5, 0.4
dem_column.gravity, dem_column.density, dem_column.poisson = g, rho, nu
dem_column.radius_min, dem_column.radius_max, dem_column.floor_radius = rmin, rmax, rf
dem_column.restitution, dem_column.v_rest, dem_column.T_max, dem_column.T_min = e_rest, v_rest, T_max, T_min

function dem_column.new(o)
  local n, seed, aspect, young, mu = o.n, o.seed, o.aspect, o.young, o.mu
  -- Area per disk in a random packing: pi <r^2> / 0.82, <r^2> = (rmax^3 - rmin^3) / (3 (rmax - rmin)).
  local area = math.pi * (rmax ^ 3 - rmin ^ 3) / (3 * (rmax - rmin)) / 0.82
  local W0 = 2 * rf * math.floor(math.sqrt(n * area / aspect) / (2 * rf) + 0.5) -- whole floor disks
  local H0 = n * area / W0
  local L = W0 * (1 + 3.5 * aspect)   -- room for the runout
  -- Headroom: 12 %, but at least two grain diameters (a column of a few rows packs less evenly).
  local top = math.max(1.12 * H0, H0 + 4 * rmax)

  local mat = grainlab.material{ density = rho, young = young, poisson = nu, friction = mu }
  local s = dem.scene{ dim = 2, box = { { 0, -2 * rf - 1e-6 }, { L, top } }, gravity = { 0, -g } }
  s:contact{ normal = "hertz", tangential = "spring" } -- for pack.deposit's own bookkeeping
  local walls = {
    { point = { 0, -2 * rf - 1e-6 }, normal = { 0, 1 } },
    { point = { 0, 0 }, normal = { 1, 0 } },
    { point = { L, 0 }, normal = { -1, 0 } },
  }
  for _, w in ipairs(walls) do s:add_wall(w) end
  local gate_def = { point = { W0, 0 }, normal = { -1, 0 } }
  local c = setmetatable({ s = s, n = n, nf = 0, W0 = W0, H0 = H0, L = L, walls = walls,
                           gate_def = gate_def, mat = mat, frame_dt = o.frame_dt or 0.005 }, dem_column)
  c.gate = s:add_wall(gate_def)
  c:add_floor(false)
  grainlab.pack.deposit(s, { n = n, radius = { rmin, rmax }, seed = seed, material = mat,
                             region = { { 0, -2 * rf }, { W0, top } }, relax_steps = 0 })
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = e_rest, impact_velocity = v_e,
             tangential = "spring" }
  return c
end

-- The floor: touching fixed disks, a whole number of them under the column. A wall is a half
-- space, so the disks beyond the gate are added when the gate is removed (ids after the grains).
function dem_column:add_floor(beyond_gate)
  local s, W0, L = self.s, self.W0, self.L
  for k = 0, math.floor(L / (2 * rf)) - 1 do
    local x = rf + 2 * rf * k
    if (x > W0) == beyond_gate and x + rf < L then
      s:add_disk{ pos = { x, -rf }, radius = rf, material = self.mat, fixed = true }
      if not beyond_gate then self.nf = self.nf + 1 end
    end
  end
end

-- State of the mobile grains (ids nf+1 .. nf+n).
function dem_column:state()
  local s, nf, n, W0 = self.s, self.nf, self.n, self.W0
  local P = s:particles()
  local xs, vmax, height, xmax, inside = {}, 0, 0, 0, 0
  local lo, hi = s:info().box[1], s:info().box[2]
  for i = nf + 1, nf + n do
    local x, y, r = P.x[i], P.y[i], P.radius[i]
    xs[#xs + 1] = x + r
    xmax = math.max(xmax, x + r)
    vmax = math.max(vmax, math.sqrt(P.vx[i] ^ 2 + P.vy[i] ^ 2))
    if x < W0 then height = math.max(height, y + r) end
    if x >= lo[1] and x <= hi[1] and y >= lo[2] and y <= hi[2] then inside = inside + 1 end
  end
  table.sort(xs)
  local e = s:measure("energy")
  return { front = xs[math.max(1, math.ceil(0.99 * #xs))], xmax = xmax, vmax = vmax,
           height = height, inside = inside,
           ke = e.kinetic + e.rotational, total = e.total }
end

function dem_column:overlap_max()
  local s = self.s
  local C, m = s:measure("contacts"), 0
  local P = s:particles()
  for k = 1, #C.overlap do
    local i, j = C.i[k], C.j[k]
    local r = j > 0 and math.min(P.radius[i], P.radius[j]) or P.radius[i]
    m = math.max(m, C.overlap[k] / r)
  end
  return m
end

-- Preparation at the stability limit, then the collapse's time step at impact speed
-- sqrt(2 g H0).
function dem_column:prepare()
  local s = self.s
  local dt_prep = s:timestep{ impact_velocity = 0.5 }.limit
  s:drag(20)
  s:run{ time = 0.1, dt = dt_prep, impact_velocity = 0.5, progress = false }
  s:drag(0)
  s:run{ time = 0.02, dt = dt_prep, impact_velocity = 0.5, progress = false }
  self.v_imp = math.sqrt(2 * g * self.H0)
  self.dt = s:timestep{ impact_velocity = self.v_imp }.dt_auto
  return self:state()
end

function dem_column:release()
  self.s:remove_wall(self.gate)
  self:add_floor(true)
end

function dem_column:collapse(on_slice)
  local t, st = 0, nil
  self.steps, self.run_wall = 0, 0
  while t < T_max - 1e-9 do
    local c = grainlab.clock()
    local r = self.s:run{ time = self.frame_dt, dt = self.dt, impact_velocity = self.v_imp, progress = false }
    self.run_wall = self.run_wall + grainlab.clock() - c
    self.steps = self.steps + r.steps
    t = t + self.frame_dt
    st = self:state()
    if on_slice then on_slice(t, st) end
    if t >= T_min - 1e-9 and st.vmax < v_rest then break end
  end
  return t, st
end

function dem_column:surface(x0, dx, k)
  local P = self.s:particles()
  local tops = {}
  for b = 1, k do tops[b] = 0 end
  for i = self.nf + 1, self.nf + self.n do
    local b = math.floor((P.x[i] - x0) / dx) + 1
    if b >= 1 and b <= k then tops[b] = math.max(tops[b], P.y[i] + P.radius[i]) end
  end
  return tops
end

return dem_column
