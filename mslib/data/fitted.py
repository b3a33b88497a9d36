"""The generator's numbers fitted to real motion capture, read from `fitted_styles.json` beside this file.

`tools/fit_styles.py` writes that file from a dataset folder of the Xia train split: the body's rest
geometry (section "body") and every style's parameter means (section "styles"), with the command
that made them and a digest of the folder it read. Nothing of the real data itself is stored.
Without the file the generator uses its hand-written values.
"""
from __future__ import annotations

import json
from pathlib import Path

FITTED_FILE = Path(__file__).with_name("fitted_styles.json")


def load_fitted(section: str, path: Path = FITTED_FILE) -> dict:
    """One section of the fitted table, or {} when the file (or the section) is absent."""
    if not path.is_file():
        return {}
    try:
        table = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not valid JSON ({e}); refit with tools/fit_styles.py") from None
    return table.get(section) or {}
