-- Whether two MPM point sets (m:points()) hold the same bits: count, positions, velocities and
-- sigma_xx, point by point. Shared by the thread-count tests of frictional contact.
return function(a, b)
  if a.count ~= b.count then return false end
  for i = 1, a.count do
    if a.x[i] ~= b.x[i] or a.y[i] ~= b.y[i] or a.vx[i] ~= b.vx[i] or a.vy[i] ~= b.vy[i] or
       a.sxx[i] ~= b.sxx[i] then
      return false
    end
  end
  return true
end
