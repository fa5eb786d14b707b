"""Study ``spring`` (thesis sec. 6.1): the deployment spring checked as a designer would.

The thesis's spring data are not self-consistent (1500 N/m from d = 4.4 mm, N = 3 needs a
mean coil diameter near 94 mm, not the stated 150 mm). The study shows which single input
reproduces 1500 N/m, carries on with the stated consistent design
(:data:`flex.spring.CONSISTENT_THESIS_SPRING`), and checks it: Wahl- and
Bergstrasser-corrected shear stress at the 22 mm press and at solid against ASTM A228's
allowable stress; solid length and clash allowance; surge frequency and the thesis's
rigid-or-flexible ratio n for the spring itself; an NGsolve model of a helix segment for
the peak stress, compared with Wahl. No mechanism is simulated.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from flex import spring as sp
from flex.plotting import figure
from flex.results import CaseResult, Dataset
from flex.scene import Scene
from flex.study import Summary

NAME = "spring"
DESCRIPTION = "helical spring: rate, stress (Wahl, FE), surge and the rigid criterion"
OVERRIDES: list[str] = []
# keys the study reads itself (the spring design), beside what its cases simulate
READS = ("drive.spring_preload_m", "drive.spring_stiffness_N_per_m", "slider.mass_kg")


def cases(scene: Scene) -> dict[str, Scene]:
    return {}


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
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
    fe = sp.fe_helix_segment_stress(design, at_press.force_N)
    d: dict[str, Dataset] = {
        "rate/input": Dataset(np.array([r.input_name for r in rows], dtype=object), "1",
                              "input changed alone"),
        "rate/unit": Dataset(np.array([r.unit for r in rows], dtype=object), "1", "its unit"),
        "rate/stated": Dataset(np.array([r.stated_value for r in rows]), "see unit",
                               "thesis value"),
        "rate/value_for_1500_N_per_m": Dataset(np.array([r.value_for_rate for r in rows]),
                                               "see unit", "value reproducing 1500 N/m"),
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
    for label, check in (("press", at_press), ("solid", at_solid)):
        d.update({
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
        })
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
    if surge.n_fixed_fixed_physical < 10:
        verdict = ("the release lasts only a few surge periods or less: it excites spring "
                   "surge, which a massless spring model misses; by the thesis's criterion "
                   f"(n > {sp.THESIS_RIGID_CRITERION_RATIO:g}) the spring is flexible")
    else:
        verdict = "the spring's surge is fast compared with the release"
    report = [
        "spring: thesis sec. 6.1 data checked",
        sp.format_rate_reproduction_table(rows),
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
    return Summary(d, "\n".join(report))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    s = {k: v.data for k, v in summary.datasets.items()}
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


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
