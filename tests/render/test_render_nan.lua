-- Fields with NaN: a cell without a value shows the background (white by default), the colour
-- range comes from the cells that have values, and a field of which no cell has a value is drawn
-- with a note across it and no colour bar, never as a silently blank frame.
local check = grainlab.check
local nan = 0 / 0

local function count(img, x0, y0, x1, y1, pred)
  local n = 0
  for y = y0, y1 do
    for x = x0, x1 do
      if pred(img:pixel(x, y)) then n = n + 1 end
    end
  end
  return n
end
local function red_ink(r, g, b) return r > 120 and g < 100 and b < 100 end
local function white(r, g, b) return r == 255 and g == 255 and b == 255 end

-- Partly NaN: rows from the bottom {1, NaN}, {3, 4}; the range is [1, 4].
local part = render.field{ values = { 1, nan, 3, 4 }, nx = 2, ny = 2, width = 300 }
local w, h = part:size()
check.is_true(white(part:pixel(math.floor(0.6 * w), math.floor(0.8 * h))), "NaN cell: background")
local r, g, b = part:pixel(math.floor(0.2 * w), math.floor(0.8 * h))
check.is_true(r < 90 and b > 60 and g < 40, "value 1 at the bottom of viridis (dark purple)")
r, g, b = part:pixel(math.floor(0.6 * w), math.floor(0.2 * h))
check.is_true(r > 200 and g > 200 and b < 80, "value 4 at the top of viridis (yellow)")
check.eq(count(part, 1, 1, w, h, red_ink), 0, "no note on a field with values")

-- All NaN: a note in the middle, no colour bar (the extent takes the whole width).
local none = render.field{ values = { nan, nan, nan, nan }, nx = 2, ny = 2, width = 300 }
local wn, hn = none:size()
check.gt(count(none, 1, math.floor(0.4 * hn), wn, math.floor(0.6 * hn), red_ink), 30, "note drawn")
check.eq(count(none, 1, 1, wn, math.floor(0.4 * hn), red_ink), 0, "only across the middle")
check.is_true(white(none:pixel(wn - 12, math.floor(0.3 * hn))), "no colour bar")
check.is_true(not white(part:pixel(w - 40, math.floor(0.1 * h))) or
              not white(part:pixel(w - 45, math.floor(0.5 * h))), "a field with values has its bar")

-- All masked: the same note.
local masked = render.field{ values = { 1, 2, 3, 4 }, mask = { false, false, false, false }, nx = 2,
                             ny = 2, width = 300 }
check.gt(count(masked, 1, 1, wn, hn, red_ink), 30, "note for a fully masked field")

-- Arrows over an empty field still draw (the note does not replace them).
local arrows = render.field{ values = { nan, nan, nan, nan }, nx = 2, ny = 2, width = 300,
                             arrows = { u = { 1, 1, 1, 1 }, v = { 0, 0, 0, 0 } } }
check.gt(count(arrows, 1, 1, wn, hn, red_ink), 30, "arrows and note")
check.done()
