"""Where a linear FFRF coupler stops being enough: its axial load and the nonlinear FE body.

A floating-frame body is linear in its own frame: the compression of the link does not
soften its bending (no geometric stiffness). Two measures say how much that matters:

- :func:`coupler_compression_N` / :func:`coupler_euler_load_N`: the link's compression
  along its chord B-C against the pinned-pinned Euler load pi^2 E I / L^2 (I = w t^3 / 12);
  near 1 the axial force changes the bending stiffness;
- :func:`compare_with_nonlinear_fe`: an FFRF run against the fully nonlinear FE coupler
  (:mod:`flex.bodies.nonlinear`, same mesh, Green-Lagrange strain) sample by sample: first and
  largest deflection peaks, the largest difference of the curves, the compression over the
  Euler load and both wall times, as summary datasets and report lines.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from flex.base.kinematics import chord_components
from flex.base.physics import euler_buckling_load_N
from flex.data.results import CaseResult, Dataset


def coupler_compression_N(data: dict[str, np.ndarray], samples: int | None = None
                          ) -> np.ndarray:
    """Compression of the coupler along its chord B-C at each sample [N] (> 0: pushed).

    The slider pushes on the coupler at C: compression is the joint C force on the coupler
    pointing from C toward B. ``samples``: only the first that many samples (None: all).
    """
    axial, _ = chord_components(data["joints/C/force_on_coupler"][:samples],
                                data["coupler/angle"][:samples])
    return -axial


def coupler_euler_load_N(coupler: dict[str, Any]) -> float:
    """Pinned-pinned Euler load [N] of a scene's ``[coupler]`` plate (in-plane buckling)."""
    return euler_buckling_load_N(coupler["length_m"], coupler["thickness_m"],
                                 coupler["width_m"], coupler["youngs_modulus_Pa"])


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


Values = dict[str, tuple[Any, str, str]]  # key -> (value, units, description)


def _peaks(curves: dict[str, np.ndarray], time_s: np.ndarray) -> Values:
    """First (signed) and largest (|.|) deflection peak of each curve [m] and their times
    [s]."""
    values: Values = {}
    for name, curve in curves.items():
        label = "FFRF" if name == "ffrf" else "nonlinear FE"
        first, largest = first_peak_index(curve), int(np.argmax(np.abs(curve)))
        values[f"first_peak_deflection_{name}"] = (float(curve[first]), "m",
                                                   f"first deflection extreme (signed), {label}")
        values[f"first_peak_time_{name}"] = (float(time_s[first]), "s",
                                             f"time of the first extreme, {label}")
        values[f"peak_deflection_{name}"] = (float(np.abs(curve[largest])), "m",
                                             f"max |midpoint deflection| over the span, {label}")
        values[f"peak_time_{name}"] = (float(time_s[largest]), "s",
                                       f"time of that peak, {label}")
    return values


def _walls(cases: dict[str, CaseResult]) -> tuple[Values, dict[str, int]]:
    """Wall time [s] of each run (``ffrf``, ``nonlinear_fe``) and per step; the step counts."""
    values: Values = {}
    steps = {name: max(int(case.counters["steps"]), 1) for name, case in cases.items()}
    for name, case in cases.items():
        label = "FFRF" if name == "ffrf" else "nonlinear FE"
        wall = case.counters["wall_time_s"]
        values[f"{name}_wall_time"] = (wall, "s", f"{label} run wall time (its whole end "
                                       "time)")
        values[f"{name}_wall_time_per_step"] = (wall / steps[name], "s",
                                                f"{label} wall time per step")
    return values, steps


def _curve_values(ffrf: dict[str, np.ndarray], fe: dict[str, np.ndarray],
                  time_s: np.ndarray, euler_load_N: float, fe_dof: int
                  ) -> tuple[Values, float]:
    """Every compared value of the two runs over the nonlinear run's span (``time_s``), and
    the largest compression of the FFRF link [N]."""
    samples = len(time_s)
    curves = {"ffrf": ffrf["coupler/midpoint_deflection"][:samples],
              "nonlinear_fe": fe["coupler/midpoint_deflection"]}
    values: Values = {
        "span_end_time": (float(time_s[-1]), "s", "both runs compared over 0 .. this time"),
        "fe_dof": (fe_dof, "1", "coordinates of the nonlinear FE body (3 per mesh node)"),
        **_peaks(curves, time_s)}
    deviation = np.abs(curves["nonlinear_fe"] - curves["ffrf"])
    worst = int(np.argmax(deviation))
    compression_N = float(coupler_compression_N(ffrf, samples).max())
    values.update({
        "first_peak_ratio": (values["first_peak_deflection_nonlinear_fe"][0]
                             / values["first_peak_deflection_ffrf"][0], "1",
                             "first extreme, nonlinear FE / FFRF"),
        "peak_deflection_ratio": (values["peak_deflection_nonlinear_fe"][0]
                                  / values["peak_deflection_ffrf"][0], "1",
                                  "largest peak, nonlinear FE / FFRF"),
        "max_deflection_deviation": (float(deviation[worst]), "m",
                                     "max |nonlinear FE - FFRF| midpoint deflection over the "
                                     "span"),
        "max_deflection_deviation_over_ffrf_peak": (
            float(deviation[worst]) / values["peak_deflection_ffrf"][0], "1",
            "that deviation / the FFRF peak"),
        "time_of_max_deflection_deviation": (float(time_s[worst]), "s", "where it occurs"),
        "max_crank_angle_deviation": (
            float(np.abs(fe["crank/angle"] - ffrf["crank/angle"][:samples]).max()),
            "rad", "max |nonlinear FE - FFRF| crank angle over the span"),
        "max_midpoint_out_of_plane": (
            float(np.abs(fe["coupler/midpoint_out_of_plane"]).max()), "m",
            "nonlinear FE: max |z| of the midpoint (face-marker tilt artefact; 0 ideal)"),
        "max_compression_over_euler_load": (compression_N / euler_load_N, "1",
                                            "max axial compression (FFRF joint C force along "
                                            "B-C) / pinned-pinned Euler load"),
        "euler_load": (euler_load_N, "N", "pi^2 E I / L^2 of the plate (I = w t^3 / 12)"),
    })
    return values, compression_N


def _report_lines(label: str, v: dict[str, Any], compression_N: float,
                  steps: dict[str, int]) -> list[str]:
    """The report lines of one comparison (``v``: the values by key, without units)."""

    def peak(name: str, kind: str) -> str:
        return (f"{v[f'{kind}_deflection_{name}'] * 1e6:.1f} um at "
                f"{v[f'{kind}_time_{name}'] * 1e3:.2f} ms")

    wall = {name: v[f"{name}_wall_time"] for name in steps}
    return [
        f"nonlinear FE reference, {label} ({v['fe_dof']} coordinates, the same mesh, "
        f"0 .. {v['span_end_time'] * 1e3:.1f} ms):",
        f"  first peak    FFRF {peak('ffrf', 'first_peak')}, nonlinear FE "
        f"{peak('nonlinear_fe', 'first_peak')} (ratio {v['first_peak_ratio']:.3f})",
        f"  largest peak  FFRF {peak('ffrf', 'peak')}, nonlinear FE "
        f"{peak('nonlinear_fe', 'peak')} (ratio {v['peak_deflection_ratio']:.3f})",
        f"  max |difference| of the curves {v['max_deflection_deviation'] * 1e6:.1f} um "
        f"({v['max_deflection_deviation_over_ffrf_peak']:.1%} of the FFRF peak) at "
        f"{v['time_of_max_deflection_deviation'] * 1e3:.2f} ms; crank angle "
        f"{v['max_crank_angle_deviation']:.2e} rad; midpoint out of plane "
        f"{v['max_midpoint_out_of_plane']:.1e} m",
        f"  axial compression up to {compression_N:.1f} N = "
        f"{compression_N / v['euler_load']:.2f} of the Euler load {v['euler_load']:.0f} N "
        f"(geometric softening, absent from the linear FFRF body)",
        f"  wall time: FFRF {wall['ffrf']:.1f} s for {steps['ffrf']} steps "
        f"({wall['ffrf'] / steps['ffrf'] * 1e3:.2f} ms/step), nonlinear FE "
        f"{wall['nonlinear_fe']:.1f} s for {steps['nonlinear_fe']} steps "
        f"({wall['nonlinear_fe'] / steps['nonlinear_fe'] * 1e3:.0f} ms/step)",
    ]


def compare_with_nonlinear_fe(label: str, ffrf_case: CaseResult, fe_case: CaseResult,
                              euler_load_N: float, prefix: str
                              ) -> tuple[dict[str, Dataset], list[str]]:
    """Compare a nonlinear FE run with the FFRF run of the same plate: the datasets
    ``<prefix>/<key>`` and the report lines (one line saying why, and no datasets, if a run
    failed or the two do not share their first samples).

    Both runs share the step and the samples, so the curves are compared sample by sample
    over the nonlinear run's span. ``euler_load_N``: the plate's pinned-pinned Euler load
    (:func:`coupler_euler_load_N`); the compression is the FFRF run's.
    """
    if fe_case.status != "ok" or ffrf_case.status != "ok":
        return {}, [f"nonlinear FE reference {label}: failed: "
                    f"{fe_case.message or ffrf_case.message}"]
    fe = {k: v.data for k, v in fe_case.datasets.items()}
    ffrf = {k: v.data for k, v in ffrf_case.datasets.items()}
    samples = len(fe["time"])
    time_s = ffrf["time"][:samples]
    if len(time_s) != samples or not np.allclose(time_s, fe["time"], rtol=0, atol=1e-12):
        return {}, [f"nonlinear FE reference {label}: the two runs have different time "
                    f"samples"]
    values, compression_N = _curve_values(ffrf, fe, time_s, euler_load_N,
                                          fe_case.attrs.get("fe_dof", -1))
    walls, steps = _walls({"ffrf": ffrf_case, "nonlinear_fe": fe_case})
    values.update(walls)
    datasets = {f"{prefix}/{key}": Dataset(value, unit, text)
                for key, (value, unit, text) in values.items()}
    plain = {key: value for key, (value, _, _) in values.items()}
    return datasets, _report_lines(label, plain, compression_N, steps)
