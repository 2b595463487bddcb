"""``plateimpact.units``, the path the README and scripts import unit factors from
(``from plateimpact.units import mm, deg``): the factors of ``plateimpact.base.units``."""

from __future__ import annotations

from .base.units import deg, g, mm

__all__ = ["deg", "g", "mm"]
