"""Index a real HumanML3D folder into a dataset folder (mslib/data/dataset_folder.py), linking instead of copying.

    python -m data_prep.humanml3d HUMANML3D_DIR OUT_DIR [--force] [--copy]

HUMANML3D_DIR is the release layout: new_joint_vecs/ID.npy (T×263), new_joints/ID.npy (T×22×3),
texts/ID.txt (captions, 'sentence#tokens#start#end' per line), train.txt/val.txt/test.txt and
Mean.npy/Std.npy. Arrays are symbolic links (or copies with --copy). Note: in the release the
positions are the decoding of the vector, so both have T rows (meta.json says so).
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import time
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from mslib.data.dataset_folder import FORMAT_VERSION, folder_is_empty, write_labels, write_meta

WHERE = ("HumanML3D is not downloadable from here: build it with the scripts of "
         "github.com/EricGuo5513/HumanML3D (AMASS + HumanAct12), then point this command at its folder.")


def first_caption(text_file: Path) -> str:
    """The first sentence of a HumanML3D texts/ID.txt file ('' when missing)."""
    if not text_file.is_file():
        return ""
    line = text_file.read_text(encoding="utf-8", errors="replace").splitlines()[:1]
    return line[0].split("#")[0].strip().replace(",", " ") if line else ""


def link_or_copy(src: Path, dst: Path, copy: bool) -> None:
    """A symbolic link to src at dst (a copy where links are not possible or asked for)."""
    if dst.exists() or dst.is_symlink():
        dst.unlink()
    if not copy:
        try:
            os.symlink(src.resolve(), dst)
            return
        except OSError:
            pass
    shutil.copyfile(src, dst)


def convert(src, out, force=False, copy=False, progress=True) -> dict:
    """Index HUMANML3D_DIR into OUT_DIR; returns counts and the problems found."""
    src, out = Path(src), Path(out)
    vecs, joints = src / "new_joint_vecs", src / "new_joints"
    if not vecs.is_dir():
        raise ValueError(f"HUMANML3D_DIR {src}: no new_joint_vecs/ folder. {WHERE}")
    if not folder_is_empty(out) and not force:
        raise ValueError(f"OUT_DIR {out} is not empty; pass --force to overwrite it")
    splits = {}
    for name in ("train", "val", "test"):
        f = src / f"{name}.txt"
        if f.is_file():
            splits.update({line.strip(): name for line in f.read_text().splitlines() if line.strip()})
    (out / "joints").mkdir(parents=True, exist_ok=True)
    (out / "features").mkdir(parents=True, exist_ok=True)
    rows, problems, t0 = [], {}, time.time()
    for vec_file in tqdm(sorted(vecs.glob("*.npy")), desc="indexing", unit="clip", disable=not progress):
        cid = vec_file.stem
        try:
            v = np.load(vec_file, mmap_mode="r", allow_pickle=False)
            if v.ndim != 2 or v.shape[1] != 263:
                raise ValueError(f"features shape {v.shape}, expected (T, 263)")
            jf = joints / f"{cid}.npy"
            if jf.is_file():
                j = np.load(jf, mmap_mode="r", allow_pickle=False)
                if j.shape != (v.shape[0], 22, 3):
                    raise ValueError(f"joints shape {j.shape}, expected ({v.shape[0]}, 22, 3)")
                link_or_copy(jf, out / "joints" / f"{cid}.npy", copy)
            link_or_copy(vec_file, out / "features" / f"{cid}.npy", copy)
        except ValueError as e:
            problems[cid] = str(e)
            continue
        rows.append({"clip_id": cid, "split": splits.get(cid, "train"), "style": "", "substyle": "",
                     "content": "", "caption": first_caption(src / "texts" / f"{cid}.txt"),
                     "n_frames": str(v.shape[0]), "source_file": vec_file.name})
    write_labels(out, rows)
    for a, b in (("Mean.npy", "mean.npy"), ("Std.npy", "std.npy")):
        if (src / a).is_file():
            link_or_copy(src / a, out / b, copy)
    meta = {"name": "humanml3d", "fps": 20, "skeleton": "humanml3d-22", "format_version": FORMAT_VERSION,
            "source": f"data_prep.humanml3d from {src.name}", "n_clips": len(rows),
            "joints_frames": "same as features (the release's positions are the decoded vector)"}
    write_meta(out, meta)
    return {"clips": len(rows), "problems": problems, "seconds": round(time.time() - t0, 1),
            "splits": {s: sum(r["split"] == s for r in rows) for s in ("train", "val", "test")}}


def main(argv=None) -> int:
    """Command-line entry point."""
    p = argparse.ArgumentParser(prog="python -m data_prep.humanml3d", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("src", metavar="HUMANML3D_DIR")
    p.add_argument("out", metavar="OUT_DIR")
    p.add_argument("--force", action="store_true")
    p.add_argument("--copy", action="store_true", help="copy the arrays instead of linking them")
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    try:
        s = convert(args.src, args.out, args.force, args.copy, progress=not args.json)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(s, sort_keys=True))
    else:
        print(f"indexed {s['clips']} clips ({s['splits']}) in {s['seconds']} s; {len(s['problems'])} problems")
        for cid, why in s["problems"].items():
            print(f"  {cid}: {why}")
    return 0 if not s["problems"] else 1


if __name__ == "__main__":
    sys.exit(main())
