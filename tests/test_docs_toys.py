"""The guides that name toy tests to copy (docs/extending.md, docs/error-budget.md) name tests
that exist: every ``tests/<file>.py`` they cite is a file of the suite, every
``tests/<file>.py::<test>`` a test function in it."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("page", ["extending.md", "error-budget.md"])
def test_every_cited_toy_test_exists(page):
    text = (ROOT / "docs" / page).read_text()
    cited = re.findall(r"tests/(\w+\.py)(?:::(\w+))?", text)
    assert cited, f"docs/{page} cites no test"
    for file, function in cited:
        path = ROOT / "tests" / file
        assert path.is_file(), f"docs/{page} cites tests/{file}, which does not exist"
        if function:
            names = {node.name for node in ast.walk(ast.parse(path.read_text()))
                     if isinstance(node, ast.FunctionDef)}
            assert function in names, f"docs/{page} cites {file}::{function}, not in it"
