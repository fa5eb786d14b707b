"""Study ``simulate``: run exactly the scene it is given, as one case.

    python -m flex run simulate --set crank.initial_angle_deg=50 --set drive.spring_preload_m=0.01

Any drive and coupler model; nothing is compared. Stores ``/cases/case/...``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from flex.plotting import figure
from flex.results import CaseResult
from flex.scene import Scene
from flex.study import Summary

NAME = "simulate"
DESCRIPTION = "one case: exactly the given scene"


def cases(scene: Scene) -> dict[str, Scene]:
    return {"case": scene}


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    case = results["case"]
    if case.status != "ok":
        return Summary(report=f"simulate: case failed: {case.message}")
    angle = case.datasets["crank/angle"].data
    return Summary(report=(f"simulate: crank angle {angle[0]:.4f} -> {angle[-1]:.4f} rad, "
                           f"max {angle.max():.4f} rad; max constraint norm "
                           f"{case.datasets['constraint_norm'].data.max():.2e} m"))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    data = {k: v.data for k, v in results["case"].datasets.items()}
    path = folder / "simulate-crank-angle.png"
    with figure(path, "Crank angle of the simulated scene", "time [s]",
                "crank angle from the slide line [rad]") as ax:
        ax.plot(data["time"], data["crank/angle"])
    return [path]


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
