"""`python -m mslib transfer`: one (content, style) pair through a registered method, written to a file.

Inputs (`load_motion`): a built-in clip id (content or style corpus), a .npy of 263-d features
((T−1)×263) or of joint positions (T×22×3), or a BVH file registered onto the template body
(data/retarget.py, joint map by dialect). Each becomes the dict the methods take (bench.py):
"features" ((T−1)×263, unnormalised, float64), "joints" (T×22×3, metres) and the labels of a dataset
item ("clip_id", "content", "caption", "style", "substyle"; empty strings where a file has none).
The output kind follows OUT's extension:
- .bvh — the HumanML3D template tree with rotations solved from the positions (motion/ik.py),
  lengths in metres (Blender's BVH import at scale 1 gives a life-size armature), 20 fps;
- .npy — the 263-d HumanML3D vector ((T−1)×263, float32);
- .gif — a stick-figure animation (viz.animate, written with pillow);
- .html — the 3-D viewer (viz.viewer_html) as one self-contained page: content, output and style side by
  side, to orbit, zoom, play and scrub offline (no server, nothing from the network).
Writes are atomic and refuse an existing OUT unless `force`.
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from ..data.retarget import canonicalize, register_bvh
from ..fileio import atomic_save_npy, atomic_write_bytes, check_writable, load_npy
from ..motion import features as F
from ..motion.bvh import write_bvh
from ..motion.ik import fit_error, positions_to_bvh
from .bench import get_method, positions

OUTPUT_KINDS = (".bvh", ".npy", ".gif", ".html")
FPS = 20.0
GIF_MAX_FRAMES = 100  # longer outputs are subsampled in time
GIF_DPI = 90


# ---------------------------------------------------------------- inputs
LABELS = ("content", "caption", "style", "substyle")
INPUT_KINDS = (".npy", ".bvh")


def _item(features, joints, clip_id: str, source: str, **labels) -> dict:
    item = {"features": np.asarray(features, np.float64), "joints": np.asarray(joints, np.float64),
            "clip_id": clip_id, "source": source}
    item.update({k: labels.get(k, "") for k in LABELS})
    return item


def builtin_folders(seed: int = 0) -> dict:
    """The built-in content and style dataset folders (built into the cache on first use)."""
    from ..data.corpora import load_builtin
    paths = load_builtin(seed=seed, progress=False)
    return {"content": paths["content"], "style": paths["style"]}


def find_clip(clip_id: str, folders: dict, arg: str = "clip") -> tuple:
    """(folder, labels row) of a clip id in the first folder that has it; a ValueError says how to list ids."""
    from ..data.dataset_folder import read_labels
    for folder in folders.values():
        for row in read_labels(folder):
            if row["clip_id"] == clip_id:
                return Path(folder), row
    where = " and ".join(f"{Path(f) / 'labels.csv'} (column clip_id)" for f in folders.values())
    raise ValueError(f"{arg} {clip_id!r} is not a file, nor a clip id of the built-in corpora "
                     f"({', '.join(folders)}); content ids look like c00000, style ids like "
                     f"t0000_neutral_walk_w00 — every id is listed in {where}")


def load_clip(clip_id: str, folders: dict | None = None, arg: str = "clip") -> dict:
    """A clip of a dataset folder by id (default: the built-in content, then style, corpus)."""
    folder, row = find_clip(clip_id, folders or builtin_folders(), arg)
    features = load_npy(folder / "features" / f"{clip_id}.npy", arg)
    joints = load_npy(folder / "joints" / f"{clip_id}.npy", arg)
    return _item(features, joints, clip_id, str(folder), **{k: row[k] for k in LABELS if k in row})


def load_npy_motion(path, arg: str = "motion") -> dict:
    """A .npy of 263-d features ((T−1)×263) or of joint positions (T×22×3, metres, Y up)."""
    path = Path(path)
    data = load_npy(path, arg)
    if data.ndim == 2 and data.shape[1] == F.N_FEATURES:
        features = F.check_features(data.astype(np.float64), f"{arg} {path}")
        if len(features) < 2:
            raise ValueError(f"{arg} {path}: need at least 2 feature frames, got {len(features)}")
        joints = F.decode(features)  # (N, 22, 3): keep N − 1 rows, so that T positions go with T − 1 rows
        features = features[:-1]
    elif data.ndim == 3 and data.shape[1:] == (F.N_JOINTS, 3):
        # canonical frame (floor, origin, facing +Z) so that features and joints describe one motion
        joints = canonicalize(F.check_positions(data, f"{arg} {path}"))
        features = F.encode(joints).astype(np.float64)
    else:
        raise ValueError(f"{arg} {path}: expected 263-d features (T-1, {F.N_FEATURES}) or joint positions "
                         f"(T, {F.N_JOINTS}, 3), got an array of shape {data.shape}")
    return _item(features, joints, path.stem, str(path))


def load_bvh_motion(path, arg: str = "motion", dialect="auto") -> dict:
    """A BVH file registered onto the template body (retarget.register_bvh: 20 fps, canonical frame)."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{arg} {path}: no such file")
    try:
        reg = register_bvh(path, dialect=dialect)
    except ValueError as e:
        raise ValueError(f"{arg} {e}") from None
    return _item(reg.features, reg.positions, path.stem, str(path))


def load_motion(spec, arg: str = "motion", dialect="auto", folders: dict | None = None) -> dict:
    """A motion from a clip id, a .npy (features or positions) or a .bvh path; `arg` names it in errors."""
    spec = str(spec)
    path = Path(spec)
    suffix = path.suffix.lower()
    if suffix == ".npy":
        return load_npy_motion(path, arg)
    if suffix == ".bvh":
        return load_bvh_motion(path, arg, dialect)
    if path.exists() or suffix or "/" in spec or "\\" in spec:
        raise ValueError(f"{arg} {spec!r}: expected a built-in clip id or a file ending in "
                         f"{' or '.join(INPUT_KINDS)}" + ("" if path.exists() else " (no such file)"))
    return load_clip(spec, folders, arg)


# ---------------------------------------------------------------- outputs


def check_output(out, force: bool = False, arg: str = "--out") -> Path:
    """OUT's extension is one we write, and it does not exist unless `force`."""
    out = Path(out)
    if out.suffix.lower() not in OUTPUT_KINDS:
        raise ValueError(f"{arg} {out}: unknown output kind {out.suffix or '(no extension)'!r}; "
                         f"end the name in {', '.join(OUTPUT_KINDS)}")
    if out.is_dir():
        raise ValueError(f"{arg} {out}: is a directory")
    return check_writable(out, force, arg)


def save_gif(path, positions, fps: float = FPS, title: str | None = None) -> Path:
    """A stick-figure animation of positions (T, 22, 3) as an animated GIF, written atomically."""
    from matplotlib.animation import PillowWriter

    from ..viz import animate
    anim = animate([positions], titles=[title] if title else None, fps=fps, max_frames=GIF_MAX_FRAMES,
                   dpi=GIF_DPI, panel_size=4.0)
    step = int(np.ceil(len(positions) / GIF_MAX_FRAMES))
    with tempfile.TemporaryDirectory() as tmp:
        tmp_gif = Path(tmp) / "anim.gif"
        anim.save(tmp_gif, writer=PillowWriter(fps=fps / step))
        atomic_write_bytes(Path(path), tmp_gif.read_bytes())
    return Path(path)


def save_html(path, positions, title: str | None = None, inputs=()) -> Path:
    """The 3-D viewer page of positions (T, 22, 3), with `inputs` ((title, positions) of the content and the
    style) on either side of it, written atomically."""
    from ..viz import viewer_html
    shown = [(title or "output", positions)]
    if len(inputs) == 2:
        shown = [inputs[0], shown[0], inputs[1]]
    page = viewer_html([m for _, m in shown], titles=[t for t, _ in shown], fps=FPS,
                       page_title=" · ".join(t for t, _ in shown))
    atomic_write_bytes(Path(path), page.encode("utf-8"))
    return Path(path)


def save_motion(out, positions, force: bool = False, arg: str = "--out", title: str | None = None,
                features=None, inputs=()) -> dict:
    """Write positions (T, 22, 3) as .bvh, .npy (263-d: `features` when given, else encoded from the
    positions), .gif or .html (with `inputs`, the (title, positions) of content and style, beside it) by
    OUT's extension; returns facts about the file (for .bvh the largest joint error of its forward
    kinematics, in cm)."""
    out = check_output(out, force, arg)
    p = F.check_positions(positions, "the method's output")
    kind = out.suffix.lower()
    info = {"out": str(out), "kind": kind[1:], "frames": int(len(p))}
    if kind == ".bvh":
        motion = positions_to_bvh(p, fps=FPS, units="m")
        write_bvh(out, motion, overwrite=True)  # check_output has already refused unforced overwrites
        info.update(units="m", bvh_fit_error_cm=round(100 * fit_error(motion, p), 4))
    elif kind == ".npy":
        vector = F.encode(p) if features is None else np.asarray(features, np.float32)
        atomic_save_npy(out, vector, force=True, arg=arg)
        info["shape"] = list(vector.shape)
    elif kind == ".html":
        save_html(out, p, title=title, inputs=inputs)
    else:
        save_gif(out, p, title=title)
    return info


def run_transfer(method: str, content, style, out, force: bool = False, device: str = "cpu",
                 dialect="auto") -> dict:
    """Load both motions, transfer with `method`, write OUT; returns a JSON-able summary."""
    check_output(out, force)  # fail before any work
    transfer = get_method(method, device)
    c = load_motion(content, "--content", dialect)
    s = load_motion(style, "--style", dialect)
    t0 = time.perf_counter()
    features = np.asarray(transfer(c, s))
    seconds = time.perf_counter() - t0
    if features.ndim != 2 or features.shape[1] != F.N_FEATURES:
        raise ValueError(f"--method {method!r}: returned shape {features.shape}, expected (T−1, {F.N_FEATURES}) features")
    result = np.asarray(positions(features), np.float64)
    inputs = ((f"content {c['clip_id']}", c["joints"]), (f"style {s['clip_id']}", s["joints"]))
    info = save_motion(out, result, force, title=method, features=features, inputs=inputs)
    return {"method": method, "content": c["clip_id"], "style": s["clip_id"],
            "content_frames": int(len(c["joints"])), "style_frames": int(len(s["joints"])),
            "transfer_ms": round(1000 * seconds, 3), **info}
