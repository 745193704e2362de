-- grainlab.figures: where a script's figures go. images/ holds the figures README.md and docs/
-- show, made by each script's full-size run; any other run (reduced size, shorter, another
-- seed or material) writes into out/ or the directory it is given, so a quick run or a test
-- never overwrites a published figure. Every script asks here, so the rule lives in one place.
local figures = {}

local function describe(v)
  if type(v) == "string" then return "'" .. v:gsub("\0", "\\0") .. "'" end
  if type(v) == "number" or type(v) == "boolean" then return tostring(v) end
  return type(v)
end

-- figures.published(actual, full): true when every parameter named in `full` has in `actual` the
-- value of the published (full-size) run. Both are tables name -> value; numbers compare exactly
-- (a parameter given on the command line with its default value still publishes).
function figures.published(actual, full)
  if type(actual) ~= "table" then
    error("bad argument #1 to 'published' (table expected, got " .. describe(actual) .. ")", 2)
  end
  if type(full) ~= "table" then
    error("bad argument #2 to 'published' (table expected, got " .. describe(full) .. ")", 2)
  end
  for name, value in pairs(full) do
    if actual[name] ~= value then return false end
  end
  return true
end

local function mkdir(dir)
  -- Directories of our own making: plain names, quoted for the shell.
  os.execute("mkdir -p '" .. dir:gsub("'", "'\\''") .. "'")
end

-- Checks opts (argument #argn of call `fname`) and returns the directory, created.
local function resolve(opts, argn, fname)
  if type(opts) ~= "table" then
    error(string.format("bad argument #%d to '%s' (table expected, got %s)", argn, fname, describe(opts)), 3)
  end
  if type(opts.published) ~= "boolean" then
    error(string.format("bad field 'published' in argument #%d to '%s' (boolean expected, got %s)",
                        argn, fname, describe(opts.published)), 3)
  end
  if opts.out ~= nil and (type(opts.out) ~= "string" or opts.out == "") then
    error(string.format("bad field 'out' in argument #%d to '%s' (directory name expected, got %s)",
                        argn, fname, describe(opts.out)), 3)
  end
  if opts.out and opts.out:find("\0", 1, true) then -- the shell would end the name there
    error(string.format("bad field 'out' in argument #%d to '%s' (directory name without NUL bytes expected, got %s)",
                        argn, fname, describe(opts.out)), 3)
  end
  for k in pairs(opts) do
    if k ~= "published" and k ~= "out" then
      error(string.format("bad argument #%d to '%s' (unknown field '%s'; valid fields: out, published)",
                          argn, fname, tostring(k)), 3)
    end
  end
  local dir = opts.published and "images" or (opts.out or "out")
  mkdir(dir)
  return dir
end

-- figures.dir{ published = bool, out = dir }: "images" for a published run, else `out`
-- (default "out"); the directory is created.
function figures.dir(opts)
  return resolve(opts, 1, "dir")
end

-- figures.path(name, { published = bool, out = dir }): the path of figure `name` (a file name or
-- a prefix the script completes), images/name for a published run, else out/name.
function figures.path(name, opts)
  if type(name) ~= "string" or name == "" or name:find("/", 1, true) then
    error("bad argument #1 to 'path' (file name without a directory expected, got " ..
          describe(name) .. ")", 2)
  end
  if name:find("\0", 1, true) then
    error("bad argument #1 to 'path' (file name without NUL bytes expected, got " .. describe(name) .. ")", 2)
  end
  return resolve(opts, 2, "path") .. "/" .. name
end

return figures
