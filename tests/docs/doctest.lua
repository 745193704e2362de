-- Doc test: every ```lua block of one Markdown file runs as written. Each block is saved as a
-- script and run by the grainlab binary under test in a fresh scratch directory (with an empty
-- out/ there), so a block sees what a user pasting it sees; a block that raises, or whose report
-- fails a check, fails the test with the file and line where the block starts. API sketches with
-- placeholders belong in tables or ```text blocks, which are not run.
--   grainlab tests/docs/doctest.lua file=README.md exe=build/grainlab [keep=true]
-- (keep=true keeps the scratch directories)
local file, exe = params.file, params.exe
assert(type(file) == "string" and type(exe) == "string", "usage: doctest.lua file=FILE.md exe=GRAINLAB")

local function quote(s) return "'" .. tostring(s):gsub("'", "'\\''") .. "'" end
if exe:sub(1, 1) ~= "/" and exe:find("/", 1, true) then -- relative to here; blocks run elsewhere
  local pwd = io.popen("pwd")
  exe = pwd:read("l") .. "/" .. exe
  pwd:close()
end

-- Collect the blocks: a fence line ```lua opens, the next line of ``` closes.
local blocks, open, n = {}, nil, 0
local fh = assert(io.open(file, "r"))
for line in fh:lines() do
  n = n + 1
  if open then
    if line:match("^%s*```%s*$") then
      blocks[#blocks + 1] = open
      open = nil
    else
      open.lines[#open.lines + 1] = line
    end
  elseif line:match("^%s*```lua%s*$") then
    open = { line = n, lines = {} }
  end
end
fh:close()
if open then
  io.stderr:write(string.format("%s:%d: ```lua block never closed\n", file, open.line))
  os.exit(1)
end

-- Scratch directory: one per block, removed afterwards (a failure prints the block's output).
local base = os.tmpname()
os.remove(base)
local failed = 0
for k, b in ipairs(blocks) do
  local dir = string.format("%s_doc%d", base, k)
  assert(os.execute("mkdir -p " .. quote(dir .. "/out")))
  local script = dir .. "/block.lua"
  local out = assert(io.open(script, "w"))
  out:write(table.concat(b.lines, "\n"), "\n")
  out:close()
  local log = dir .. "/log.txt"
  local t0 = grainlab.clock()
  local ok = os.execute(string.format("cd %s && %s --quiet block.lua > log.txt 2>&1",
                                      quote(dir), quote(exe)))
  local secs = grainlab.clock() - t0
  local lf = io.open(log, "r")
  local text = lf and lf:read("a") or ""
  if lf then lf:close() end
  if ok then
    print(string.format("ok    %s:%d (%d lines, %.2f s)", file, b.line, #b.lines, secs))
  else
    failed = failed + 1
    -- Error positions inside the block ("block.lua:7:") point into the Markdown file.
    text = text:gsub("block%.lua:(%d+):", function(l) return string.format("%s:%d:", file, b.line + tonumber(l)) end)
    print(string.format("FAIL  %s:%d: the ```lua block starting here does not run as written:\n%s",
                        file, b.line, text))
  end
  if params.keep then print("      scratch directory kept: " .. dir) else os.execute("rm -rf " .. quote(dir)) end
end
print(string.format("%s: %d lua blocks, %d failed", file, #blocks, failed))
if failed > 0 then os.exit(1) end
