"""Provenance: what produced a result. The inputs record of a run (what ``run --inputs``
reads back), the versions and source commit, and which code computed it (each plug-in's
and the core's source hash). Above storage, whose plate-file format the inputs record
uses for its plate."""
