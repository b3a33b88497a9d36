"""torch Datasets over dataset folders (mslib/data/dataset_folder.py): any motion folder, content clips, style clips,
and the held-out benchmark pairs (content test clip, style test clip) drawn from a seed.

Items are dicts: "features" (T−1, 263) float32 — normalised with the folder's mean/std unless
`normalize=False` — "joints" (T, 22, 3) float32 when asked for, the clip id, content, caption, and
the labels a dataset exposes. Clips differ in length; `collate_motions` pads a batch and returns the
lengths and a mask, or `length=` crops every clip to a fixed number of feature frames.
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import torch
from torch.utils.data import Dataset

from .dataset_folder import read_labels, read_meta
from .styles import CONTENTS, STYLES, SUBSTYLES

SPLITS = ("train", "val", "test")
STYLE_INDEX = {s: i for i, s in enumerate(STYLES)}
CONTENT_INDEX = {c: i for i, c in enumerate(CONTENTS)}
SUBSTYLE_INDEX = {f"{s}/{ss}": i for i, (s, ss) in enumerate((s, ss) for s in STYLES for ss in SUBSTYLES[s])}


class MotionFolder(Dataset):
    """Clips of a dataset folder (optionally one split), loaded lazily and kept in memory.

    length: crop (or, for shorter clips, edge-pad) every clip to this many feature frames —
    a random crop when `random_crop` (seeded by `seed` and the item index), else centred.
    cache: keep loaded arrays in memory (the full content corpus takes about 250 MB).
    """

    def __init__(self, folder, split: str | None = None, normalize: bool = True, joints: bool = False,
                 length: int | None = None, random_crop: bool = False, seed: int = 0,
                 labels=("style", "substyle", "content", "caption"), cache: bool = True):
        self.folder = Path(folder)
        if split is not None and split not in SPLITS:
            raise ValueError(f"split: must be one of {SPLITS} or None, got {split!r}")
        if length is not None and int(length) < 1:
            raise ValueError(f"length: must be a positive number of frames, got {length}")
        self.meta = read_meta(self.folder)
        rows = read_labels(self.folder)
        self.rows = [r for r in rows if split is None or r["split"] == split]
        if not self.rows:
            raise ValueError(f"{self.folder}: no clips in split {split!r}")
        self.split, self.joints, self.length = split, joints, None if length is None else int(length)
        self.random_crop, self.seed, self.labels = random_crop, int(seed), tuple(labels)
        self.mean = np.load(self.folder / "mean.npy").astype(np.float32)
        self.std = np.load(self.folder / "std.npy").astype(np.float32)
        self.normalize, self.cache = normalize, cache
        self._cache: dict = {}

    def __len__(self) -> int:
        return len(self.rows)

    @property
    def clip_ids(self) -> list:
        return [r["clip_id"] for r in self.rows]

    def index_of(self, clip_id: str) -> int:
        """Position of a clip id in this dataset."""
        for i, r in enumerate(self.rows):
            if r["clip_id"] == clip_id:
                return i
        raise ValueError(f"clip_id: {clip_id!r} is not in {self.folder} (split {self.split!r})")

    def _arrays(self, i: int):
        cid = self.rows[i]["clip_id"]
        if cid in self._cache:
            return self._cache[cid]
        f = np.load(self.folder / "features" / f"{cid}.npy").astype(np.float32)
        j = np.load(self.folder / "joints" / f"{cid}.npy").astype(np.float32) if self.joints else None
        if self.cache:
            self._cache[cid] = (f, j)
        return f, j

    def _crop(self, i: int, f, j):
        if self.length is None:
            return f, j
        L, T = self.length, len(f)
        if T < L:  # pad by repeating the last frame (joints: one more frame than features)
            f = np.concatenate([f, np.repeat(f[-1:], L - T, 0)])
            j = None if j is None else np.concatenate([j, np.repeat(j[-1:], L - T, 0)])
            return f, j
        start = (int(np.random.default_rng([self.seed, i]).integers(T - L + 1)) if self.random_crop
                 else (T - L) // 2)
        return f[start:start + L], None if j is None else j[start:start + L + 1]

    def __getitem__(self, i: int) -> dict:
        if not -len(self) <= i < len(self):
            raise IndexError(f"index {i} out of range for {len(self)} clips")
        i = i % len(self)
        row = self.rows[i]
        f, j = self._arrays(i)
        f, j = self._crop(i, f, j)
        if self.normalize:
            f = (f - self.mean) / self.std
        item = {"features": torch.from_numpy(np.ascontiguousarray(f, np.float32)), "clip_id": row["clip_id"],
                "length": len(f)}
        if j is not None:
            item["joints"] = torch.from_numpy(np.ascontiguousarray(j, np.float32))
        for key in self.labels:
            item[key] = row.get(key, "")
        if "style" in self.labels and row.get("style") in STYLE_INDEX:
            item["style_index"] = STYLE_INDEX[row["style"]]
        if "substyle" in self.labels and f"{row.get('style')}/{row.get('substyle')}" in SUBSTYLE_INDEX:
            item["substyle_index"] = SUBSTYLE_INDEX[f"{row['style']}/{row['substyle']}"]
        if "content" in self.labels and row.get("content") in CONTENT_INDEX:
            item["content_index"] = CONTENT_INDEX[row["content"]]
        return item


class ContentClips(MotionFolder):
    """Content corpus clips: features, content and caption; style labels hidden unless asked for."""

    def __init__(self, folder, split: str | None = "train", with_style: bool = False, **kwargs):
        labels = ("content", "caption") + (("style", "substyle") if with_style else ())
        super().__init__(folder, split, labels=labels, **kwargs)


class StyleClips(MotionFolder):
    """Style corpus clips: features (and joints), style, sub-style and content labels, caption."""

    def __init__(self, folder, split: str | None = "train", **kwargs):
        kwargs.setdefault("joints", True)
        super().__init__(folder, split, labels=("style", "substyle", "content", "caption"), **kwargs)


def collate_motions(items: list) -> dict:
    """Pad a list of items to the longest clip: "features" (B, T, 263), "joints" (B, T+1, 22, 3),
    "lengths" (B,), "mask" (B, T) True on real frames; other keys become lists (or tensors of ints)."""
    if not items:
        raise ValueError("items: empty batch")
    lengths = torch.tensor([len(it["features"]) for it in items])
    T = int(lengths.max())
    out = {"lengths": lengths, "mask": torch.arange(T)[None] < lengths[:, None]}
    out["features"] = torch.stack([torch.cat([it["features"], it["features"][-1:].expand(T - len(it["features"]), -1)])
                                   for it in items])
    if "joints" in items[0]:
        out["joints"] = torch.stack([torch.cat([it["joints"], it["joints"][-1:].expand(
            T + 1 - len(it["joints"]), -1, -1)]) for it in items])
    for key in items[0]:
        if key in out or key in ("features", "joints", "length"):
            continue
        vals = [it[key] for it in items]
        out[key] = torch.tensor(vals) if isinstance(vals[0], int) else vals
    return out


# ---------------------------------------------------------------- benchmark pairs
def _split_rows(folder, split: str) -> list:
    if split not in SPLITS:
        raise ValueError(f"split: must be one of {SPLITS}, got {split!r}")
    rows = [r for r in read_labels(folder) if r["split"] == split]
    if not rows:
        raise ValueError(f"{folder}: has no {split} clips to draw pairs from")
    return sorted(rows, key=lambda r: r["clip_id"])


def benchmark_pairs(content_folder, style_folder, n_pairs: int = 500, seed: int = 0, split: str = "test") -> list:
    """A fixed draw of (content clip id, style clip id) pairs from one split (the benchmark: "test";
    design choices are tuned on "val"): styles in turn, clips at random; the same seed always gives
    the same pairs, another seed another draw."""
    if int(n_pairs) < 1:
        raise ValueError(f"n_pairs: must be at least 1, got {n_pairs}")
    content = [r["clip_id"] for r in _split_rows(content_folder, split)]
    by_style: dict = {}
    for r in _split_rows(style_folder, split):
        by_style.setdefault(r["style"], []).append(r["clip_id"])
    styles = [s for s in STYLES if s in by_style] + sorted(set(by_style) - set(STYLES))
    rng = np.random.default_rng([int(seed), 4242])
    pairs = []
    for k in range(int(n_pairs)):
        pool = by_style[styles[k % len(styles)]]
        pairs.append((content[int(rng.integers(len(content)))], pool[int(rng.integers(len(pool)))]))
    return pairs


def write_pairs(path, pairs) -> None:
    """pairs.csv: pair_id, content_clip, style_clip."""
    from ..fileio import atomic_write_bytes
    lines = ["pair_id,content_clip,style_clip"] + [f"{i},{c},{s}" for i, (c, s) in enumerate(pairs)]
    atomic_write_bytes(Path(path), ("\n".join(lines) + "\n").encode("utf-8"))


def read_pairs(path) -> list:
    """The (content_clip, style_clip) pairs of a pairs.csv."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no benchmark pairs file (build the corpora: python -m mslib data build)")
    with open(path, newline="", encoding="utf-8") as fh:
        return [(r["content_clip"], r["style_clip"]) for r in csv.DictReader(fh)]


class BenchmarkPairs(Dataset):
    """Held-out pairs: item k = {"content": content test item, "style": style test item, "pair": k}.

    pairs: explicit (content id, style id) pairs (e.g. `read_pairs`); default: a fresh draw of
    `n_pairs` from `seed` (`benchmark_pairs`)."""

    def __init__(self, content_folder, style_folder, n_pairs: int = 500, seed: int = 0, pairs=None,
                 split: str = "test", **kwargs):
        self.pairs = list(pairs) if pairs is not None else benchmark_pairs(content_folder, style_folder,
                                                                           n_pairs, seed, split)
        self.content = ContentClips(content_folder, split=split, with_style=True, **kwargs)
        self.style = StyleClips(style_folder, split=split, **kwargs)
        self._ci = {cid: i for i, cid in enumerate(self.content.clip_ids)}
        self._si = {cid: i for i, cid in enumerate(self.style.clip_ids)}
        missing = [p for p in self.pairs if p[0] not in self._ci or p[1] not in self._si]
        if missing:
            raise ValueError(f"pairs: {len(missing)} pair(s) name clips outside the {split} splits, e.g. {missing[0]}")

    def __len__(self) -> int:
        return len(self.pairs)

    def __getitem__(self, k: int) -> dict:
        c, s = self.pairs[k]
        return {"pair": k, "content": self.content[self._ci[c]], "style": self.style[self._si[s]]}
