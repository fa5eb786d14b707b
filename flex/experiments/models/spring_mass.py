"""The deployment spring with its mass (issue 16): the chain model's convergence to the
continuous coil, and what the coil's mass changes in the deployment.

``make spring`` finds the thesis spring's own surge at n = delta_t / T = 0.96: by flex's
criterion the spring, not a link, is the mechanism's flexible part, while every mechanism
model treats it as massless. ``drive.spring_model = "chain"``
(:class:`flex.dynamics.builder.SpringChain`) gives it its mass. Here:

- :func:`chain_first_omega_rad_per_s`: the first natural frequency [rad/s] of the chain
  fixed at one end and carrying a mass at the other, from its own mass and stiffness
  matrices (numpy; independent of the Exudyn build), and :func:`chain_convergence`, its
  convergence to the continuous coil's closed form (``beta tan beta = m_s / M``,
  :func:`flex.bodies.spring.surge_frequency_fixed_end_mass_Hz`) with the observed order;
- :func:`deployment_cases` and :func:`deployment_table`: the thesis deployment and the wing
  deployment (the wing study's fitted spring, :func:`wing_spring_scene`), massless against
  chains of :data:`MEASURED_SEGMENTS` segments, rigid links and an FFRF plate coupler: peak
  crank speed [rad/s] and its time [s], deployment time [s], peak joint forces [N], peak
  coupler midpoint deflection [m], the governing error against the finest chain [-];
- :func:`sweep_cases` and :func:`error_law_lines`: the massless spring's governing error
  against the spring's n = delta_t f_surge over a sweep of coil and slider masses, and its
  fitted law ``e = c n^-p`` (docs/spring-mass.md);
- :func:`massless_predictions`: that error as ``drive.spring_model = "auto"`` predicts it
  from each case's rigid probe (:mod:`flex.fidelity.spring_choice`), against the measured.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from flex.bodies import spring as sp
from flex.data import tables
from flex.data.headlines import first_maximum_index
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene
from flex.data.scene_edit import derive_scene
from flex.fidelity.laws import (
    fit_error_law,
)

#: chain segment counts of the deployment measurement (rigid links and FFRF coupler)
MEASURED_SEGMENTS: tuple[int, ...] = (1, 2, 4, 8, 16, 32, 64)
#: segment counts of the frequency convergence
CONVERGENCE_SEGMENTS: tuple[int, ...] = (1, 2, 4, 8, 16, 32, 64)
#: the deployment scenes: thesis (bundled, 22 mm preload) and wing (fitted spring), each with
#: an end time that holds the slower chain deployment's first crank-angle maximum [s]
SCENES_END_TIME_S: dict[str, float] = {"thesis": 0.05, "wing": 0.04}
#: the link models measured: the bundled rigid links, and an FFRF steel plate coupler at a
#: fixed step of 1e-5 s (the "auto" step, 1.7e-4 s, follows the coupler's modes, not the
#: chain's: 16 segments of the thesis spring reach 3.8e3 rad/s); the chain counts of each
LINKS: dict[str, tuple[list[str], tuple[int, ...]]] = {
    "rigid": ([], MEASURED_SEGMENTS),
    "ffrf": (['coupler.geometry="plate"', 'coupler.model="ffrf"', "simulation.step_s=1e-5"],
             MEASURED_SEGMENTS)}
#: the FFRF coupler plate's thickness by scene [m]: the thesis's Table 5 model 0 (1 mm);
#: the wing's loads (~250 N at C) would buckle it (Euler load 257 N): 3 mm there
FFRF_THICKNESS_M: dict[str, float] = {"thesis": 0.001, "wing": 0.003}


# --- 1. The chain's first frequency and its convergence --------------------------------------

def chain_matrices(spring_mass_kg: float, rate_N_per_m: float, end_mass_kg: float,
                   segments: int) -> tuple[np.ndarray, np.ndarray]:
    """Mass [kg] and stiffness [N/m] matrices of a spring of ``segments`` lumped segments
    fixed at one end, a mass ``end_mass_kg`` at the other: coordinates are the displacements
    of the ``segments`` moving segment ends (the free end last); each segment has rate
    ``segments`` x k and half its mass m_s / segments at each of its ends."""
    n = int(segments)
    if n < 1:
        raise ValueError(f"segments = {segments!r}: must be an integer >= 1")
    masses = np.full(n, spring_mass_kg / n)
    masses[-1] = end_mass_kg + spring_mass_kg / (2 * n)
    stiffness = np.zeros((n, n))
    for segment in range(n):  # segment between end (segment - 1) (or the frame) and segment
        ends = [segment - 1, segment] if segment else [segment]
        local = np.array([[1.0, -1.0], [-1.0, 1.0]]) if segment else np.array([[1.0]])
        stiffness[np.ix_(ends, ends)] += n * rate_N_per_m * local
    return np.diag(masses), stiffness


def chain_first_omega_rad_per_s(spring_mass_kg: float, rate_N_per_m: float,
                                end_mass_kg: float, segments: int) -> float:
    """First natural circular frequency [rad/s] of :func:`chain_matrices`' chain."""
    from scipy.linalg import eigh

    mass, stiffness = chain_matrices(spring_mass_kg, rate_N_per_m, end_mass_kg, segments)
    return float(math.sqrt(eigh(stiffness, mass, eigvals_only=True)[0]))


def continuous_first_omega_rad_per_s(spring_mass_kg: float, rate_N_per_m: float,
                                     end_mass_kg: float) -> float:
    """The continuous coil's first circular frequency [rad/s], ``beta sqrt(k / m_s)`` with
    ``beta tan beta = m_s / M`` (:func:`flex.bodies.spring.surge_frequency_fixed_end_mass_Hz`)."""
    return 2.0 * math.pi * sp.surge_frequency_fixed_end_mass_Hz(rate_N_per_m, spring_mass_kg,
                                                                end_mass_kg)


@dataclass(frozen=True)
class ConvergenceRow:
    """One chain against the continuous coil: its first frequency [rad/s], relative error
    [-] and the order observed from the previous row (NaN on the first)."""

    segments: int
    omega_rad_per_s: float
    relative_error: float
    observed_order: float


def chain_convergence(spring_mass_kg: float, rate_N_per_m: float, end_mass_kg: float,
                      segments: tuple[int, ...] = CONVERGENCE_SEGMENTS
                      ) -> list[ConvergenceRow]:
    """The chain's first frequency for each count of ``segments`` against the continuous
    coil's (:func:`continuous_first_omega_rad_per_s`); the order between successive rows is
    ``log(e_prev / e) / log(N / N_prev)``."""
    exact = continuous_first_omega_rad_per_s(spring_mass_kg, rate_N_per_m, end_mass_kg)
    rows: list[ConvergenceRow] = []
    for n in segments:
        omega = chain_first_omega_rad_per_s(spring_mass_kg, rate_N_per_m, end_mass_kg, n)
        error = abs(omega / exact - 1.0)
        order = (math.log(rows[-1].relative_error / error) / math.log(n / rows[-1].segments)
                 if rows else math.nan)
        rows.append(ConvergenceRow(n, omega, error, order))
    return rows


# --- 2. The deployments --------------------------------------------------------------------

def wing_spring_mass_kg(rate_N_per_m: float) -> float:
    """Active-coil mass [kg] of the thesis spring design re-sized to ``rate_N_per_m``: wire
    (4.4 mm), active coils (3) and music wire kept, the mean coil diameter solved for the rate
    (:data:`flex.bodies.spring.CONSISTENT_THESIS_SPRING`'s way)."""
    design = sp.CONSISTENT_THESIS_SPRING
    diameter_m = sp.mean_coil_diameter_for_rate_m(rate_N_per_m, design.shear_modulus_Pa,
                                                  design.wire_diameter_m, design.active_coils)
    return sp.active_coil_mass_kg(design.density_kg_per_m3, design.wire_diameter_m,
                                  diameter_m, design.active_coils)


def wing_spring_scene(scene: Scene) -> Scene:
    """``scene`` with the wing welded on and the wing study's fitted spring
    (:func:`flex.experiments.thesis.wing.fit_spring`), its mass from :func:`wing_spring_mass_kg`."""
    from flex.experiments.thesis.wing import fit_spring

    fitted, values = fit_spring(derive_scene(scene, ["wing.enabled=true"]))
    return derive_scene(fitted, [
        f"drive.spring_mass_kg={wing_spring_mass_kg(values['stiffness_N_per_m'])!r}"])


def deployment_cases(scenes: Mapping[str, Scene],
                     segments: tuple[int, ...] | None = None) -> dict[str, Scene]:
    """Cases ``<scene>_<links>_massless`` and ``<scene>_<links>_chain_<N>`` for each of
    ``scenes`` (name -> scene; end time from :data:`SCENES_END_TIME_S`, default 0.05 s; FFRF
    plate from :data:`FFRF_THICKNESS_M`, default 1 mm), each link set of :data:`LINKS` and
    each of its chain counts (or of ``segments``); validated."""
    out: dict[str, Scene] = {}
    for name, scene in scenes.items():
        for links, (overrides, counts) in LINKS.items():
            plate = [f"coupler.thickness_m={FFRF_THICKNESS_M.get(name, 0.001)!r}"]
            base = derive_scene(scene, [*overrides, *(plate if links == "ffrf" else []),
                                        "simulation.end_time_s="
                                        f"{SCENES_END_TIME_S.get(name, 0.05)!r}"])
            out[f"{name}_{links}_massless"] = derive_scene(
                base, ['drive.spring_model="massless"'])
            for n in counts if segments is None else segments:
                out[f"{name}_{links}_chain_{n}"] = derive_scene(
                    base, ['drive.spring_model="chain"', f"drive.spring_segments={n}"])
    return out


#: the measured quantities: key -> (unit, meaning)
QUANTITIES: dict[str, tuple[str, str]] = {
    "peak_crank_speed": ("rad/s", "largest crank angular velocity"),
    "peak_crank_speed_time": ("s", "its time"),
    "deployment_time": ("s", "first crank-angle maximum (NaN: none within the run)"),
    "peak_force_A": ("N", "largest |force| at joint A"),
    "peak_force_B": ("N", "largest |force| at joint B"),
    "peak_force_C": ("N", "largest |force| at joint C"),
    "peak_midpoint_deflection": ("m", "largest |coupler midpoint deflection| (FFRF only)"),
    "governing_error": ("1", "max of crank-angle and slider-position deviation from the "
                             "finest chain over its deployment, relative to its swing and "
                             "travel (the measures auto bounds for the links)"),
}


def stop_index(crank_angle_rad: np.ndarray) -> int | None:
    """Index of the crank angle's first maximum after it has covered half its largest rise
    (None: none within the series): an FFRF coupler's start-up ripple on the crank angle
    holds maxima before the deployment does."""
    rise = np.asarray(crank_angle_rad) - crank_angle_rad[0]
    half = int(np.argmax(rise >= 0.5 * rise.max()))
    later = first_maximum_index(rise[half:])
    return None if later is None else half + later


def deployment_values(data: Mapping[str, np.ndarray]) -> dict[str, float]:
    """:data:`QUANTITIES` of one run (result paths -> arrays), over the run up to the end of
    its deployment swing (:func:`stop_index`; the whole run if it has none)."""
    stop = stop_index(data["crank/angle"])
    window = slice(None) if stop is None else slice(0, stop + 1)
    speed = np.asarray(data["crank/angular_velocity"])[window]
    peak = int(np.argmax(speed))
    deflection = data.get("coupler/midpoint_deflection")
    return {
        "peak_crank_speed": float(speed[peak]),
        "peak_crank_speed_time": float(data["time"][peak]),
        "deployment_time": math.nan if stop is None else float(data["time"][stop]),
        **{f"peak_force_{joint}": float(np.max(data[f"joints/{joint}/force_modulus"][window]))
           for joint in "ABC"},
        "peak_midpoint_deflection": math.nan if deflection is None
        else float(np.max(np.abs(np.asarray(deflection)[window]))),
    }


def governing_error(run: Mapping[str, np.ndarray], full: Mapping[str, np.ndarray]) -> float:
    """Largest of max |crank angle - full's| / full's swing and max |slider position -
    full's| / full's travel, over ``full``'s deployment (:func:`stop_index`); both runs
    sampled at the same times [-]."""
    stop = stop_index(full["crank/angle"])
    count = len(full["time"]) if stop is None else stop + 1
    errors = []
    for key in ("crank/angle", "slider/position"):
        reference = np.asarray(full[key])[:count]
        deviation = np.max(np.abs(np.asarray(run[key])[:count] - reference))
        errors.append(float(deviation / np.max(np.abs(reference - reference[0]))))
    return max(errors)


def _arrays(case: CaseResult) -> dict[str, np.ndarray]:
    return {k: np.asarray(v.data) for k, v in case.datasets.items()}


def deployment_table(results: Mapping[str, CaseResult]) -> dict[str, dict[str, float]]:
    """:func:`deployment_values` of every ok case, with its :func:`governing_error` against
    the finest chain of its scene and links: case name -> quantity -> value."""
    ok = {name: _arrays(case) for name, case in results.items() if case.status == "ok"}
    table = {}
    for name, data in ok.items():
        group = name.split("_chain_")[0].removesuffix("_massless")
        finest = max((n for n in ok if n.startswith(group + "_chain_")),
                     key=lambda n: int(n.rsplit("_", 1)[1]), default=name)
        table[name] = {**deployment_values(data),
                       "governing_error": governing_error(data, ok[finest])}
    return table


def table_datasets(table: Mapping[str, Mapping[str, float]]) -> dict[str, Dataset]:
    """The table as ``deployment/case`` (names) and ``deployment/<quantity>`` datasets."""
    return {"deployment/case": Dataset(np.array(list(table), dtype=object), "1", "case"),
            **tables.table_datasets(table.values(), QUANTITIES, "deployment")}


def convergence_datasets(rows: list[ConvergenceRow], prefix: str) -> dict[str, Dataset]:
    """A convergence table as ``<prefix>/segments|omega|relative_error|observed_order``."""
    return {
        f"{prefix}/segments": Dataset(np.array([r.segments for r in rows]), "1", "N"),
        f"{prefix}/omega": Dataset(np.array([r.omega_rad_per_s for r in rows]), "rad/s",
                                   "first frequency of the chain"),
        f"{prefix}/relative_error": Dataset(np.array([r.relative_error for r in rows]), "1",
                                            "against beta tan beta = m_s / M"),
        f"{prefix}/observed_order": Dataset(np.array([r.observed_order for r in rows]), "1",
                                            "log(e_prev / e) / log(N / N_prev)"),
    }


def change_percent(value: float, base: float) -> float:
    """``100 (value / base - 1)`` [%]; NaN where ``base`` is 0 or NaN (e.g. the deflection
    of a rigid coupler)."""
    return 100.0 * (value / base - 1.0) if base and math.isfinite(base) else math.nan


def format_table(table: Mapping[str, Mapping[str, float]]) -> list[str]:
    """Report lines: each case's quantities and, for chains, the change from the massless
    case of the same scene and links [%]."""
    lines = ["  case                   governing w_peak rad/s (t ms)  t_dep ms   |F_A| |F_B| "
             "|F_C| N"
             "   defl um   change vs massless: w_peak, t_dep, F_A, F_B, F_C, defl [%]"]
    for name, v in table.items():
        base = table.get(name.split("_chain_")[0] + "_massless", v)
        change = ", ".join(f"{change_percent(v[k], base[k]):+.1f}" for k in (
            "peak_crank_speed", "deployment_time", "peak_force_A", "peak_force_B",
            "peak_force_C", "peak_midpoint_deflection"))
        lines.append(
            f"  {name:22s} {v['governing_error']:8.2e} "
            f"{v['peak_crank_speed']:7.2f} ({v['peak_crank_speed_time'] * 1e3:5.2f})"
            f"  {v['deployment_time'] * 1e3:7.2f}  {v['peak_force_A']:5.2f} "
            f"{v['peak_force_B']:5.2f} {v['peak_force_C']:5.2f}  "
            f"{v['peak_midpoint_deflection'] * 1e6:7.1f}   {change}")
    return lines


def summary(scenes: Mapping[str, Scene], results: Mapping[str, CaseResult]
            ) -> tuple[dict[str, Dataset], str]:
    """The study's datasets and report: for each of ``scenes`` (name -> base scene) the
    chain's convergence to its coil with the slider as end mass, then the deployment table
    of ``results`` (:func:`deployment_cases`' cases)."""
    datasets: dict[str, Dataset] = {}
    report = ["spring_mass: the deployment spring with its mass (drive.spring_model = chain)"]
    for name, scene in scenes.items():
        drive = scene["drive"]
        rows = chain_convergence(drive["spring_mass_kg"], drive["spring_stiffness_N_per_m"],
                                 scene["slider"]["mass_kg"])
        datasets.update(convergence_datasets(rows, f"convergence_{name}"))
        report.append(
            f"  {name}: k = {drive['spring_stiffness_N_per_m']:.0f} N/m, m_s = "
            f"{drive['spring_mass_kg'] * 1e3:.1f} g, slider {scene['slider']['mass_kg'] * 1e3:.1f}"
            f" g: first frequency {rows[-1].omega_rad_per_s:.2f} rad/s; chain error "
            + ", ".join(f"N={r.segments}: {r.relative_error:.2e}" for r in rows)
            + f"; observed order {rows[-1].observed_order:.3f}")
    table = deployment_table(results)
    datasets.update(table_datasets(table))
    cases = {**deployment_cases(scenes), **sweep_cases(scenes["thesis"])}
    lines, law = error_law_lines(massless_errors(cases, table))
    datasets["error_law/coefficient"] = Dataset(law.coefficient, "1", "c of e = c n^-p")
    datasets["error_law/exponent"] = Dataset(law.exponent, "1", "p of e = c n^-p")
    predictions = massless_predictions(cases, table)
    datasets.update(prediction_datasets(predictions))
    report += ["  deployments (rigid: bundled links; ffrf: steel plate coupler, 1 mm thesis, "
               "3 mm wing):", *format_table(table), *lines, *prediction_lines(predictions)]
    return datasets, "\n".join(report)


def draw_speed(results: Mapping[str, CaseResult], folder: Path) -> list[Path]:
    """``spring-mass-speed.png``: crank speed [rad/s] against time [ms] of the rigid-link
    runs, massless and every chain, both scenes."""
    from flex.base.plotting import figure

    path = folder / "spring-mass-speed.png"
    with figure(path, "Crank speed with a massless spring and with spring chains",
                "time [ms]", "crank angular velocity [rad/s]") as ax:
        for name, case in results.items():
            if "_rigid_" in name and case.status == "ok":
                ax.plot(case.datasets["time"].data * 1e3,
                        case.datasets["crank/angular_velocity"].data, label=name,
                        ls="-" if name.endswith("massless") else "--")
        ax.legend(fontsize=6)
    return [path]


# --- 3. The massless spring's error against the spring's n ----------------------------------

#: the sweep behind the massless spring's error law: coil masses [kg] x slider masses [kg],
#: rigid links, the bundled spring rate and preload, each massless against a chain of
#: :data:`SWEEP_SEGMENTS` (the rate only scales time: a 4 x stiffer spring gave the same
#: errors to 3 digits, measured)
SWEEP_MASSES_KG: tuple[float, ...] = (0.003, 0.01, 0.03, 0.1, 0.3)
SWEEP_SLIDER_MASSES_KG: tuple[float, ...] = (0.0264, 0.1)
SWEEP_SEGMENTS = 64


def sweep_cases(scene: Scene) -> dict[str, Scene]:
    """``sweep_<coil g>g_slider_<slider g>g_massless`` and ``..._chain_64`` for every coil
    and slider mass of the sweep (end time 0.1 s: the heaviest chain's deployment);
    validated."""
    out: dict[str, Scene] = {}
    for mass_kg in SWEEP_MASSES_KG:
        for slider_kg in SWEEP_SLIDER_MASSES_KG:
            base = derive_scene(scene, [f"drive.spring_mass_kg={mass_kg!r}",
                                        f"slider.mass_kg={slider_kg!r}",
                                        "simulation.end_time_s=0.1"])
            name = f"sweep_{mass_kg * 1e3:g}g_slider_{slider_kg * 1e3:g}g"
            out[f"{name}_massless"] = derive_scene(base, ['drive.spring_model="massless"'])
            out[f"{name}_chain_{SWEEP_SEGMENTS}"] = derive_scene(
                base, ['drive.spring_model="chain"', f"drive.spring_segments={SWEEP_SEGMENTS}"])
    return out


def spring_n(scene: Scene, delta_t_s: float) -> float:
    """The spring's n = delta_t / T (T = 1 / f, physical convention) with its fixed-fixed
    surge frequency (:func:`flex.bodies.spring.surge_frequency_fixed_fixed_Hz`), as the
    ``spring`` study's."""
    drive = scene["drive"]
    return sp.rigid_or_flexible_ratio(delta_t_s, sp.surge_frequency_fixed_fixed_Hz(
        drive["spring_stiffness_N_per_m"], drive["spring_mass_kg"]), "physical")


def massless_errors(cases: Mapping[str, Scene],
                    table: Mapping[str, Mapping[str, float]]) -> dict[str, tuple[float, float]]:
    """For every ``*_massless`` case of ``table`` (:func:`deployment_table`; ``cases`` their
    scenes): ``(n, governing error)``, n (:func:`spring_n`) from the massless run's own
    deployment time (what the rigid probe of ``auto`` would give)."""
    return {name: (spring_n(cases[name], values["deployment_time"]), values["governing_error"])
            for name, values in table.items() if name.endswith("_massless")}


def error_law_lines(points: Mapping[str, tuple[float, float]]) -> tuple[list[str], Any]:
    """Report lines of the massless spring's error against n and its fitted law
    ``e = c n^-p`` (:func:`flex.fidelity.laws.fit_error_law`); returns them and the law."""
    n = np.array([v[0] for v in points.values()])
    errors = np.array([v[1] for v in points.values()])
    law = fit_error_law(n, errors)
    lines = [f"  massless spring's governing error against the spring's n = delta_t f_surge "
             f"(fixed-fixed): e = {law.coefficient:.3g} n^-{law.exponent:.3f} (R^2 = "
             f"{law.r_squared:.3f}, {law.n_points} runs, n = {law.n_min:.3g} ... "
             f"{law.n_max:.3g}); n for 1 % (95 % upper band): {law.k(0.01, bound='upper'):.3g}"]
    lines += [f"    {name:34s} n = {value[0]:7.3f}  error {value[1]:.3e}"
              for name, value in sorted(points.items(), key=lambda item: item[1][0])]
    return lines, law


# --- 4. The prediction drive.spring_model = "auto" decides by -------------------------------

def massless_predictions(cases: Mapping[str, Scene], table: Mapping[str, Mapping[str, float]]
                         ) -> dict[str, tuple[float, float, float]]:
    """For every ``*_massless`` case of ``table`` (:func:`deployment_table`; ``cases`` their
    scenes): ``(predicted, measured governing error, m_s / M_min)`` [-], the prediction
    (:func:`flex.fidelity.spring_choice.predict_massless_spring_error`) from the case's
    rigid probe (:func:`flex.fidelity.probe.deployment_probe`: an FFRF coupler's rigid
    twin), as ``drive.spring_model = "auto"`` makes it."""
    from flex.fidelity.probe import deployment_probe
    from flex.fidelity.spring_choice import predict_massless_spring_error

    out = {}
    for name, values in table.items():
        if name.endswith("_massless"):
            _, _, probe = deployment_probe(cases[name])
            prediction = predict_massless_spring_error(probe,
                                                       cases[name]["drive"]["spring_mass_kg"])
            out[name] = (prediction.error, values["governing_error"], prediction.mass_ratio)
    return out


#: ``prediction/<column>``: one row per case with a massless spring (:func:`prediction_datasets`)
PREDICTION_COLUMNS = {
    "case": ("1", "case", object),
    "predicted": ("1", "the massless spring's governing error predicted from the rigid probe",
                  float),
    "measured": ("1", "its governing error against the finest chain", float),
    "mass_ratio": ("1", "m_s / M_min, M_min the smallest mass reduced to the slider", float)}


def prediction_datasets(predictions: Mapping[str, tuple[float, float, float]]
                        ) -> dict[str, Dataset]:
    """:func:`massless_predictions` as ``prediction/case|predicted|measured|mass_ratio``."""
    rows = ({"case": name, "predicted": predicted, "measured": measured, "mass_ratio": ratio}
            for name, (predicted, measured, ratio) in predictions.items())
    return tables.table_datasets(rows, PREDICTION_COLUMNS, "prediction")


def prediction_lines(predictions: Mapping[str, tuple[float, float, float]]) -> list[str]:
    """Report lines: predicted against measured, case by case, and the ratio's range."""
    ratios = [p / m for p, m, _ in predictions.values() if m > 0]
    lines = ["  drive.spring_model = auto: the massless spring's governing error predicted "
             "from the rigid probe (flex.fidelity.spring_choice) against measured"
             + (f": predicted / measured {min(ratios):.3f} ... {max(ratios):.3f}"
                if ratios else "")]
    lines += [f"    {name:34s} m_s/M_min = {ratio:6.3f}  predicted {p:.3e}  measured {m:.3e}"
              f"  ratio {p / m if m > 0 else math.nan:.3f}"
              for name, (p, m, ratio) in predictions.items()]
    return lines
