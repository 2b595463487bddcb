"""The commands of ``plateimpact``: one module each, with the same two functions.

``arguments(parser, registry)`` adds the command's options to its sub-parser (plug-in
options from ``registry``); ``run(args, registry, out) -> int`` does the work, writes
through the :class:`~plateimpact.cli.writer.Writer` ``out`` and returns the exit code.
:data:`COMMANDS` names them with their help lines, so that ``main`` lists every command
(``--help``) without importing one, and imports only the one invoked.
"""

from __future__ import annotations

from typing import NamedTuple


class Command(NamedTuple):
    """A command: its name on the command line, its module here, its help line."""

    name: str
    module: str
    help: str


#: Every command, in the order ``--help`` lists them.
COMMANDS = (
    Command("presets", "presets", "list the plate presets and the default sphere"),
    Command("plugins", "plugins", "list the installed plug-ins by kind"),
    Command("run", "run", "run one scene"),
    Command("crater", "crater", "the crater section of one scene (eqs 31-39)"),
    Command("sweep", "sweep", "run a grid of speeds and obliquities"),
    Command(
        "calibrate",
        "calibrate",
        "fit a model's plate constants to measured shots, by the calibration procedure an "
        "installed plug-in package provides (the built-ins': the report's)",
    ),
    Command(
        "validate",
        "validate",
        "run the model on measured shots: outcome agreement, residual-speed and "
        "exit-obliquity errors, the shots that disagree",
    ),
    Command(
        "limits",
        "limits",
        "outcome bands, ballistic and ricochet limits along speed or obliquity",
    ),
    Command(
        "map", "map", "the outcome map of the (speed, obliquity) plane, or limit curves of plates"
    ),
    Command(
        "v50",
        "v50",
        "V50 of go/no-go shots: probit or logit fit with confidence intervals, or the "
        "MIL-STD-662F estimate",
    ),
    Command(
        "uncertainty",
        "uncertainty",
        "distributions on the inputs, propagated: the probability of each outcome with its "
        "confidence interval",
    ),
    Command("reproduce", "reproduce", "run the report's figure families into one archive"),
    Command(
        "compile",
        "compile",
        "compile the fast path of every installed model now (otherwise it compiles in the "
        "background on first use)",
    ),
    Command(
        "show", "show", "list an archive's runs and stored limits, their metadata and a summary"
    ),
    Command(
        "compare",
        "compare",
        "compare two runs of an archive (outcome changes in ranges of impact speed), or two "
        "stored limits boundary by boundary",
    ),
    Command("plot", "plot", "exit curves, trajectories or crater sections of runs in an archive"),
    Command(
        "export",
        "export",
        "write one run as netCDF-4 (FILE.nc: xarray, ncdump, Panoply) or a CSV table "
        "(FILE.csv: one row per scene, units in the header), or a stored record (limits, a "
        "map) as netCDF-4",
    ),
    Command(
        "upgrade",
        "upgrade",
        "rewrite a format-1 archive (one file) as format 2 (an index and its data files); "
        "the old file is kept as ARCHIVE.format1.h5",
    ),
)
