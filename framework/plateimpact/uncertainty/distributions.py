"""The distributions an uncertain input can take, each in the input's user unit (m/s, mm,
deg, g, N/m², kg/m³), sampled by its inverse distribution function so that Monte Carlo,
scrambled Sobol' and Latin hypercube points all map through the same ``ppf``."""

from __future__ import annotations

import abc
import math
from typing import Any

import attrs
import numpy as np
from scipy import stats


def _finite(instance: object, attribute: attrs.Attribute, value: float) -> None:
    if not math.isfinite(value):
        raise ValueError(f"{attribute.name} must be a finite number, got {value!r:.40}")


def _positive(instance: object, attribute: attrs.Attribute, value: float) -> None:
    _finite(instance, attribute, value)
    if not value > 0.0:
        raise ValueError(f"{attribute.name} must be > 0, got {value!r:.40}")


class Distribution(abc.ABC):
    """A distribution of one input [its user unit]."""

    #: The name a spec gives it ({"normal": {...}}).
    kind: str = ""

    @abc.abstractmethod
    def ppf(self, u: np.ndarray) -> np.ndarray:
        """The values at probabilities ``u`` in (0, 1) (the inverse distribution function)."""

    @abc.abstractmethod
    def cdf(self, x: float) -> float:
        """P(X <= x)."""

    def mass_outside(self, low: float, high: float) -> float:
        """The probability of a value below ``low`` or above ``high``."""
        below = self.cdf(low) if math.isfinite(low) else 0.0
        above = 1.0 - self.cdf(high) if math.isfinite(high) else 0.0
        return below + above

    @classmethod
    def settings(cls) -> tuple[str, ...]:
        """The names of its settings, in order."""
        return tuple(field.name for field in attrs.fields(cls))  # type: ignore[arg-type]

    def describe(self) -> dict[str, Any]:
        """The spec's form of this distribution: {kind: {setting: value}}."""
        return {self.kind: attrs.asdict(self)}  # type: ignore[arg-type]


@attrs.frozen
class Fixed(Distribution):
    """Always ``value``."""

    kind = "fixed"
    value: float = attrs.field(converter=float, validator=_finite)

    def ppf(self, u: np.ndarray) -> np.ndarray:
        return np.full(np.shape(u), self.value)

    def cdf(self, x: float) -> float:
        return 1.0 if x >= self.value else 0.0


@attrs.frozen
class Normal(Distribution):
    """Normal of ``mean`` and standard deviation ``sd``."""

    kind = "normal"
    mean: float = attrs.field(converter=float, validator=_finite)
    sd: float = attrs.field(converter=float, validator=_positive)

    def ppf(self, u: np.ndarray) -> np.ndarray:
        return np.asarray(stats.norm.ppf(u, self.mean, self.sd), float)

    def cdf(self, x: float) -> float:
        return float(stats.norm.cdf(x, self.mean, self.sd))


@attrs.frozen
class LogNormal(Distribution):
    """exp of a normal: ``median`` (= e^μ) and ``sigma`` (σ of the logarithm)."""

    kind = "lognormal"
    median: float = attrs.field(converter=float, validator=_positive)
    sigma: float = attrs.field(converter=float, validator=_positive)

    def ppf(self, u: np.ndarray) -> np.ndarray:
        return np.asarray(stats.lognorm.ppf(u, self.sigma, scale=self.median), float)

    def cdf(self, x: float) -> float:
        return float(stats.lognorm.cdf(x, self.sigma, scale=self.median))


@attrs.frozen
class Uniform(Distribution):
    """Uniform on [``low``, ``high``]."""

    kind = "uniform"
    low: float = attrs.field(converter=float, validator=_finite)
    high: float = attrs.field(converter=float, validator=_finite)

    def __attrs_post_init__(self) -> None:
        if not self.high > self.low:
            raise ValueError(f"high must be > low, got low {self.low:g}, high {self.high:g}")

    def ppf(self, u: np.ndarray) -> np.ndarray:
        return self.low + (self.high - self.low) * np.asarray(u, float)

    def cdf(self, x: float) -> float:
        return float(np.clip((x - self.low) / (self.high - self.low), 0.0, 1.0))


@attrs.frozen
class TruncatedNormal(Distribution):
    """A normal of ``mean`` and ``sd`` cut to [``low``, ``high``] and renormalised: the
    explicit way to keep a normal inside a parameter's range."""

    kind = "truncnormal"
    mean: float = attrs.field(converter=float, validator=_finite)
    sd: float = attrs.field(converter=float, validator=_positive)
    low: float = attrs.field(converter=float)
    high: float = attrs.field(converter=float)

    def __attrs_post_init__(self) -> None:
        if not self.high > self.low or math.isnan(self.low) or math.isnan(self.high):
            raise ValueError(f"high must be > low, got low {self.low:g}, high {self.high:g}")
        if self._frozen().cdf(self.high) - self._frozen().cdf(self.low) <= 0.0:
            raise ValueError("[low, high] holds none of the normal's probability")

    def _frozen(self) -> Any:
        a, b = (self.low - self.mean) / self.sd, (self.high - self.mean) / self.sd
        return stats.truncnorm(a, b, loc=self.mean, scale=self.sd)

    def ppf(self, u: np.ndarray) -> np.ndarray:
        return np.asarray(self._frozen().ppf(u), float)

    def cdf(self, x: float) -> float:
        return float(self._frozen().cdf(x))


#: Every distribution by the name a spec gives it.
KINDS: dict[str, type[Distribution]] = {
    cls.kind: cls for cls in (Fixed, Normal, LogNormal, Uniform, TruncatedNormal)
}
