"""How far a coupler model is from the nonlinear FE reference, and how loaded the link is.

- :func:`coupler_compression_N`: the link's compression along its chord B-C, against the
  pinned-pinned Euler load pi^2 E I / L^2 (I = w t^3 / 12) of its plate
  (:attr:`flex.base.physics.Plate.euler_load_N`);
  near 1 the axial force changes the bending stiffness (the linear FFRF body is blind to
  it, flex's default FFRF body carries it: :mod:`flex.bodies.geometric_stiffness`);
- :func:`compare_with_reference`: the runs of one plate as several models (FFRF, linear
  FFRF, rigid twin) against the fully nonlinear FE coupler (:mod:`flex.bodies.nonlinear`, same
  mesh, Green-Lagrange strain) sample by sample over its span: first and largest deflection
  peaks and their errors, the largest difference of the curves, the crank angle, the
  compression over the Euler load and the reference's wall time, as summary datasets and
  report lines.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from flex.base.kinematics import chord_components
from flex.data.headlines import first_peak_index
from flex.data.results import CaseResult, Dataset
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, FFRF, RIGID


def coupler_compression_N(data: dict[str, np.ndarray], samples: int | None = None
                          ) -> np.ndarray:
    """Compression of the coupler along its chord B-C at each sample [N] (> 0: pushed).

    The slider pushes on the coupler at C: compression is the joint C force on the coupler
    pointing from C toward B. ``samples``: only the first that many samples (None: all).
    """
    axial, _ = chord_components(data["joints/C/force_on_coupler"][:samples],
                                data["coupler/angle"][:samples])
    return -axial


Values = dict[str, tuple[Any, str, str]]  # key -> (value, units, description)

#: what each compared model (a case named after it) is called in reports
LABELS = {**{name: model.label for name, model in BUILTIN_LINK_MODELS.items()},
          "linear": "linear FFRF (geometric_stiffness = false)"}


def _model_values(data: dict[str, np.ndarray], reference: dict[str, np.ndarray],
                  samples: int, label: str) -> Values:
    """One model's run against the reference over the reference's ``samples``: its first
    and largest deflection peaks and their errors relative to the reference's, the largest
    curve difference over the reference's peak, the crank angle's largest difference."""
    curve = np.asarray(data["coupler/midpoint_deflection"][:samples], dtype=float)
    ref = np.asarray(reference["coupler/midpoint_deflection"], dtype=float)
    ref_first, ref_peak = ref[first_peak_index(ref)], float(np.abs(ref).max())
    first = float(curve[first_peak_index(curve)]) if np.any(curve) else 0.0
    peak = float(np.abs(curve).max())
    return {
        "first_peak_deflection": (first, "m", f"first deflection extreme (signed), {label}"),
        "first_peak_error": (first / ref_first - 1.0, "1",
                             f"first extreme, {label} / reference - 1"),
        "peak_deflection": (peak, "m", f"max |midpoint deflection| over the span, {label}"),
        "peak_error": (peak / ref_peak - 1.0, "1", f"largest peak, {label} / reference - 1"),
        "max_curve_difference_over_peak": (
            float(np.abs(curve - ref).max()) / ref_peak, "1",
            f"max |{label} - reference| midpoint deflection over the span / reference peak"),
        "max_crank_angle_difference": (
            float(np.abs(data["crank/angle"][:samples] - reference["crank/angle"]).max()),
            "rad", f"max |{label} - reference| crank angle over the span"),
    }


#: the motion quantities whose FFRF error is compared with the elasticity's effect on them:
#: name -> (series, how it is read over the span: "peak" of |series| or "end" value)
MOTION = {"joint A peak force": ("joints/A/force_modulus", "peak"),
          "joint B peak force": ("joints/B/force_modulus", "peak"),
          "joint C peak force": ("joints/C/force_modulus", "peak"),
          "crank angle": ("crank/angle", "end"),
          "slider position": ("slider/position", "end")}


def motion_error_fractions(ffrf: dict[str, np.ndarray], rigid: dict[str, np.ndarray],
                           reference: dict[str, np.ndarray], samples: int) -> dict[str, float]:
    """|FFRF - reference| / |FFRF - rigid twin| of each :data:`MOTION` quantity over the
    reference's ``samples``: the FFRF body's model error as a fraction of what the
    elasticity changes (what :data:`flex.config.ladder.FFRF_MOTION_ERROR_FRACTION`
    bounds)."""
    out = {}
    for name, (path, how) in MOTION.items():
        if how == "peak":
            ffrf_value, rigid_value, reference_value = (
                float(np.abs(data[path][:samples]).max()) for data in (ffrf, rigid, reference))
        else:
            ffrf_value, rigid_value, reference_value = (
                float(data[path][samples - 1]) for data in (ffrf, rigid, reference))
        effect = abs(ffrf_value - rigid_value)
        out[name] = abs(ffrf_value - reference_value) / effect if effect > 0 else float("nan")
    return out


def _error_text(value: float) -> str:
    return f"{value:+.2%}" if np.isfinite(value) else "-"


def compare_with_reference(label: str, cases: dict[str, CaseResult], reference: CaseResult,
                           euler_load_N: float, prefix: str
                           ) -> tuple[dict[str, Dataset], list[str]]:
    """Compare each model's run of one plate (``cases``: ``ffrf``, ``linear``, ``rigid``, any
    of them) with the nonlinear FE ``reference`` run over the reference's span: the
    datasets ``<prefix>/<model>/<key>`` and ``<prefix>/<key>`` (span, the reference's
    peaks, the compression over the Euler load, wall times) and the report lines (one line
    saying why, and no datasets, if the reference failed). Runs that failed or do not share
    the reference's first samples are named and skipped.
    """
    if reference.status != "ok":
        return {}, [f"nonlinear FE reference {label}: failed: {reference.message}"]
    ref = {k: v.data for k, v in reference.datasets.items()}
    samples = len(ref["time"])
    found, skipped = _compared_models(cases, ref)
    compression = (float(coupler_compression_N(
        {k: v.data for k, v in cases[FFRF].datasets.items()}, samples).max())
        if FFRF in found else float("nan"))
    common: Values = {
        "span_end_time": (float(ref["time"][-1]), "s", "runs compared over 0 .. this time"),
        "reference_peak_deflection": (float(np.abs(ref["coupler/midpoint_deflection"]).max()),
                                      "m", "max |midpoint deflection| of the reference"),
        "reference_dof": (reference.attrs.get("fe_dof", -1), "1",
                          "coordinates of the nonlinear FE body (3 per mesh node)"),
        "reference_wall_time": (reference.counters["wall_time_s"], "s",
                                "nonlinear FE run wall time"),
        "max_compression_over_euler_load": (compression / euler_load_N, "1",
                                            "max axial compression (FFRF joint C force along "
                                            "B-C) / pinned-pinned Euler load"),
    }
    datasets = {f"{prefix}/{key}": Dataset(value, unit, text)
                for key, (value, unit, text) in common.items()}
    for name, values in found.items():
        datasets.update({f"{prefix}/{name}/{key}": Dataset(value, unit, text)
                         for key, (value, unit, text) in values.items()})
    lines = [f"nonlinear FE reference, {label} ({common['reference_dof'][0]} coordinates, the "
             f"same mesh, 0 .. {common['span_end_time'][0] * 1e3:.1f} ms, "
             f"{common['reference_wall_time'][0]:.0f} s): peak "
             f"{common['reference_peak_deflection'][0] * 1e6:.4g} um; compression up to "
             f"{common['max_compression_over_euler_load'][0]:.3g} of the Euler load"]
    for name, values in found.items():
        v = {key: value for key, (value, _, _) in values.items()}
        lines.append(f"  {LABELS.get(name, name):45s} peak {v['peak_deflection'] * 1e6:9.4g} um "
                     f"({_error_text(v['peak_error'])}), first peak "
                     f"{_error_text(v['first_peak_error'])}, curves "
                     f"{v['max_curve_difference_over_peak']:.1%} of the peak apart")
    _motion_fractions(cases, found, ref, prefix, datasets, lines)
    if skipped:
        lines.append(f"  not compared: {', '.join(skipped)}")
    return datasets, lines


def _compared_models(cases: dict[str, CaseResult], ref: dict[str, np.ndarray]
                     ) -> tuple[dict[str, Values], list[str]]:
    """Each model run that shares the reference's first samples, its values against the
    reference (:func:`_model_values`); and the runs skipped, with why."""
    samples = len(ref["time"])
    found: dict[str, Values] = {}
    skipped = []
    for name, case in cases.items():
        data = {k: v.data for k, v in case.datasets.items()}
        if case.status != "ok" or len(data.get("time", ())) < samples or not np.allclose(
                data["time"][:samples], ref["time"], rtol=0, atol=1e-12):
            skipped.append(f"{name} ({case.message or 'other time samples'})")
            continue
        found[name] = _model_values(data, ref, samples, LABELS.get(name, name))
    return found, skipped


def _motion_fractions(cases: dict[str, CaseResult], found: dict[str, Values],
                      ref: dict[str, np.ndarray], prefix: str, datasets: dict[str, Dataset],
                      lines: list[str]) -> None:
    """The FFRF run's error on the motion as a fraction of what the elasticity changes
    (against its rigid twin), added to ``datasets`` and ``lines`` (in place)."""
    samples = len(ref["time"])
    if FFRF in found and RIGID in found:
        fractions = motion_error_fractions(
            {k: v.data for k, v in cases[FFRF].datasets.items()},
            {k: v.data for k, v in cases[RIGID].datasets.items()}, ref, samples)
        datasets.update({f"{prefix}/ffrf/motion_error_fraction/{name.replace(' ', '_')}":
                         Dataset(value, "1", f"|FFRF - reference| / |FFRF - rigid twin|, "
                                 f"{name} over the span") for name, value in fractions.items()})
        lines.append("  FFRF against the reference on the motion, as a fraction of the "
                     "elasticity's effect (FFRF - rigid twin): " + ", ".join(
                         f"{name} {value:.3g}" for name, value in fractions.items()))
