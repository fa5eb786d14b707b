"""What an integration costs and how far it is: an estimate before it starts, progress while
it runs (:mod:`flex.dynamics.solver` uses both).

- :func:`estimated_run_time_s`: steps x a rough cost per step of the scene's models
  (:data:`STEP_COST_RIGID_S`, ...); :func:`announce_integration` prints it before a run
  estimated above :data:`ANNOUNCE_RUN_S`.
- :class:`SolverOutput`: what Exudyn prints during a solve (its step lines every 2 s of wall
  time become progress lines on stderr; the rest is kept for a failure's message).
"""

from __future__ import annotations

import io
import re
import sys
from collections.abc import Callable, Mapping
from typing import Any

from flex.base.progress import Progress, duration_text
from flex.data.scene import Scene
from flex.dynamics.link_models import (
    BUILTIN_LINK_MODELS,
    LinkModel,
    entries,
)

#: an integration whose estimated wall time exceeds this is announced on stderr first [s]
ANNOUNCE_RUN_S = 30.0
#: wall time per step [s] of the integration, rough (2-core machine, shared; within ~3x):
#: the rigid model (planar, full Newton: 12-30 us measured); each flexible link model adds
#: its own (:mod:`flex.dynamics.link_models`: an FFRF link per modal coordinate, the
#: nonlinear FE coupler per DOF of its mesh)
STEP_COST_RIGID_S = 3e-5


def estimated_run_time_s(scene: Scene, modes: dict[str, int] | None = None,
                         link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> float:
    """Rough wall time [s] of integrating a concrete scene (solver keys resolved) once:
    steps x an estimated cost per step (:data:`STEP_COST_RIGID_S` and each link model's
    ``step_cost_s``). ``modes``: the modes of built reductions by link (default: the
    scene's)."""
    steps = scene["simulation"]["end_time_s"] / scene["simulation"]["step_s"]
    per_step = STEP_COST_RIGID_S
    for link, model in entries(scene, link_models).items():
        per_step += model.step_cost_s(scene[link], (modes or {}).get(link))
    return steps * per_step


def announce_integration(scene: Scene, name: str, reductions: dict[str, Any],
                         link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> None:
    """Say on stderr, before it starts, what a long integration will cost (estimate)."""
    # a nonlinear FE coupler's plate has no modes: its cost comes from its mesh
    modes = {link: built.modes for link, built in reductions.items()
             if getattr(built, "modes", None) is not None}
    estimate = estimated_run_time_s(scene, modes, link_models)
    if estimate > ANNOUNCE_RUN_S:
        sim = scene["simulation"]
        print(f"flex: integrating {name}: {round(sim['end_time_s'] / sim['step_s'])} steps of "
              f"{sim['step_s']:g} s to t = {sim['end_time_s']:g} s, ~{duration_text(estimate)} "
              f"(estimate; progress follows)", file=sys.stderr, flush=True)


class SolverOutput(io.StringIO):
    """What Exudyn prints during a solve: kept for a failure's message, except its banner and
    step lines; each step line (``STEP<n>, t = <t>s, timeToGo = <s>s, ...``, every 2 s of
    wall time) becomes a progress line on stderr (:class:`flex.base.progress.Progress`: the
    first after 2 s, then at most one per 10 s)."""

    _STEP = re.compile(r"STEP(\d+), t = ([-+0-9.eE]+)s, timeToGo = ([-+0-9.eE]+)s")
    _NOISE = ("+++", "EXUDYN V", "STEP", "Solver terminated successfully", "solver finished")

    def __init__(self, label: str, end_time_s: float,
                 stop: Callable[[], None] | None = None) -> None:
        super().__init__()
        self.end_time_s = end_time_s
        self.progress = Progress(f"integrating {label}" if label else "integrating")
        self.stop = stop
        self._line = ""

    def write(self, text: str) -> int:
        try:
            self._line += text
            while "\n" in self._line:
                line, self._line = self._line.split("\n", 1)
                self._take(line)
        except KeyboardInterrupt:  # a signal handled while Exudyn called us: Exudyn would
            if self.stop is not None:  # drop the exception, so stop the solve (run() then
                self.stop()  # raises the interrupt it noted)
        return len(text)

    def _take(self, line: str) -> None:
        found = self._STEP.search(line)
        if found:
            now, to_go = float(found.group(2)), float(found.group(3))
            self.progress.update(f"t = {now:.4g} of {self.end_time_s:.4g} s "
                                 f"({100 * now / self.end_time_s:.3g} %, step "
                                 f"{int(found.group(1))}), ~{duration_text(to_go)} to go")
        elif line.strip() and not line.lstrip().startswith(self._NOISE):
            super().write(line + "\n")

    def getvalue(self) -> str:
        """What was kept, with a last line not yet ended by a newline."""
        pending = self._line if self._line.strip() and not self._line.lstrip().startswith(
            self._NOISE) else ""
        return super().getvalue() + pending
