"""One simulated case of any scene (the ``simulate`` study): its one-line report and its
crank-angle figure. Angles in rad, constraint norm in m, time in s."""

from __future__ import annotations

from pathlib import Path

from flex.data.results import CaseResult, Dataset


def summary(case: CaseResult) -> tuple[dict[str, Dataset], str]:
    """No datasets, and the report: crank angle at start and end and its maximum [rad], the
    largest constraint norm [m] and what the tolerance covered (or why the case failed)."""
    if case.status != "ok":
        return {}, f"simulate: case failed: {case.message}"
    from flex.fidelity.stored_budget import coverage_text, stored_coverage

    angle = case.datasets["crank/angle"].data
    coverage = stored_coverage(case.attrs)
    covered = (f"; {coverage_text(coverage, float(case.attrs['tolerance_relative']))}"
               if coverage else "")
    return {}, (f"simulate: crank angle {angle[0]:.4f} -> {angle[-1]:.4f} rad, "
                f"max {angle.max():.4f} rad; max constraint norm "
                f"{case.datasets['constraint_norm'].data.max():.2e} m{covered}")


def draw_crank_angle(case: CaseResult, folder: Path) -> list[Path]:
    """``simulate-crank-angle.png`` in ``folder``: the case's crank angle against time."""
    from flex.base.plotting import figure

    path = folder / "simulate-crank-angle.png"
    with figure(path, "Crank angle of the simulated scene", "time [s]",
                "crank angle from the slide line [rad]") as ax:
        ax.plot(case.datasets["time"].data, case.datasets["crank/angle"].data)
    return [path]
