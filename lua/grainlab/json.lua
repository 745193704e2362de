-- JSON encoding for reports: objects with sorted keys (so equal reports give equal files),
-- arrays, numbers in the shortest form that reads back exactly, strings, booleans.
-- Non-finite numbers have no JSON form and are written as null.
local json = {}

local escapes = { ['"'] = '\\"', ['\\'] = '\\\\', ['\b'] = '\\b', ['\f'] = '\\f',
                  ['\n'] = '\\n', ['\r'] = '\\r', ['\t'] = '\\t' }

local function encode_string(s)
  return '"' .. s:gsub('[%c"\\]', function(c)
    return escapes[c] or string.format('\\u%04x', c:byte())
  end) .. '"'
end

local function encode_number(x)
  if math.type(x) == "integer" then return string.format("%d", x) end
  if x ~= x or x == math.huge or x == -math.huge then return "null" end
  for digits = 15, 17 do
    local s = string.format("%." .. digits .. "g", x)
    if tonumber(s) == x then return s end
  end
end

local function is_array(t)
  local n = #t
  for k in pairs(t) do
    if math.type(k) ~= "integer" or k < 1 or k > n then return false end
  end
  return true
end

local function encode(v, indent, path, out, seen)
  local tv = type(v)
  if tv == "string" then out[#out + 1] = encode_string(v)
  elseif tv == "number" then out[#out + 1] = encode_number(v)
  elseif tv == "boolean" then out[#out + 1] = tostring(v)
  elseif tv == "nil" then out[#out + 1] = "null"
  elseif tv == "table" then
    if seen[v] then error("cannot encode a table that contains itself (at " .. path .. ")", 0) end
    seen[v] = true
    local inner = indent .. "  "
    if next(v) == nil then
      out[#out + 1] = is_array(v) and "[]" or "{}"
    elseif is_array(v) then
      out[#out + 1] = "[\n"
      for i = 1, #v do
        out[#out + 1] = inner
        encode(v[i], inner, path .. "[" .. i .. "]", out, seen)
        out[#out + 1] = i < #v and ",\n" or "\n"
      end
      out[#out + 1] = indent .. "]"
    else
      local keys = {}
      for k in pairs(v) do
        if type(k) ~= "string" then
          error("cannot encode a non-string key " .. tostring(k) .. " (at " .. path .. ")", 0)
        end
        keys[#keys + 1] = k
      end
      table.sort(keys)
      out[#out + 1] = "{\n"
      for i, k in ipairs(keys) do
        out[#out + 1] = inner .. encode_string(k) .. ": "
        encode(v[k], inner, path .. "." .. k, out, seen)
        out[#out + 1] = i < #keys and ",\n" or "\n"
      end
      out[#out + 1] = indent .. "}"
    end
    seen[v] = nil
  else
    error("cannot encode a " .. tv .. " (at " .. path .. ")", 0)
  end
end

-- json.encode(value) -> string (pretty-printed, two-space indent, trailing newline).
function json.encode(value)
  local out = {}
  encode(value, "", "value", out, {})
  out[#out + 1] = "\n"
  return table.concat(out)
end

return json
