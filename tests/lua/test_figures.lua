-- grainlab.figures: the one rule for where a script's figures go (images/ for the published,
-- full-size run; out/ or the given directory for any other), and its argument checks.
local check = grainlab.check
local figures = require("grainlab.figures")

-- published(): every named parameter at its published value; extra actual values do not matter.
check.eq(figures.published({ n = 3300, strain = 0.2 }, { n = 3300, strain = 0.2 }), true, "all at the published values")
check.eq(figures.published({ n = 3300, strain = 0.01 }, { n = 3300, strain = 0.2 }), false, "shorter run")
check.eq(figures.published({ n = 330, strain = 0.2, bc = "mbc" }, { n = 3300, strain = 0.2 }), false, "smaller run")
check.eq(figures.published({ n = 3300, bc = "mbc" }, { n = 3300 }), true, "a parameter outside the list does not count")
check.eq(figures.published({ n = 3300.0 }, { n = 3300 }), true, "3300.0 from the command line is 3300")
check.eq(figures.published({ shape = "bspline" }, { shape = "linear" }), false, "strings compare")
check.eq(figures.published({}, { quick = false }), false, "a missing value is not the published one")

-- path(): unpublished runs go to out/ (or the directory given), which is created.
local tmp = os.tmpname()
os.remove(tmp)
local dir = tmp .. "_figs"
check.eq(figures.path("a.png", { published = false, out = dir }), dir .. "/a.png", "unpublished: the given directory")
local f = io.open(dir .. "/a.png", "w")
check.is_true(f ~= nil, "the out directory was created")
if f then f:close() end
check.eq(figures.dir{ published = false, out = dir }, dir, "dir(): unpublished")

-- The published branch, in a scratch working directory (images/ there, not in the source tree).
local exe = arg and arg[-1]
check.is_true(type(exe) == "string", "the binary's path is arg[-1]")
if exe:sub(1, 1) ~= "/" then -- relative to here; the scratch directory is elsewhere
  local pwd = io.popen("pwd")
  exe = pwd:read("l") .. "/" .. exe
  pwd:close()
end
local work = tmp .. "_work"
os.execute("mkdir -p '" .. work .. "'")
local p = io.popen(string.format("cd '%s' && '%s' --quiet -e '%s' 2>&1", work, exe,
  [[local f = require("grainlab.figures")
    io.write(f.path("x.png", { published = true }), " ", f.path("y.png", { published = false }))]]))
local got = p:read("a")
p:close()
check.eq(got, "images/x.png out/y.png", "published -> images/, unpublished -> out/")
check.is_true(io.open(work .. "/images") ~= nil and io.open(work .. "/out") ~= nil, "both directories created")
os.execute("rm -rf '" .. dir .. "' '" .. work .. "'")

-- Argument errors name the call and the field.
check.errors(function() figures.path("a.png", {}) end,
             "bad field 'published' in argument #2 to 'path' (boolean expected, got nil)", "published missing")
check.errors(function() figures.path("sub/a.png", { published = false }) end,
             "bad argument #1 to 'path' (file name without a directory expected, got 'sub/a.png')", "a directory in the name")
check.errors(function() figures.path("a.png", { published = false, out = "" }) end,
             "bad field 'out' in argument #2 to 'path' (directory name expected, got '')", "empty out")
check.errors(function() figures.dir{ published = true, ot = "x" } end,
             "bad argument #1 to 'dir' (unknown field 'ot'; valid fields: out, published)", "typo")
check.errors(function() figures.published(nil, {}) end,
             "bad argument #1 to 'published' (table expected, got nil)", "published without tables")
check.done()
