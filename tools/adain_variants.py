"""Paper A stage 1, design checks on the VALIDATION split (never the benchmark's test pairs);
writes notebooks/data/02_adain_variants.json, which notebook 02 reads.

    python tools/adain_variants.py [--only variants,strength] [--steps 1500] [--pairs 200]

variants  where the style statistics come from, each trained with the course sizes for `--steps`
          decoder steps (plus as many autoencoder steps where the recipe has them), scored by the
          independent evaluator on `--pairs` (content, style) pairs from the val splits at three
          style strengths w:
          separate_joint   A §3.2.1 as written: a transformer E_s on joint positions, trained jointly with
                           E_c and the decoder (its stored rows were made at commit 3748be4 with the content
                           skip on, as the workbook's first course model; that option has left the library);
          separate_frozen  the same E_s, but E_c, E_s and the decoder first trained as an autoencoder,
                           then E_s frozen as A Eq. 3's loss network (no skip);
          shared_frozen    the course recipe: one encoder E for content and style, pre-trained, then frozen.
strength  the packaged course checkpoint at w ∈ {0.4, 0.45, 0.5, 0.55, 0.6, 0.7} on the same val pairs:
          how the course preset's `style_strength` was chosen.
"""
from __future__ import annotations

import argparse
import sys
import time
from dataclasses import asdict, replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tools.common import DATA_DIR, current_commit, score_outputs, update_json, val_pairs  # noqa: E402

OUT = DATA_DIR / "02_adain_variants.json"

VARIANTS = {
    "separate_joint": dict(shared_encoder=False, pretrain_steps=0),
    "separate_frozen": dict(shared_encoder=False),
    "shared_frozen": dict(shared_encoder=True),
}
STRENGTHS = (0.5, 0.75, 1.0)


def score(model, pairs, evaluator, strength: float) -> dict:
    """H, CRA, SRA, FSF of the model's transfers at one style strength."""
    from mslib.evaluation.bench import positions
    outs = [positions(model.transfer_features(c["features"], s["features"], strength=strength)) for c, s in pairs]
    r = score_outputs(outs, pairs, evaluator)
    return {"strength": strength, **{k: round(float(r[k]), 4) for k in ("h", "cra", "sra", "fsf")}}


def variants(paths, pairs, evaluator, steps: int) -> dict:
    """Train each variant for `steps` decoder steps and score it on the val pairs."""
    from mslib.models import adain as A
    from mslib.training import TrainConfig
    cfg, tcfg = A.AdainConfig.preset("course"), A.ADAIN_TRAINING["course"]
    rows = []
    for name, change in VARIANTS.items():
        t0 = time.time()
        vcfg = replace(cfg, **{"pretrain_steps": steps, **change})
        model, h = A.train_adain("course", paths["content"], paths["style"], seed=0, progress=False, config=vcfg,
                                 train_config=TrainConfig(**{**asdict(tcfg), "steps": steps}))
        for w in STRENGTHS:
            rows.append({"variant": name, **score(model, pairs, evaluator, w)})
            print(rows[-1], flush=True)
        rows[-1]["seconds"] = round(time.time() - t0, 1)
    return {"steps": steps, "rows": rows}


def strength(pairs, evaluator) -> dict:
    """The packaged checkpoint at several style strengths."""
    from mslib.checkpoints import checkpoint_digest
    from mslib.models.adain import load_adain
    model = load_adain()
    rows = [score(model, pairs, evaluator, w) for w in (0.4, 0.45, 0.5, 0.55, 0.6, 0.7)]
    for r in rows:
        print(r, flush=True)
    return {"rows": rows, "checkpoint": checkpoint_digest("adain"), "course_strength": model.cfg.style_strength}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", default="variants,strength", help="comma-separated sections to run (variants, strength)")
    ap.add_argument("--steps", type=int, default=1500, help="decoder (and autoencoder) steps of each variant")
    ap.add_argument("--pairs", type=int, default=200, help="val pairs to score on")
    args = ap.parse_args(argv)
    unknown = set(args.only.split(",")) - {"variants", "strength"}
    if unknown:
        ap.error(f"--only: unknown sections {sorted(unknown)}; expected variants and/or strength")
    import torch
    from mslib.data.corpora import load_builtin
    from mslib.evaluation.bench import Evaluator
    torch.manual_seed(0)
    paths = load_builtin(progress=False)
    pairs, evaluator = val_pairs(args.pairs), Evaluator()
    todo = args.only.split(",")
    result = {}
    if "variants" in todo:
        result["variants"] = variants(paths, pairs, evaluator, args.steps)
    if "strength" in todo:
        result["strength"] = strength(pairs, evaluator)
    command = " ".join(["python tools/adain_variants.py", *(argv if argv is not None else sys.argv[1:])])
    for part in result.values():
        part.update(command=command, val_pairs=args.pairs, commit=current_commit())
    print(update_json(OUT, result))  # sections not re-run are kept
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
