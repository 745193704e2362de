-- Every function of the API answers help() with its own text: the modules (grainlab and its
-- Lua-side parts, dem, mpm, dsmc, render, analysis) and the methods of every userdata type.
-- A new function without a doc record fails here.
local check = grainlab.check

local captured = dofile("../lua/lib/captured.lua")

local missing, checked, seen = {}, 0, {}
local function own_help(path, fn)
  checked = checked + 1
  local d = grainlab.doc_of(fn)
  if not d or d.doc == "" or d.usage == "" then
    missing[#missing + 1] = path
    return
  end
  local text = captured(help, fn)
  if text:find("no documentation", 1, true) or text:sub(1, #d.usage) ~= d.usage then
    missing[#missing + 1] = path .. " (help shows: " .. text:sub(1, 60) .. ")"
  end
end

local function walk(path, t, sep)
  if seen[t] then return end
  seen[t] = true
  for k, v in pairs(t) do
    local p = path .. sep .. tostring(k)
    if type(v) == "function" then
      own_help(p, v)
    elseif type(v) == "table" and type(k) == "string" then
      walk(p, v, ".")
    end
  end
end

for _, m in ipairs{ "grainlab", "dem", "mpm", "dsmc", "render", "analysis" } do
  check.eq(type(_G[m]), "table", m .. " is loaded")
  check.is_true(grainlab.doc_of(_G[m]), m .. " is documented")
  walk(m, _G[m], ".")
end
for _, m in ipairs{ "pack", "biax", "check" } do
  check.is_true(grainlab.doc_of(grainlab[m]), "grainlab." .. m .. " is documented")
end
own_help("help", help)

-- The scene types and the other userdata types, from their named metatables: a new type is
-- walked without being listed here.
local types = {}
for name, mt in pairs(debug.getregistry()) do
  if type(name) == "string" and type(mt) == "table" and type(rawget(mt, "__index")) == "table" and
     (name:match("^grainlab%.") or name:match("^dem%.") or name:match("^mpm%.") or
      name:match("^dsmc%.") or name:match("^render%.") or name:match("^analysis%.")) then
    types[#types + 1] = name
    check.is_true(grainlab.doc_of(mt), name .. " is documented")
    walk(name, rawget(mt, "__index"), ":")
  end
end
table.sort(types)
for _, t in ipairs{ "dem.scene", "mpm.scene", "dsmc.scene", "render.image", "grainlab.rng" } do
  check.contains(" " .. table.concat(types, " ") .. " ", " " .. t .. " ", "type " .. t .. " walked")
end

table.sort(missing)
check.eq(table.concat(missing, "\n"), "", "functions without their own help text")
check.gt(checked, 100, "functions walked")
check.contains(captured(help, grainlab.pack.deposit), "grainlab.pack.deposit(s, { n =", "help(grainlab.pack.deposit)")
check.contains(captured(help, grainlab.pack.deposit), "gravity deposition", "pack.deposit's own text")
check.contains(captured(help, "grainlab.biax.setup"), "grainlab.biax.setup(state, bc, cfg)", "help by name")
check.contains(captured(help, grainlab.pack), "deposit        gravity deposition", "module listing keeps first lines")
check.done()
