"""The notebooks' sources and saved notebooks hold no control characters (a LaTeX `\\frac` or `\\tau` typed
into a non-raw Python string loses its backslash to a form feed or a tab, and the equation renders broken)."""
import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"


def _build_tool():
    """tools/build_notebooks.py, imported by path (tools/ is not a package)."""
    spec = importlib.util.spec_from_file_location("build_notebooks", ROOT / "tools" / "build_notebooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


BUILD = _build_tool()
control_characters = BUILD.control_characters


def test_control_characters_are_found_and_the_build_refuses_them(tmp_path):
    assert control_characters("a\n\\frac{1}{2}\n") == []
    assert control_characters("a\n\x0crac{1}{2}\n\tau\r") == [2, 3]
    src = tmp_path / "99_broken.py"
    src.write_bytes("# %% [markdown]\n# $\\lVert x\rVert$\n".encode())
    with pytest.raises(ValueError, match=r"99_broken.py: control characters on lines \[2\]"):
        BUILD.build(src)


@pytest.mark.parametrize("src", sorted((NOTEBOOKS / "src").glob("*.py")), ids=lambda p: p.name)
def test_notebook_source_has_no_control_characters(src):
    assert control_characters(src.read_bytes().decode("utf-8")) == [], src


@pytest.mark.parametrize("nb", sorted(NOTEBOOKS.glob("*.ipynb")), ids=lambda p: p.name)
def test_saved_notebook_markdown_has_no_control_characters(nb):
    cells = json.loads(nb.read_text(encoding="utf-8"))["cells"]
    bad = [i for i, c in enumerate(cells) if c["cell_type"] == "markdown" and control_characters("".join(c["source"]))]
    assert bad == [], f"{nb.name}: markdown cells {bad}"


@pytest.mark.parametrize("src", sorted((NOTEBOOKS / "src").glob("*.py")), ids=lambda p: p.name)
def test_saved_notebook_cells_are_its_sources(src):
    """Each saved notebook holds exactly its source's cells (kind and text): an edit made in the .ipynb alone
    would be lost at the next build, and one made in the source alone would never reach nbval."""
    cells = json.loads((NOTEBOOKS / f"{src.stem}.ipynb").read_text(encoding="utf-8"))["cells"]
    saved = [(c["cell_type"], "".join(c["source"])) for c in cells]
    assert saved == [(kind, body) for kind, body, _ in BUILD.read_cells(src)], src.stem
