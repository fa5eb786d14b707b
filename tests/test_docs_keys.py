"""docs/model.md lists every scene key of the schema (the README promises it): a key added
to :data:`flex.data.scene.SCHEMA` without a line in the table fails here, naming it."""

from __future__ import annotations

from pathlib import Path

import pytest

from flex.data.scene import SCHEMA

MODEL_MD = Path(__file__).resolve().parents[1] / "docs" / "model.md"


def _rows() -> dict[str, str]:
    """The table row of each section, ``| `[section]` | ... |``."""
    rows = {}
    for line in MODEL_MD.read_text(encoding="utf-8").splitlines():
        if line.startswith("| `["):
            rows[line.split("`")[1].strip("[]")] = line
    return rows


KEYS = [(section, key) for section, fields in SCHEMA.items() for key in fields]


@pytest.mark.parametrize("section, key", KEYS, ids=[f"{s}.{k}" for s, k in KEYS])
def test_every_scene_key_is_in_docs_model_md(section, key):
    rows = _rows()
    assert section in rows, f"docs/model.md has no row for [{section}]"
    row = rows[section]
    if section == "crank" and f"`{key}`" not in row:  # "the plate keys of [coupler]"
        assert "plate keys of `[coupler]`" in row and f"`{key}`" in rows["coupler"], key
        return
    assert f"`{key}`" in row, f"docs/model.md, row [{section}], does not name `{key}`"


def test_the_docs_name_no_section_the_schema_lacks():
    assert set(_rows()) == set(SCHEMA)
