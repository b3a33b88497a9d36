"""A Table 2 ablation: the dual-stream DSDN against its dynamic-only and static-only streams.

    OMP_NUM_THREADS=1 .venv/bin/python tools/dsdn_ablation.py [--steps N] [--seed S] [--json] [--out FILE]
    OMP_NUM_THREADS=1 .venv/bin/python tools/dsdn_ablation.py --strength [--out FILE]

Builds the neutral-transfer training pairs once (A §4.3.1, with the packaged adain checkpoint), trains
the three modes of `mslib.models.dsdn.DSDN` with the course preset on the same pairs and seed, and
prints L_rec (A Eq. 11) and L_vel (A Eq. 12) on the training and validation pairs for each; `--out`
writes the rows as JSON (notebook 05 reads notebooks/data/05_dsdn_ablation.json, made by this command).

`--strength` instead scores the packaged stages 1 + 2 on 200 (content, style) pairs from the *val*
splits at correction strengths κ ∈ {0, 0.25, 0.5, 0.75, 1} (H, CRA, SRA, FSF, jitter): the evidence
for the course preset's κ = 0.5 (H within 0.01 of stage 1's, κ = 0, while FSF and jitter fall); with
`--out` the rows are added to that file under "strength".
"""
from __future__ import annotations

import argparse
import json
from dataclasses import asdict
from pathlib import Path

from mslib.data.corpora import load_builtin
from mslib.fileio import atomic_write_bytes
from mslib.models import adain as D
from mslib.models.adain import load_adain


def main(argv=None) -> list:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=None, help="override the course preset's steps")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true", help="one JSON line per mode")
    ap.add_argument("--out", default=None, help="write the rows to this JSON file")
    ap.add_argument("--strength", action="store_true", help="the correction-strength sweep on val pairs instead")
    args = ap.parse_args(argv)
    if args.strength:
        return strength_sweep(args.out)
    paths = load_builtin(progress=False)
    stage1 = load_adain()
    cfg = D.DsdnConfig.preset("course")
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
        old = json.loads(Path(args.out).read_text()) if Path(args.out).is_file() else {}
        keep = {"strength": old["strength"]} if "strength" in old else {}
        atomic_write_bytes(Path(args.out), (json.dumps({"command": "tools/dsdn_ablation.py", "seed": args.seed,
                                                          "rows": rows, **keep}, indent=1) + "\n").encode())
    return rows


def strength_sweep(out=None, kappas=(0.0, 0.25, 0.5, 0.75, 1.0), n_pairs: int = 200) -> list:
    """H, CRA, SRA, FSF and jitter of stages 1 + 2 on val pairs at several correction strengths κ."""
    import numpy as np
    from mslib.checkpoints import checkpoint_digest
    from mslib.evaluation.bench import Evaluator, evaluate, load_pairs
    from mslib.evaluation.metrics import jitter
    from mslib.motion.features import decode
    paths = load_builtin(progress=False)
    stage1, stage2 = load_adain(), D.load_dsdn()
    pairs, ev = load_pairs(0, n_pairs, paths["content"], paths["style"], split="val"), Evaluator()
    raw = [stage1.transfer_features(c["features"], s["features"]) for c, s in pairs]
    rows = []
    for k in kappas:
        pos = [decode(stage2.correct_features(f, strength=k)) for f in raw]
        r = evaluate(pos, pairs, ev)
        rows.append({"strength": k, **{m: round(float(r[m]), 4) for m in ("h", "cra", "sra", "fsf")},
                     "jitter": round(float(np.mean([jitter(p) for p in pos])), 3)})
        print(json.dumps(rows[-1]), flush=True)
    if out:
        old = json.loads(Path(out).read_text()) if Path(out).is_file() else {}
        part = {"rows": rows, "val_pairs": n_pairs, "command": "tools/dsdn_ablation.py --strength",
                "checkpoints": {n: checkpoint_digest(n) for n in ("adain", "dsdn")}}
        atomic_write_bytes(Path(out), (json.dumps({**old, "strength": part}, indent=1) + "\n").encode())
    return rows


if __name__ == "__main__":
    main()
