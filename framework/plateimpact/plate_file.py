"""Plate files: one plate as JSON, in user units, for ``--plate-file`` and study scripts.

    {"format": "plateimpact-plate-1", "material": "2024-T3",
     "thickness_mm": 3.18, "pstar_mm": 3.0, "alpha_deg": 45.0,
     "a_N_m2": 1.01e9, "b_kg_m3": 1260.0, "units": {...}, "calibration": {...}}

The keys are those of ``plateimpact presets --json``; the unit is in each key's name (and
spelt out under ``units``). Other keys (``calibration``: how a and b were found) are
kept for the reader and ignored by :func:`load_plate_file`.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from typing import Any

from .bodies import Plate
from .errors import ParameterError, PlateFileError
from .units import deg, mm

FORMAT = "plateimpact-plate-1"

#: Key in the file -> (Plate field, SI value of one file unit, unit).
FIELDS = {
    "thickness_mm": ("thickness", mm, "mm"),
    "pstar_mm": ("critical_penetration", mm, "mm"),
    "alpha_deg": ("failure_angle", deg, "deg"),
    "a_N_m2": ("a", 1.0, "N/m^2"),
    "b_kg_m3": ("b", 1.0, "kg/m^3"),
}

UNITS = {
    "thickness_mm": "plate thickness T [mm]",
    "pstar_mm": "critical penetration P* [mm]",
    "alpha_deg": "failure angle alpha* [deg]",
    "a_N_m2": "Poncelet strength term a [N/m^2]",
    "b_kg_m3": "Poncelet inertial term b [kg/m^3]",
}


def plate_to_dict(plate: Plate, extra: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The plate-file object of ``plate``; ``extra`` adds keys (e.g. ``calibration``)."""
    out: dict[str, Any] = {"format": FORMAT, "material": plate.material}
    for key, (field, unit, _) in FIELDS.items():
        out[key] = getattr(plate, field) / unit
    out["alpha_deg"] = round(out["alpha_deg"], 12)  # 45, not 45.00000000000001
    out["units"] = UNITS
    out.update(extra or {})
    return out


def plate_from_dict(data: object, source: str = "plate file") -> Plate:
    """A :class:`Plate` from a plate-file object; :class:`PlateFileError` names ``source``."""
    if not isinstance(data, dict):
        raise PlateFileError(f"{source}: expected a JSON object, got {type(data).__name__}")
    if data.get("format") != FORMAT:
        raise PlateFileError(
            f"{source}: not a plateimpact plate file (format {data.get('format')!r}, "
            f"expected {FORMAT!r})"
        )
    missing = [key for key in ("material", *FIELDS) if key not in data]
    if missing:
        raise PlateFileError(
            f"{source}: missing key{'s' * (len(missing) > 1)} {', '.join(missing)}"
        )
    if not isinstance(data["material"], str):
        raise PlateFileError(f"{source}: material must be a string, got {data['material']!r}")
    values = {}
    for key, (field, unit, _) in FIELDS.items():
        value = data[key]
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise PlateFileError(f"{source}: {key} must be a number, got {value!r}")
        values[field] = value * unit
    try:
        return Plate(material=data["material"], **values)
    except ParameterError as exc:
        key = next(k for k, (field, _, _) in FIELDS.items() if field == exc.parameter)
        raise PlateFileError(f"{source}: {key}: {exc}") from None


def load_plate_file(path: str | os.PathLike[str]) -> Plate:
    """The plate in a plate file (JSON; see the module's description)."""
    source = os.fspath(path)
    try:
        with open(source, encoding="utf-8") as handle:
            data = json.load(handle)
    except OSError as exc:
        raise PlateFileError(f"{source}: cannot read: {exc.strerror}") from None
    except (ValueError, UnicodeDecodeError) as exc:  # JSONDecodeError is a ValueError
        reason = str(exc).splitlines()[0]
        raise PlateFileError(f"{source}: not valid JSON: {reason}") from None
    return plate_from_dict(data, source)


def plate_file_text(plate: Plate, extra: Mapping[str, Any] | None = None) -> str:
    """The plate file of ``plate`` as text (pretty JSON; P* = inf is written ``Infinity``)."""
    return json.dumps(plate_to_dict(plate, extra), indent=2) + "\n"


def save_plate_file(
    path: str | os.PathLike[str], plate: Plate, extra: Mapping[str, Any] | None = None
) -> None:
    """Write ``plate`` to ``path`` as a plate file."""
    with open(os.fspath(path), "w", encoding="utf-8") as handle:
        handle.write(plate_file_text(plate, extra))
