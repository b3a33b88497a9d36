"""A Table 2 ablation: the dual-stream DSDN against its dynamic-only and static-only streams.

    OMP_NUM_THREADS=1 .venv/bin/python tools/dsdn_ablation.py [--steps N] [--seed S] [--json] [--out FILE]

Builds the neutral-transfer training pairs once (A §4.3.1, with the packaged adain checkpoint), trains
the three modes of `mslib.models.dsdn.DSDN` with the course preset on the same pairs and seed, and
prints L_rec (A Eq. 11) and L_vel (A Eq. 12) on the training and validation pairs for each; `--out`
writes the rows as JSON (notebook 05 reads notebooks/data/05_dsdn_ablation.json, made by this command).
"""
from __future__ import annotations

import argparse
import json
from dataclasses import asdict
from pathlib import Path

from mslib.data.corpora import load_builtin
from mslib.fileio import atomic_write_bytes
from mslib.models import dsdn as D
from mslib.models.adain import load_adain


def main(argv=None) -> list:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=None, help="override the course preset's steps")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true", help="one JSON line per mode")
    ap.add_argument("--out", default=None, help="write the rows to this JSON file")
    args = ap.parse_args(argv)
    paths = load_builtin(progress=False)
    stage1 = load_adain()
    cfg, _ = D.PRESETS["course"]
    data = tuple(D.neutral_pairs(stage1, paths["content"], paths["style"], split, cfg.clip_frames, args.seed)
                 for split in ("train", "val"))
    rows = []
    for mode in D.MODES:
        model, h = D.train_dsdn("course", None, None, seed=args.seed, steps=args.steps, progress=False,
                                config=D.DsdnConfig(**{**asdict(cfg), "mode": mode}), stage1=stage1, data=data)
        rows.append({"mode": mode, **{f"{split}_{k}": D.evaluate_pairs(model, data[i])[k]
                                      for i, split in enumerate(("train", "val")) for k in ("rec", "vel")},
                     "steps": h["step"][-1]})
    for r in rows:
        print(json.dumps(r) if args.json else
              f"{r['mode']:<8} train L_rec {r['train_rec']:.4f} L_vel {r['train_vel']:.4f}   "
              f"val L_rec {r['val_rec']:.4f} L_vel {r['val_vel']:.4f}")
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        atomic_write_bytes(Path(args.out), (json.dumps({"command": "tools/dsdn_ablation.py", "seed": args.seed,
                                                          "rows": rows}, indent=1) + "\n").encode())
    return rows


if __name__ == "__main__":
    main()
