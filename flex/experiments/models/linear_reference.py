"""The ladder's rungs against the p-converged 3-D plate, on what that reference converges:
the first pinned-pinned bending frequency and the static section-mean deflection.

For each plate: the reference (:func:`flex.bodies.plate_reference.plate_reference`, its error
from its order sequence), the exact beam uncalibrated (E, kappa = 5/6) and calibrated on it
(:func:`flex.bodies.beam_calibration.beam_calibration`: the static deflection is matched by
construction, the frequency is the check), and the order-2 tetrahedral mesh of the FFRF body
and the FE coupler (the reduction's pinned-pinned frequency, 6 fixed-interface modes: the same
mesh's stiffness and mass). Linear only: the deployment's nonlinear dynamics are compared with
the nonlinear FE coupler by :mod:`flex.experiments.models.ladder`; a converged nonlinear 3-D
reference of the deployment does not exist here (docs/references.md).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from flex.base.physics import Plate
from flex.bodies.beam_calibration import beam_calibration
from flex.bodies.plate_reference import plate_reference
from flex.data.results import Dataset
from flex.data.scene import Scene
from flex.data.scene_edit import derive_scene
from flex.dynamics.link_models import reduction_for_scene

#: the rungs compared, by label: what each one's first bending frequency is read from
LINEAR_RUNGS = ("exact beam (uncalibrated)", "exact beam (calibrated)", "order-2 tetrahedra")


def linear_rung(scene: Scene, thickness_m: float, mesh_size_m: float,
                cache_dir: Path | None) -> dict[str, float]:
    """One plate's reference (frequency [Hz] and its relative error, section-mean deflection
    [m] and its relative error, the centroid's offset) and each rung's frequency relative to
    it, the uncalibrated beam's static deflection relative to it."""
    plate_scene = derive_scene(scene, {"coupler.thickness_m": thickness_m,
                                       "coupler.geometry": "plate", "coupler.model": "ffrf",
                                       "coupler.modes": 6, "coupler.mesh_size_m": mesh_size_m})
    reference = plate_reference(Plate.of(plate_scene["coupler"]), cache_dir=cache_dir)
    calibration = beam_calibration(reference)
    mesh_Hz = reduction_for_scene(plate_scene, cache_dir=cache_dir).pinned_pinned_frequency_Hz
    f_ref = reference.first_bending_Hz
    return {"thickness_m": thickness_m, "reference_Hz": f_ref,
            "reference_Hz_error": reference.first_bending_relative_error,
            "reference_deflection_m": reference.section_mean_deflection_m,
            "reference_deflection_error": reference.section_mean_relative_error,
            "centroid_offset": reference.centroid_offset,
            "exact beam (uncalibrated)": calibration.beam_first_bending_Hz / f_ref - 1.0,
            "exact beam (calibrated)": calibration.calibrated_first_bending_Hz / f_ref - 1.0,
            "order-2 tetrahedra": mesh_Hz / f_ref - 1.0,
            "uncalibrated_deflection": (calibration.beam_deflection_m
                                        / calibration.reference_deflection_m - 1.0),
            "stiffness_factor": calibration.bending_stiffness_factor,
            "idealization": calibration.idealization}


def linear_summary(scene: Scene, plates: Mapping[float, float], cache_dir: Path | None
                   ) -> tuple[dict[str, Dataset], str]:
    """Datasets (``linear/t<t>mm/...``) and a Markdown table of :func:`linear_rung` for each
    plate (thickness [m] -> mesh size [m])."""
    rows = [linear_rung(scene, thickness, mesh, cache_dir) for thickness, mesh in plates.items()]
    datasets: dict[str, Dataset] = {}
    for row in rows:
        prefix = f"linear/t{row['thickness_m'] * 1e3:g}mm"
        datasets[f"{prefix}/reference_first_bending"] = Dataset(
            row["reference_Hz"], "Hz", "p-converged 3-D plate, first pinned-pinned bending "
            f"frequency (relative error {row['reference_Hz_error']:.1g} from its orders)")
        datasets[f"{prefix}/reference_deflection"] = Dataset(
            row["reference_deflection_m"], "m", "its static section-mean mid-span deflection "
            "under its own weight")
        for label in LINEAR_RUNGS:
            key = label.replace(" ", "_").replace("(", "").replace(")", "").replace("-", "_")
            datasets[f"{prefix}/{key}_frequency"] = Dataset(
                row[label], "1", f"{label}: first bending frequency / the reference's - 1")
        datasets[f"{prefix}/calibrated_idealization"] = Dataset(
            row["idealization"], "1", "the calibrated beam's measured model error (its rung)")
    return datasets, _table(rows)


def _table(rows: list[dict[str, Any]]) -> str:
    lines = ["Against the p-converged 3-D plate (linear: pinned-pinned, its own weight; "
             "relative differences):", "",
             "| t [mm] | 3-D f1 [Hz] (error) | uncalibrated beam f1 / static | calibrated "
             "beam f1 (idealization) | order-2 tetrahedra f1 | centroid vs section mean |",
             "|---|---|---|---|---|---|"]
    for row in rows:
        lines.append(
            f"| {row['thickness_m'] * 1e3:g} | {row['reference_Hz']:.6g} "
            f"({row['reference_Hz_error']:.1e}) | {row['exact beam (uncalibrated)']:+.4%} / "
            f"{row['uncalibrated_deflection']:+.4%} | {row['exact beam (calibrated)']:+.4%} "
            f"({row['idealization']:.1e}) | {row['order-2 tetrahedra']:+.4%} | "
            f"{-row['centroid_offset']:+.3%} |")
    return "\n".join(lines)


__all__ = ["LINEAR_RUNGS", "linear_rung", "linear_summary"]
