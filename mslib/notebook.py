"""Notebook set-up: one call in each notebook's first cell makes its outputs stable for nbval."""
from __future__ import annotations

import json
import random
import sys
import warnings

import numpy as np
from pathlib import Path

FIGURE_DPI = 100


def setup_notebook(seed: int = 0) -> None:
    """Seed python/numpy/torch, print precision, PNG inline figures, no warnings; prints nothing."""
    random.seed(seed)
    np.random.seed(seed)
    np.set_printoptions(precision=4, suppress=True)
    try:
        import torch
    except ImportError:  # the library needs torch, but the set-up itself should not
        torch = None
    if torch is not None:
        torch.manual_seed(seed)
        torch.set_printoptions(precision=4, sci_mode=False)
        # (no torch.use_deterministic_algorithms: it imports torch._dynamo, ~5 s, and CPU
        # kernels are deterministic for a fixed thread count anyway)
    warnings.filterwarnings("ignore")
    import matplotlib
    import matplotlib.pyplot  # noqa: F401 — resolves the backend first, so our rcParams stick
    matplotlib.rcParams["figure.dpi"] = FIGURE_DPI
    matplotlib.rcParams["svg.hashsalt"] = "mslib"  # stable ids should anyone save an SVG
    ipython = sys.modules.get("IPython")  # a running kernel has imported it; never import it here
    if ipython is not None and ipython.get_ipython() is not None:
        try:
            from matplotlib_inline.backend_inline import set_matplotlib_formats
        except ImportError:
            return None
        set_matplotlib_formats("png")
    return None


FINDINGS_DIR = Path(__file__).resolve().parent.parent / "notebooks" / "data"


def load_findings(name: str, required: bool = True) -> dict:
    """The stored results `data/<name>.json` of a tool in `tools/` (they are too slow for a notebook), read from the
    notebook's own folder first (a handed-out copy of the workbook carries its `data/`), else from the repository's
    `notebooks/data/`; a missing file is a ValueError naming it (or `{}` with `required=False`)."""
    local = Path.cwd() / "data" / f"{name}.json"
    path = local if local.is_file() else FINDINGS_DIR / f"{name}.json"
    if not path.is_file():
        if not required:
            return {}
        raise ValueError(f"{path}: no stored findings; the tool that writes them is named in the notebook")
    return json.loads(path.read_text())


def readable_command(command: str) -> str:
    """A stored command as a reader can run it: checkpoint arguments (`LABEL=PATH`, or a bare path) keep only
    their file name, since the folder was a scratch folder of the machine that made the row."""
    import re
    return re.sub(r"(?<![\w.])(?:/[^\s/=]+)+/([^\s/]+)", r"\1", command)


def demo_style(by_style_rows) -> str:
    """The demo pairs' style: the non-neutral style whose transfers the evaluator recognised most often on
    *validation* pairs (rows as `bench.by_style` gives them; a tie goes to the first name), so a picture shows
    a style the method does move — chosen on val, never on the pair it is shown on."""
    rows = [r for r in by_style_rows if r["style"] != "neutral"]
    if not rows:
        raise ValueError("by_style_rows: no non-neutral style to choose from")
    return max(sorted(rows, key=lambda r: r["style"]), key=lambda r: r["sra"])["style"]


def neutral_walk(content_folder=None) -> str:
    """The clip id of the first neutral walk of the built-in content corpus (or of `content_folder`): a content for an
    explorer whose own style is none of the styles it is sent to (the content corpus's clips carry random styles)."""
    import csv
    if content_folder is None:
        from .data.corpora import load_builtin
        content_folder = load_builtin(progress=False)["content"]
    with open(Path(content_folder) / "labels.csv", encoding="utf-8") as f:
        for row in csv.DictReader(f):
            if row["style"] == "neutral" and row["content"] == "walk":
                return row["clip_id"]
    raise ValueError(f"{content_folder}: no neutral walk in labels.csv")


def demo_pairs(pairs, read_style, style: str | None = None, n: int = 1) -> list:
    """The first `n` pairs of a draw that can show a style (one per style, or all of `style`): the style clip is
    not neutral and the evaluator reads it as its own style (`read_style(joints)` names what it reads), and the
    content clip's content differs from the style clip's — a rule fixed before any transfer is looked at."""
    chosen, seen = [], set()
    for content, clip in pairs:
        s = clip["style"]
        if s == "neutral" or (style is not None and s != style) or (style is None and s in seen):
            continue
        if content["content"] == clip.get("content") or read_style(clip["joints"]) != s:
            continue
        chosen.append((content, clip))
        seen.add(s)
        if len(chosen) == n:
            return chosen
    raise ValueError(f"pairs: only {len(chosen)} of the {len(pairs)} pairs can show "
                     f"{'the style ' + repr(style) if style else 'a style'} by the rule, {n} asked for")
