-- help(x): the documentation of any API object, from the doc registry the bindings fill.
local grainlab = grainlab

local function indent(text, pad)
  return pad .. text:gsub("\n", "\n" .. pad)
end

local function first_line(text) return (text:match("^[^\n]*")) end

local function resolve(path)
  local v = _G
  for sep, name in ("." .. path):gmatch("([.:])([%a_][%w_]*)") do
    if type(v) ~= "table" and not (getmetatable(v) and type(getmetatable(v).__index) == "table") then
      return nil
    end
    local ok, field = pcall(function() return v[name] end)
    if not ok then return nil end
    v = field
  end
  return v
end

-- Fields of a table (or of a userdata's methods), each with the first line of its doc.
local function list_fields(t, out)
  local names = {}
  for k in pairs(t) do if type(k) == "string" and not k:match("^_") then names[#names + 1] = k end end
  table.sort(names)
  for _, k in ipairs(names) do
    local v = t[k]
    local d = grainlab.doc_of(v)
    local what = d and first_line(d.doc) or (type(v) == "table" and "(table)" or type(v))
    if type(v) ~= "function" and type(v) ~= "table" then what = type(v) .. ": " .. tostring(v) end
    out[#out + 1] = string.format("  %-14s %s", k, what)
  end
end

local function help(x, ...)
  if select("#", ...) > 0 then error("help takes one argument", 2) end
  local out = {}
  if x == nil then
    out[#out + 1] = "grainlab " .. grainlab.version ..
      ": granular materials on three scales (MPM, DEM, DSMC), scripted in Lua 5.4."
    out[#out + 1] = "  help(x)        documentation of an API object: help(grainlab.report), help('grainlab.rng')"
    out[#out + 1] = "  params         the name=value pairs given on the command line"
    out[#out + 1] = "Modules:"
    local mods = {}
    for k, v in pairs(_G) do
      local d = type(v) == "table" and grainlab.doc_of(v)
      if d then mods[#mods + 1] = string.format("  %-14s %s", k, first_line(d.doc)) end
    end
    table.sort(mods)
    for _, m in ipairs(mods) do out[#out + 1] = m end
  else
    if type(x) == "string" then
      local v = resolve(x)
      if v == nil then
        print("help: no API object named '" .. x .. "'")
        return
      end
      x = v
    end
    local d = grainlab.doc_of(x)
    local mt = getmetatable(x)
    if not d and type(x) == "userdata" and type(mt) == "table" then d = grainlab.doc_of(mt) end
    if d then
      out[#out + 1] = d.usage
      if d.doc ~= "" then out[#out + 1] = indent(d.doc, "  ") end
    else
      out[#out + 1] = "no documentation for this " .. type(x)
    end
    if type(x) == "table" then
      list_fields(x, out)
    elseif type(mt) == "table" and type(mt.__index) == "table" then
      out[#out + 1] = "methods:"
      list_fields(mt.__index, out)
    end
  end
  print(table.concat(out, "\n"))
end

grainlab.doc(help, { name = "help", usage = "help([x])",
  doc = "Prints the documentation of x (an API function, module, object, or its name as a string);\nwith no argument, an overview." })
return help
