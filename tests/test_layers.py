"""The library's layers: each flex module imports only from its own layer or lower ones.

The layers, lowest first (README "Layout" describes each module):
"""

from __future__ import annotations

import ast
from pathlib import Path

FLEX = Path(__file__).resolve().parent.parent / "flex"

LAYERS: list[tuple[str, set[str]]] = [
    ("foundations: errors, closed forms, the thesis's numbers, figure helpers",
     {"errors", "physics", "thesis", "kinematics", "plotting"}),
    ("scenes and result files", {"scene", "results", "outputs", "plate"}),
    ("settings: what a scene resolves to, which keys it uses", {"settings", "usage"}),
    ("bodies: beams, meshes, modes, reductions, the nonlinear FE coupler, the spring",
     {"beams", "fe_modes", "beam_elements", "mesh_convergence", "thesis_tables", "reduction",
      "nonlinear", "spring"}),
    ("mechanism and solvers: Exudyn model, integration, the independent reference DAE",
     {"mechanism", "solver", "reference"}),
    ("fidelity: the rigid-or-flexible criterion, auto, simulate any scene",
     {"criteria", "simulation", "softening", "caseloop"}),
    ("experiments: fits, work-precision, benchmark, stability, per-study computations",
     {"lawfit", "couplerfit", "crankfit", "lawplots", "tradeoff", "reference_plans",
      "workprecision", "defaults_check", "workprecision_report", "benchmark",
      "benchmark_report", "stability", "twins", "deployment", "wing", "constant_speed",
      "spring_check", "single_case", "modal"}),
    ("result tools: inspect, compare, plot, report",
     {"inspect", "compare", "plotcurves", "report"}),
    ("running studies, the public face", {"study", "api"}),
    ("sweeps", {"sweep"}),
    ("command line", {"cli", "__main__"}),
]
__doc__ += "\n".join(f"{i}. {text}: {', '.join(sorted(names))}"
                     for i, (text, names) in enumerate(LAYERS))


def layer_of(module: str) -> int:
    for index, (_, names) in enumerate(LAYERS):
        if module in names:
            return index
    raise AssertionError(f"flex/{module}.py is in no layer: add it to tests/test_layers.py "
                         f"(and to the README layout)")


def flex_imports(path: Path) -> set[str]:
    """The flex modules ``path`` imports (relative or absolute), at any depth."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level == 1 and node.module:
                found.add(node.module.split(".")[0])
            elif node.level == 1:
                found.update(alias.name for alias in node.names)
            elif node.module and node.module.startswith("flex."):
                found.add(node.module.split(".")[1])
        elif isinstance(node, ast.Import):
            found.update(alias.name.split(".")[1] for alias in node.names
                         if alias.name.startswith("flex."))
    return found - {"__version__"}


def modules() -> list[Path]:
    return sorted(p for p in FLEX.glob("*.py") if p.name != "__init__.py")


def test_every_module_has_a_layer():
    for path in modules():
        layer_of(path.stem)


def test_no_module_imports_from_a_higher_layer():
    upward = []
    for path in modules():
        own = layer_of(path.stem)
        for target in flex_imports(path):
            if target != "__init__" and layer_of(target) > own:
                upward.append(f"{path.stem} (layer {own}) imports {target} "
                              f"(layer {layer_of(target)})")
    assert not upward, upward


def test_the_library_never_imports_the_studies():
    for path in modules():
        text = path.read_text()
        assert "from studies" not in text and "import studies" not in text, path.name
