-- Every contact law of src/dem/laws.h goes by one name everywhere: the names s:contact accepts
-- (listed by its refusal of an unknown one) are the ones s:info returns after choosing each, the
-- ones s:contact's usage line in help() offers, and each one but 'none' is in docs/dem.md's law
-- table. A row added to laws.h without its help and docs fails here.
--   grainlab tests/dem/test_law_names.lua docs=docs/dem.md
local check = grainlab.check
local docs = assert(params.docs, "give docs=PATH of docs/dem.md")

-- field of s:contact, the label of its row in docs/dem.md's table, s:info's key
local fields = {
  { field = "normal", row = "normal", info = "normal" },
  { field = "damping", row = "damping", info = "damping" },
  { field = "tangential", row = "tangential", info = "tangential" },
  { field = "rolling_resistance", row = "rolling resistance", info = "rolling_resistance" },
  { field = "cohesion", row = "cohesion", info = "cohesion" },
}

local function scene() return dem.scene{ dim = 2, box = { { 0, 0 }, { 1, 1 } } } end

-- the names s:contact accepts, in the order of its list
local function accepted(field)
  local s = scene()
  local msg = check.errors(function() s:contact{ [field] = "no such law" } end,
                           "bad field '" .. field .. "' in argument #1 to 'contact' (one of ",
                           field .. ": an unknown law is refused with the list")
  local list = assert(msg:match("%(one of (.-) expected"), msg)
  local names = {}
  for name in list:gmatch("'([%w_]+)'") do names[#names + 1] = name end
  return names
end

-- a contact table choosing law `name` for `field`, with what that law requires
local function choose(field, name)
  local c = { [field] = name }
  if field == "normal" and (name == "linear" or name == "power") then c.stiffness = 1e5 end
  if field == "cohesion" and name == "capillary" then
    c.liquid_volume, c.surface_tension = 1e-12, 0.07
  end
  if field == "damping" then c.normal = "hertz" end
  return c
end

local usage = grainlab.doc_of(scene().contact).usage
local text = assert(io.open(docs)):read("a")

local total = 0
for _, f in ipairs(fields) do
  local names = accepted(f.field)
  check.is_true(#names >= 2, f.field .. ": at least two laws listed")
  total = total + #names
  local set = {}
  for _, name in ipairs(names) do
    set[name] = true
    -- s:info names the law chosen
    local s = scene()
    s:contact(choose(f.field, name))
    check.eq(s:info()[f.info], name, f.field .. " = '" .. name .. "': s:info returns its name")
  end

  -- help(): the usage line's alternatives for the field, as a set
  local alts = usage:match(f.field .. " = ('[^,]-')[,}]")
  check.is_true(alts ~= nil, f.field .. ": the usage line lists its laws")
  local offered = {}
  for name in (alts or ""):gmatch("'([%w_]+)'") do offered[name] = true end
  for name in pairs(set) do
    check.is_true(offered[name], f.field .. " = '" .. name .. "': in help(s.contact)'s usage")
  end
  for name in pairs(offered) do
    check.is_true(set[name], f.field .. " = '" .. name .. "': help offers only laws s:contact accepts")
  end

  -- docs/dem.md: the law table's row names each law ('none' is the absence of one)
  local row = text:match("\n| " .. f.row:gsub("%p", "%%%0") .. " | ([^\n]*)")
  check.is_true(row ~= nil, "docs/dem.md's law table has a row '" .. f.row .. "'")
  for _, name in ipairs(names) do
    if name ~= "none" then
      check.is_true((row or ""):find("`" .. name .. "`", 1, true) ~= nil,
                    string.format("docs/dem.md's row '%s' names `%s`", f.row, name))
    end
  end
end
print(string.format("%d laws in %d lists: one name each in s:contact, s:info, help and docs/dem.md",
                    total, #fields))
check.done()
