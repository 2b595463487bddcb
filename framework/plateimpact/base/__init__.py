"""The lowest layer: SI unit factors, the error types, what is read from someone else's
files (JSON within bounds, text made printable) and the declarations of parameters (unit,
range, default, flag). It imports nothing else of plateimpact."""
