"""What a run's results mean and what may help when a run fails: validity warnings of a
finished run (:func:`validity_warning`), the scene's time scales (:func:`time_scales`),
its extreme inputs and the advice a divergence carries (:func:`divergence_advice`,
:func:`check_finite`). Split from :mod:`flex.dynamics.solver` (which re-exports these names).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from flex.base.channel import (
    CHANNEL_EDGE_PERIODS,
    channel_filter,
    channel_text,
    undetermined_samples,
)
from flex.base.errors import SimulationError
from flex.data.headlines import channel_series
from flex.data.plates import plate_mass_properties
from flex.data.results import Dataset
from flex.data.scene import LINKS, Scene, model_names, quoted
from flex.dynamics.builder import Mechanism
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel

# a constraint norm above this is a failed assembly, not a tolerance question
CONSTRAINT_NORM_LIMIT_M = 1e-4


# ------------------------------------------------------------------------------------------
# validity of a finished run
# ------------------------------------------------------------------------------------------
#: case attribute holding why a finished (``ok``) run may not mean what it says
VALIDITY_WARNING = "validity_warning"
#: largest peak elastic midpoint deflection of an FFRF link, as a fraction of its length,
#: within which its results are trusted: the FFRF body is linear elasticity in a floating
#: frame (small strains and elastic rotations; its geometric stiffness is of second order);
#: beyond ~1 % of the length the stability study's comparison with the nonlinear FE coupler
#: (README "Numerical stability") shows the two models part
FFRF_DEFLECTION_LIMIT = 0.01


def _buckling_warnings(scene: Scene, datasets: dict[str, Dataset],
                       link_models: Mapping[str, LinkModel]) -> list[str]:
    """A flexible coupler compressed beyond its Euler load pi^2 E I / L^2: an FFRF body's
    geometric stiffness is linear in the load and holds no buckled shape; a body that
    buckles (the exact beam, the nonlinear FE plate) deflects as imperfections it does not
    have would make it (an exact beam 1.5-100 x beyond it was certified to 0.07-5 % without
    a word of buckling)."""
    from flex.base.kinematics import chord_components
    from flex.base.physics import Plate

    coupler, model = scene["coupler"], link_models[scene["coupler"]["model"]]
    if ((model.rigid and coupler["geometry"] != "plate")
            or "joints/C/force_on_coupler" not in datasets):
        return []
    axial, _ = chord_components(datasets["joints/C/force_on_coupler"].data,
                                datasets["coupler/angle"].data)
    ratio = float(np.max(-axial, initial=0.0)) / Plate.of(coupler).euler_load_N
    if ratio <= 1.0:
        return []
    if model.rigid:  # its predicted bending was "nan +- nan"
        return [f"coupler: the rigid coupler's loads compress its plate to {ratio:.3g} x its "
                f"Euler load (pi^2 E I / L^2): a plate would buckle, which the rigid model "
                f"does not show, and no bending is predicted for it; use a thicker coupler"]
    if model.linear_elastic:
        return [f"coupler: compressed to {ratio:.3g} x its Euler load (pi^2 E I / L^2): the "
                f"FFRF body's geometric stiffness is linear in the load and holds no buckled "
                f"shape; use coupler.model = {_references('coupler', link_models)} or a "
                f"thicker coupler"]
    return [f"coupler: compressed to {ratio:.3g} x its Euler load (pi^2 E I / L^2): it "
            f"buckles, and a buckled plate's deflection and stress follow imperfections the "
            f"{model.label or model.name} model does not have (an initial bow, an eccentric "
            f"pin) and round-off; its model error was not measured there (no certificate): "
            f"use a thicker coupler"]


def _references(link: str, link_models: Mapping[str, LinkModel]) -> str:
    return quoted(model_names(link, link_models, reference=True))


def validity_warning(scene: Scene, datasets: dict[str, Dataset],
                     link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> str:
    """Why the results of a finished run may not be valid ("" if nothing is known against
    them): an FFRF coupler compressed beyond its Euler load; an FFRF link whose peak
    elastic midpoint deflection exceeds :data:`FFRF_DEFLECTION_LIMIT` of its length (linear
    FFRF validity)."""
    warnings = _buckling_warnings(scene, datasets, link_models)
    for link in LINKS:
        name = f"{link}/midpoint_deflection"
        if not link_models[scene[link]["model"]].linear_elastic or name not in datasets:
            continue
        peak = float(np.max(np.abs(datasets[name].data)))
        length = scene[link]["length_m"]
        if peak > FFRF_DEFLECTION_LIMIT * length:
            warnings.append(
                f"{link}: peak elastic midpoint deflection {peak:.3g} m is "
                f"{100 * peak / length:.3g} % of {link}.length_m = {length:g} m, beyond the "
                f"{100 * FFRF_DEFLECTION_LIMIT:g} % within which the FFRF body (small "
                f"elastic rotations in its floating frame) is trusted; "
                + (f"compare with {link}.model = {_references(link, link_models)} or use a "
                   f"stiffer {link}" if _references(link, link_models)
                   else f"use a stiffer {link}"))
    return "; ".join(warnings)


# ------------------------------------------------------------------------------------------
# divergence advice: is a smaller step the answer?
# ------------------------------------------------------------------------------------------
#: steps per period that resolve a time scale with the implicit integrator (generalized-
#: alpha period error (2 pi / 20)^2 / 12 = 0.8 %)
STEPS_PER_PERIOD = 20.0
#: an input this far (factor) from the bundled scene's value is named as extreme
EXTREME_FACTOR = 100.0
#: keys the step advice speaks of itself (not "extreme inputs")
_STEP_KEYS = ("simulation.end_time_s", "simulation.step_s", "simulation.output_step_s")


def mechanism_reductions(mech: Mechanism) -> dict[str, Any]:
    """The reductions of a built mechanism's FFRF links, by link name (rigid links: none)."""
    return {link: body["reduction"] for link, body in (("crank", mech.crank),
                                                       ("coupler", mech.coupler))
            if body.get("reduction") is not None}


def mechanism_mass_at_slider(scene: Scene) -> float:
    """Smallest inertia of the rigid mechanism reduced to the slider coordinate [kg].

    Kinetic energy 2 T = m_eff(theta) v_slider^2 (crank about A with the wing, coupler,
    slider; links with their lumped or plate mass properties), minimised over the crank
    angle (away from the dead centres, where the slider stops and m_eff is infinite).
    """
    from flex.base.kinematics import slider_crank
    from flex.dynamics.builder import wing_mass_properties

    l1, l2 = scene["crank"]["length_m"], scene["coupler"]["length_m"]
    theta = np.linspace(-np.pi, np.pi, 721)
    state = slider_crank(l1, l2, theta, 1.0, 0.0, scene["slider"]["offset_m"])
    m1, j1 = plate_mass_properties(scene, "crank")
    m2, j2 = plate_mass_properties(scene, "coupler")
    inertia_a = j1 + m1 * (l1 / 2) ** 2
    if scene["wing"]["enabled"]:
        mass_w, inertia_w, centre_w = wing_mass_properties(scene)
        inertia_a += inertia_w + mass_w * centre_w**2
    v_slider = state.slider_velocity_m_per_s
    centre_x = (-l1 * np.sin(theta) + v_slider) / 2
    centre_y = l1 * np.cos(theta) / 2
    energy = (inertia_a + m2 * (centre_x**2 + centre_y**2)
              + j2 * state.coupler_angular_velocity_rad_per_s**2
              + scene["slider"]["mass_kg"] * v_slider**2)
    moving = np.abs(v_slider) > 1e-3 * np.max(np.abs(v_slider))
    return float(np.min(energy[moving] / v_slider[moving] ** 2))


def time_scales(scene: Scene, reductions: dict[str, Any] | None = None,
                link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS
                ) -> list[tuple[float, float, str]]:
    """The scene's time scales a fixed step must resolve: ``(period [s], steps per period
    needed, what)``, shortest first. ``reductions``: the built reductions by link (their
    highest retained mode is then known, else estimated from the plate); each link model
    adds its own (:mod:`flex.dynamics.link_models`, point 7)."""

    reductions = reductions or {}
    out: list[tuple[float, float, str]] = []
    drive, sim = scene["drive"], scene["simulation"]
    with np.errstate(all="ignore"):
        if drive["kind"] == "spring" and drive["spring_stiffness_N_per_m"] > 0:
            mass = mechanism_mass_at_slider(scene)
            out.append((2 * np.pi * np.sqrt(mass / drive["spring_stiffness_N_per_m"]),
                        STEPS_PER_PERIOD, "period of the spring on the mechanism's inertia"))
        elif drive["kind"] == "constant_speed" and drive["crank_speed_rad_per_s"] != 0:
            out.append((2 * np.pi / abs(drive["crank_speed_rad_per_s"]),
                        STEPS_PER_PERIOD, "crank turn (constant speed)"))
        for link in LINKS:
            values = scene[link]
            scale = link_models[values["model"]].time_scale(link, values,
                                                            reductions.get(link))
            if scale is not None:
                omega, how = scale
                out.append((2 * np.pi / omega, STEPS_PER_PERIOD, f"period of the {link}'s {how}"))
        if sim["integrator"] == "explicit_penalty":
            # lightest inertia a joint spring moves: body masses and J / (L/2)^2; two
            # bodies on one spring: 2 k / m. Explicit Runge-Kutta is stable up to
            # omega h ~ 2.8 (RK44): omega h <= 1 keeps a margin (measured limit 1.6e-5 s at
            # 1e8 N/m on the thesis links: omega h = 2.8)
            m1, j1 = plate_mass_properties(scene, "crank")
            m2, j2 = plate_mass_properties(scene, "coupler")
            lightest = min(m1, m2, scene["slider"]["mass_kg"],
                           j1 / (scene["crank"]["length_m"] / 2) ** 2,
                           j2 / (scene["coupler"]["length_m"] / 2) ** 2)
            omega = np.sqrt(2 * sim["penalty_stiffness_N_per_m"] / lightest)
            out.append((2 * np.pi / omega, 2 * np.pi,
                        "period of the penalty joints (explicit_penalty)"))
    return sorted((float(period), need, what) for period, need, what in out)


#: the headline channel's cut-off over the lowest first bending frequency of the scene's
#: flexible links: passes a link's first bending mode (gain 0.9998 forward-backward) and
#: stops its third, the next one that moves the midpoint (9x the first: gain 1.5e-4), and
#: the links' axial ringing above it (docs/criterion.md, "The headline channel")
CHANNEL_FACTOR = 3.0


def channel_cutoff_Hz(scene: Scene,
                      link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS
                      ) -> float | None:
    """Cut-off [Hz] of the zero-phase low-pass channel the deployment's headline peaks are
    read on (:mod:`flex.data.headlines`): :data:`CHANNEL_FACTOR` times the lowest
    pinned-pinned first bending frequency of the scene's flexible plate links (Euler-
    Bernoulli, :attr:`flex.base.physics.Plate.pinned_pinned_omega`); None when no link is
    flexible (a rigid mechanism has no elastic ringing to filter)."""
    from flex.base.physics import Plate

    omegas = [Plate.of(values).pinned_pinned_omega for values in (scene[link] for link in LINKS)
              if not link_models[values["model"]].rigid and values["geometry"] == "plate"]
    return CHANNEL_FACTOR * min(omegas) / (2.0 * np.pi) if omegas else None


#: dataset marking the channel's determined samples (1) and its undetermined tail (0)
CHANNEL_DETERMINED = "channel/determined"
#: case attribute holding the channel's cut-off [Hz]
CHANNEL_ATTR = "channel_cutoff_Hz"


def channel_datasets(datasets: Mapping[str, Dataset], cutoff_Hz: float | None,
                     series: tuple[str, ...] | None = None) -> dict[str, Dataset]:
    """The ``series`` a run has (None: those the built-in headlines read on the channel,
    :func:`flex.data.headlines.channel_series`), on its headline channel (``channel/<path>``):
    low-passed forward and backward (zero phase; SAE J211 / ISO 6487 read crash-test peaks
    on such channels) at ``cutoff_Hz`` (:func:`channel_cutoff_Hz`) by
    :func:`flex.base.channel.channel_filter`; none where the run has no channel (no cut-off,
    a sampling that holds nothing above it, a run shorter than twice the channel's
    undetermined tail); with them :data:`CHANNEL_DETERMINED`, which marks that tail
    (:data:`flex.base.channel.CHANNEL_EDGE_PERIODS`). A series whose ``channel/<path>`` the
    run already has is left as it is: a link's stress peaks are read on its low-passed field
    (:mod:`flex.base.channel`), never the peak series low-passed."""
    time_s = np.asarray(datasets["time"].data, dtype=float)
    low_pass = channel_filter(time_s, cutoff_Hz)
    if low_pass is None:
        return {}
    determined = np.ones(time_s.size, dtype=np.uint8)
    determined[time_s.size - undetermined_samples(time_s, cutoff_Hz):] = 0
    return {CHANNEL_DETERMINED: Dataset(
        determined, "1", f"1 where the headline channel is determined by the run's samples, "
        f"0 within {CHANNEL_EDGE_PERIODS:g} cut-off periods of the run's end (the filter reads "
        f"its padding there; the headlines are not read on those samples)")} | {
        f"channel/{path}": Dataset(
        low_pass(np.asarray(datasets[path].data, dtype=float)),
        datasets[path].units, f"{datasets[path].description}, {channel_text(cutoff_Hz)}")
        for path in (channel_series() if series is None else series)
        if path in datasets and f"channel/{path}" not in datasets}


def extreme_inputs(scene: Scene,
                   link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> list[str]:
    """The inputs the scene's models use that are not finite or lie :data:`EXTREME_FACTOR`
    or more from the bundled scene's values (``"auto"`` solver keys: the rigid entry of
    ``flex/config/solver_defaults.toml``), most extreme first, as ``key = value (bundled: x)``."""
    from flex.config.settings import AUTO, solver_defaults
    from flex.config.usage import unused_keys
    from flex.data.scene import DEFAULT_SCENE, SCHEMA, read_toml, scene_path

    bundled = read_toml(scene_path(DEFAULT_SCENE), DEFAULT_SCENE)
    unused = unused_keys(scene, link_models=link_models)
    found: list[tuple[float, str]] = []
    for section, fields in SCHEMA.items():
        for key, field in fields.items():
            name = f"{section}.{key}"
            value = scene.get(section, {}).get(key)
            default = bundled.get(section, {}).get(key)
            if default == AUTO:
                default = solver_defaults()["rigid"].get(key)
            if (name in unused or name in _STEP_KEYS or field.kind is not float
                    or isinstance(value, bool) or not isinstance(value, int | float)
                    or not isinstance(default, int | float) or default <= 0):
                continue
            if not np.isfinite(value):
                found.append((np.inf, f"{name} = {value!r}"))
            elif value > 0:
                factor = abs(np.log10(value / default))
                if factor >= np.log10(EXTREME_FACTOR):
                    found.append((factor, f"{name} = {value:g} (bundled: {default:g})"))
    return [text for _, text in sorted(found, key=lambda item: -item[0])]


def divergence_advice(scene: Scene, reductions: dict[str, Any] | None = None,
                      link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> str:
    """What may help a diverged run, in one line: a smaller step only where the step does
    not resolve the scene's fastest time scale (:func:`time_scales`); the extreme inputs
    (:func:`extreme_inputs`) always."""
    try:
        step = float(scene["simulation"]["step_s"])
        scales = time_scales(scene, reductions, link_models)
        extremes = extreme_inputs(scene, link_models)
    except Exception:  # noqa: BLE001 - advice must never hide the divergence itself
        return "check the scene's extreme inputs and simulation.step_s"
    parts = []
    unresolved = [(period, need, what) for period, need, what in scales
                  if not (np.isfinite(period) and step <= period / need)]
    if unresolved:
        period, need, what = unresolved[0]
        if np.isfinite(period):
            parts.append(f"try a smaller simulation.step_s: h = {step:g} s is "
                         f"{period / step:.3g} steps per {what} ({period:.3g} s); it needs "
                         f"h <= {period / need:.3g} s")
        else:
            parts.append(f"the {what} is not finite")
    elif scales:
        period, need, what = scales[0]
        parts.append(f"the step already resolves the fastest time scale flex knows of "
                     f"({what}, {period:.3g} s: {period / step:.3g} steps), so a smaller "
                     f"simulation.step_s is unlikely to help")
    if extremes:
        parts.append("extreme inputs: " + ", ".join(extremes[:3]))
    elif not unresolved:
        sim = scene["simulation"]
        if (sim["integrator"] == "generalized_alpha" and sim["formulation"] == "index3"
                and sim["spectral_radius"] == 1.0):
            parts.append("simulation.spectral_radius = 1 leaves the index-3 constraint modes "
                         "undamped: try 0.9 or less")
        else:  # it said "check the solver settings" to users who had set none
            used = ", ".join(f"{key} = {sim[key]!r}" for key in (
                "step_s", "newton", "newton_relative_tolerance", "spectral_radius"))
            parts.append(f"no input is {EXTREME_FACTOR:g}x from the bundled scene; the run "
                         f"used {used} (flex's own where [simulation] says \"auto\"): flex "
                         f"knows no cause; please report the scene")
    return "; ".join(parts)


#: fewer steps than this per period of the drive (the spring on the mechanism's inertia, or a
#: constant-speed crank turn) cannot represent the motion at all (Nyquist): what the run
#: integrates is an alias (measured: a 1e12 N/m spring at h = 1e-5 s, 0.2 steps per period,
#: turned the crank 95,128 rad in 1 ms, with every sample finite)
MIN_DRIVE_STEPS_PER_PERIOD = 2.0
#: the time scales of the drive (:func:`time_scales`' names), whose motion the run is about
DRIVE_SCALES = ("period of the spring on the mechanism's inertia", "crank turn (constant speed)")


def check_resolved(scene: Scene, settings: dict[str, Any],
                   reductions: dict[str, Any] | None,
                   link_models: Mapping[str, LinkModel]) -> None:
    """Raise :class:`SimulationError` when the step is longer than half the drive's period
    (:data:`MIN_DRIVE_STEPS_PER_PERIOD`): the run's motion is then not the mechanism's,
    however finite its samples."""
    step = float(settings["step_s"])
    for period, _, what in time_scales(scene, reductions, link_models):
        if what in DRIVE_SCALES and np.isfinite(period) \
                and period / step < MIN_DRIVE_STEPS_PER_PERIOD:
            raise SimulationError(
                f"solution diverged from the mechanism's motion (fewer than "
                f"{MIN_DRIVE_STEPS_PER_PERIOD:g} steps per {what}: the run integrates an "
                f"alias of it): {divergence_advice(scene, reductions or {}, link_models)}")


def check_finite(datasets: dict[str, Dataset], settings: dict[str, Any],
                 scene: Scene | None = None, reductions: dict[str, Any] | None = None,
                 link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> None:
    """Raise :class:`SimulationError` at the earliest sample where the solution diverged.

    Diverged: the motion's own time scale not resolved (:func:`check_resolved`), any
    dataset not finite (NaN, inf), or the constraint norm above
    :data:`CONSTRAINT_NORM_LIMIT_M` (an exploding or torn-apart assembly). The message names
    the integration step (time / step_s), the time [s] and what went wrong, and, given the
    ``scene`` (and its ``reductions`` by link), what may help (:func:`divergence_advice`).
    """
    if scene is not None:
        check_resolved(scene, settings, reductions, link_models)
    time_s = np.asarray(datasets["time"].data, dtype=float)
    problems: list[tuple[int, str]] = []
    for name, dataset in datasets.items():
        data = np.asarray(dataset.data, dtype=float)
        bad = ~np.isfinite(data.reshape(len(time_s), -1)).all(axis=1)
        if bad.any():
            problems.append((int(np.argmax(bad)), f"{name} is not finite"))
    norm = np.asarray(datasets["constraint_norm"].data, dtype=float)
    above = norm > CONSTRAINT_NORM_LIMIT_M
    if above.any():
        index = int(np.argmax(above))
        problems.append((index, f"constraint norm {norm[index]:.3g} m exceeds "
                                f"{CONSTRAINT_NORM_LIMIT_M:g} m"))
    if not problems:
        return
    index, what = min(problems, key=lambda problem: problem[0])
    now = time_s[index] if np.isfinite(time_s[index]) else float("nan")
    step = int(round(now / settings["step_s"])) if np.isfinite(now) else index
    advice = ("" if scene is None
              else f"; {divergence_advice(scene, reductions or {}, link_models)}")
    raise SimulationError(f"solution diverged at step {step} (t = {now:.6g} s, step "
                          f"{settings['step_s']:g} s): {what}{advice}")


#: the old private names, still imported by flex/dynamics/solver.py (to go with that import)
