"""The headline quantities of a run, as a registry: what every error budget, ``inspect``,
report, ``make estimates`` and refinement iterate over.

:data:`BUILTIN_HEADLINES` is an immutable mapping (``types.MappingProxyType``) from a
quantity's name to its :class:`Headline`, in the order they are printed. A function that
estimates, budgets or certifies headline quantities takes the registry as an argument,
``headlines``, with the built-ins as its default; a caller with a quantity of its own builds
its own registry (``MappingProxyType({**BUILTIN_HEADLINES, "mine": Headline(...)})``) and
passes it along (tests/test_ladder.py runs such a toy through :func:`flex.simulate`,
``inspect`` and the report).

The contract of an entry:

1. ``name``: the case attribute suffix (``headline_<name>``, ``estimated_error_<name>``); it
   ends with its unit by convention (``_m``, ``_Pa``, ``_N``, ``_s``, ``_rad``);
2. ``unit`` and ``what``: how it is printed;
3. ``read(datasets)``: its value from a run's datasets [its unit], or None when the run does
   not have it (a rigid link's deflection, a deployment not reached): missing, never zero;
4. ``kind``: how two runs' values are compared (the step, modes, mesh and model terms are
   such differences): ``"value"`` (the values' difference), ``"peak"`` (the largest
   ``|series|`` over ``window``: :func:`flex.fidelity.error_estimate.peak_difference`, which
   also counts a crest that moves), ``"first_crest"`` (the largest ``|series|`` of its first
   lobe; a rigid twin's missing series counts as zero), ``"history"`` (a whole curve: its
   value is the series' peak ``|series|``, its difference to another run the largest
   difference of the two curves over the run, :func:`history_difference`: the error of the
   curve, relative to its peak); ``series``: the dataset it is read from. A ``"peak"`` is a
   raw maximum: it races between the sub-crests of undamped ringing and has no order of
   convergence, so its budget is a *bound*, not an estimate (:attr:`Headline.bound`), and
   says so. No built-in is one: the whole-run peaks and the histories are read on the
   headline channel (``channel``), where a run's top retained mode, which the step leaves
   unresolved, is filtered out and they converge (``make estimates`` flagged 37 % of its
   pairs outside the asymptotic range while they were raw, session 14);
5. ``window``: the part of the run it is read over, in words;
6. ``link``: the link whose own elastic response it is (its model term is the link's rung's
   ``own_fraction``, :mod:`flex.config.ladder`), or None for a quantity of the motion (the
   rungs' ``motion_fraction``);
7. ``certified``: a link's own deflection the ``"deflections"`` and
   ``"flexible_deflections"`` groups of ``fidelity.quantities`` name (:data:`QUANTITY_GROUPS`;
   refinement refines every quantity asked until it meets the tolerance); ``crest_gap``: its
   budget stores the peak's crest gap (:func:`crest_gap`);
   ``mesh_order``: its order of convergence under mesh refinement (the budget's mesh term
   extrapolates a finer mesh's difference with it).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

#: how a headline quantity is compared between two runs (module doc, point 4)
KINDS = ("value", "peak", "first_crest", "history")
#: the series whose first maximum ends the deployment (:func:`deployment_end`)
DEPLOYMENT_SERIES = "crank/angle"


#: a series whose whole swing is below this, relative to its magnitude (at least 1), has
#: not moved: round-off of a mechanism at rest (an FFRF coupler at preload 0 swings its crank
#: by ~1e-13 rad), or the integrator's start transient of a crank held by its damper (1e9-
#: 1e11 N s/m: ~1e-9 rad, stated as a deployment of 2e-5 s); a deployment turns ~1 rad
STILL_FRACTION = 1e-6
#: a maximum counts once the series has risen this fraction of its whole swing above its
#: lowest value so far: a first step that lowers the crank angle by round-off (4e-8 rad at
#: h <= 1e-5 s, against a swing of ~1 rad) is not a maximum
RISE_FRACTION = 1e-3


def first_maximum_index(values: np.ndarray) -> int | None:
    """Index of the first real maximum of a series (the deployment's end on the crank
    angle): the first sample after which it falls, once it has risen by
    :data:`RISE_FRACTION` of its whole swing; None when it only rises, only falls, never
    moves (:data:`STILL_FRACTION`) or holds a value that is not finite. The one formula of
    the deployment time (:func:`deployment_times`, the error budget's headline, ``flex
    design``)."""
    values = np.asarray(values, dtype=float)
    if len(values) < 3 or not np.all(np.isfinite(values)):
        return None
    swing = float(np.max(values) - np.min(values))
    if swing <= STILL_FRACTION * max(1.0, float(np.max(np.abs(values)))):
        return None
    rise = values - np.minimum.accumulate(values)
    risen = rise > RISE_FRACTION * swing
    if not risen.any():
        return None
    start = int(np.argmax(risen))
    step = np.diff(values[start:])
    tops = start + np.flatnonzero((step < 0) & np.r_[True, step[:-1] >= 0])
    # a top the series later passes by more than it rose to it is a wiggle on the way (a
    # crank held by its damper: a step-scale wiggle of 1e-9 rad within a creep of 3e-8 rad
    # was a "deployment" of 2e-5 s), not the deployment's end
    later = np.maximum.accumulate(values[::-1])[::-1]
    real = tops[later[tops] - values[tops] <= rise[tops]]
    return int(real[0]) if real.size else None


def crest_value(magnitude: np.ndarray, index: int) -> float:
    """The crest of a sampled series ``magnitude`` at its sample ``index``: the vertex of the
    parabola through that sample and its neighbours where it is a local maximum inside the
    series, else the sample itself [the series' unit]. A sampled maximum lies below the crest
    by up to A (omega h)^2 / 8 and by how much depends on where the samples fall: the 2 mm
    plate's first crest read 2.17574, 2.17601, 2.17741, 2.17744e-5 m at h = 43.6, 21.8, 10.9
    and 5.45 us (no order), its vertex 2.17680, 2.17729, 2.17742, 2.17745e-5 m (order 2.0,
    session 14)."""
    values = np.asarray(magnitude, dtype=float)
    middle = float(values[index])
    if not 0 < index < values.size - 1:
        return middle
    left, right = float(values[index - 1]), float(values[index + 1])
    curvature = left - 2.0 * middle + right
    if not (curvature < 0 and left <= middle >= right):
        return middle
    return middle - (left - right) ** 2 / (8.0 * curvature)


def first_peak_index(deflection: np.ndarray) -> int:
    """Index of the first extreme: the largest |deflection| of the first lobe.

    The first lobe starts where |deflection| first exceeds 10 % of its largest value and
    ends where the deflection changes sign (or with the series), so the ripple of higher
    modes riding on the first swing does not count as a peak.
    """
    magnitude = np.abs(deflection)
    start = int(np.argmax(magnitude > 0.1 * magnitude.max()))
    sign_changes = np.flatnonzero(np.sign(deflection[start:]) != np.sign(deflection[start]))
    end = start + int(sign_changes[0]) if len(sign_changes) else len(deflection)
    return start + int(np.argmax(magnitude[start:end]))


@dataclass(frozen=True)
class Headline:
    """One headline quantity (see the module's contract)."""

    name: str
    unit: str
    what: str
    read: Callable[[Mapping[str, Any]], float | None]
    kind: str = "value"
    series: str | None = None
    window: str = "the whole run"
    link: str | None = None
    certified: bool = False
    crest_gap: bool = False
    #: its order of convergence under mesh refinement, what the budget's mesh term
    #: extrapolates with (a displacement or the motion 2, a stress at the outer fibre 1)
    mesh_order: int = 2
    #: the series it reads on the headline channel (its own and, over the deployment, the
    #: crank angle that ends it): the run stores them filtered (:func:`channel_series`)
    channel: tuple[str, ...] = ()

    @property
    def bound(self) -> bool:
        """Its budget's total is a bound, not an estimate: a raw maximum (``kind`` ``"peak"``,
        point 4 of the module's contract), whose terms are crest mismatches."""
        return self.kind == "peak"

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"headline {self.name}: kind {self.kind!r} is not one of {KINDS}")
        if self.kind != "value" and self.series is None:
            raise ValueError(f"headline {self.name}: a {self.kind} needs its series")


def final_value(path: str) -> Callable[[Mapping[str, Any]], float | None]:
    """Reader of the last sample of dataset ``path`` (None without it)."""
    return lambda datasets: float(datasets[path].data[-1]) if path in datasets else None


def peak_value(path: str) -> Callable[[Mapping[str, Any]], float | None]:
    """Reader of the largest ``|path|`` over the run (None without it, or all zero)."""
    def read(datasets: Mapping[str, Any]) -> float | None:
        if path not in datasets:
            return None
        values = np.abs(np.asarray(datasets[path].data, dtype=float))
        return float(np.max(values)) if values.size and np.any(values) else None
    return read


def first_crest_value(path: str) -> Callable[[Mapping[str, Any]], float | None]:
    """Reader of the first crest of ``|path|``: the largest magnitude of the series' first
    lobe (:func:`flex.data.headlines.first_peak_index`), a peak that does not race: the
    largest crest of an undamped ringing plate can move from one crest to a neighbour a
    fraction of a per cent lower when the phase error changes (docs/criterion.md)."""
    def read(datasets: Mapping[str, Any]) -> float | None:
        if path not in datasets:
            return None
        values = channel(datasets, path)
        if not values.size or not np.any(values):
            return None
        return crest_value(np.abs(values), first_peak_index(values))
    return read


def channel_curve(datasets: Mapping[str, Any], path: str) -> tuple[np.ndarray, np.ndarray]:
    """Series ``path`` on the headline channel with its times (:func:`channel`: up to the
    channel's undetermined tail; the raw series where the run has no channel) [s, the series'
    unit]."""
    values = channel(datasets, path)
    return np.asarray(datasets["time"].data, dtype=float)[:values.size], values


def history_difference(run: Mapping[str, Any], other: Mapping[str, Any], path: str
                       ) -> float:
    """The largest difference of two runs' curves ``path`` on the headline channel
    (:func:`channel_curve`) over the times both determine [its unit]: the other run
    interpolated on the run's times (a run without the series counts as zero: a rigid twin
    has no deflection; a run without a channel, the rigid twin, is its raw curve: it has no
    ringing to filter)."""
    time_s, mine = channel_curve(run, path)
    if path not in other:
        return float(np.max(np.abs(mine)))
    other_s, theirs = channel_curve(other, path)
    inside = time_s <= other_s[-1]
    return float(np.max(np.abs(mine[inside] - np.interp(time_s[inside], other_s, theirs))))


def channel_peak_value(path: str) -> Callable[[Mapping[str, Any]], float | None]:
    """Reader of the largest ``|path|`` over the whole run on the headline channel
    (:func:`channel`: up to its undetermined tail), at its crest between samples
    (:func:`crest_value`); None without the series, or all zero."""
    def read(datasets: Mapping[str, Any]) -> float | None:
        if path not in datasets:
            return None
        values = np.abs(channel(datasets, path))
        if not values.size or not np.any(values):
            return None
        return crest_value(values, int(np.argmax(values)))
    return read


#: a midpoint deflection is a difference of positions the size of the mechanism: within
#: this many units in the last place of those positions it is their round-off, not a
#: deflection (an exact beam run for 1e-9 s stated 9e-17 m "+- 0.062 %")
ROUNDOFF_ULPS = 64.0


def deflection_resolution_m(datasets: Mapping[str, Any], link: str) -> float:
    """The round-off of ``<link>/midpoint_deflection`` [m]: :data:`ROUNDOFF_ULPS` units in
    the last place of the link's midpoint position (0 without it)."""
    path = f"{link}/midpoint_position"
    if path not in datasets:
        return 0.0
    values = np.abs(np.asarray(datasets[path].data, dtype=float))
    if not values.size or not np.isfinite(values).all():
        return 0.0
    return ROUNDOFF_ULPS * float(np.finfo(float).eps) * float(values.max())


def above_roundoff(read: Callable[[Mapping[str, Any]], float | None], link: str
                   ) -> Callable[[Mapping[str, Any]], float | None]:
    """``read``, None where its value is within the round-off of the link's deflection
    (:func:`deflection_resolution_m`): missing, not a number with an error stated as if it
    meant something."""
    def checked(datasets: Mapping[str, Any]) -> float | None:
        value = read(datasets)
        if value is None or abs(value) <= deflection_resolution_m(datasets, link):
            return None
        return value
    return checked


def crest_gap(values: np.ndarray) -> float | None:
    """How far the second-largest crest of ``|values|`` lies below the largest [the series'
    units]: a peak's crest uncertainty (an error of the run larger than this may have picked
    another crest as the peak); None with fewer than two crests."""
    magnitude = np.abs(np.asarray(values, dtype=float))
    inner = magnitude[1:-1]
    crests = inner[(inner > magnitude[:-2]) & (inner >= magnitude[2:])]
    if crests.size < 2:
        return None
    top, second = np.sort(crests)[-2:][::-1]
    return float(top - second)


def channel(datasets: Mapping[str, Any], path: str) -> np.ndarray:
    """Series ``path`` on the run's headline channel, ``channel/<path>`` (zero-phase
    low-pass at the cut-off the run stores as ``channel_cutoff_Hz``,
    :func:`flex.dynamics.advice.channel_datasets`) up to its undetermined tail at the run's
    end (``channel/determined``: where the filter reads its padding, not the run), or the
    whole series itself where the run has none (nothing flexible, or a sampling that holds
    nothing above the cut-off) [the series' unit]. Its samples are the run's first ones:
    index k is the time ``time[k]``."""
    if f"channel/{path}" not in datasets:
        return np.asarray(datasets[path].data, dtype=float)
    values = np.asarray(datasets[f"channel/{path}"].data, dtype=float)
    if "channel/determined" not in datasets:  # a file written before the tail was marked
        return values
    return values[:int(np.count_nonzero(np.asarray(datasets["channel/determined"].data)))]


def deployment_end(datasets: Mapping[str, Any]) -> int | None:
    """Index of the deployment's last sample: the crank angle's first maximum
    (:func:`flex.data.headlines.first_maximum_index`); None when it has none (a constant-
    speed crank, a deployment not reached: the deployment is then the whole run)."""
    if DEPLOYMENT_SERIES not in datasets:
        return None
    top = first_maximum_index(channel(datasets, DEPLOYMENT_SERIES))
    return None if top is None or top == 0 else top


def deployment_peak_value(path: str) -> Callable[[Mapping[str, Any]], float | None]:
    """Reader of the largest ``|path|`` over the deployment (release to the crank's first
    maximum, :func:`deployment_end`; the whole run without one) on the headline channel
    (:func:`channel`), at its crest between samples (:func:`crest_value`; a largest sample
    at the window's end is read as it is); None without the series, or all zero."""
    def read(datasets: Mapping[str, Any]) -> float | None:
        if path not in datasets:
            return None
        end = deployment_end(datasets)
        values = np.abs(channel(datasets, path))[:None if end is None else end + 1]
        if not values.size or not np.any(values):
            return None
        return crest_value(values, int(np.argmax(values)))
    return read


def peak_at_deployment_end(datasets: Mapping[str, Any], path: str) -> bool:
    """Whether the largest ``|path|`` over the deployment (on the headline channel, as
    :func:`deployment_peak_value` reads it) is the deployment's last sample with ``|path|``
    still rising into it: no crest, a value that follows the deployment time (the stiff 10 mm
    plate's deflection, the aluminium 1 mm plate's). False without a deployment end (the
    window is then the whole run) or without the series."""
    end = deployment_end(datasets)
    if path not in datasets or end is None or end < 1:
        return False
    values = np.abs(channel(datasets, path))[:end + 1]
    return bool(values.size > 1 and np.argmax(values) == values.size - 1
                and values[-1] > values[-2])


def deployment_time_s(datasets: Mapping[str, Any]) -> float | None:
    """Time of the first maximum of the crank angle [s] (delta_t, docs/criterion.md;
    :func:`flex.data.headlines.first_maximum_index`, which ignores round-off); None
    when the crank angle has no maximum within the run (a deployment not reached, a
    constant-speed crank, a crank that never moves): missing, not the end time."""
    top = deployment_end(datasets)
    if top is None:
        return None
    angle = channel(datasets, DEPLOYMENT_SERIES)
    time_s = np.asarray(datasets["time"].data, dtype=float)
    # the parabola through the top sample and its neighbours: the maximum between samples
    # (a sample time alone is off by up to half a step, more than the run's own error)
    left, middle, right = angle[top - 1:top + 2]
    curvature = left - 2.0 * middle + right
    offset = 0.5 * (left - right) / curvature if curvature < 0 else 0.0
    return float(time_s[top] + np.clip(offset, -0.5, 0.5) * (time_s[top + 1] - time_s[top]))


DEPLOYMENT = ("release to the first crank maximum (without one: to the run's end, less the "
              "channel's undetermined tail), on the headline channel")
_CHANNEL_TEXT = " (headline channel)"
WHOLE_RUN = ("the whole run less the channel's undetermined tail, on the headline channel "
             "(a run without one: the raw whole run)")


def _link_headlines(link: str) -> list[list[Headline]]:
    """A flexible link's own quantities: its peak deflection, bending and von Mises stress
    over the deployment on the headline channel (the primary ones), and the same over the
    whole run, the return swing included (on the channel too: a raw maximum races between
    the sub-crests of undamped ringing)."""
    deflection = f"{link}/midpoint_deflection"
    away = " (away from the joint faces)"
    series = [(deflection, "deflection_m", f"peak elastic midpoint deflection of the {link}"),
              (f"{link}/peak_bending_stress", "bending_stress_Pa",
               f"peak bending stress of the {link}"),
              (f"{link}/peak_von_mises_stress", "von_mises_Pa",
               f"peak von Mises stress of the {link}{away}")]
    deployment = [Headline(f"{link}_deployment_peak_{suffix}", suffix.rsplit("_", 1)[1], what
                           + " over the deployment" + _CHANNEL_TEXT,
                           _reader(deployment_peak_value(path), path, link), "value", path,
                           window=DEPLOYMENT,
                           link=link, certified=path == deflection,
                           mesh_order=2 if path == deflection else 1,
                           channel=(path, DEPLOYMENT_SERIES))
                  for path, suffix, what in series]
    whole = [Headline(f"{link}_peak_{suffix}", suffix.rsplit("_", 1)[1],
                      what + " over the whole run" + _CHANNEL_TEXT,
                      _reader(channel_peak_value(path), path, link), "value", path,
                      window=WHOLE_RUN, link=link, crest_gap=path == deflection,
                      mesh_order=2 if path == deflection else 1, channel=(path,))
             for path, suffix, what in series]
    return [deployment, whole]


def _reader(read: Callable[[Mapping[str, Any]], float | None], path: str, link: str
            ) -> Callable[[Mapping[str, Any]], float | None]:
    """A link quantity's reader: a deflection's within its round-off is missing."""
    return above_roundoff(read, link) if path.endswith("/midpoint_deflection") else read


def _first_crest(link: str) -> Headline:
    deflection = f"{link}/midpoint_deflection"
    return Headline(f"{link}_first_crest_deflection_m", "m",
                    f"first crest of the elastic midpoint deflection of the {link} (largest "
                    f"|deflection| of the first lobe){_CHANNEL_TEXT}",
                    above_roundoff(first_crest_value(deflection), link), "first_crest",
                    deflection,
                    window="the first lobe of the deflection, on the headline channel",
                    link=link, channel=(deflection,))


def _joint_force(joint: str, deployment: bool) -> Headline:
    path = f"joints/{joint}/force_modulus"
    if deployment:
        return Headline(f"joint_{joint}_deployment_peak_force_N", "N",
                        f"peak force of joint {joint} over the deployment{_CHANNEL_TEXT}",
                        deployment_peak_value(path), "value", path, window=DEPLOYMENT,
                        channel=(path, DEPLOYMENT_SERIES))
    return Headline(f"joint_{joint}_peak_force_N", "N",
                    f"peak force of joint {joint} over the whole run{_CHANNEL_TEXT}",
                    channel_peak_value(path), "value", path, window=WHOLE_RUN,
                    channel=(path,))


def _history(path: str, what: str, link: str | None) -> Headline:
    """The curve ``path`` on the headline channel as a headline: its value the peak, its
    error the largest difference to a finer run over the whole run
    (``estimated_error_history_<path>``)."""
    peak = channel_peak_value(path)
    return Headline(f"history_{path.replace('/', '_')}", "m" if path.endswith(("position",
                    "deflection")) else "rad", f"{what} over the whole run{_CHANNEL_TEXT} "
                    "(value: its peak |value|; error: the largest difference of the curve)",
                    above_roundoff(peak, link) if link else peak, "history", path,
                    window=WHOLE_RUN, link=link, channel=(path,))


def _builtin() -> dict[str, Headline]:
    own = {link: _link_headlines(link) for link in ("coupler", "crank")}
    entries = [
        Headline("crank_angle_end_rad", "rad", "crank angle at the end time",
                 final_value("crank/angle"), window="the end time"),
        Headline("slider_position_end_m", "m", "slider position at the end time",
                 final_value("slider/position"), window="the end time"),
        Headline("deployment_time_s", "s", "deployment time (first maximum of the crank angle)",
                 deployment_time_s, window="release to the first crank maximum",
                 channel=(DEPLOYMENT_SERIES,)),
        # the printed order: over the deployment (deflections, bending stresses, von Mises,
        # joint forces), then the first crests, then the same over the whole run
        *(own[link][0][k] for k in range(3) for link in ("coupler", "crank")),
        *(_joint_force(joint, True) for joint in "ABC"),
        *(_first_crest(link) for link in ("coupler", "crank")),
        *(own[link][1][k] for k in range(3) for link in ("coupler", "crank")),
        *(_joint_force(joint, False) for joint in "ABC"),
        _history("crank/angle", "crank angle history", None),
        _history("slider/position", "slider position history", None),
        *(_history(f"{link}/midpoint_deflection", f"elastic midpoint deflection history of the "
                   f"{link}", link) for link in ("coupler", "crank")),
    ]
    return {entry.name: entry for entry in entries}


#: the built-in headline quantities, by name, in the order they are printed (immutable)
BUILTIN_HEADLINES: Mapping[str, Headline] = MappingProxyType(_builtin())


#: groups of headline quantities ``fidelity.quantities`` may name besides single quantities:
#: the motion; each link's own deployment peak deflection (asked: the link is modelled
#: flexible); the same, of the links that are flexible in the run (asked: no link is made
#: flexible for it)
QUANTITY_GROUPS: Mapping[str, tuple[str, ...]] = MappingProxyType({
    "motion": ("crank_angle_end_rad", "slider_position_end_m", "deployment_time_s"),
    "deflections": tuple(name for name, entry in BUILTIN_HEADLINES.items() if entry.certified),
    "flexible_deflections": tuple(name for name, entry in BUILTIN_HEADLINES.items()
                                  if entry.certified),
})
#: what ``fidelity.tolerance`` applies to unless ``fidelity.quantities`` says otherwise: the
#: motion, and each flexible link's peak deflection over the deployment
DEFAULT_QUANTITIES = ("motion", "flexible_deflections")


def channel_series(headlines: Mapping[str, Headline] = BUILTIN_HEADLINES) -> tuple[str, ...]:
    """The series the ``headlines`` read on the headline channel (each once, the crank angle
    that ends the deployment first): what a run stores filtered as ``channel/<path>``
    (:func:`flex.dynamics.advice.channel_datasets`)."""
    found = [DEPLOYMENT_SERIES] + [path for headline in headlines.values()
                                   for path in headline.channel]
    return tuple(dict.fromkeys(found))

__all__ = ["BUILTIN_HEADLINES", "DEFAULT_QUANTITIES", "KINDS", "QUANTITY_GROUPS", "WHOLE_RUN",
           "Headline", "above_roundoff", "channel", "channel_curve", "channel_peak_value",
           "channel_series", "crest_gap", "crest_value", "deflection_resolution_m",
           "deployment_end", "deployment_peak_value", "deployment_time_s", "final_value",
           "first_crest_value", "history_difference", "peak_at_deployment_end", "peak_value"]
