-- Assertions for script tests: each failure raises an error that names what was checked, the
-- values and the tolerance, at the line of the test that made the check.
--   local check = grainlab.check
--   check.near(e_measured, e_theory, 1e-3, "restitution")
local check = { count = 0 }

local function fmt(v)
  if math.type(v) == "float" then return string.format("%.10g", v) end
  if type(v) == "string" then return string.format("%q", v) end
  return tostring(v)
end

local function fail(what, msg)
  error((what and (what .. ": ") or "") .. msg, 3)
end

local function number(v, what, name)
  if type(v) ~= "number" then fail(what, name .. " is " .. type(v) .. ", not a number") end
end

-- |a - b| <= rtol |b|
function check.near(a, b, rtol, what)
  number(a, what, "value"); number(b, what, "reference"); number(rtol, what, "rtol")
  check.count = check.count + 1
  local err = math.abs(a - b)
  if not (err <= rtol * math.abs(b)) then
    fail(what, string.format("expected %s within relative %g, got %s (relative error %.3g)",
                             fmt(b), rtol, fmt(a), b ~= 0 and err / math.abs(b) or math.huge))
  end
end

-- |a - b| <= atol
function check.near_abs(a, b, atol, what)
  number(a, what, "value"); number(b, what, "reference"); number(atol, what, "atol")
  check.count = check.count + 1
  if not (math.abs(a - b) <= atol) then
    fail(what, string.format("expected %s within %g, got %s (error %.3g)", fmt(b), atol, fmt(a),
                             math.abs(a - b)))
  end
end

function check.eq(a, b, what)
  check.count = check.count + 1
  if a ~= b then fail(what, string.format("expected %s, got %s", fmt(b), fmt(a))) end
end

function check.is_true(v, what)
  check.count = check.count + 1
  if not v then fail(what, "expected a true value, got " .. fmt(v)) end
end

local function compare(op, test)
  return function(a, b, what)
    number(a, what, "value"); number(b, what, "bound")
    check.count = check.count + 1
    if not test(a, b) then fail(what, string.format("expected %s %s %s", fmt(a), op, fmt(b))) end
  end
end
check.le = compare("<=", function(a, b) return a <= b end)
check.lt = compare("<", function(a, b) return a < b end)
check.ge = compare(">=", function(a, b) return a >= b end)
check.gt = compare(">", function(a, b) return a > b end)

-- The string s contains `text` literally.
function check.contains(s, text, what)
  check.count = check.count + 1
  if type(s) ~= "string" or not s:find(text, 1, true) then
    fail(what, string.format("expected text containing %q, got %s", text, fmt(s)))
  end
end

-- fn(...) raises an error whose message contains `text` literally; returns the message.
function check.errors(fn, text, what, ...)
  check.count = check.count + 1
  local ok, msg = pcall(fn, ...)
  if ok then fail(what, string.format("expected an error containing %q, but the call succeeded", text)) end
  msg = tostring(msg)
  if not msg:find(text, 1, true) then
    fail(what, string.format("expected an error containing %q, got %q", text, msg))
  end
  return msg
end

-- Prints the closing line that ctest's log shows: "N passed, 0 failed".
function check.done()
  print(string.format("%d passed, 0 failed", check.count))
end

grainlab.doc(check, { name = "grainlab.check", doc = [[Assertions for script tests; each raises an error naming what failed:
  check.near(a, b, rtol, what)   |a-b| <= rtol|b|        check.near_abs(a, b, atol, what)
  check.eq(a, b, what)           a == b                  check.is_true(v, what)
  check.le/lt/ge/gt(a, b, what)  comparisons             check.contains(s, text, what)
  check.errors(fn, text, what, ...) -> message: fn(...) must raise an error containing text
  check.done()                   prints "N passed, 0 failed"]] })

return check
