-- A report with one failing check (and a NaN, which must fail too).
local ok = grainlab.report{
  scenario = "cli_fail",
  metrics = { error_rel = 0.5 },
  checks = {
    { name = "small_error", value = 0.5, limit = 0.01 },
    { name = "finite", value = 0/0, limit = 1 },
    { name = "fine", value = 1, limit = 2 },
  },
}
print("report returned", ok)
