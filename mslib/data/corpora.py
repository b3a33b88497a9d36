"""The built-in benchmark on disk: a content corpus, a style corpus with raw BVH takes, held-out pairs.

    BUILD/
      build.json          generator version, seed, sizes, counts, build seconds (written last)
      content/            dataset folder (mslib/data/dataset_folder.py): 20 fps, 2–10 s, every content, mild random
                          style (style labels kept for evaluation only), captions, 80/10/10 split
      style/              dataset folder: 32-frame windows (8-frame overlap) of the style takes at
                          20 fps, style + sub-style + content labels, captions naming the style,
                          split 70/15/15 by take (a take never spans two splits)
      style_bvh/          the raw takes: TAKE.bvh on the mocap skeleton (cm, 30 fps) + takes.csv
      pairs.csv           held-out benchmark pairs (content test clip, style test clip) of the seed

The style folder is loaded back from the BVH files through the real registration pipeline
(retarget.py: resample 30 → 20 fps, rescale to the reference body, floor, origin, facing +Z), as a
real mocap set would be (A §4.1); the generator's own template motion is only used to test it.

Caching: `build_corpora()` with no `out_dir` builds into `MSLIB_CACHE` (default ~/.cache/mslib) as
`builtin-v{GENERATOR_VERSION}-{fingerprint}-seed{S}`, the fingerprint hashing the source of every
module that shapes the data, so an edited generator never reuses a stale build. A build happens in a temporary
folder renamed into place at the end, under a lock file, so concurrent builders neither collide
nor leave half-written corpora. Every clip is a pure function of (seed, index), so the work is
split over a process pool without changing a single number.
"""
from __future__ import annotations

import csv
import io
import json
import os
import shutil
import time
import uuid
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ..fileio import atomic_write_bytes
from .dataset_folder import write_csv, write_labels, write_meta
from .batch_features import encode_many
from .styles import CONTENTS, STYLE_CONTENTS, STYLES, SUBSTYLES
from .retarget import canonicalize, window_starts
from .synth import GENERATOR_VERSION, generate_clips

DEFAULT_SIZES = {"n_content": 2000, "takes_per_group": 10, "n_pairs": 500}
CONTENT_FPS, TAKE_FPS = 20.0, 30.0
WINDOW, STRIDE = 32, 24  # 32-frame windows with 8 frames of overlap (A §4.1)
TAKE_DURATION = (5.0, 8.0)  # seconds
CONTENT_INTENSITY = (0.0, 0.5)  # "mild random style"
EXTRA_COLUMNS = ("take", "seed", "index", "intensity", "start_frame")  # after the §8 columns
_TAKE_INDEX = 1_000_000  # takes draw from other generator streams than content clips


# ---------------------------------------------------------------- where
def source_fingerprint() -> str:
    """8 hex digits hashing the source of every module the built data depends on (and the fitted styles)."""
    import hashlib
    here = Path(__file__).resolve().parent
    files = sorted(here.glob("*.py")) + sorted(here.glob("*.json")) + [here.parent / "motion" / n for n in
                                         ("features.py", "skeleton.py", "rotations.py", "bvh.py")]
    h = hashlib.sha256()
    for f in files:
        if f.name not in ("datasets.py", "__init__.py"):
            h.update(f.name.encode() + b"\0" + f.read_bytes())
    return h.hexdigest()[:8]



def cache_root() -> Path:
    """The cache folder: $MSLIB_CACHE, else ~/.cache/mslib."""
    env = os.environ.get("MSLIB_CACHE")
    return Path(env).expanduser() if env else Path.home() / ".cache" / "mslib"


def _sizes(n_content, takes_per_group, n_pairs) -> dict:
    sizes = {"n_content": int(n_content), "takes_per_group": int(takes_per_group), "n_pairs": int(n_pairs)}
    if sizes["n_content"] < 10:
        raise ValueError(f"n_content: need at least 10 clips (one per content), got {n_content}")
    if sizes["takes_per_group"] < 2:
        raise ValueError(f"takes_per_group: need at least 2 takes per style and content, got {takes_per_group}")
    if sizes["n_pairs"] < 1:
        raise ValueError(f"n_pairs: must be at least 1, got {n_pairs}")
    return sizes


def default_dir(seed: int = 0, **sizes) -> Path:
    """The cache folder of a build: builtin-v{version}-seed{seed}[-sizes if not the defaults]."""
    s = _sizes(**{**DEFAULT_SIZES, **sizes})
    name = f"builtin-v{GENERATOR_VERSION}-{source_fingerprint()}-seed{int(seed)}"
    if s != DEFAULT_SIZES:
        name += f"-c{s['n_content']}-t{s['takes_per_group']}-p{s['n_pairs']}"
    return cache_root() / name


# ---------------------------------------------------------------- what
def content_plan(seed: int, n_content: int) -> list:
    """One spec per content clip: contents in turn, a random style at a mild intensity, a split."""
    order = np.random.default_rng([seed, 77]).permutation(n_content)
    split = np.empty(n_content, dtype=object)
    n_val = n_test = max(1, int(round(0.1 * n_content)))
    split[order[:n_test]], split[order[n_test:n_test + n_val]] = "test", "val"
    split[order[n_test + n_val:]] = "train"
    plan = []
    for i in range(n_content):
        rng = np.random.default_rng([seed, i, 101])
        style = STYLES[int(rng.integers(len(STYLES)))]
        plan.append(dict(clip_id=f"c{i:05d}", content=CONTENTS[i % len(CONTENTS)], style=style,
                         intensity=float(rng.uniform(*CONTENT_INTENSITY)), seed=seed, index=i,
                         split=str(split[i])))
    return plan


def take_plan(seed: int, takes_per_group: int) -> list:
    """One spec per style take: every style × Xia content, sub-styles in turn, split by take."""
    plan, k = [], takes_per_group
    for si, style in enumerate(STYLES):
        subs = SUBSTYLES[style]
        for ci, content in enumerate(STYLE_CONTENTS):
            g = si * len(STYLE_CONTENTS) + ci
            # ≈15 % test and val per group; the odd take alternates between them across groups
            n_test = int(np.floor(0.15 * k + (0.5 if g % 2 == 0 else 0.0)))
            n_val = int(np.floor(0.15 * k + (0.0 if g % 2 == 0 else 0.5)))
            if n_test + n_val == 0:
                n_test, n_val = (1, 0) if g % 2 == 0 else (0, 1)
            n_val = min(n_val, k - 1 - n_test)
            order = np.random.default_rng([seed, g, 78]).permutation(k)
            split = {int(j): ("test" if r < n_test else "val" if r < n_test + n_val else "train")
                     for r, j in enumerate(order)}
            for rep in range(k):
                j = g * k + rep
                rng = np.random.default_rng([seed, j, 202])
                plan.append(dict(take=f"t{j:04d}_{style}_{content}", content=content, style=style,
                                 substyle=subs[(rep + ci) % len(subs)], seed=seed, index=_TAKE_INDEX + j,
                                 split=split[rep], duration=float(rng.uniform(*TAKE_DURATION))))
    return plan


# ---------------------------------------------------------------- work (runs in pool workers)
class _Stats:
    """Running sums for the train split's mean and std over feature frames."""

    def __init__(self):
        self.n, self.s1, self.s2 = 0, np.zeros(263), np.zeros(263)

    def add(self, f):
        f = np.asarray(f, np.float64)
        self.n += len(f)
        self.s1 += f.sum(0)
        self.s2 += (f * f).sum(0)

    def merge(self, other):
        self.n += other.n
        self.s1 += other.s1
        self.s2 += other.s2


def _save(path: Path, array):
    np.save(path, np.asarray(array, np.float32))


def _content_chunk(root: str, specs: list):
    """Generate, encode and write a chunk of content clips; label rows and train stats back."""
    root = Path(root)
    clips = generate_clips([dict(content=s["content"], style=s["style"], seed=s["seed"],
                                 index=s["index"], fps=CONTENT_FPS, intensity=s["intensity"])
                            for s in specs])
    feats = encode_many([c.positions for c in clips])
    rows, stats = [], _Stats()
    for s, c, f in zip(specs, clips, feats):
        _save(root / "content" / "joints" / f"{s['clip_id']}.npy", c.positions)
        _save(root / "content" / "features" / f"{s['clip_id']}.npy", f)
        if s["split"] == "train":
            stats.add(f)
        rows.append({"clip_id": s["clip_id"], "split": s["split"], "style": s["style"],
                     "substyle": c.meta["substyle"], "content": s["content"], "caption": c.meta["caption"],
                     "n_frames": c.n_frames, "source_file": "", "take": s["clip_id"], "seed": s["seed"],
                     "index": s["index"], "intensity": f"{s['intensity']:.3f}", "start_frame": 0})
    return "content", rows, stats, sum(c.n_frames for c in clips)


def window_id(take: str, k: int) -> str:
    """The clip id of a take's k-th window: `t0350_strutting_walk_w02`."""
    return f"{take}_w{k:02d}"


def take_of(clip_id: str) -> str:
    """The take a style clip was cut from (`window_id` undone); an id without a window suffix is its own take."""
    take, sep, k = clip_id.rpartition("_w")
    return take if sep and k.isdigit() else clip_id


def _take_chunk(root: str, specs: list):
    """Generate takes at 30 fps, write their BVH files, cut 20 fps windows, encode and write them."""
    from ..motion.bvh import write_bvh
    from .mocap_skeleton import to_bvh_motion
    root = Path(root)
    takes = generate_clips([dict(content=s["content"], style=s["style"], substyle=s["substyle"],
                                 seed=s["seed"], index=s["index"], fps=TAKE_FPS, duration=s["duration"],
                                 canonical=False) for s in specs])
    from ..motion.bvh import read_bvh
    from .retarget import register_motion
    windows, rows, take_rows = [], [], []
    for s, take in zip(specs, takes):
        bvh_path = root / "style_bvh" / f"{s['take']}.bvh"
        write_bvh(bvh_path, to_bvh_motion(take.rotations, take.root, take.skeleton))
        registered = register_motion(read_bvh(bvh_path), "builtin", source=bvh_path.name).positions
        cap = take.meta["style_caption"]
        take_rows.append({"take": s["take"], "file": f"{s['take']}.bvh", "split": s["split"],
                          "style": s["style"], "substyle": s["substyle"], "content": s["content"],
                          "caption": cap, "n_frames": take.n_frames, "fps": TAKE_FPS,
                          "seed": s["seed"], "index": s["index"]})
        for k, start in enumerate(window_starts(len(registered), WINDOW, WINDOW - STRIDE)):
            clip_id = window_id(s["take"], k)
            windows.append(canonicalize(registered[start:start + WINDOW], floor=False))
            rows.append({"clip_id": clip_id, "split": s["split"], "style": s["style"],
                         "substyle": s["substyle"], "content": s["content"], "caption": cap,
                         "n_frames": WINDOW, "source_file": f"style_bvh/{s['take']}.bvh", "take": s["take"],
                         "seed": s["seed"], "index": s["index"], "intensity": "1.000", "start_frame": start})
    feats = encode_many(windows, bucket=WINDOW)
    stats = _Stats()
    for r, w, f in zip(rows, windows, feats):
        _save(root / "style" / "joints" / f"{r['clip_id']}.npy", w)
        _save(root / "style" / "features" / f"{r['clip_id']}.npy", f)
        if r["split"] == "train":
            stats.add(f)
    return "style", (rows, take_rows), stats, sum(t.n_frames for t in takes)


# ---------------------------------------------------------------- writing folders
def _finish_folder(folder: Path, name: str, rows: list, stats: _Stats, seed: int, **meta) -> dict:
    """labels.csv, mean.npy/std.npy of the train split, meta.json."""
    from ..motion.features import Normalizer, block_averaged_std
    rows = sorted(rows, key=lambda r: r["clip_id"])
    write_labels(folder, rows, EXTRA_COLUMNS)
    mean = stats.s1 / max(stats.n, 1)
    std = np.sqrt(np.maximum(stats.s2 / max(stats.n, 1) - mean ** 2, 0.0))
    Normalizer(mean, block_averaged_std(std)).save(folder)
    splits = {s: sum(r["split"] == s for r in rows) for s in ("train", "val", "test")}
    info = {"name": name, "fps": 20, "skeleton": "humanml3d-22", "format_version": 1,
            "source": f"mslib built-in stylized mocap, generator v{GENERATOR_VERSION}, seed {seed}",
            "generator_version": GENERATOR_VERSION, "seed": seed, "n_clips": len(rows), "splits": splits,
            "styles": list(STYLES), "substyles": {k: list(v) for k, v in SUBSTYLES.items()}, **meta}
    write_meta(folder, info)
    return info


def _chunks(items, size):
    return [items[i:i + size] for i in range(0, len(items), size)]


def _pool_context():
    """fork on Linux (instant: the parent's imports are shared), spawn elsewhere (the safe default)."""
    import multiprocessing as mp
    import sys
    return mp.get_context("fork" if sys.platform.startswith("linux") else "spawn")


def _run(root: Path, seed: int, sizes: dict, workers: int, progress: bool) -> dict:
    """Build everything into `root` (an empty folder)."""
    for sub in ("content/joints", "content/features", "style/joints", "style/features", "style_bvh"):
        (root / sub).mkdir(parents=True, exist_ok=True)
    cplan = content_plan(seed, sizes["n_content"])
    tplan = take_plan(seed, sizes["takes_per_group"])
    jobs = [(_take_chunk, c) for c in _chunks(tplan, 8)] + [(_content_chunk, c) for c in _chunks(cplan, 40)]
    content_rows, style_rows, take_rows = [], [], []
    cstats, sstats = _Stats(), _Stats()
    frames = {"content": 0, "style": 0}
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=len(cplan) + len(tplan), desc="built-in corpora", unit="clip")

    def collect(out, n):
        kind, rows, stats, nf = out
        frames[kind] += nf
        if kind == "content":
            content_rows.extend(rows)
            cstats.merge(stats)
        else:
            style_rows.extend(rows[0])
            take_rows.extend(rows[1])
            sstats.merge(stats)
        if bar is not None:
            bar.update(n)

    if workers > 1:
        with ProcessPoolExecutor(max_workers=workers, mp_context=_pool_context()) as pool:
            futures = [(pool.submit(fn, str(root), chunk), len(chunk)) for fn, chunk in jobs]
            for fut, n in futures:
                collect(fut.result(), n)
    else:
        for fn, chunk in jobs:
            collect(fn(str(root), chunk), len(chunk))
    if bar is not None:
        bar.close()

    cinfo = _finish_folder(root / "content", "builtin-content", content_rows, cstats, seed,
                           contents=list(CONTENTS), style_labels="for evaluation only")
    sinfo = _finish_folder(root / "style", "builtin-style", style_rows, sstats, seed,
                           contents=list(STYLE_CONTENTS), window=WINDOW, overlap=WINDOW - STRIDE,
                           takes=len(take_rows), raw="../style_bvh (mocap skeleton, cm, 30 fps)")
    write_csv(root / "style_bvh" / "takes.csv", sorted(take_rows, key=lambda r: r["take"]),
               ("take", "file", "split", "style", "substyle", "content", "caption", "n_frames", "fps",
                "seed", "index"))
    from .datasets import benchmark_pairs, write_pairs
    pairs = benchmark_pairs(root / "content", root / "style", n_pairs=sizes["n_pairs"], seed=seed)
    write_pairs(root / "pairs.csv", pairs)
    return {"content_clips": cinfo["n_clips"], "content_splits": cinfo["splits"],
            "content_frames": frames["content"], "style_takes": len(take_rows),
            "style_clips": sinfo["n_clips"], "style_splits": sinfo["splits"],
            "style_take_frames_30fps": frames["style"], "bvh_files": len(take_rows), "pairs": len(pairs)}


# ---------------------------------------------------------------- cache and locking
def _complete(folder: Path, seed: int, sizes: dict):
    """The build.json of a complete, current build in `folder`, else None."""
    try:
        info = json.loads((folder / "build.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    ok = (info.get("generator_version") == GENERATOR_VERSION and info.get("fingerprint") == source_fingerprint()
          and info.get("seed") == seed
          and info.get("sizes") == sizes)
    return info if ok else None


@contextmanager
def _lock(path: Path):
    """An exclusive advisory lock on `path` (POSIX); elsewhere the final rename decides."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a+") as fh:
        try:
            import fcntl
            fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        except ImportError:  # Windows: no flock; concurrent builders race and the first rename wins
            pass
        yield


def build_corpora(out_dir=None, seed: int = 0, force: bool = False, progress: bool = True,
                  n_content: int = DEFAULT_SIZES["n_content"],
                  takes_per_group: int = DEFAULT_SIZES["takes_per_group"],
                  n_pairs: int = DEFAULT_SIZES["n_pairs"], workers: int = 2) -> dict:
    """Build (or reuse) the built-in corpora; returns counts, the folder and the build seconds.

    out_dir: where to build (default: the cache, see `default_dir`); a complete build of the same
    generator version, seed and sizes there is reused unless `force`. workers: processes to use.
    """
    if int(seed) < 0:
        raise ValueError(f"seed: must be non-negative, got {seed}")
    if int(workers) < 1:
        raise ValueError(f"workers: must be at least 1, got {workers}")
    seed, sizes = int(seed), _sizes(n_content, takes_per_group, n_pairs)
    out = Path(out_dir).expanduser() if out_dir is not None else default_dir(seed, **sizes)
    if out.exists() and not out.is_dir():
        raise ValueError(f"out_dir: {out} exists and is not a folder")
    if out.is_dir() and not force and _complete(out, seed, sizes) is None and any(out.iterdir()):
        raise ValueError(f"out_dir: {out} is not empty and holds no built-in corpora of generator "
                         f"v{GENERATOR_VERSION}, seed {seed} and these sizes; pass force=True (--force) "
                         "to replace it")
    with _lock(out.parent / f".{out.name}.lock"):
        info = None if force else _complete(out, seed, sizes)
        if info is not None:
            return _summary(out, info, cached=True)
        tmp = out.parent / f".{out.name}.tmp-{os.getpid()}-{uuid.uuid4().hex[:8]}"
        start = time.perf_counter()
        try:
            tmp.mkdir(parents=True)
            counts = _run(tmp, seed, sizes, int(workers), progress)
            info = {"generator_version": GENERATOR_VERSION, "fingerprint": source_fingerprint(),
                    "seed": seed, "sizes": sizes,
                    "build_seconds": round(time.perf_counter() - start, 2), "workers": int(workers), **counts}
            atomic_write_bytes(tmp / "build.json", json.dumps(info, indent=2, sort_keys=True).encode())
            _move_into_place(tmp, out)
        finally:
            if tmp.exists():
                shutil.rmtree(tmp, ignore_errors=True)
    return _summary(out, info, cached=False)


def _move_into_place(tmp: Path, out: Path) -> None:
    """Rename the finished build onto `out`, replacing an old one; a concurrent winner is kept."""
    old = None
    if out.exists():
        old = out.parent / f".{out.name}.old-{uuid.uuid4().hex[:8]}"
        os.rename(out, old)
    try:
        os.rename(tmp, out)
    except OSError:
        if not out.exists():
            raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def _summary(out: Path, info: dict, cached: bool) -> dict:
    keys = ("content_clips", "content_splits", "content_frames", "style_takes", "style_clips",
            "style_splits", "style_take_frames_30fps", "bvh_files", "pairs", "build_seconds", "workers")
    return {"out_dir": str(out), "seed": info["seed"], "generator_version": info["generator_version"],
            "cached": cached, **{k: info[k] for k in keys if k in info}}


def load_builtin(seed: int = 0, progress: bool = True, **sizes) -> dict:
    """Paths of the built-in corpora of a seed (built into the cache first if needed):
    {"root", "content", "style", "style_bvh", "pairs"}."""
    summary = build_corpora(None, seed=seed, progress=progress, **sizes)
    root = Path(summary["out_dir"])
    return {"root": root, "content": root / "content", "style": root / "style",
            "style_bvh": root / "style_bvh", "pairs": root / "pairs.csv"}
