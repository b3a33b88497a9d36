"""The benchmark on real motion capture: real contents against the styles of real stylized takes.

The built-in benchmark (`bench.load_pairs`) draws its pairs from the generator's corpora, so it can only say
how a method does in the built-in world. Here both sides are real:

- **styles**: every take of a real style folder (a dataset folder made by `data_prep.bvh … --labels xia`,
  e.g. the 40 takes of the Xia test grid: eight styles × walk, run, jump, punch, kick);
- **contents**: the *neutral* takes of that folder, and real motions from elsewhere given as files
  (`FILE[=CONTENT]`: a 263-d HumanML3D-format .npy, a T×22×3 .npy or a .bvh; CONTENT names the action
  for the content classifier, a file without one is left out of CRA only).

Every content meets every style take except itself (a neutral take is not its own style reference).
Long contents are cut to their first `max_frames` feature rows (10 s at 20 fps, HumanML3D's longest
motion), so one 35-second 100STYLE take does not outweigh the rest.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

MAX_FRAMES = 200  # feature rows of a content (10 s at 20 fps)


def parse_content_spec(spec: str) -> tuple[Path, str]:
    """'FILE[=CONTENT]' → (path, content label or '')."""
    path, _, label = str(spec).partition("=")
    if not path:
        raise ValueError(f"--real-content {spec!r}: expected FILE or FILE=CONTENT")
    return Path(path), label.strip()


def folder_takes(folder, arg: str = "--real-style", split: str | None = None) -> list:
    """Every clip of a real dataset folder with a style label (of one `split`, or all), as the dicts the methods
    take."""
    from ..data.dataset_folder import read_labels, read_meta
    from ..fileio import load_npy
    from .transfer_io import _item
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"{arg} {folder}: no such folder (make one with "
                         "`python -m data_prep.bvh XIA_BVH_DIR OUT_DIR --dialect auto --labels xia`)")
    try:
        read_meta(folder)
        rows = [r for r in read_labels(folder) if r.get("style") and split in (None, r["split"])]
    except ValueError as e:
        raise ValueError(f"{arg} {folder}: {e}") from None
    if not rows:
        raise ValueError(f"{arg} {folder}: no clip{'' if split is None else f' of the {split} split'} has a style "
                         "label (convert it with --labels xia)")
    items = []
    for r in sorted(rows, key=lambda r: r["clip_id"]):
        features = load_npy(folder / "features" / f"{r['clip_id']}.npy", arg)
        joints = load_npy(folder / "joints" / f"{r['clip_id']}.npy", arg)
        items.append(_item(features, joints, r["clip_id"], str(folder),
                           **{k: r.get(k, "") for k in ("style", "substyle", "content", "caption")}))
    return items


def cut(item: dict, max_frames: int = MAX_FRAMES) -> dict:
    """A content item cut to its first `max_frames` feature rows (and max_frames + 1 positions)."""
    if len(item["features"]) <= max_frames:
        return item
    return {**item, "features": item["features"][:max_frames], "joints": item["joints"][:max_frames + 1]}


def real_contents(style_takes: list, specs=(), max_frames: int = MAX_FRAMES) -> list:
    """The neutral takes among `style_takes`, then one item per 'FILE[=CONTENT]' spec, each cut to max_frames."""
    from .transfer_io import load_motion
    contents = [t for t in style_takes if t["style"] == "neutral"]
    for spec in specs:
        path, label = parse_content_spec(spec)
        if path.suffix.lower() not in (".npy", ".bvh"):
            raise ValueError(f"--real-content {spec!r}: expected a .npy or .bvh file")
        contents.append({**load_motion(path, "--real-content"), "content": label, "style": ""})
    if not contents:
        raise ValueError("real pairs: no content (the style folder has no neutral take and no --real-content "
                         "file was given)")
    return [cut(c, max_frames) for c in contents]


def real_pairs(style_folder, content_specs=(), n_pairs: int | None = None, seed: int = 0,
               max_frames: int = MAX_FRAMES, split: str | None = None) -> list:
    """(content, style) pairs: every content with every style take but itself (the takes of one `split` of the
    folder, or all); `n_pairs` draws that many at random (styles in turn, the same seed the same draw)."""
    styles = folder_takes(style_folder, split=split)
    contents = real_contents(styles, content_specs, max_frames)
    pairs = [(c, s) for c in contents for s in styles
             if not (c["source"] == s["source"] and c["clip_id"] == s["clip_id"])]
    if n_pairs is None or n_pairs >= len(pairs):
        return pairs
    if int(n_pairs) < 1:
        raise ValueError(f"--pairs: must be at least 1, got {n_pairs}")
    rng = np.random.default_rng([int(seed), 4243])
    by_style: dict = {}
    for k, (_, s) in enumerate(pairs):
        by_style.setdefault(s["style"], []).append(k)
    queues = [list(rng.permutation(by_style[name])) for name in sorted(by_style)]  # each style's pairs shuffled
    chosen = [q[j] for j in range(max(map(len, queues))) for q in queues if j < len(q)]  # styles in turn
    return [pairs[k] for k in chosen[:int(n_pairs)]]
