"""What the 1 % answer costs: a run with its error budget against the run alone, and the
command line against the same run in process (``make bench``'s ``budget`` part).

For each plate of a :class:`BudgetPlan` (the bundled scene with its overrides: an FFRF
coupler at ``fidelity.tolerance``, flex's own settings), warm (reductions and references
cached, every import done), alternating ``repeats`` times: the run without its budget
(``simulation.error_estimate = false``) and with it, in process; the ratio of their medians
is what the budget costs. Then the command
line ``flex run simulate`` of the plan's command plate, whole process with its figures,
against the same scene in process: the ratio is what start-up, writing and drawing add.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from flex.base.errors import FlexError
from flex.data.scene import Scene, apply_overrides

Say = Callable[[str], None]


@dataclass(frozen=True)
class BudgetPlan:
    """The plates (name -> overrides of the bundled scene, ``--set`` values of the command
    line), the tolerance, and the plate whose command line is timed."""

    plates: Mapping[str, Sequence[str]]
    tolerance: float
    command_plate: str


def _timed(simulate: Callable[..., Any], scene: Scene, cache_dir: Path | None) -> float:
    start = time.perf_counter()
    simulate(scene, cache_dir=cache_dir)
    return time.perf_counter() - start


def bench_budget(plan: BudgetPlan, repeats: int, cache_dir: Path | None, say: Say,
                 notes: dict[str, Any]) -> None:
    """``notes["budget"]``: per plate the medians [s] of the run alone and with its budget
    and their ratio; ``notes["command_line"]``: the command's median whole-process time [s],
    the in-process one and their ratio."""
    from flex.fidelity.simulation import simulate

    rows = []
    for name in plan.plates:
        plate = _scene(plan, name)
        alone = apply_overrides(plate, ["simulation.error_estimate=false"])
        simulate(plate, cache_dir=cache_dir)  # warm: reductions, references, imports
        times: dict[str, list[float]] = {"run": [], "budget": []}
        for _ in range(repeats):
            times["run"].append(_timed(simulate, alone, cache_dir))
            times["budget"].append(_timed(simulate, plate, cache_dir))
        run_s, budget_s = (statistics.median(times[key]) for key in ("run", "budget"))
        rows.append({"plate": name, "run_s": run_s, "budget_s": budget_s,
                     "ratio": budget_s / run_s})
        say(f"{name}: run {run_s:.3f} s, with its budget {budget_s:.3f} s "
            f"({budget_s / run_s:.1f}x)")
    notes["budget"] = rows
    notes["command_line"] = _command_line(plan, repeats, cache_dir, say)


def _overrides(plan: BudgetPlan, name: str) -> list[str]:
    return [*plan.plates[name], f"fidelity.tolerance={plan.tolerance!r}"]


def _scene(plan: BudgetPlan, name: str) -> Scene:
    from flex.data.scene import load_scene

    return load_scene(None, _overrides(plan, name))


def _command_line(plan: BudgetPlan, repeats: int, cache_dir: Path | None, say: Say
                  ) -> dict[str, Any]:
    """The command line's whole-process median against the same scene in process."""
    from flex.fidelity.simulation import simulate

    scene = _scene(plan, plan.command_plate)
    in_process = statistics.median(_timed(simulate, scene, cache_dir) for _ in range(repeats))
    with tempfile.TemporaryDirectory(prefix="flex-bench-cli-") as folder:
        argv = [sys.executable, "-m", "flex", "run", "simulate", "--quiet",
                "--out", str(Path(folder) / "cli.h5"),
                *(arg for item in _overrides(plan, plan.command_plate)
                  for arg in ("--set", item))]
        env = dict(os.environ, MPLBACKEND="Agg")
        if cache_dir is not None:
            env["FLEX_CACHE_DIR"] = str(Path(cache_dir).parent)
        times = []
        for attempt in range(repeats + 1):  # the first warms the file system's caches
            start = time.perf_counter()
            done = subprocess.run(argv, capture_output=True, text=True, env=env, check=False)
            if done.returncode != 0:
                raise FlexError(f"the timed command line failed ({done.returncode}): "
                                f"{done.stderr.strip()[-300:]}")
            if attempt:
                times.append(time.perf_counter() - start)
    command_s = statistics.median(times)
    say(f"command line {command_s:.2f} s against {in_process:.2f} s in process "
        f"({command_s / in_process:.1f}x)")
    return {"plate": plan.command_plate, "command_s": command_s, "in_process_s": in_process,
            "ratio": command_s / in_process}


__all__ = ["BudgetPlan", "bench_budget"]
