"""Paper C, design checks on the VALIDATION split (never the benchmark's test pairs).

    .venv/bin/python tools/contrastive_findings.py train VARIANT OUT.pt   # one training recipe
    .venv/bin/python tools/contrastive_findings.py val course OUT.pt       # H, CRA, SRA on a val draw
    .venv/bin/python tools/contrastive_findings.py strength                # the course model at several w

`train` trains one variant of the course preset for the same steps as the packaged checkpoint:
    literal      C §3, §4.1 as written: G sees only the two codes (`content_skip=False`), E_c without
                 the final instance norm (`content_norm=False`), C Eq. 5 from the first step;
    joint        the course sizes and content skip, C Eq. 5 from the first step (the course recipe
                 before the autoencoder phase);
    autoencoder  the autoencoder phase alone: C Eq. 1 + 2 (β = γ = 0), no contrastive terms;
    course       the course recipe: the autoencoder phase, then E_s frozen and all of C Eq. 5.
`val` scores checkpoints ("course" = the packaged one) with the independent evaluator on 200
(content, style) pairs drawn from the val splits, styles in turn, and reports how often the predicted
content is the *style* clip's content (content leaking through the style code), all at C's transfer
(style strength w = 1). `strength` scores the packaged checkpoint on the same pairs at several w
(E_s(M^T) + w·(E_s(M^S) − E_s(M^T))): how the course preset's `style_strength` was chosen. With `--save`
both write into notebooks/data/03_contrastive_recipes.json, which notebook 03 reads. The findings (a)–(d)
themselves: `python -m mslib.models.contrastive_analysis`.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
RECIPES_JSON = ROOT / "notebooks" / "data" / "03_contrastive_recipes.json"

from mslib.data.corpora import load_builtin  # noqa: E402
from mslib.models import contrastive as C  # noqa: E402


VARIANTS = {  # course config → overrides; the joint recipes train as many steps as the course's two phases
    "literal": lambda c: dict(content_skip=False, content_norm=False, pretrain_steps=0, steps=c.pretrain_steps + c.steps),
    "joint": lambda c: dict(pretrain_steps=0, steps=c.pretrain_steps + c.steps),
    "autoencoder": lambda c: dict(beta=0.0, gamma=0.0, pretrain_steps=0, steps=c.pretrain_steps),
    "course": lambda c: {},
}


def score(model, pairs, evaluator, strength=None) -> dict:
    """Bench metrics on the pairs, plus the share of outputs classified as the style clip's content."""
    from mslib.evaluation.bench import evaluate
    from mslib.motion.features import decode
    outs = [decode(model.transfer_features(c["features"], s["features"], strength)) for c, s in pairs]
    row = evaluate(outs, pairs, evaluator)
    c_logits = evaluator.score(outs)[0]
    pred = [evaluator.content.classes[i] for i in c_logits.argmax(1)]
    leak = np.mean([p == s["content"] != c["content"] for p, (c, s) in zip(pred, pairs)])
    return {"h": row["h"], "cra": row["cra"], "sra": row["sra"], "fmd": row["fmd"],
            "content_from_style_clip": 100.0 * float(leak)}


STRENGTHS = (0.5, 0.6, 0.7, 0.8, 0.9, 1.0)


def _command(argv) -> str:
    return " ".join(["python tools/contrastive_findings.py", *(argv if argv is not None else sys.argv[1:])])


def _save(part: dict) -> None:
    """Merge `part` into the JSON notebook 03 reads (sections not re-run are kept)."""
    latest = json.loads(RECIPES_JSON.read_text()) if RECIPES_JSON.is_file() else {}
    RECIPES_JSON.parent.mkdir(parents=True, exist_ok=True)
    RECIPES_JSON.write_text(json.dumps({**latest, **part}, indent=1) + "\n")
    print(RECIPES_JSON)


def main(argv=None) -> int:
    """Command line (module docstring)."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("train")
    t.add_argument("variant", choices=sorted(VARIANTS))
    t.add_argument("out")
    t.add_argument("--seed", type=int, default=0)
    w = sub.add_parser("strength", help="the packaged checkpoint at several style strengths on the val pairs")
    w.add_argument("--save", action="store_true")
    v = sub.add_parser("val")
    v.add_argument("checkpoints", nargs="+", help="`course`, a path, or LABEL=PATH")
    v.add_argument("--save", action="store_true", help=f"write the rows to {RECIPES_JSON.relative_to(ROOT)}")
    args = p.parse_args(argv)
    paths = load_builtin(progress=False)
    if args.cmd == "train":
        course = C.ContrastiveConfig.preset("course")
        cfg = C.ContrastiveConfig.preset("course", **VARIANTS[args.variant](course))
        C.train(cfg, paths["content"], paths["style"], seed=args.seed, out=args.out)
        print(args.out)
        return 0
    from mslib.evaluation.bench import Evaluator, load_pairs
    pairs, evaluator = load_pairs(0, 200, paths["content"], paths["style"], split="val"), Evaluator()
    if args.cmd == "strength":
        model = C.load()
        sweep = []
        for st in STRENGTHS:
            sweep.append({"strength": st, **{k: round(float(v), 4) for k, v in score(model, pairs, evaluator, st).items()}})
            print(sweep[-1], flush=True)
        if args.save:
            _save({"strength": {"command": _command(argv), "course_strength": model.cfg.style_strength, "rows": sweep}})
        return 0
    rows = []
    for arg in args.checkpoints:
        label, _, ck = arg.rpartition("=") if "=" in arg else (Path(arg).stem, "", arg)
        if ck != "course" and not Path(ck).is_file():
            raise SystemExit(f"checkpoint {ck}: no such file")
        model = C.load(None if ck == "course" else ck)
        row = {"variant": label, **{k: round(float(v), 4) for k, v in score(model, pairs, evaluator, 1.0).items()},
               "steps": [model.cfg.pretrain_steps, model.cfg.steps]}
        rows.append(row)
        print(row, flush=True)
    if args.save:
        _save({"command": _command(argv), "val_pairs": len(pairs), "rows": rows})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
