-- grainlab.material{…}: a validated, read-only description of a grain material, shared by the
-- methods (DEM reads density, young, poisson, friction, restitution, rolling_friction,
-- work_of_adhesion).
local FIELDS = {
  name        = { kind = "string" },
  density     = { kind = "positive", required = true },  -- kg/m^3
  young       = { kind = "positive", required = true },  -- Pa
  poisson     = { kind = "range", lo = 0, hi = 0.5, open_hi = true, default = 0.3 },
  friction    = { kind = "nonneg", default = 0 },         -- Coulomb coefficient
  restitution = { kind = "range", lo = 0, hi = 1, open_lo = true, default = 1 },
  rolling_friction = { kind = "nonneg", default = 0 },    -- rolling resistance mu_r (DEM)
  work_of_adhesion = { kind = "nonneg", default = 0 },    -- Gamma, J/m^2 (DEM jkr, dmt)
}

local function describe(v)
  if type(v) == "string" then return "'" .. v .. "'" end
  if type(v) == "number" or type(v) == "boolean" then return tostring(v) end
  return type(v)
end

local function bad(field, expected, got)
  error(string.format("bad field '%s' in argument #1 to 'material' (%s expected, got %s)",
                      field, expected, describe(got)), 3)
end

-- A material is shared by every grain and wall made of it (and registered once per scene), so it
-- cannot change afterwards: the fields live in a private table behind __index, and every
-- assignment -- to a field that exists or not -- is refused, naming the field.
local values_of = setmetatable({}, { __mode = "k" })
local meta = {
  __name = "grainlab.material",
  __index = function(m, k) return values_of[m][k] end,
  __newindex = function(_, k)
    error(string.format("a grainlab.material is read-only: field %s cannot be set (make a new one with grainlab.material{...})",
                        describe(k)), 2)
  end,
  __pairs = function(m) return next, values_of[m], nil end,
  __tostring = function(m)
    return string.format("grainlab.material %s(density %g, young %g, poisson %g, friction %g, restitution %g)",
      m.name and (m.name .. " ") or "", m.density, m.young, m.poisson, m.friction, m.restitution)
  end,
}

local function material(t)
  if type(t) ~= "table" then
    error("bad argument #1 to 'material' (table expected, got " .. type(t) .. ")", 2)
  end
  for k in pairs(t) do
    if not FIELDS[k] then
      error("bad argument #1 to 'material' " .. require("grainlab.args").unknown(k,
        { "density", "friction", "name", "poisson", "restitution", "rolling_friction",
          "work_of_adhesion", "young" }), 2)
    end
  end
  local m = {}
  for name, f in pairs(FIELDS) do
    local v = t[name]
    if v == nil then
      if f.required then bad(name, f.kind == "positive" and "positive number" or "number", nil) end
      v = f.default
    elseif f.kind == "string" then
      if type(v) ~= "string" then bad(name, "string", v) end
    else
      local ok = type(v) == "number" and v == v and v >= -1e100 and v <= 1e100 -- as the C bindings
      if f.kind == "positive" then ok = ok and v > 0
      elseif f.kind == "nonneg" then ok = ok and v >= 0
      else
        ok = ok and (f.open_lo and v > f.lo or not f.open_lo and v >= f.lo)
                and (f.open_hi and v < f.hi or not f.open_hi and v <= f.hi)
      end
      if not ok then
        local expected = f.kind == "positive" and "positive number" or f.kind == "nonneg" and "non-negative number"
          or string.format("number in %s%g, %g%s", f.open_lo and "(" or "[", f.lo, f.hi, f.open_hi and ")" or "]")
        bad(name, expected, v)
      end
    end
    m[name] = v
  end
  local proxy = setmetatable({}, meta)
  values_of[proxy] = m
  return proxy
end

local field_names = {}
for name in pairs(FIELDS) do field_names[#field_names + 1] = name end
table.sort(field_names)
grainlab.doc(material, { name = "grainlab.material", fields = field_names,
  usage = "grainlab.material{ density = 2650, young = 30e9, poisson = 0.3, friction = 0.45, restitution = 0.5, rolling_friction = 0, work_of_adhesion = 0, name = 'quartz' }",
  doc = [[A read-only grain material. density (kg/m^3) and young (Pa) are required; poisson defaults
to 0.3, friction (Coulomb mu) to 0, restitution to 1 (elastic), rolling_friction (the rolling
resistance mu_r of a DEM contact law with rolling_resistance) to 0, work_of_adhesion (the work
of adhesion Gamma in J/m^2 of the DEM normal laws jkr and dmt, twice the surface energy per
surface) to 0. A DEM pair uses the smaller friction, restitution and rolling_friction of its two
materials, the geometric mean of their work_of_adhesion and the effective modulus of both.]] })
return material
