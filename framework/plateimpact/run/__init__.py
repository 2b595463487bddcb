"""Running a model: a simulation (a resistance law, a failure model and an integrator
resolved by plug-in name) over one scene or a batch, the variants a study names, and
progress bars. Below storage, because an archive records and reads back variants; it
imports base, model, solve and registry."""
