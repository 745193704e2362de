-- The boundary between a script and the Lua-side library. A public function wrapped here reports
-- an error at the user's line, as a C binding does: whether the library's own checks raised it or
-- a C call the library made (s:run inside grainlab.pack.settle), the message carries the position
-- of the first line of the user's code on the stack instead of a line of lua/grainlab/*.lua.
--   pack.deposit = entry.wrap(pack.deposit)
-- A runtime error in the library's own code (a bug: "attempt to index a nil value") keeps its
-- position and gets the library's traceback, so it can be found.
local entry = {}

local LIBRARY = "@lua/grainlab/" -- the chunk names of the embedded modules (cmake/embed_lua.cmake)

local function is_library(info) return info.source:sub(1, #LIBRARY) == LIBRARY end

-- "file:line: " of the innermost frame of the user's code, counted from the message handler's
-- caller (level 3 here: 1 is this function, 2 the handler, 3 the function that raised).
local function user_where()
  for level = 3, math.huge do
    local info = debug.getinfo(level, "Sl")
    if not info then return "" end
    if info.what ~= "C" and not is_library(info) then
      return info.currentline > 0 and string.format("%s:%d: ", info.short_src, info.currentline) or ""
    end
  end
end

local function handler(msg)
  if type(msg) ~= "string" or msg:find("\nstack traceback:\n", 1, true) then return msg end
  local rest = msg:match("^lua/grainlab/[%w_]+%.lua:%d+: (.*)$")
  if not rest then return msg end -- the user's own position (a callback), or none
  local raiser = debug.getinfo(2, "S")
  if raiser and raiser.what ~= "C" and is_library(raiser) then
    return debug.traceback(msg, 2) -- raised by the virtual machine in the library's code
  end
  return user_where() .. rest
end

-- The entry the script called, while it runs (the outermost one when entries nest): the C
-- bindings name it in their notices (bind_entry_name), so that a note about a grain that
-- grainlab.pack.deposit added says "grainlab.pack.deposit", not "add_disk".
local state = {}
debug.getregistry()["grainlab.entry"] = state

-- The error is raised from the wrapper's own frame (not a tail call), so that a traceback goes
-- from the user's line straight to the entry.
function entry.wrap(fn, name)
  return function(...)
    local outer = state.current
    state.current = outer or name
    local r = table.pack(xpcall(fn, handler, ...))
    state.current = outer
    if not r[1] then error(r[2], 0) end
    return table.unpack(r, 2, r.n)
  end
end

-- Wraps every function of a module table in place; prefix names them ("grainlab.pack").
function entry.wrap_all(module, prefix)
  for name, v in pairs(module) do
    if type(v) == "function" then module[name] = entry.wrap(v, prefix .. "." .. name) end
  end
  return module
end

return entry
