-- Functions the checkpoint tests share: read and write a file whole, forge files a real writer
-- could have produced (the container's FNV-1a 64 checksum recomputed over a changed body, so that
-- a changed field reaches the checks behind the checksum), and compare two states dumped as text.
local M = {}

function M.read(path)
  local f = assert(io.open(path, "rb"))
  local s = f:read("a")
  f:close()
  return s
end

function M.write(path, s)
  local f = assert(io.open(path, "wb"))
  f:write(s)
  f:close()
end

-- FNV-1a 64 of everything before the last 8 bytes, stored there (Lua integers wrap).
function M.reseal(s)
  local h = -3750763034362895579 -- 0xcbf29ce484222325
  for i = 1, #s - 8 do h = (h ~ s:byte(i)) * 0x100000001b3 end
  return s:sub(1, #s - 8) .. string.pack("<i8", h)
end

-- The offset (0-based) just after the payload of s's section of that tag, before its padding:
-- values at the end of a section are forged at F.section_end(s, tag) - 8 and below.
function M.section_end(s, tag)
  local at = 64
  while at < #s - 24 do
    local t = s:sub(at + 1, at + 16):gsub("%z+$", "")
    local size = string.unpack("<I8", s, at + 25)
    if t == tag then return at + 32 + size end
    at = at + 32 + size + (8 - size % 8) % 8
  end
  error("no section '" .. tag .. "'")
end

-- s with bytes written over it after position at.
function M.put(s, at, bytes) return s:sub(1, at) .. bytes .. s:sub(at + #bytes + 1) end

-- Two states dumped as lists of lines (values as %a) are the same: the line count, the first line
-- that differs (by its number), then the whole.
function M.same_lines(a, b, what)
  local check = grainlab.check
  check.eq(#a, #b, what .. ": line count")
  for i = 1, #a do
    if a[i] ~= b[i] then check.eq(b[i], a[i], string.format("%s: line %d", what, i)) end
  end
  check.eq(table.concat(a, "\n"), table.concat(b, "\n"), what)
end

return M
