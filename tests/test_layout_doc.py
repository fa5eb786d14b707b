"""docs/layout.md (the README's layout section points to it) lists every module of flex/
(by its file name, in backticks) and every folder (as `folder/`)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_module_and_folder_of_flex_is_listed():
    text = (ROOT / "docs" / "layout.md").read_text()
    names = set(re.findall(r"`([a-z_]+\.py)`", text))
    folders = set(re.findall(r"`([a-z_]+)/`", text))
    missing = []
    for path in sorted((ROOT / "flex").rglob("*.py")):
        relative = path.relative_to(ROOT / "flex")
        if "__pycache__" in relative.parts:
            continue
        if path.name not in names:
            missing.append(str(relative))
        missing += [f"{folder}/" for folder in relative.parts[:-1] if folder not in folders]
    assert not missing, f"docs/layout.md does not list: {sorted(set(missing))}"
