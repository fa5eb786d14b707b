"""The thesis's deployment spring checked as a designer would (sec. 6.1): the summary and the
figure of the ``spring`` study, from the formulas of :mod:`flex.bodies.spring`.

:func:`summary` shows which single input reproduces the stated 1500 N/m, then checks the
consistent design (:data:`flex.bodies.spring.CONSISTENT_THESIS_SPRING`): Wahl- and
Bergstrasser-corrected shear stress [Pa] at the press and at solid against ASTM A228's
allowable stress, solid length [m], surge frequencies [Hz] and the thesis's rigid-or-flexible
ratio n for the spring itself, and the peak stress of an NGsolve helix segment against Wahl.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from flex.bodies import spring as sp
from flex.bodies import spring_fe
from flex.data.results import Dataset


def design_datasets(design: sp.SpringDesign) -> dict[str, Dataset]:
    """The design's inputs and derived sizes as ``design/*`` datasets (SI)."""
    return {
        "design/wire_diameter": Dataset(design.wire_diameter_m, "m", "d"),
        "design/mean_coil_diameter": Dataset(design.mean_coil_diameter_m, "m", "D"),
        "design/active_coils": Dataset(design.active_coils, "1", "N_a"),
        "design/free_length": Dataset(design.free_length_m, "m", "L0"),
        "design/rate": Dataset(design.rate_N_per_m, "N/m", "k = G d^4 / (8 D^3 N_a)"),
        "design/spring_index": Dataset(design.spring_index, "1", "C = D / d"),
        "design/solid_length": Dataset(design.solid_length_m, "m", "L_s, plain-ground ends"),
        "design/deflection_to_solid": Dataset(design.deflection_to_solid_m, "m", "L0 - L_s"),
        "design/active_mass": Dataset(design.active_mass_kg, "kg", "mass of the active coils"),
    }


def stress_datasets(label: str, check: sp.SpringStressCheck) -> dict[str, Dataset]:
    """One stress check as ``stress_<label>/*`` datasets (m, N, Pa, factors)."""
    return {
        f"stress_{label}/deflection": Dataset(check.deflection_m, "m", "compression"),
        f"stress_{label}/force": Dataset(check.force_N, "N", "F = k y"),
        f"stress_{label}/wahl_factor": Dataset(check.wahl_factor, "1", "K_W"),
        f"stress_{label}/wahl_shear_stress": Dataset(check.wahl_shear_stress_Pa, "Pa",
                                                     "K_W 8 F D / (pi d^3)"),
        f"stress_{label}/bergstrasser_shear_stress": Dataset(
            check.bergstrasser_shear_stress_Pa, "Pa", "K_B 8 F D / (pi d^3)"),
        f"stress_{label}/allowable_shear_stress": Dataset(
            check.allowable_shear_stress_Pa, "Pa", "0.45 S_ut, ASTM A228"),
        f"stress_{label}/safety_factor": Dataset(check.safety_factor, "1",
                                                 "allowable / Wahl stress"),
    }


def rate_datasets(rows: list[sp.RateReproduction]) -> dict[str, Dataset]:
    """The rate reproduction table as ``rate/*`` datasets."""
    return {
        "rate/input": Dataset(np.array([r.input_name for r in rows], dtype=object), "1",
                              "input changed alone"),
        "rate/unit": Dataset(np.array([r.unit for r in rows], dtype=object), "1", "its unit"),
        "rate/stated": Dataset(np.array([r.stated_value for r in rows]), "see unit",
                               "thesis value"),
        "rate/value_for_1500_N_per_m": Dataset(np.array([r.value_for_rate for r in rows]),
                                               "see unit", "value reproducing 1500 N/m"),
    }


def summary(scene: Any) -> tuple[dict[str, Dataset], str]:
    """The ``spring`` summary: the scene gives the press (``drive.spring_preload_m``, m)
    and the slider mass (kg, the end mass of the surge check); ``(datasets, report)``."""
    design = sp.CONSISTENT_THESIS_SPRING
    press_m = scene["drive"]["spring_preload_m"]
    rows = sp.rate_reproduction_table()
    at_press = sp.spring_stress_check(design, press_m)
    at_solid = sp.spring_stress_check(design, design.deflection_to_solid_m)
    surge = sp.surge_check(design)
    surge_half_swing = sp.surge_check(design, sp.MECHANISM_HALF_SWING_TIME_S)
    with_slider_Hz = sp.surge_frequency_fixed_end_mass_Hz(design.rate_N_per_m,
                                                          design.active_mass_kg,
                                                          scene["slider"]["mass_kg"])
    fe = spring_fe.fe_helix_segment_stress(design, at_press.force_N)
    d = {**rate_datasets(rows), **design_datasets(design), **stress_datasets("press", at_press),
         **stress_datasets("solid", at_solid)}
    d.update({
        "fe/inner_fibre_max_shear_stress": Dataset(fe.inner_fibre_max_shear_Pa, "Pa",
                                                   "NGsolve helix segment, inner fibre"),
        "fe/over_wahl": Dataset(fe.fe_over_wahl, "1", "FE / Wahl"),
        "fe/over_bergstrasser": Dataset(fe.fe_over_bergstrasser, "1", "FE / Bergstrasser"),
        "fe/degrees_of_freedom": Dataset(fe.degrees_of_freedom, "1", "FE model size"),
        "surge/fixed_fixed_frequency": Dataset(surge.fixed_fixed_Hz, "Hz", "both ends fixed"),
        "surge/fixed_free_frequency": Dataset(surge.fixed_free_Hz, "Hz", "one end free"),
        "surge/with_slider_frequency": Dataset(with_slider_Hz, "Hz",
                                               "one end fixed, slider as end mass"),
        "surge/n_physical": Dataset(surge.n_fixed_fixed_physical, "1",
                                    "delta_t / T, T = 1/f, delta_t = "
                                    f"{sp.THESIS_DEPLOYMENT_TIME_S:g} s"),
        "surge/n_thesis_convention": Dataset(surge.n_fixed_fixed_thesis, "1",
                                             "delta_t * omega (thesis T = 1/omega)"),
        "surge/n_physical_half_swing": Dataset(surge_half_swing.n_fixed_fixed_physical, "1",
                                               "half swing / T"),
    })
    report = ["spring: thesis sec. 6.1 data checked", sp.format_rate_reproduction_table(rows),
              *_report(design, press_m, at_press, at_solid, fe, surge, with_slider_Hz)]
    return d, "\n".join(report)


def _report(design: sp.SpringDesign, press_m: float, at_press: sp.SpringStressCheck,
            at_solid: sp.SpringStressCheck, fe: spring_fe.HelixSegmentStress, surge: sp.SurgeCheck,
            with_slider_Hz: float) -> list[str]:
    """Report lines of the design, the two stress checks, the FE check and the surge."""
    if surge.n_fixed_fixed_physical < 10:
        verdict = ("the release lasts only a few surge periods or less: it excites spring "
                   "surge, which a massless spring model misses; by the thesis's criterion "
                   f"(n > {sp.THESIS_RIGID_CRITERION_RATIO:g}) the spring is flexible")
    else:
        verdict = "the spring's surge is fast compared with the release"
    return [
        f"  design used: d = {design.wire_diameter_m * 1e3:.2f} mm, D = "
        f"{design.mean_coil_diameter_m * 1e3:.1f} mm, N_a = {design.active_coils:g}, L0 = "
        f"{design.free_length_m * 1e3:.1f} mm -> k = {design.rate_N_per_m:.1f} N/m, C = "
        f"{design.spring_index:.1f}, solid length {design.solid_length_m * 1e3:.1f} mm",
        f"  at the {press_m * 1e3:.0f} mm press: F = {at_press.force_N:.1f} N, tau_Wahl = "
        f"{at_press.wahl_shear_stress_Pa / 1e6:.1f} MPa (Bergstrasser "
        f"{at_press.bergstrasser_shear_stress_Pa / 1e6:.1f}), allowable "
        f"{at_press.allowable_shear_stress_Pa / 1e6:.0f} MPa, safety factor "
        f"{at_press.safety_factor:.2f}",
        f"  at solid: tau_Wahl = {at_solid.wahl_shear_stress_Pa / 1e6:.1f} MPa, safety factor "
        f"{at_solid.safety_factor:.2f}",
        f"  NGsolve helix segment: inner-fibre max shear {fe.inner_fibre_max_shear_Pa / 1e6:.1f}"
        f" MPa = {fe.fe_over_wahl:.4f} x Wahl, {fe.fe_over_bergstrasser:.4f} x Bergstrasser",
        f"  surge: {surge.fixed_fixed_Hz:.1f} Hz fixed-fixed, {surge.fixed_free_Hz:.1f} Hz "
        f"fixed-free, {with_slider_Hz:.1f} Hz with the slider as end mass; n = delta_t/T = "
        f"{surge.n_fixed_fixed_physical:.2f} (thesis convention "
        f"{surge.n_fixed_fixed_thesis:.2f}); {verdict}",
    ]


def draw_stress(datasets: dict[str, Dataset], folder: Path) -> list[Path]:
    """``spring-stress.png``: Wahl stress [MPa] against compression [mm] up to solid, the
    allowable stress and the FE point at the press, from the summary's ``datasets``."""
    from flex.base.plotting import figure

    s = {k: v.data for k, v in datasets.items()}
    design = sp.CONSISTENT_THESIS_SPRING
    deflection = np.linspace(1e-4, design.deflection_to_solid_m, 60)
    wahl = [sp.spring_stress_check(design, y).wahl_shear_stress_Pa / 1e6 for y in deflection]
    path = folder / "spring-stress.png"
    with figure(path, "Spring shear stress against compression (consistent thesis spring "
                "design)", "spring compression [mm]", "shear stress [MPa]") as ax:
        ax.plot(deflection * 1e3, wahl, label="closed form, Wahl-corrected (curvature factor)")
        ax.axhline(s["stress_press/allowable_shear_stress"] / 1e6, color="r", ls="--",
                   label="allowable: 0.45 \u00d7 ultimate tensile strength, music wire ASTM A228")
        ax.plot(s["stress_press/deflection"] * 1e3, s["fe/inner_fibre_max_shear_stress"] / 1e6,
                "ks", label=f"3D FE of a helix segment (NGsolve), inner-fibre maximum, at "
                            f"{float(s['stress_press/deflection']) * 1e3:g} mm")
        ax.axvline(s["design/deflection_to_solid"] * 1e3, color="gray", ls=":",
                   label=f"solid length reached (coils touch): "
                         f"{float(s['design/deflection_to_solid']) * 1e3:.1f} mm")
        ax.set_ylim(0, None)
        ax.legend(fontsize="small", loc="center left")
    return [path]
