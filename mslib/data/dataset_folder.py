"""The dataset-folder format: what data_prep writes and every loader reads.

    DATASET/
      meta.json            {"name", "fps": 20, "skeleton": "humanml3d-22", "format_version", "source", ...}
      labels.csv           clip_id,split,style,substyle,content,caption,n_frames,source_file
      joints/CLIP.npy      T×22×3 float32, metres, Y up, the template body
      features/CLIP.npy    (T−1)×263 float32, unnormalised HumanML3D vector
      mean.npy, std.npy    263-d statistics of the train split (per-block averaged std)
"""
from __future__ import annotations

import csv
import json
import os
from pathlib import Path

import numpy as np

from ..fileio import atomic_save_npy, atomic_write_bytes
from ..motion.features import Normalizer

FORMAT_VERSION = 1
LABEL_COLUMNS = ("clip_id", "split", "style", "substyle", "content", "caption", "n_frames", "source_file")
SPLITS = ("train", "val", "test")


def split_for(key: str, fractions=(0.7, 0.15, 0.15)) -> str:
    """A stable train/val/test split from a key (e.g. a take name): same key, same split, anywhere."""
    import zlib
    u = (zlib.crc32(key.encode("utf-8")) % 10_000) / 10_000
    return SPLITS[0] if u < fractions[0] else SPLITS[1] if u < fractions[0] + fractions[1] else SPLITS[2]


class DatasetWriter:
    """Writes clips into a dataset folder one at a time; `close()` writes labels, stats and meta."""

    def __init__(self, folder, name: str, source: str, force: bool = False, **meta):
        self.folder = Path(folder)
        if self.folder.exists() and any(self.folder.iterdir()) and not force:
            raise ValueError(f"OUT_DIR {self.folder} is not empty; pass --force to add to it or overwrite it")
        (self.folder / "joints").mkdir(parents=True, exist_ok=True)
        (self.folder / "features").mkdir(parents=True, exist_ok=True)
        self.meta = {"name": name, "fps": 20, "skeleton": "humanml3d-22", "format_version": FORMAT_VERSION,
                     "source": source, **meta}
        self.rows = {}
        labels = self.folder / "labels.csv"
        if labels.is_file():  # resuming: keep the clips already converted
            self.rows = {r["clip_id"]: r for r in read_labels(self.folder)}

    def has(self, clip_id: str) -> bool:
        """True when the clip's files and label row already exist (a resumed run skips it)."""
        return clip_id in self.rows and (self.folder / "features" / f"{clip_id}.npy").is_file()

    def add(self, clip_id: str, joints, features, split: str, **labels) -> None:
        """Write one clip's arrays (atomically) and remember its label row."""
        if split not in SPLITS:
            raise ValueError(f"split: expected one of {SPLITS}, got {split!r}")
        joints = np.asarray(joints, np.float32)
        features = np.asarray(features, np.float32)
        if joints.ndim != 3 or joints.shape[1:] != (22, 3) or features.shape != (len(joints) - 1, 263):
            raise ValueError(f"clip {clip_id}: joints {joints.shape} and features {features.shape} do not "
                             "fit T×22×3 and (T−1)×263")
        atomic_save_npy(self.folder / "joints" / f"{clip_id}.npy", joints, force=True)
        atomic_save_npy(self.folder / "features" / f"{clip_id}.npy", features, force=True)
        row = {c: "" for c in LABEL_COLUMNS}
        row.update({k: ("" if v is None else str(v)) for k, v in labels.items() if k in LABEL_COLUMNS})
        row.update(clip_id=clip_id, split=split, n_frames=str(len(joints)))
        self.rows[clip_id] = row

    def close(self) -> dict:
        """Write labels.csv, mean/std of the train split and meta.json; return the meta."""
        rows = [self.rows[k] for k in sorted(self.rows)]
        write_labels(self.folder, rows)
        train = [r["clip_id"] for r in rows if r["split"] == "train"] or [r["clip_id"] for r in rows]
        if train:
            norm = Normalizer.fit([np.load(self.folder / "features" / f"{c}.npy") for c in train])
            norm.save(self.folder)
        counts = {s: sum(r["split"] == s for r in rows) for s in SPLITS}
        self.meta.update(n_clips=len(rows), splits=counts)
        write_meta(self.folder, self.meta)
        return dict(self.meta)


def write_labels(folder, rows, extra_columns=()) -> None:
    """labels.csv from a list of dicts (the §8 columns, then any extra ones), atomically."""
    write_csv(Path(folder) / "labels.csv", rows, LABEL_COLUMNS + tuple(extra_columns))


def write_csv(path, rows, columns) -> None:
    """A CSV of dicts with the given columns (missing values empty, others ignored), atomically."""
    import io
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(columns), lineterminator="\n", extrasaction="ignore")
    writer.writeheader()
    writer.writerows([{c: r.get(c, "") for c in columns} for r in rows])
    atomic_write_bytes(Path(path), buf.getvalue().encode("utf-8"))


def write_meta(folder, meta: dict) -> None:
    """meta.json, atomically."""
    atomic_write_bytes(Path(folder) / "meta.json", json.dumps(meta, indent=2, sort_keys=True).encode())


def read_labels(folder) -> list:
    """The rows of a dataset folder's labels.csv as dicts (a ValueError names a malformed file)."""
    path = Path(folder) / "labels.csv"
    if not path.is_file():
        raise ValueError(f"{folder}: not a dataset folder (no labels.csv); see mslib/data/dataset_folder.py or data_prep/README.md")
    with open(path, newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        missing = [c for c in LABEL_COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(f"{path}: missing columns {missing}")
        return list(reader)


def read_meta(folder) -> dict:
    """meta.json of a dataset folder, checked for the format version."""
    path = Path(folder) / "meta.json"
    if not path.is_file():
        raise ValueError(f"{folder}: not a dataset folder (no meta.json)")
    meta = json.loads(path.read_text(encoding="utf-8"))
    if meta.get("format_version") != FORMAT_VERSION:
        raise ValueError(f"{path}: format_version {meta.get('format_version')!r}, this mslib reads "
                         f"{FORMAT_VERSION}; re-run the data_prep command that made it")
    return meta


def folder_is_empty(folder) -> bool:
    """True when a folder is missing or has no entries."""
    folder = Path(folder)
    return not folder.exists() or not any(os.scandir(folder))
