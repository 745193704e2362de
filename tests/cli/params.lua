-- Prints each parameter with its Lua type, sorted, for test_cli.sh.
local keys = {}
for k in pairs(params) do keys[#keys + 1] = k end
table.sort(keys)
for _, k in ipairs(keys) do
  local v = params[k]
  print(k, math.type(v) or type(v), v)
end
print("arg0", arg[0])
