"""Study scripts: each file defines one study (``study()``) and runs it when executed.

Installed as ``plateimpact_studies`` so that ``plateimpact reproduce`` can run them all.
"""
