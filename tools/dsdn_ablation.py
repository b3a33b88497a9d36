"""A Table 2 ablation: the dual-stream DSDN against its dynamic-only and static-only streams.

    OMP_NUM_THREADS=1 .venv/bin/python tools/dsdn_ablation.py [--steps N] [--seed S] [--json] [--out FILE]
    OMP_NUM_THREADS=1 .venv/bin/python tools/dsdn_ablation.py --strength [--pairs N] [--out FILE]

Builds the neutral-transfer training pairs once (A §4.3.1, with the packaged adain checkpoint), trains
the three modes of `mslib.models.adain.DSDN` with the course preset on the same pairs and seed, and
prints L_rec (A Eq. 11) and L_vel (A Eq. 12) on the training and validation pairs for each; `--out`
writes the rows as JSON (notebook 05 reads notebooks/data/05_dsdn_ablation.json, made by this command).

`--strength` instead scores the packaged stages 1 + 2 on 200 (content, style) pairs from the *val*
splits at correction strengths κ ∈ {0, 0.25, 0.5, 0.75, 1} (H, CRA, SRA, FSF, jitter): how the course
preset's κ is chosen (the highest val H; a tie goes to the smaller κ, which keeps more stage-1 style); with
`--out` the rows are added to that file under "strength". Either run keeps the other's part of the file.
"""
from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tools.common import current_commit, score_outputs, update_json, val_pairs  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=None, help="override the course preset's steps")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true", help="one JSON line per mode")
    ap.add_argument("--out", default=None, help="write the rows to this JSON file")
    ap.add_argument("--strength", action="store_true", help="the correction-strength sweep on val pairs instead")
    ap.add_argument("--pairs", type=int, default=200, help="val pairs of the strength sweep")
    args = ap.parse_args(argv)
    if args.strength:
        strength_sweep(args.out, n_pairs=args.pairs)
    else:
        ablation(args.steps, args.seed, args.json, args.out)
    return 0


def ablation(steps=None, seed: int = 0, as_json: bool = False, out=None) -> list:
    """Train the three DSDN modes on the same neutral-transfer pairs; their L_rec and L_vel on train and val."""
    from mslib.data.corpora import load_builtin
    from mslib.models import adain as D
    paths = load_builtin(progress=False)
    stage1 = D.load_adain()
    cfg = D.DsdnConfig.preset("course")
    data = tuple(D.neutral_pairs(stage1, paths["content"], paths["style"], split, cfg.clip_frames, seed)
                 for split in ("train", "val"))
    rows = []
    for mode in D.MODES:
        model, h = D.train_dsdn("course", None, None, seed=seed, steps=steps, progress=False,
                                config=D.DsdnConfig(**{**asdict(cfg), "mode": mode}), stage1=stage1, data=data)
        rows.append({"mode": mode, **{f"{split}_{k}": D.evaluate_pairs(model, data[i])[k]
                                      for i, split in enumerate(("train", "val")) for k in ("rec", "vel")},
                     "steps": h["step"][-1]})
    for r in rows:
        print(json.dumps(r) if as_json else
              f"{r['mode']:<8} train L_rec {r['train_rec']:.4f} L_vel {r['train_vel']:.4f}   "
              f"val L_rec {r['val_rec']:.4f} L_vel {r['val_vel']:.4f}")
    if out:
        update_json(out, {"command": "tools/dsdn_ablation.py", "seed": seed, "rows": rows, "commit": current_commit()})
    return rows


def strength_sweep(out=None, kappas=(0.0, 0.25, 0.5, 0.75, 1.0), n_pairs: int = 200, pairs=None, ev=None) -> list:
    """H, CRA, SRA, FSF and jitter of stages 1 + 2 at several correction strengths κ, on `n_pairs` val pairs
    judged by the packaged evaluator (or on `pairs` judged by `ev`)."""
    import numpy as np
    from mslib.checkpoints import checkpoint_digest
    from mslib.evaluation.bench import Evaluator, positions
    from mslib.evaluation.metrics import jitter
    from mslib.models.adain import load_adain, load_dsdn
    stage1, stage2 = load_adain(), load_dsdn()
    pairs, ev = pairs or val_pairs(n_pairs), ev or Evaluator()
    raw = [stage1.transfer_features(c["features"], s["features"]) for c, s in pairs]
    rows = []
    for k in kappas:
        pos = [positions(stage2.correct_features(f, strength=k)) for f in raw]
        r = score_outputs(pos, pairs, ev)
        rows.append({"strength": k, **{m: round(r[m], 4) for m in ("h", "cra", "sra", "fsf")},
                     "jitter": round(float(np.mean([jitter(p) for p in pos])), 3)})
        print(json.dumps(rows[-1]), flush=True)
    if out:
        part = {"rows": rows, "val_pairs": n_pairs, "command": "tools/dsdn_ablation.py --strength",
                "checkpoints": {n: checkpoint_digest(n) for n in ("adain", "dsdn")}, "commit": current_commit()}
        update_json(out, {"strength": part})
    return rows


if __name__ == "__main__":
    raise SystemExit(main())
