"""Shared helpers of tools/: where things are, the one way to write a stored table, val pairs and scoring.

    from tools.common import ROOT, DATA_DIR, update_json, val_pairs, score_outputs, current_commit

A tool stays runnable as `python tools/NAME.py` by putting ROOT on sys.path before that import:

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

Nothing here imports torch when the module is imported (a tool's `--help` stays quick).
"""
from __future__ import annotations

import json
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]  # the repository root
from mslib.notebook import FINDINGS_DIR as DATA_DIR  # noqa: E402 (the stored tables the notebooks read)


def update_json(path, sections: dict) -> Path:
    """Replace the top-level keys `sections` of the JSON object at `path` (created if absent), keeping the
    others; written atomically (indent=1), so a failed run leaves the previous file whole. Returns the path."""
    from mslib.fileio import atomic_write_bytes
    path = Path(path)
    old = json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}
    if not isinstance(old, dict):
        raise ValueError(f"{path}: expected a JSON object at the top level, found {type(old).__name__}")
    text = json.dumps({**old, **sections}, indent=1) + "\n"  # serialise first: a bad value raises before writing
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(path, text.encode("utf-8"))
    return path


def val_pairs(n: int = 200, seed: int = 0) -> list:
    """`n` held-out (content, style) pairs from the VALIDATION splits of the built-in corpora (design
    choices are made here; the benchmark's test pairs stay unseen)."""
    from mslib.evaluation.bench import load_pairs
    return load_pairs(seed, n, split="val")


def score_outputs(positions_list, pairs, evaluator=None) -> dict:
    """The benchmark's metrics (h, cra, sra, sra_top3, fmd, fsf, fsr, tsi, diversity) of output joint
    positions, one (T, 22, 3) array per (content, style) pair; `evaluator` defaults to a new bench.Evaluator."""
    import numpy as np
    from mslib.evaluation.bench import Evaluator, evaluate
    from mslib.motion.features import N_JOINTS
    outputs = [np.asarray(p, np.float64) for p in positions_list]
    if len(outputs) != len(pairs) or not pairs:
        raise ValueError(f"expected one output per pair ({len(pairs)} pairs, at least one), got {len(outputs)}")
    bad = [i for i, p in enumerate(outputs) if p.ndim != 3 or p.shape[1:] != (N_JOINTS, 3)]
    if bad:
        raise ValueError(f"outputs {bad[:5]}: expected joint positions (T, {N_JOINTS}, 3), got "
                         f"{outputs[bad[0]].shape} (features? pass them through bench.positions)")
    return {k: float(v) for k, v in evaluate(outputs, pairs, evaluator or Evaluator()).items()}


def recorded_command(tool: str, argv, scratch=("--workdir", "--keep")) -> str:
    """`python tools/TOOL.py ARGS` as a stored row records it: without the options that only name a scratch
    folder of this machine (a reader's clone has no such path; the results do not depend on it)."""
    args, skip = [], False
    for a in argv:
        if skip:
            skip = False
        elif a in scratch:
            skip = True
        elif not a.startswith(tuple(f"{o}=" for o in scratch)):
            args.append(a)
    return " ".join([f"python tools/{tool}.py", *args])


def current_commit() -> str:
    """`git rev-parse --short HEAD` of ROOT (a stored row's provenance), or "unknown" outside a git checkout."""
    try:
        out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                             timeout=10)
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() if out.returncode == 0 and out.stdout.strip() else "unknown"


def main(argv=None) -> int:
    """`python tools/common.py`: print ROOT, DATA_DIR and the current commit (what a tool's rows will record)."""
    import argparse
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args(argv)
    print(f"ROOT     {ROOT}\nDATA_DIR {DATA_DIR}\ncommit   {current_commit()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
