"""The references ``make references`` stores: a scene's physics converged once, with its error.

:func:`make_reference` lifts a scene to the top of flex's ladder that has the physics and
converges it:

- every plate link becomes the **calibrated exact beam** (:func:`reference_elements`: 256
  elements, 128 for a stocky plate; its bending stiffness calibrated on the p-converged 3-D
  plate of the same geometry, :mod:`flex.bodies.beam_calibration`); a lumped link stays
  rigid (it has no elasticity to model); a damped plate link is refused (the beam has no
  damping model), and so is a plate crank on a lumped coupler (a beam crank needs a beam
  coupler; the FFRF crank's own top rung, 24 modes on half its mesh, took 300 s per 2 ms);
- the step is :data:`REFERENCE_STEP_S` (:data:`RIGID_REFERENCE_STEP_S` without a plate
  link);
- the **accuracy** of each headline quantity [its unit] is the sum of each knob's error
  from two coarser levels (elements halved and quartered, step doubled and quadrupled: the
  finer change over 2^p - 1 at the observed order p within 0.5 of 2, else a bound, 3x the
  larger change; a raw peak, or a peak whose time moves between the levels, always
  the bound) plus the
  beam's **model term**, its measured idealization (the calibration's residual against the
  3-D plate, relative) times the elastic part of the quantity: the whole value of a link's
  own quantity (a deflection, a stress), the difference to the rigid twin for a quantity of
  the motion or a joint force.

What the accuracy leaves out: the nonlinear 3-D plate's anticlastic stiffening (~0.2 % x
beta^2, under 1e-5 of the deflection for the thesis plates' deployments,
``../shared/reference-notes.md``), and 3-D effects of the dynamics beyond the calibrated
first bending mode (the nonlinear 3-D plate converged on the deployment is not built: Exudyn's
nodal meshes stop at order 2). The stored curves are the finest run's headline series, sampled
every :data:`flex.data.reference_store.CURVE_STEP_S`.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.base.physics import Plate
from flex.data.headlines import BUILTIN_HEADLINES, Headline, channel_series
from flex.data.plates import is_damped
from flex.data.reference_store import CURVE_STEP_S, StoredReference, physics_identity
from flex.data.results import CaseResult, Dataset
from flex.data.scene import LINKS, Scene, to_toml
from flex.data.scene_edit import derive_scene
from flex.dynamics.advice import CHANNEL_DETERMINED
from flex.dynamics.exact_beam_link import beam_calibration_of
from flex.dynamics.link_models import EXACT_BEAM, RIGID
from flex.dynamics.solver import NEWTON_RETRY_ATTR
from flex.fidelity.simulation import simulate_case

#: the reference beam's elements: a slender plate's (length / thickness at least
#: :data:`SLENDER_RATIO`; a 1 mm plate's deployment peak: 64 -> 128 changed it by 3.8e-4,
#: 128 -> 256 by 6e-5-1.2e-4, at 2.5e-6 and 1.25e-6 s) and a stockier one's. On its residual
#: the beam's Newton failed there (256 elements on the 3 mm plate at 60 rad/s, 128 on the 5 mm
#: plate: the residual's round-off floor grows with the elements' axial stiffness), and 64 were
#: used; stopping on the increment (flex.dynamics.exact_beam_link) the 5 and 10 mm plates run
#: 128 elements through, their histories converging at order 2 over 32 / 64 / 128 elements
#: (the 10 mm plate's crank angle: 7.5e-7 then 2.2e-7 rad, session 14)
REFERENCE_ELEMENTS = 256
STOCKY_REFERENCE_ELEMENTS = 128
SLENDER_RATIO = 30.0
#: the reference step [s], with a beam or rigid links only (1e-5 s is the rigid default).
#: The 1 mm plate's crank angle history at 256 elements: 5e-6 -> 2.5e-6 -> 1.25e-6 s moved it
#: by 2.1e-7 then 5.0e-8 rad (order 2.1; with Newton stopping on its residual, 2.9e-6 then
#: 1.6e-5 rad: its round-off floor's noise). 256 elements at 1.25e-6 s: ~50 s and ~4 GB (a
#: sensor per element and step) per run
REFERENCE_STEP_S = 1.25e-6
RIGID_REFERENCE_STEP_S = 1.25e-6
#: a peak whose time moves by more than this many of the coarser run's steps between two
#: levels is not one feature converging: its change counts whole (:func:`_peak_moved`)
PEAK_SHIFT_STEPS = 2.0
#: the runs behind a reference: the finest, one coarser level of each knob, the rigid twin
FINEST, ELEMENTS, STEP, RIGID_TWIN = "finest", "elements", "step", "rigid"


def lift(scene: Scene) -> tuple[list[str], str, list[str]]:
    """The overrides that put ``scene``'s links on the reference rung, a phrase saying what
    the reference is, and the plate links (module doc); :class:`SceneError` for a plate link
    the beam cannot stand for."""
    overrides, parts, plates = [], [], []
    for link in LINKS:
        values = scene[link]
        if values["geometry"] != "plate":
            overrides.append(f'{link}.model="{RIGID}"')
            continue
        if is_damped(values):
            raise SceneError(f"{link}.damping_ratio = {values['damping_ratio']!r}: a stored "
                             f"reference needs an undamped plate (the exact beam has no "
                             f"damping model); accepted: 0")
        if link == "crank" and scene["coupler"]["geometry"] != "plate":
            raise SceneError("crank.geometry = \"plate\" with a lumped coupler: no stored "
                             "reference (a beam crank needs a beam coupler, and the FFRF "
                             "crank's top rung took 300 s per 2 ms); accepted: a plate "
                             "coupler with it")
        elements = reference_elements(values)
        overrides += [f'{link}.model="{EXACT_BEAM}"', f"{link}.elements={elements}"]
        parts.append(f"the calibrated exact beam {link} ({elements} elements)")
        plates.append(link)
    return overrides, ", ".join(parts) or "the rigid mechanism", plates


def reference_elements(values: Mapping[str, Any]) -> int:
    """A plate link's reference elements: :data:`REFERENCE_ELEMENTS` when slender (length /
    thickness >= :data:`SLENDER_RATIO`), else :data:`STOCKY_REFERENCE_ELEMENTS`."""
    slender = float(values["length_m"]) / float(values["thickness_m"]) >= SLENDER_RATIO
    return REFERENCE_ELEMENTS if slender else STOCKY_REFERENCE_ELEMENTS


def _runs(scene: Scene, plates: list[str]) -> dict[str, tuple[list[str], float]]:
    """Each run's extra overrides and step [s]: the finest, two coarser levels of each knob
    (``<knob>`` and ``<knob>_2``), the rigid twin."""
    step_s = REFERENCE_STEP_S if plates else RIGID_REFERENCE_STEP_S
    runs = {FINEST: ([], step_s), STEP: ([], 2 * step_s), f"{STEP}_2": ([], 4 * step_s)}
    if plates:
        for level, divisor in ((ELEMENTS, 2), (f"{ELEMENTS}_2", 4)):
            runs[level] = ([f"{link}.elements={reference_elements(scene[link]) // divisor}"
                            for link in plates], step_s)
        runs[RIGID_TWIN] = ([f'{link}.model="{RIGID}"' for link in plates], step_s)
    return runs


def _knob_error(headline: Headline, done: Mapping[str, CaseResult], knob: str) -> float:
    """The finest run's error in one knob [the quantity's unit] from its two coarser levels
    (:func:`flex.fidelity.error_estimate.finest_estimate`: the finer change over 2^p - 1 at
    the observed order p when it lies within 0.5 of 2; outside, a bound, 3x the larger
    change). A raw peak, or a peak that is not one feature over the three levels
    (:func:`_peak_moved`), has no order: 3x the larger change. The 3 mm plate's
    joint A peak at 32 / 64 / 128 / 256 elements moved by 5.6, 10.4 and 4.3 mN: one level's
    change over 3 had stated a third of the 64-element value's error."""
    from flex.fidelity.error_estimate import BOUND_FACTOR, finest_estimate

    fine = _change(headline, done[FINEST], done[knob])
    coarse = _change(headline, done[knob], done[f"{knob}_2"])
    moved = _peak_moved(headline, done[FINEST], done[knob], done[f"{knob}_2"])
    if headline.bound or moved:
        return BOUND_FACTOR * max(fine, coarse)
    return finest_estimate([coarse, fine], 2)[0]


def make_reference(name: str, scene: Scene, cache_dir: Path | None = None) -> CaseResult:
    """The reference of ``scene``'s physics (module doc) as a case: the finest run's headline
    series decimated to :data:`CURVE_STEP_S`, and attributes ``reference_value_<q>``,
    ``reference_accuracy_<q>`` [q's unit], ``reference_model``, ``reference_evidence``,
    ``physics_toml``. A failed run makes a failed case."""
    try:
        overrides, what, plates = lift(scene)
        common = [*overrides, "simulation.error_estimate=false", "simulation.output_step_s=0.0"]
        runs = {key: derive_scene(scene, [*common, *extra, f"simulation.step_s={step_s!r}"])
                for key, (extra, step_s) in _runs(scene, plates).items()}
    except SceneError as exc:
        return CaseResult(name, to_toml(scene), status="failed", message=str(exc))
    done: dict[str, CaseResult] = {}
    for key, run_scene in runs.items():
        done[key] = simulate_case(run_scene, f"{name}_{key}", cache_dir=cache_dir)
        if done[key].status != "ok":
            return CaseResult(name, to_toml(scene), status="failed",
                              message=f"reference run {key} failed: {done[key].message}")
    idealization = max((beam_calibration_of(Plate.of(scene[link]), cache_dir).idealization
                        for link in plates), default=0.0)
    case = CaseResult(name, done[FINEST].scene_toml, datasets=_curves(done[FINEST].datasets))
    case.attrs.update(reference_model=what, physics_toml=to_toml(physics_identity(scene)))
    evidence = []
    for quantity, headline in BUILTIN_HEADLINES.items():
        value = headline.read(done[FINEST].datasets)
        if value is None:
            continue
        changes = {key: _knob_error(headline, done, key) for key in (ELEMENTS, STEP)
                   if key in done}
        model = idealization * _elastic_part(headline, done)
        case.attrs[f"reference_value_{quantity}"] = value
        case.attrs[f"reference_accuracy_{quantity}"] = sum(changes.values()) + model
        evidence.append(f"{quantity}: " + ", ".join(f"{k} {v:.3g}" for k, v in changes.items())
                        + f", model {model:.3g} {headline.unit}")
    case.attrs["reference_evidence"] = (
        f"{what}; step {runs[FINEST]['simulation']['step_s']:g} s; "
        + "".join(f"{key}: {run.attrs[NEWTON_RETRY_ATTR]}; " for key, run in done.items()
                  if NEWTON_RETRY_ATTR in run.attrs)
        + "accuracy = each knob's "
        f"error from two coarser levels (at the observed order, else 3x the larger change) + "
        f"idealization {idealization:.2g} x the elastic part. "
        + "; ".join(evidence))
    return case


#: bumped when how a reference's accuracy is computed changes, and made of the reference's
#: discretization, so a resumed sweep remakes its cases when either changes (2: a peak that
#: moves between levels counts its change whole only when its shift does not shrink,
#: :func:`_peak_moved`; a resumed sweep had kept 64-element stocky references after their
#: constant changed: the scene a case gets is the physics, not the lifted one)
make_reference.case_version = (  # type: ignore[attr-defined]
    f"3/newton on the increment/elements {REFERENCE_ELEMENTS}, {STOCKY_REFERENCE_ELEMENTS} "
    f"below L/t {SLENDER_RATIO:g}/step {REFERENCE_STEP_S:g}, rigid {RIGID_REFERENCE_STEP_S:g}")


def _change(headline: Headline, finest: CaseResult, coarse: CaseResult) -> float:
    """How far one coarser run lies from the finest [the quantity's unit]: a history's
    largest curve difference, any other quantity's value difference."""
    from flex.fidelity.error_estimate import headline_difference

    if headline.kind == "history":
        return float(headline_difference(headline, finest.datasets, coarse.datasets) or 0.0)
    mine, other = headline.read(finest.datasets), headline.read(coarse.datasets)
    return abs(mine - other) if other is not None else float("inf")


def _peak_moved(headline: Headline, finest: CaseResult, coarse: CaseResult,
                coarser: CaseResult) -> bool:
    """Whether a peak is not one feature converging over the three levels: its time moves by
    more than :data:`PEAK_SHIFT_STEPS` of the coarser run's steps between the finest and the
    first level, and that shift is not at most half the shift between the two coarser levels.
    Then the change counts whole. The rigid thesis joint C's deployment peak is the preload at
    t = 0 at 2.5e-6 s and the multiplier's Newton jitter 1.5e-5 s later, 4.5e-7 higher, at
    1.25e-6 s: another feature. A late crest of a bending link moves with the link's converging
    frequency and is the same feature: the 3 mm plate's deployment peak at 18 ms lay at
    17.8725, 17.8875 and 17.89125 ms at 32, 64 and 128 elements (shifts 15 and 3.75 us; its
    values changed by 1.9e-8 then 4.8e-9 m, order 2). Quantities without a series (end
    values, the deployment time): False."""
    times = [_peak_time_s(headline, run.datasets) for run in (finest, coarse, coarser)]
    if None in times:
        return False
    step_s = float(np.median(np.diff(np.asarray(coarse.datasets["time"].data, dtype=float))))
    shift_fine, shift_coarse = abs(times[0] - times[1]), abs(times[1] - times[2])
    return shift_fine > PEAK_SHIFT_STEPS * step_s and shift_fine > 0.5 * shift_coarse


def _peak_time_s(headline: Headline, datasets: Mapping[str, Dataset]) -> float | None:
    """Time [s] of the largest ``|series|`` a peak reads (on the headline channel over the
    deployment where the headline reads it so), None for a quantity without a series."""
    from flex.data.headlines import DEPLOYMENT, channel, deployment_end

    path = headline.series
    if headline.kind not in ("value", "peak") or path is None or path not in datasets:
        return None
    on_channel = path in headline.channel and f"channel/{path}" in datasets
    values = np.abs(channel(datasets, path) if on_channel
                    else np.asarray(datasets[path].data, dtype=float))
    end = deployment_end(datasets) if on_channel and headline.window == DEPLOYMENT else None
    values = values[:None if end is None else end + 1]
    if not values.size:
        return None
    return float(np.asarray(datasets["time"].data, dtype=float)[int(np.argmax(values))])


def _elastic_part(headline: Headline, done: Mapping[str, CaseResult]) -> float:
    """The part of a quantity the links' elasticity makes [its unit] (module doc)."""
    if RIGID_TWIN not in done:
        return 0.0
    finest = done[FINEST].datasets
    if headline.link is not None:
        return abs(headline.read(finest) or 0.0)
    from flex.fidelity.error_estimate import headline_difference

    return float(headline_difference(headline, finest, done[RIGID_TWIN].datasets) or 0.0)


def _curves(datasets: Mapping[str, Dataset]) -> dict[str, Dataset]:
    """The headline series (raw and on the channel) sampled every :data:`CURVE_STEP_S`."""
    time_s = np.asarray(datasets["time"].data, dtype=float)
    every = max(1, round(CURVE_STEP_S / float(np.median(np.diff(time_s)))))
    paths = {h.series for h in BUILTIN_HEADLINES.values() if h.series} | {
        f"channel/{path}" for path in channel_series()} | {"channel/determined"}
    out = {"time": Dataset(time_s[::every], "s", "time")}
    for path in sorted(paths):
        if path in datasets:
            item = datasets[path]
            out[path] = Dataset(np.asarray(item.data)[::every], item.units, item.description)
    return out


def stored_reference(case: CaseResult) -> StoredReference:
    """The store's entry of a reference case (:func:`make_reference`): its values,
    accuracies and the history series' curves."""
    import tomllib

    values, accuracies, units = {}, {}, {}
    for quantity, headline in BUILTIN_HEADLINES.items():
        if f"reference_value_{quantity}" in case.attrs:
            values[quantity] = float(case.attrs[f"reference_value_{quantity}"])
            accuracies[quantity] = float(case.attrs[f"reference_accuracy_{quantity}"])
            units[quantity] = headline.unit
    # the store keeps the curves a true error is read from (the histories', on the headline
    # channel where they are read so, with its determined part); the study's file keeps
    # every headline series
    histories = [h for h in BUILTIN_HEADLINES.values() if h.kind == "history"]
    kept = {"time", CHANNEL_DETERMINED} | {h.series for h in histories} | {
        f"channel/{h.series}" for h in histories if h.series in h.channel}
    curves = {path: d for path, d in case.datasets.items() if path in kept}
    return StoredReference(case.name, tomllib.loads(case.attrs["physics_toml"]),
                           str(case.attrs["reference_model"]),
                           str(case.attrs["reference_evidence"]), values, accuracies, units,
                           {path: np.asarray(d.data) for path, d in curves.items()},
                           {path: d.units for path, d in curves.items()})


#: the reference table's columns (:func:`reference_table`)
REFERENCE_COLUMNS = {"reference": ("1", "stored reference (physics)"),
                     "quantity": ("1", "headline quantity (units in its name)"),
                     "value": ("see quantity", "the reference's value"),
                     "accuracy": ("see quantity", "its own error (knobs' changes + model term)"),
                     "relative_accuracy": ("1", "accuracy / |value|")}


def reference_table(results: Mapping[str, CaseResult]) -> tuple[dict[str, Any], str]:
    """The study's findings: a table of every stored value with its accuracy, and a few
    lines on the references made and failed."""
    from flex.data.tables import findings_table

    rows, failed = [], []
    for name, case in results.items():
        if case.status != "ok":
            failed.append(f"{name} ({case.message})")
            continue
        for quantity in BUILTIN_HEADLINES:
            if f"reference_value_{quantity}" in case.attrs:
                value = float(case.attrs[f"reference_value_{quantity}"])
                accuracy = float(case.attrs[f"reference_accuracy_{quantity}"])
                rows.append({"reference": name, "quantity": quantity, "value": value,
                             "accuracy": accuracy,
                             "relative_accuracy": accuracy / abs(value) if value else 0.0})
    made = [n for n, c in results.items() if c.status == "ok"]
    lines = [f"- {len(made)} references made: " + ", ".join(
        f"{n} ({results[n].attrs.get('reference_model', '')})" for n in made)]
    if failed:
        lines.append(f"- failed: {'; '.join(failed)}")
    lines += ["- accuracy: one coarser level of each knob (elements halved, step doubled), the "
              "change itself, plus the calibrated beam's idealization times the elastic part; "
              "it leaves out the 3-D plate's nonlinear anticlastic stiffening and 3-D dynamics "
              "beyond the calibrated first bending mode", "", "[[table:references]]"]
    tables = findings_table("references", "Stored values and their accuracy", rows,
                            REFERENCE_COLUMNS)
    return tables, "\n".join(lines)


def curve_at(reference: StoredReference, path: str, time_s: np.ndarray
             ) -> tuple[np.ndarray, float]:
    """A stored curve at ``time_s`` [s] by a cubic spline through its samples, and the
    interpolation's own error [the curve's unit]: the largest difference to the spline
    through every other sample, over 2^4 - 1 (a cubic spline's order 4 in the spacing).
    A linear interpolation of the crank angle sampled every 1e-5 s is off by ~1e-7 rad
    between samples, the size of a rigid run's history error."""
    from scipy.interpolate import CubicSpline

    stored_s = np.asarray(reference.curves["time"], dtype=float)
    values = np.asarray(reference.curves[path], dtype=float)
    inside = np.clip(np.asarray(time_s, dtype=float), stored_s[0], stored_s[-1])
    fine = CubicSpline(stored_s, values)(inside)
    coarse = CubicSpline(stored_s[::2], values[::2])(inside)
    return fine, float(np.max(np.abs(fine - coarse))) / 15.0


def install_references(study_file: str | Path, store_file: str | Path) -> list[str]:
    """Write the references of a ``make references`` result file (its ``ok`` cases) to the
    store ``store_file`` (:func:`flex.data.reference_store.write_store`, with the study
    file's provenance); the names written. :class:`flex.base.errors.ResultFileError` for a
    file that is not a references study's, or has no reference made."""
    from flex.base.errors import ResultFileError
    from flex.data.reference_store import write_store
    from flex.data.results import open_results

    with open_results(study_file) as h5:
        if h5.attrs.get("study") != "references":
            raise ResultFileError(f"{study_file}: not a `make references` result (study "
                                  f"{h5.attrs.get('study')!r})")
        provenance = {k: str(v) for k, v in h5.attrs.items() if k != "scene_toml"}
        references = {name: stored_reference(_case_of(name, group))
                      for name, group in h5["cases"].items()
                      if group.attrs.get("status") == "ok"}
    if not references:
        raise ResultFileError(f"{study_file}: no reference was made (every case failed)")
    write_store(store_file, references, provenance)
    return sorted(references)


def _case_of(name: str, group: Any) -> CaseResult:
    datasets: dict[str, Dataset] = {}

    def collect(path: str, item: Any) -> None:
        if hasattr(item, "shape"):
            datasets[path] = Dataset(np.asarray(item[()]), str(item.attrs.get("units", "1")))

    group.visititems(collect)
    return CaseResult(name, str(group.attrs.get("scene_toml", "")), datasets=datasets,
                      attrs={k: v for k, v in group.attrs.items()})


def main(argv: list[str] | None = None) -> int:
    """``python -m flex.experiments.workprecision.stored_references install <study file>
    <store file>`` (``make references-install``); exit 2 with one line on bad input."""
    import sys

    from flex.base.errors import FlexError

    args = sys.argv[1:] if argv is None else argv
    if len(args) != 3 or args[0] != "install":
        print("usage: python -m flex.experiments.workprecision.stored_references install "
              "<results/references.h5> <flex/data/references.h5>", file=sys.stderr)
        return 2
    try:
        names = install_references(args[1], args[2])
    except FlexError as exc:
        print(f"references-install: {exc}", file=sys.stderr)
        return 2
    print(f"installed {len(names)} references into {args[2]}: {', '.join(names)}")
    return 0


__all__ = ["REFERENCE_ELEMENTS", "REFERENCE_STEP_S", "RIGID_REFERENCE_STEP_S", "SLENDER_RATIO",
           "STOCKY_REFERENCE_ELEMENTS", "curve_at", "install_references", "lift",
           "make_reference", "reference_elements", "reference_table", "stored_reference"]


if __name__ == "__main__":
    raise SystemExit(main())
