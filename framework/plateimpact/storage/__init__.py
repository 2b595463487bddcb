"""Storage: archives of study runs (an HDF5 index and a netCDF-4 file per run), their
locks, records and export, plate files, shot files and the all-or-nothing writers of
every output. Nothing here runs a simulation: of run/ it imports the Variant an archive
records and reads back; base, model, solve, registry and run never import it."""
