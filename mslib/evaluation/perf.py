"""`python -m mslib perf`: inference time per 64-frame clip and parameter count of every method.

Per method: build it once, warm up, then time `repeats` (≥ 20 by default) transfers of the same
64-frame content clip (64 rows of the 263-d vector, 65 positions) with a built-in style clip, and
report the median in milliseconds beside the issue's target. The parameter count comes from the
optional protocol documented in mslib/models/registry.py (`transfer.n_parameters`, or `.parameters()` of a module).
"""
from __future__ import annotations

import time

import numpy as np

from .bench import get_method, known_methods, positions

FRAMES = 64
REPEATS = 20
WARMUP = 3
# targets on 2 CPU cores: the one-pass methods ≤ 10 ms; the diffusion samplers at their presets, B's DDIM (20 steps) with
# CFG ≤ 60 ms and D's SDEdit (20 DDIM steps, three-way CFG, style guidance) ≤ 150 ms per clip
TARGETS_MS = {"adain": 10.0, "adain+dsdn": 10.0, "contrastive": 10.0, "mcm_ldm": 60.0, "clusterstyle": 150.0}
JSON_KEYS = ("method", "ms_median", "ms_min", "ms_max", "repeats", "n_parameters", "target_ms", "met")


def parameter_count(transfer):
    """A method's parameter count: `transfer.n_parameters`, else the sum over `transfer.parameters()`,
    else None (unknown)."""
    n = getattr(transfer, "n_parameters", None)
    if n is not None:
        return int(n)
    if callable(getattr(transfer, "parameters", None)):
        return int(sum(p.numel() for p in transfer.parameters()))
    return None


def perf_inputs(frames: int = FRAMES, seed: int = 0) -> tuple:
    """A (content, style) pair of built-in test clips, the content cut to `frames` feature rows."""
    from ..data.dataset_folder import read_labels
    from .transfer_io import builtin_folders, load_clip
    folders = builtin_folders(seed)
    tests = {k: [r for r in read_labels(f) if r["split"] == "test"] for k, f in folders.items()}
    long = [r["clip_id"] for r in tests["content"] if int(r["n_frames"]) > frames]
    if long and tests["style"]:
        content = load_clip(long[0], folders)
        content["features"] = content["features"][:frames]  # (frames, 263)
        content["joints"] = content["joints"][:frames + 1]  # (frames + 1, 22, 3)
        return content, load_clip(tests["style"][0]["clip_id"], folders)
    raise ValueError(f"frames: no built-in test clip has {frames} frames")


def time_method(name: str, content: dict, style: dict, repeats: int = REPEATS, warmup: int = WARMUP,
                device: str = "cpu") -> dict:
    """Median/min/max milliseconds of `repeats` timed transfers after `warmup` untimed ones."""
    if int(repeats) < 1:
        raise ValueError(f"--repeats: must be at least 1, got {repeats}")
    transfer = get_method(name, device)
    for _ in range(int(warmup)):
        transfer(content, style)
    ms = []
    for _ in range(int(repeats)):
        t0 = time.perf_counter()
        out = positions(transfer(content, style))
        np.asarray(out)  # a lazy or device result is only done once it is on the host
        ms.append(1000.0 * (time.perf_counter() - t0))
    target = TARGETS_MS.get(name)
    median = float(np.median(ms))
    return {"method": name, "ms_median": median, "ms_min": float(np.min(ms)), "ms_max": float(np.max(ms)),
            "repeats": int(repeats), "n_parameters": parameter_count(transfer), "target_ms": target,
            "met": None if target is None else bool(median <= target)}


def run_perf(methods=None, repeats: int = REPEATS, frames: int = FRAMES, device: str = "cpu",
             seed: int = 0) -> dict:
    """Time every registered method (or the named ones) on one 64-frame clip; a JSON-able report."""
    import torch
    if int(repeats) < 1:
        raise ValueError(f"--repeats: must be at least 1, got {repeats}")
    known = known_methods()
    names = known if not methods else list(methods)
    unknown = [n for n in names if n not in known]
    if unknown:
        raise ValueError(f"--methods: unknown {', '.join(map(repr, unknown))}; known methods: {', '.join(known)}")
    content, style = perf_inputs(frames, seed)
    rows = []
    for n in names:
        try:
            rows.append(time_method(n, content, style, repeats, device=device))
        except ValueError as e:  # e.g. a method whose checkpoint is not trained yet: report it, go on
            rows.append({**dict.fromkeys(JSON_KEYS), "method": n, "target_ms": TARGETS_MS.get(n), "error": str(e)})
    return {"frames": int(len(content["features"])), "repeats": int(repeats), "device": device,
            "torch_threads": torch.get_num_threads(), "content": content["clip_id"], "style": style["clip_id"],
            "rows": rows}


def format_perf(report: dict) -> str:
    """A plain-text table of a `run_perf` report."""
    head = f"{'method':<14}{'ms (median)':>12}{'min':>9}{'max':>9}{'parameters':>12}{'target ms':>11}  met"
    lines = [head]
    for r in report["rows"]:
        if r.get("error"):
            lines.append(f"{r['method']:<14}  not timed: {r['error']}")
            continue
        n = "?" if r["n_parameters"] is None else f"{r['n_parameters']:,}"
        target = "—" if r["target_ms"] is None else f"{r['target_ms']:g}"
        met = "—" if r["met"] is None else ("met" if r["met"] else "MISSED")
        lines.append(f"{r['method']:<14}{r['ms_median']:>12.3f}{r['ms_min']:>9.3f}{r['ms_max']:>9.3f}"
                     f"{n:>12}{target:>11}  {met}")
    lines.append(f"{report['frames']}-frame clip, median of {report['repeats']} runs after warm-up, "
                 f"{report['device']}, {report['torch_threads']} torch thread(s)")
    return "\n".join(lines)
