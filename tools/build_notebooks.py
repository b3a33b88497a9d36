"""Build notebooks/NN_name.ipynb from notebooks/src/NN_name.py (percent format) and execute them.

    .venv/bin/python tools/build_notebooks.py [NAME ...]                  # default: every source
    .venv/bin/python tools/build_notebooks.py --sources-only [NAME ...]   # code moved, outputs kept

Cells are separated by `# %%` (code) and `# %% [markdown]` (markdown, lines starting '# '). Two headers
mark nbgrader cells (tools/release.py hands them out and grades them):

    # %% [nbgrader solution id=NAME]          the exercise; its reference answer between
                                              ### BEGIN SOLUTION and ### END SOLUTION
    # %% [nbgrader tests id=NAME points=N]    locked, graded checks; optionally some between
                                              ### BEGIN HIDDEN TESTS and ### END HIDDEN TESTS

Each notebook runs top to bottom in a fresh kernel with notebooks/ as the working folder and is
saved with its outputs, which nbval then compares. `--sources-only` writes the
sources into the saved notebook and keeps its outputs, for a change that moves code without changing
what it prints (an import path, a renamed function): nbval then checks that the new code still prints
the stored outputs. It refuses when the cells no longer line up (a cell added, removed or retyped). The kernels start with the numeric
code path the tests use (`mslib.cpu_paths`), meant to let a machine with AVX-512 write what one with AVX2
checks (checked so far only on an AVX2 machine).
"""
from __future__ import annotations

import re
import sys
import time
from pathlib import Path

import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]
SRC, OUT = ROOT / "notebooks" / "src", ROOT / "notebooks"
sys.path.insert(0, str(ROOT))
from mslib.cpu_paths import pin_cpu_code_paths  # noqa: E402


NBGRADER_MARKER = re.compile(r"^# %%\s*\[nbgrader(?P<args>[^\]]*)\]\s*$")
GRADE_ID = re.compile(r"^[A-Za-z0-9_-]+$")
MARKER_USAGE = "`# %% [nbgrader solution id=NAME]` or `# %% [nbgrader tests id=NAME points=N]`"
# nbgrader's region delimiters (matched anywhere in a line, as nbgrader does) and the one cell kind each may sit in
DELIMITERS = {"solution": ("BEGIN SOLUTION", "END SOLUTION"), "tests": ("BEGIN HIDDEN TESTS", "END HIDDEN TESTS")}


def nbgrader_metadata(args: str, where: str) -> dict:
    """The cell metadata of an nbgrader marker's arguments (`solution id=X`, `tests id=X points=N`)."""
    words = args.split()
    if not words or words[0] not in DELIMITERS:
        found = repr(words[0]) if words else "nothing"
        raise ValueError(f"{where}: unknown nbgrader cell kind {found}; expected {MARKER_USAGE}")
    kind, options = words[0], {}
    for word in words[1:]:
        key, eq, value = word.partition("=")
        if not eq or key not in ("id", "points") or key in options:
            raise ValueError(f"{where}: bad nbgrader option {word!r} (once each: id=NAME, points=N on a tests cell)")
        options[key] = value
    grade_id = options.get("id")
    if not grade_id or not GRADE_ID.match(grade_id):
        raise ValueError(f"{where}: nbgrader cell needs id=NAME (letters, digits, _ and -), got {grade_id!r}")
    if kind == "solution":
        if "points" in options:
            raise ValueError(f"{where}: points= belongs on the tests cell that grades {grade_id}, not its solution")
        return {"grade": False, "solution": True, "locked": False, "grade_id": grade_id, "schema_version": 3}
    return {"grade": True, "solution": False, "locked": True, "points": positive_points(options.get("points"), where),
            "grade_id": grade_id, "schema_version": 3}


def positive_points(text, where: str):
    """`points=` of a tests cell as a positive int (or float); a ValueError naming the marker otherwise."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        value = float("nan")
    if not value > 0 or value == float("inf"):
        raise ValueError(f"{where}: a tests cell needs points=N with N a positive number, got {text!r}")
    return int(value) if value.is_integer() else value


def check_delimiters(lines: list, meta: dict, header: str) -> None:
    """Refuse misplaced, unclosed or nested nbgrader regions in one cell's (line number, text) `lines`."""
    path = header.rsplit(", line ", 1)[0]
    nb_kind = "solution" if meta.get("solution") else "tests" if meta.get("grade") else None
    for region, (begin, end) in DELIMITERS.items():
        opened, regions = None, 0
        for number, line in lines:
            if begin not in line and end not in line:
                continue
            where = f"{path}, line {number}"
            if nb_kind != region:
                raise ValueError(f"{where}: {line.strip()!r} outside an nbgrader {region} cell ({MARKER_USAGE})")
            if begin in line:
                if opened is not None:
                    raise ValueError(f"{where}: {begin} inside the region opened on line {opened}")
                opened = number
            else:
                if opened is None:
                    raise ValueError(f"{where}: {end} without a {begin} before it")
                opened, regions = None, regions + 1
        if opened is not None:
            raise ValueError(f"{path}, line {opened}: {begin} is never closed by {end}")
        if region == "solution" and nb_kind == "solution" and not regions:
            raise ValueError(f"{header}: solution cell {meta['grade_id']!r} has no ### BEGIN SOLUTION / "
                             "### END SOLUTION region (nbgrader would blank the whole cell)")


def parse_percent(text: str, path="<source>"):
    """Split a percent-format script into (kind, source, metadata) cells (metadata {} or {"nbgrader": ...})."""
    cells, header, lines, seen = [], None, [], {}

    def flush():
        if header is None:
            return
        kind, meta, number = header
        while lines and lines[0][1] == "":  # blank lines around a cell are not part of it
            lines.pop(0)
        while lines and lines[-1][1] == "":
            lines.pop()
        check_delimiters(lines, meta.get("nbgrader", {}), f"{path}, line {number}")
        body = "\n".join(line for _, line in lines)
        if kind == "markdown":
            body = "\n".join(l[2:] if l.startswith("# ") else l.lstrip("#") for l in body.splitlines())
        if meta and not body.strip():
            raise ValueError(f"{path}, line {number}: nbgrader cell {meta['nbgrader']['grade_id']!r} is empty")
        if body.strip():
            cells.append((kind, body, meta))

    for number, line in enumerate(text.splitlines(), 1):
        if line.startswith("# %%"):
            flush()
            header, lines = cell_header(line, f"{path}, line {number}", seen) + (number,), []
        elif header is not None:
            lines.append((number, line))
    flush()
    return cells


def cell_header(line: str, where: str, seen: dict) -> tuple:
    """(kind, metadata) of a `# %%` line; `seen` maps the grade ids met so far to where (duplicates refused)."""
    marker = NBGRADER_MARKER.match(line)
    if marker is None:
        if re.search(r"\[[^\]]*nbgrader", line):
            raise ValueError(f"{where}: malformed nbgrader marker {line!r}; expected {MARKER_USAGE}")
        return ("markdown" if "[markdown]" in line else "code"), {}
    meta = nbgrader_metadata(marker["args"], where)
    if meta["grade_id"] in seen:
        raise ValueError(f"{where}: grade id {meta['grade_id']!r} already used at {seen[meta['grade_id']]}")
    seen[meta["grade_id"]] = where.rsplit(", ", 1)[-1]
    return "code", {"nbgrader": meta}


def control_characters(text: str) -> list:
    """Line numbers (1-based) of lines holding a control character other than the newline: a LaTeX `\\frac` or
    `\\tau` typed into a non-raw Python string loses its backslash to a form feed or a tab."""
    return [i for i, line in enumerate(text.split("\n"), 1) if any(ord(ch) < 32 for ch in line)]


def read_cells(src: Path) -> list:
    """The (kind, source, metadata) cells of a notebook source, refusing control characters."""
    text = src.read_bytes().decode("utf-8")  # not read_text: it would turn a stray \r into a newline
    bad = control_characters(text)
    if bad:
        raise ValueError(f"{src}: control characters on lines {bad} (a LaTeX backslash lost to an escape?)")
    return parse_percent(text, src)


def new_cell(kind: str, source: str, metadata: dict):
    """One nbformat v4 cell of a parsed source cell."""
    if kind == "markdown":
        return nbformat.v4.new_markdown_cell(source, metadata=metadata)
    return nbformat.v4.new_code_cell(source, metadata=metadata)


def build(src: Path, timeout: int = 600, out_dir: Path = OUT) -> float:
    """Write and execute one notebook into `out_dir` (its working folder); returns its run time in seconds."""
    cells = read_cells(src)
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.cells = [new_cell(*cell) for cell in cells]
    pin_cpu_code_paths()  # before the kernel starts: it inherits the environment
    t0 = time.time()
    NotebookClient(nb, timeout=timeout, kernel_name="python3",
                   resources={"metadata": {"path": str(out_dir)}}).execute()
    for i, cell in enumerate(nb.cells):  # stable ids keep diffs small
        cell["id"] = f"c{i:03d}"
    out = Path(out_dir) / f"{src.stem}.ipynb"
    nbformat.write(nb, out)
    return time.time() - t0


def sync_sources(src: Path, out_dir: Path = OUT) -> int:
    """Write the source's cells and nbgrader metadata into the saved notebook (outputs kept); returns cells changed."""
    cells = read_cells(src)
    path = Path(out_dir) / f"{src.stem}.ipynb"
    nb = nbformat.read(path, as_version=4)
    kinds = [c.cell_type for c in nb.cells]
    if kinds != [k for k, _, _ in cells]:
        raise ValueError(f"{path}: its cells no longer line up with {src} ({len(kinds)} saved, {len(cells)} in the "
                         "source, or a cell changed kind); rebuild it: tools/build_notebooks.py " + src.stem)
    changed = 0
    for cell, (_, body, meta) in zip(nb.cells, cells):
        if cell.source != body or cell.metadata.get("nbgrader") != meta.get("nbgrader"):
            cell.source, changed = body, changed + 1
            cell.metadata.pop("nbgrader", None)
            cell.metadata.update(meta)
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
