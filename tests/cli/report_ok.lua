-- A report whose checks all pass.
grainlab.report{
  scenario = "cli_ok",
  params = { n = params.n or 10, label = "x" },
  metrics = { restitution = 0.9, particle_steps_per_s = 1.5e6, steps = 1000 },
  checks = {
    { name = "restitution_rel_err", value = 1e-4, limit = 1e-3 },
    { name = "energy_drop", value = 0.2, limit = 0.1, op = ">=" },
    { name = "converged", pass = true },
  },
}
