"""The notebooks' sources and saved notebooks hold no control characters (a LaTeX `\\frac` or `\\tau` typed
into a non-raw Python string loses its backslash to a form feed or a tab, and the equation renders broken)."""
import json
from pathlib import Path

import pytest

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"


def control_characters(text: str) -> list:
    """Line numbers (1-based) of lines holding a control character other than the newline."""
    return [i for i, line in enumerate(text.split("\n"), 1) if any(ord(ch) < 32 for ch in line)]


def test_control_characters_are_found():
    assert control_characters("a\n\\frac{1}{2}\n") == []
    assert control_characters("a\n\x0crac{1}{2}\n\tau\r") == [2, 3]


@pytest.mark.parametrize("src", sorted((NOTEBOOKS / "src").glob("*.py")), ids=lambda p: p.name)
def test_notebook_source_has_no_control_characters(src):
    assert control_characters(src.read_bytes().decode("utf-8")) == [], src


@pytest.mark.parametrize("nb", sorted(NOTEBOOKS.glob("*.ipynb")), ids=lambda p: p.name)
def test_saved_notebook_markdown_has_no_control_characters(nb):
    cells = json.loads(nb.read_text(encoding="utf-8"))["cells"]
    bad = [i for i, c in enumerate(cells) if c["cell_type"] == "markdown" and control_characters("".join(c["source"]))]
    assert bad == [], f"{nb.name}: markdown cells {bad}"
