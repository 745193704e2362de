local function inner(v)
  return v.field -- v is nil
end
inner(nil)
