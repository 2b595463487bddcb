"""The lowest layer: SI unit factors, the error types, what is read from someone else's
files (JSON within bounds, text made printable), the declarations of parameters (unit,
range, default, flag) and numbers and tables for people in the units those declare
(display). It imports nothing else of plateimpact."""
