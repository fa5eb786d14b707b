"""The library's layers are its folders: a module imports only from its own folder or lower ones.

Lowest first: ``flex/base``, ``data``, ``config``, ``bodies``, ``dynamics``, ``fidelity``,
``experiments``, ``tools``, then the top modules ``flex/study.py``, ``api.py``,
``sweep`` (a package), ``cli.py`` (README "Layout" describes each module).
"""

from __future__ import annotations

import ast
from pathlib import Path

FLEX = Path(__file__).resolve().parent.parent / "flex"
#: the folders (and the top modules) from the lowest layer up
LAYERS = ["base", "data", "config", "bodies", "dynamics", "fidelity", "experiments", "tools",
          "study", "api", "sweep", "cli", "__main__"]


def layer_of(dotted: str) -> int:
    """Layer of a module ``flex.<folder>.<name>`` or a top module ``flex.<name>``."""
    parts = dotted.split(".")
    assert parts[0] == "flex", dotted
    key = parts[1] if len(parts) > 1 else "__init__"
    if key == "__init__":
        return -1  # the package face (``__version__``): importable from anywhere
    assert key in LAYERS, f"{dotted}: flex/{key} is in no layer: add it to tests/test_layers.py"
    return LAYERS.index(key)


def dotted_name(path: Path) -> str:
    parts = path.relative_to(FLEX.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_main_block(node: ast.AST) -> bool:
    """``if __name__ == "__main__":`` -- a program's entry, run only as ``python -m``."""
    test = getattr(node, "test", None)
    return (isinstance(node, ast.If) and isinstance(test, ast.Compare)
            and isinstance(test.left, ast.Name) and test.left.id == "__name__"
            and any(isinstance(c, ast.Constant) and c.value == "__main__"
                    for c in test.comparators))


def flex_imports(path: Path) -> set[str]:
    """The flex modules ``path`` imports, at any depth (every import is absolute), except in
    its ``if __name__ == "__main__":`` block: that is an edge (``python -m flex.sweep`` hands
    over to the command line), never run when the module is imported."""
    found = set()
    tree = ast.parse(path.read_text())
    tree.body = [node for node in tree.body if not _is_main_block(node)]
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path}: relative import (use flex.<layer>.<module>)"
            if node.module and (node.module == "flex" or node.module.startswith("flex.")):
                found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names if alias.name.startswith("flex."))
    return found


def modules() -> list[Path]:
    return sorted(p for p in FLEX.rglob("*.py") if "__pycache__" not in p.parts)


def test_every_module_sits_in_a_layer_folder():
    for path in modules():
        if path.parent == FLEX and path.stem not in ("__init__",):
            assert path.stem in LAYERS, f"flex/{path.name} belongs in a layer folder"
        else:
            layer_of(dotted_name(path))


def test_no_module_imports_from_a_higher_layer():
    upward = []
    for path in modules():
        name = dotted_name(path)
        own = layer_of(name)
        for target in flex_imports(path):
            if layer_of(target) > own:
                upward.append(f"{name} imports {target}")
    assert not upward, upward


def test_the_library_never_imports_the_studies():
    for path in modules():
        text = path.read_text()
        assert "from studies" not in text and "import studies" not in text, path.name


def _shelf_imports(shelf: str) -> dict[str, set[str]]:
    """Per module of ``flex/experiments/<shelf>``: the other experiments shelves it imports."""
    found = {}
    for path in sorted((FLEX / "experiments" / shelf).rglob("*.py")):
        shelves = {target.split(".")[2] for target in flex_imports(path)
                   if target.startswith("flex.experiments.") and len(target.split(".")) > 2}
        found[dotted_name(path)] = shelves - {shelf}
    return found


def test_fitting_builds_on_workprecision_never_the_other_way():
    """The laws and the FFRF rule are fitted on work-precision measurements
    (``experiments/fitting`` imports ``experiments/workprecision``); work-precision never
    imports the fitting."""
    backward = [name for name, shelves in _shelf_imports("workprecision").items()
                if "fitting" in shelves]
    assert not backward, f"workprecision imports fitting: {backward}"
    assert any("workprecision" in shelves for shelves in _shelf_imports("fitting").values())
