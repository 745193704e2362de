-- What fn(...) prints, as one string (print's arguments tab-separated, one line per call); an
-- error in fn is raised again after print is restored. Shared by the help tests.
return function(fn, ...)
  local lines, real = {}, print
  print = function(...) lines[#lines + 1] = table.concat({ ... }, "\t") end
  local ok, err = pcall(fn, ...)
  print = real
  if not ok then error(err, 0) end
  return table.concat(lines, "\n")
end
