-- The assertion library itself: each check passes on good values and fails, with a message
-- naming what and by how much, on bad ones.
local check = grainlab.check

check.near(1.0005, 1.0, 1e-3, "near passes")
check.contains(check.errors(check.near, "expected 1 within relative 0.001, got 1.01 (relative error 0.01)", "near fails", 1.01, 1.0, 1e-3, "e_n"),
  "e_n: ", "near names what")
check.errors(check.near, "(relative error nan)", "NaN never passes", 0/0, 1.0, 1e-3, "nan")
check.near_abs(0.05, 0, 0.1, "near_abs passes")
check.errors(check.near_abs, "expected 0 within 0.1, got 0.2", "near_abs fails", 0.2, 0, 0.1)
check.errors(check.eq, 'expected "b", got "a"', "eq fails", "a", "b")
check.errors(check.le, "expected 3 <= 2", "le fails", 3, 2)
check.errors(check.gt, "expected 2 > 2", "gt fails", 2, 2)
check.errors(check.is_true, "expected a true value, got nil", "is_true fails", nil)
check.errors(check.contains, "expected text containing", "contains fails", "abc", "x")
check.errors(check.errors, "but the call succeeded", "errors fails without an error", function() end, "x")
check.errors(check.errors, "expected an error containing \"qzq\", got", "errors fails on the wrong message", function() error("y") end, "qzq")
check.errors(check.near, "value is string, not a number", "type check", "1", 1, 0.1)
check.done()
