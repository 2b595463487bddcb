"""Storage: archives of study runs, plate files and shot files. Nothing here computes
physics; the physics and running layers never import it."""
