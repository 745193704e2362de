-- Doc test: every ```lua block of one Markdown file runs as written. Each block is saved as a
-- script and run by the grainlab binary under test in a fresh scratch directory (with an empty
-- out/ there), so a block sees what a user pasting it sees; a block that raises, or whose report
-- fails a check, fails the test with the file and line where the block starts. API sketches with
-- placeholders belong in tables or ```text blocks, which are not run.
-- Shown output is checked too: a line of a block that calls print and ends in a comment
-- `--> what it prints` must print exactly that, whitespace runs aside (print's tabs may be shown as
-- spaces), every time it prints, and at least once:
--   print(#rec, rec:column("height")[#rec])          --> 110  0.00099937850657244
-- (a multi-line print call carries the comment on its first line).
-- A block whose fence is directly preceded by the line `<!-- doctest: continue -->` runs in the
-- previous block's scratch directory and sees the files it wrote (a tutorial's second script
-- loading the checkpoint of its first); every other block starts from an empty out/.
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
local blocks, open, n, prev = {}, nil, 0, nil
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
    local continues = prev and prev:match("^%s*<!%-%-%s*doctest:%s*continue%s*%-%->%s*$") ~= nil
    if continues and #blocks == 0 then
      io.stderr:write(string.format("%s:%d: 'doctest: continue' before the first ```lua block\n", file, n))
      os.exit(1)
    end
    open = { line = n, lines = {}, continues = continues }
  end
  prev = line
end
fh:close()
if open then
  io.stderr:write(string.format("%s:%d: ```lua block never closed\n", file, open.line))
  os.exit(1)
end

-- The outputs a block shows: { [line in the block] = expected text }.
local function shown(b)
  local want = {}
  for i, l in ipairs(b.lines) do
    local text = l:match("%-%->%s*(.-)%s*$")
    if text and l:find("print", 1, true) then want[i] = text end
  end
  return want
end

-- Run before the block (grainlab -e): print also records, for each line of block.lua, what it
-- printed, one "LINE<TAB>TEXT" line per call in prints.txt (%q-quoted: newlines stay on one line).
local PRELUDE = [[
local raw, log = print, assert(io.open("prints.txt", "w"))
print = function(...)
  local info = debug.getinfo(2, "Sl")
  if info and info.source == "@block.lua" then
    local parts = {}
    for i = 1, select("#", ...) do parts[i] = tostring((select(i, ...))) end
    log:write(info.currentline, "\t", string.format("%q", table.concat(parts, "\t")), "\n")
    log:flush()
  end
  return raw(...)
end]]

local function words(text) return (text:gsub("%s+", " "):gsub("^ ", ""):gsub(" $", "")) end

-- The mismatches between what the block printed and what its `-->` comments show.
local function compare(dir, b, want)
  local got, bad = {}, {}
  local f = io.open(dir .. "/prints.txt", "r")
  for line in f and f:lines() or function() end do
    local n, q = line:match("^(%d+)\t(.*)$")
    n = tonumber(n)
    if n and want[n] then
      local text = load("return " .. q)()
      got[n] = true
      if words(text) ~= words(want[n]) then
        bad[#bad + 1] = { n, string.format("%s:%d: printed '%s', the docs show '%s'", file, b.line + n, text, want[n]) }
      end
    end
  end
  if f then f:close() end
  for n in pairs(want) do
    if not got[n] then bad[#bad + 1] = { n, string.format("%s:%d: never printed (the docs show '%s')", file, b.line + n, want[n]) } end
  end
  table.sort(bad, function(x, y) return x[1] < y[1] end) -- stable enough: one message per print
  local out = {}
  for i, m in ipairs(bad) do out[i] = m[2] end
  return out
end

-- Scratch directory: one per block (or per run of continued blocks), removed once no later block
-- continues in it (a failure prints the block's output).
local base = os.tmpname()
os.remove(base)
local failed, dir = 0, nil
for k, b in ipairs(blocks) do
  if not b.continues then
    dir = string.format("%s_doc%d", base, k)
    assert(os.execute("mkdir -p " .. quote(dir .. "/out")))
  end
  local script = dir .. "/block.lua"
  local out = assert(io.open(script, "w"))
  out:write(table.concat(b.lines, "\n"), "\n")
  out:close()
  local log = dir .. "/log.txt"
  local t0 = grainlab.clock()
  local want = shown(b)
  local ok = os.execute(string.format("cd %s && %s --quiet %s block.lua > log.txt 2>&1",
                                      quote(dir), quote(exe), next(want) and "-e " .. quote(PRELUDE) or ""))
  local secs = grainlab.clock() - t0
  local lf = io.open(log, "r")
  local text = lf and lf:read("a") or ""
  if lf then lf:close() end
  local mismatch = ok and compare(dir, b, want) or {}
  local nshown = 0
  for _ in pairs(want) do nshown = nshown + 1 end
  if ok and #mismatch == 0 then
    print(string.format("ok    %s:%d (%d lines, %d shown outputs, %.2f s)", file, b.line, #b.lines, nshown, secs))
  elseif ok then
    failed = failed + 1
    print(string.format("FAIL  %s:%d: the ```lua block starting here does not print what it shows:\n%s",
                        file, b.line, table.concat(mismatch, "\n")))
  else
    failed = failed + 1
    -- Error positions inside the block ("block.lua:7:") point into the Markdown file.
    text = text:gsub("block%.lua:(%d+):", function(l) return string.format("%s:%d:", file, b.line + tonumber(l)) end)
    print(string.format("FAIL  %s:%d: the ```lua block starting here does not run as written:\n%s",
                        file, b.line, text))
  end
  if not (blocks[k + 1] and blocks[k + 1].continues) then
    if params.keep then print("      scratch directory kept: " .. dir) else os.execute("rm -rf " .. quote(dir)) end
  end
end
print(string.format("%s: %d lua blocks, %d failed", file, #blocks, failed))
if failed > 0 then os.exit(1) end
