"""The numbers of docs/references.md: plate references and the exact beam's calibration
(computed cold in a temporary cache, then read warm), and the evidence for their errors
(orders 3 to 7, graded and equal elements).

Run from the clone: ``.venv/bin/python docs/plate_references.py`` (a few minutes on one core:
the order-7 evidence is most of it); it prints the Markdown tables the page quotes.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import ngsolve  # noqa: F401 - imported before the clock starts (0.5 s)

from flex.base.physics import Plate, anticlastic_centroid_offset
from flex.bodies.beam_calibration import beam_calibration
from flex.bodies.plate_pfem import HexMesh
from flex.bodies.plate_reference import aitken_limit, plate_reference


def steel(length_mm: float, thickness_mm: float, width_mm: float) -> Plate:
    """A steel plate (E 200 GPa, rho 7850 kg/m^3, nu 0.3) of the given sizes [mm]."""
    return Plate(length_mm / 1e3, thickness_mm / 1e3, width_mm / 1e3, 200e9, 7850.0, 0.3)


PLATES = {"80 x 1 x 10": steel(80, 1, 10), "80 x 3 x 10": steel(80, 3, 10),
          "250 x 1 x 20": steel(250, 1, 20), "250 x 3 x 20": steel(250, 3, 20)}
EVIDENCE = ("80 x 1 x 10", "80 x 3 x 10")


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        cache = Path(folder)
        print("| plate [mm] | order | unknowns | section-mean deflection [m] | centroid [m] "
              "| f1 [Hz] |\n|---|---|---|---|---|---|")
        references = {}
        for name, plate in PLATES.items():
            start = time.perf_counter()
            references[name] = plate_reference(plate, cache_dir=cache)
            cold_s = time.perf_counter() - start
            start = time.perf_counter()
            warm = plate_reference(plate, cache_dir=cache)
            warm_s = time.perf_counter() - start
            assert warm.from_cache and warm == references[name]
            print("\n".join(_order_rows(name, references[name], cold_s, warm_s)))
        print("\n| plate [mm] | centroid below mean | 0.4 nu (w^2 - t^2)/L^2 | EI_eff/EI "
              "| beam f1 - 3D, uncalibrated | calibrated | shear share |"
              "\n|---|---|---|---|---|---|---|")
        for name, plate in PLATES.items():
            print(_calibration_row(name, plate, references[name]))
        print("\n| plate [mm] | mesh | deflection 3-4-5-6-7: changes [m] | limit of 3-5 "
              "- order 7, relative | its stated error | limit of 5-7 - order 7 | stated "
              "error |\n|---|---|---|---|---|---|---|")
        for name in EVIDENCE:
            for layers in (1, 0):
                print(_evidence_row(name, PLATES[name], layers, cache))


def _order_rows(name: str, ref, cold_s: float, warm_s: float) -> list[str]:
    lines = [f"| {name} | {p} | {n} | {d:.9e} | {c:.9e} | {f:.6f} |" for p, n, d, c, f in zip(
        ref.orders, ref.dof_counts, ref.section_mean_deflections_m, ref.centroid_deflections_m,
        ref.first_bending_frequencies_Hz, strict=True)]
    lines.append(
        f"| {name} | limit | cold {cold_s:.1f} s, warm {warm_s * 1e3:.0f} ms "
        f"| {ref.section_mean_deflection_m:.9e} +- {ref.section_mean_relative_error:.1e} "
        f"(ratio {ref.section_mean_convergence_ratio:.2f}) | {ref.centroid_deflection_m:.9e} "
        f"| {ref.first_bending_Hz:.6f} +- {ref.first_bending_relative_error:.1e} "
        f"(ratio {ref.first_bending_convergence_ratio:.2f}) |")
    return lines


def _calibration_row(name: str, plate: Plate, ref) -> str:
    calibration = beam_calibration(ref)
    estimate = anticlastic_centroid_offset(*plate.sizes_m, plate.poisson_ratio)
    return (f"| {name} | {ref.centroid_offset:.4%} | {estimate:.4%} "
            f"| {calibration.bending_stiffness_factor:.6f} +- "
            f"{calibration.bending_stiffness_factor_error:.1e} "
            f"| {calibration.uncalibrated_frequency_relative_difference:+.4%} "
            f"| {calibration.frequency_relative_difference:+.5%} "
            f"(+- {calibration.frequency_relative_uncertainty:.5%}) "
            f"| {calibration.shear_share:.3%} |")


def _evidence_row(name: str, plate: Plate, layers: int, cache: Path) -> str:
    ref = plate_reference(plate, orders=(3, 4, 5, 6, 7), cache_dir=cache,
                          mesh=HexMesh(graded_layers=layers))
    values = ref.section_mean_deflections_m
    order7 = values[-1]
    low_limit, low_error, _ = aitken_limit(values[:3])
    changes = ", ".join(f"{b - a:.1e}" for a, b in zip(values[:-1], values[1:], strict=True))
    mesh = "8 x 1 x 2, " + ("ends graded" if layers else "equal")
    return (f"| {name} | {mesh} | {changes} | {(low_limit - order7) / order7:+.1e} "
            f"| {low_error / order7:.1e} "
            f"| {(ref.section_mean_deflection_m - order7) / order7:+.1e} "
            f"| {ref.section_mean_relative_error:.1e} |")


if __name__ == "__main__":
    main()
