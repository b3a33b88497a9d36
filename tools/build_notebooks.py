"""Build notebooks/NN_name.ipynb from notebooks/src/NN_name.py (percent format) and execute them.

    .venv/bin/python tools/build_notebooks.py [NAME ...]                  # default: every source
    .venv/bin/python tools/build_notebooks.py --sources-only [NAME ...]   # code moved, outputs kept

Cells are separated by `# %%` (code) and `# %% [markdown]` (markdown, lines starting '# ').
Each notebook runs top to bottom in a fresh kernel with notebooks/ as the working folder and is
saved with its outputs, which nbval then compares. `--sources-only` writes the
sources into the saved notebook and keeps its outputs, for a change that moves code without changing
what it prints (an import path, a renamed function): nbval then checks that the new code still prints
the stored outputs. It refuses when the cells no longer line up (a cell added, removed or retyped). The kernels start with the numeric
code path the tests use (`mslib.cpu_paths`), meant to let a machine with AVX-512 write what one with AVX2
checks (checked so far only on an AVX2 machine).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]
SRC, OUT = ROOT / "notebooks" / "src", ROOT / "notebooks"
sys.path.insert(0, str(ROOT))
from mslib.cpu_paths import pin_cpu_code_paths  # noqa: E402


def parse_percent(text: str):
    """Split a percent-format script into (kind, source) cells."""
    cells, kind, lines = [], None, []

    def flush():
        if kind is not None:
            body = "\n".join(lines).strip("\n")
            if kind == "markdown":
                body = "\n".join(l[2:] if l.startswith("# ") else l.lstrip("#") for l in body.splitlines())
            if body.strip():
                cells.append((kind, body))

    for line in text.splitlines():
        if line.startswith("# %%"):
            flush()
            kind, lines = ("markdown" if "[markdown]" in line else "code"), []
        elif kind is not None:
            lines.append(line)
    flush()
    return cells


def control_characters(text: str) -> list:
    """Line numbers (1-based) of lines holding a control character other than the newline: a LaTeX `\\frac` or
    `\\tau` typed into a non-raw Python string loses its backslash to a form feed or a tab."""
    return [i for i, line in enumerate(text.split("\n"), 1) if any(ord(ch) < 32 for ch in line)]


def build(src: Path, timeout: int = 600) -> float:
    """Write and execute one notebook; returns its run time in seconds."""
    text = src.read_bytes().decode("utf-8")  # not read_text: it would turn a stray \r into a newline
    bad = control_characters(text)
    if bad:
        raise ValueError(f"{src}: control characters on lines {bad} (a LaTeX backslash lost to an escape?)")
    cells = parse_percent(text)
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.cells = [nbformat.v4.new_markdown_cell(s) if k == "markdown" else nbformat.v4.new_code_cell(s)
                for k, s in cells]
    pin_cpu_code_paths()  # before the kernel starts: it inherits the environment
    t0 = time.time()
    NotebookClient(nb, timeout=timeout, kernel_name="python3",
                   resources={"metadata": {"path": str(OUT)}}).execute()
    for i, cell in enumerate(nb.cells):  # stable ids keep diffs small
        cell["id"] = f"c{i:03d}"
    out = OUT / f"{src.stem}.ipynb"
    nbformat.write(nb, out)
    return time.time() - t0


def sync_sources(src: Path) -> int:
    """Write the source's cells into the saved notebook, keeping its outputs; returns how many cells changed."""
    text = src.read_bytes().decode("utf-8")
    bad = control_characters(text)
    if bad:
        raise ValueError(f"{src}: control characters on lines {bad} (a LaTeX backslash lost to an escape?)")
    cells = parse_percent(text)
    path = OUT / f"{src.stem}.ipynb"
    nb = nbformat.read(path, as_version=4)
    kinds = [c.cell_type for c in nb.cells]
    if kinds != [k for k, _ in cells]:
        raise ValueError(f"{path}: its cells no longer line up with {src} ({len(kinds)} saved, {len(cells)} in the "
                         "source, or a cell changed kind); rebuild it: tools/build_notebooks.py " + src.stem)
    changed = 0
    for cell, (_, body) in zip(nb.cells, cells):
        if cell.source != body:
            cell.source, changed = body, changed + 1
    if changed:
        from mslib.fileio import atomic_write_bytes
        atomic_write_bytes(path, (nbformat.writes(nb) + "\n").encode("utf-8"))
    return changed


if __name__ == "__main__":
    args = sys.argv[1:]
    if {"-h", "--help"} & set(args):
        print(__doc__)
        raise SystemExit(0)
    sources_only = "--sources-only" in args
    names = [a for a in args if a != "--sources-only"]
    sources = sorted(SRC.glob("*.py"))
    if names:
        sources = [s for s in sources if any(n in s.stem for n in names)]
    for s in sources:
        if sources_only:
            print(f"{s.stem}: {sync_sources(s)} cells' sources updated, outputs kept", flush=True)
        else:
            print(f"{s.stem}: executed in {build(s):.1f} s", flush=True)
