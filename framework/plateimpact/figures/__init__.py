"""Figures: every figure plateimpact draws, one module per subject, drawn on
matplotlib Figure objects (never through pyplot, so the user's backend is left alone).
matplotlib is imported by these modules only. The top layer but the command line: it
imports what it draws (studies, limits, comparisons, validations, V50 fits)."""
