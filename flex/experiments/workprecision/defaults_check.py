"""Whether flex's bundled solver defaults are what the work-precision runs measured as fastest.

The setting labelled :data:`DEFAULT_LABEL` is what a user gets: the bundled scene's ``"auto"``
solver keys (:data:`flex.config.settings.AUTO_OVERRIDES`), which :mod:`flex.config.settings` fills
from
``flex/config/solver_defaults.toml`` (README "Defaults"). On the 1 mm FFRF plate (the bundled 2 mm
mesh and 6 modes) they resolve to its ``ffrf_coupler`` entry, the certified 1 % pick
h = 4e-4 s, modified Newton 1e-8; on the rigid scene to the ``rigid`` entry.
:func:`ffrf_defaults_check` and :func:`rigid_defaults_check` store whether a run confirms
both (``<scene>/default/matches_table``): within the tolerance (certified) and no slower than
the run's pick by more than :data:`DEFAULT_TIE` (two runs of make tradeoff swapped the 2 mm and
4 mm meshes at h = 4e-4 s: 83 / 62 ms, then 63 / 70 ms); tests/test_tradeoff.py checks that it
reaches the tolerance, and how much faster it is than the rigid-model settings.
"""

from __future__ import annotations

from collections.abc import Sequence

from flex.base.errors import SceneError
from flex.config.settings import AUTO_OVERRIDES, resolve_solver_settings
from flex.data.results import Dataset
from flex.data.scene import Scene
from flex.dynamics.link_models import FFRF
from flex.experiments.workprecision.measurement import (
    Measurement,
    Reference,
    Setting,
    describe,
    scene_for,
)
from flex.experiments.workprecision.pareto import fastest, recommend

DEFAULT_LABEL = "flex defaults (auto)"
#: the default scene's tolerance, as the test suite holds it to the reference DAE (crank angle
#: 1e-6 rad, slider 1e-7 m) on the 1e-5 s output grid of the thesis table (README); and
#: robust: spectral radius below 1 (with rho = 1 the index-3 integrator leaves its algebraic
#: modes undamped and Newton failed after 0.78 s of free motion: make stability)
DEFAULT_TOLERANCE = {"crank_angle_rad": 1e-6, "slider_position_m": 1e-7, "max_step_s": 1e-5,
                     "max_spectral_radius": 0.95}
#: timing noise between runs on the shared machine: a setting this much slower than the pick
#: still counts as equally fast for the defaults check
DEFAULT_TIE = 0.5


def default_setting() -> Setting:
    """The bundled scene's solver keys ("auto"): what a user gets."""
    return Setting(DEFAULT_LABEL, AUTO_OVERRIDES, group="flex defaults")


def is_default(setting: Setting) -> bool:
    """Whether ``setting`` is the bundled scene's solver settings (all keys "auto")."""
    return setting.engine == "exudyn" and setting.overrides == AUTO_OVERRIDES


def same_discretization(plate_scene: Scene, setting: Setting) -> bool:
    """Whether ``setting`` runs the plate scene's own mesh, modes and element order."""
    try:
        scene = scene_for(plate_scene, setting)
    except SceneError:
        return False
    return (setting.element_order == 2 and scene["coupler"]["model"] == FFRF
            and all(scene["coupler"][key] == plate_scene["coupler"][key]
                    for key in ("mesh_size_m", "modes")))


def within_default_tolerance(m: Measurement, base: Scene) -> bool:
    """Whether a run of the rigid scene ``base`` (solver keys pinned) meets
    :data:`DEFAULT_TOLERANCE` ("auto" keys resolved)."""
    limit = DEFAULT_TOLERANCE
    if not (m.ok and m.setting.engine == "exudyn"):
        return False
    sim = resolve_solver_settings(scene_for(base, m.setting))[0]["simulation"]
    return (m.errors["crank_angle_rad"] <= limit["crank_angle_rad"]
            and m.errors["slider_position_m"] <= limit["slider_position_m"]
            and sim["step_s"] <= limit["max_step_s"] * (1 + 1e-9)
            and sim["spectral_radius"] <= limit["max_spectral_radius"])


def default_recommendation(measurements: Sequence[Measurement], base: Scene
                           ) -> Measurement | None:
    """The fastest Exudyn setting meeting :data:`DEFAULT_TOLERANCE` on the rigid scene
    ``base``."""
    within = [m for m in measurements if within_default_tolerance(m, base)]
    return fastest(within) if within else None


def _verdict(matches: bool) -> str:
    return "confirmed" if matches else "NOT confirmed"


def rigid_defaults_check(group: str, measurements: Sequence[Measurement], base: Scene
                         ) -> tuple[dict[str, Dataset], list[str]]:
    """``<group>/default/...`` datasets and report lines: the fastest run within
    :data:`DEFAULT_TOLERANCE` and whether the defaults' run matches it."""
    best = default_recommendation(measurements, base)
    table = [m for m in measurements if m.ok and is_default(m.setting)]
    matches = bool(best and table and within_default_tolerance(table[0], base)
                   and table[0].wall_time_s <= (1 + DEFAULT_TIE) * best.wall_time_s)
    datasets = {
        f"{group}/default/setting": Dataset(
            best.setting.label if best else "", "1",
            "fastest setting within the default scene's tolerance (DEFAULT_TOLERANCE)"),
        f"{group}/default/knobs": Dataset(repr(best.setting.knobs()) if best else "", "1",
                                          "its knobs"),
        f"{group}/default/matches_table": Dataset(
            matches, "1", f"the defaults are within DEFAULT_TOLERANCE and at most "
                          f"{DEFAULT_TIE:g} x slower than the pick")}
    return datasets, [f"    default scene tolerance {DEFAULT_TOLERANCE}: {describe(best)}; "
                      f"defaults {describe(table[0]) if table else 'not run'}: "
                      f"{_verdict(matches)}"]


def ffrf_defaults_check(group: str, measurements: Sequence[Measurement],
                        reference: Reference, plate_scene: Scene
                        ) -> tuple[dict[str, Dataset], list[str]]:
    """``<group>/default/...`` datasets and report lines: the fastest certified run within
    the plate scene's ``fidelity.tolerance`` on its own mesh and modes (the solver defaults
    are for the scene's own discretization), on any, and whether the defaults' run is
    certified within it and at most :data:`DEFAULT_TIE` slower than the pick."""
    level = float(plate_scene["fidelity"]["tolerance"])
    resolved = resolve_solver_settings(scene_for(plate_scene, default_setting()))[1]
    pick = recommend(measurements, reference, [level],
                     eligible=lambda m: m.setting.engine == "exudyn"
                     and same_discretization(plate_scene, m.setting))[0]
    coarser = recommend(measurements, reference, [level],
                        eligible=lambda m: m.setting.engine == "exudyn")[0]
    table = [m for m in measurements if m.ok and is_default(m.setting)]
    matches = bool(pick.measurement and table
                   and table[0].error + reference.accuracy <= level
                   and table[0].wall_time_s <= (1 + DEFAULT_TIE) * pick.measurement.wall_time_s)
    datasets = {
        f"{group}/default/level": Dataset(level, "1", "the scene's tolerance"),
        f"{group}/default/setting": Dataset(
            pick.measurement.setting.label if pick.measurement else "", "1",
            f"fastest certified setting within it ({pick.reason or 'certified'})"),
        f"{group}/default/table_setting": Dataset(
            f"{DEFAULT_LABEL}: {resolved.keys if resolved else ''}", "1",
            "what the bundled scene's solver keys resolve to (flex/config/solver_defaults.toml)"),
        f"{group}/default/matches_table": Dataset(
            matches, "1", f"the defaults are within the tolerance (certified) and at most "
                          f"{DEFAULT_TIE:g} x slower than the pick"),
        f"{group}/default/any_discretization_setting": Dataset(
            coarser.measurement.setting.label if coarser.measurement else "", "1",
            "fastest certified setting within it on any mesh and modes")}
    return datasets, [f"    scene tolerance {level:g}, scene's mesh and modes: "
                      f"{describe(pick.measurement)}; defaults "
                      f"{describe(table[0]) if table else 'not run'}: {_verdict(matches)}; "
                      f"on any mesh and modes: {describe(coarser.measurement)}"]
