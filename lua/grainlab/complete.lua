-- Tab completion for the REPL: the candidates for the word being typed ("s:ad" -> "s:add_disk(").
-- Walks tables and the __index tables of metatables with rawget only, so completing never runs
-- user code.
local keywords = { "and", "break", "do", "else", "elseif", "end", "false", "for", "function",
                   "goto", "if", "in", "local", "nil", "not", "or", "repeat", "return", "then",
                   "true", "until", "while" }

local function lookup(v, key, depth)
  depth = depth or 0
  if depth > 8 then return nil end
  if type(v) == "table" then
    local r = rawget(v, key)
    if r ~= nil then return r end
  end
  local mt = getmetatable(v)
  if type(mt) == "table" and type(rawget(mt, "__index")) == "table" then
    return lookup(rawget(mt, "__index"), key, depth + 1)
  end
  return nil
end

local function names_of(v, out, depth)
  depth = depth or 0
  if depth > 8 then return end
  if type(v) == "table" then
    for k in next, v do
      if type(k) == "string" and k:match("^[%a_][%w_]*$") then out[k] = out[k] or lookup(v, k) end
    end
  end
  local mt = getmetatable(v)
  if type(mt) == "table" and type(rawget(mt, "__index")) == "table" then
    names_of(rawget(mt, "__index"), out, depth + 1)
  end
end

return function(word)
  local path, sep, partial = word:match("^([%a_][%w_.]*)([.:])([%w_]*)$")
  local base = _G
  if path then
    for name in path:gmatch("[^.]+") do
      base = lookup(base, name)
      if base == nil then return {} end
    end
  else
    if not word:match("^[%a_]?[%w_]*$") then return {} end
    path, sep, partial = "", "", word
  end
  local found = {}
  names_of(base, found)
  local list = {}
  for name, value in pairs(found) do
    if name:sub(1, #partial) == partial and (sep ~= ":" or type(value) == "function") then
      list[#list + 1] = { name, value }
    end
  end
  if sep == "" then
    for _, k in ipairs(keywords) do
      if k:sub(1, #partial) == partial then list[#list + 1] = { k, nil } end
    end
  end
  table.sort(list, function(a, b) return a[1] < b[1] end)
  local out = {}
  for i, item in ipairs(list) do
    local suffix = ""
    if #list == 1 then
      local t = type(item[2])
      suffix = (t == "function" and "(") or (t == "table" and sep ~= ":" and ".") or ""
    end
    out[i] = path .. sep .. item[1] .. suffix
  end
  return out
end
