"""Paper C, design checks on the VALIDATION split (never the benchmark's test pairs).

    .venv/bin/python tools/contrastive_findings.py train-literal OUT.pt   # the paper-literal variant
    .venv/bin/python tools/contrastive_findings.py val course OUT.pt       # H, CRA, SRA on a val draw

`train-literal` trains the course preset with `content_skip=False, content_norm=False` (G sees only
the two codes, E_c without the final instance norm: C §3, §4.1 as written) for the same steps and
seed as the packaged checkpoint. `val` scores checkpoints ("course" = the packaged one) with the
independent evaluator on 200 (content, style) pairs drawn from the val splits, styles in turn, and
reports how often the predicted content is the *style* clip's content (content leaking through the
style code). The findings (a)–(d) themselves: `python -m mslib.models.contrastive_analysis`.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mslib.data.corpora import load_builtin  # noqa: E402
from mslib.models import contrastive as C  # noqa: E402


def score(model, pairs, evaluator) -> dict:
    """Bench metrics on the pairs, plus the share of outputs classified as the style clip's content."""
    from mslib.evaluation.bench import evaluate
    from mslib.motion.features import decode
    outs = [decode(model.transfer_features(c["features"], s["features"])) for c, s in pairs]
    row = evaluate(outs, pairs, evaluator)
    c_logits = evaluator.score(outs)[0]
    pred = [evaluator.content.classes[i] for i in c_logits.argmax(1)]
    leak = np.mean([p == s["content"] != c["content"] for p, (c, s) in zip(pred, pairs)])
    return {"h": row["h"], "cra": row["cra"], "sra": row["sra"], "fmd": row["fmd"],
            "content_from_style_clip": 100.0 * float(leak)}


def main(argv=None) -> int:
    """Command line (module docstring)."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("train-literal")
    t.add_argument("out")
    v = sub.add_parser("val")
    v.add_argument("checkpoints", nargs="+")
    args = p.parse_args(argv)
    paths = load_builtin(progress=False)
    if args.cmd == "train-literal":
        cfg = C.ContrastiveConfig.preset("course", content_skip=False, content_norm=False)
        C.train(cfg, paths["content"], paths["style"], seed=0, out=args.out)
        print(args.out)
        return 0
    from mslib.evaluation.bench import Evaluator, load_pairs
    pairs, evaluator = load_pairs(0, 200, paths["content"], paths["style"], split="val"), Evaluator()
    for ck in args.checkpoints:
        if ck != "course" and not Path(ck).is_file():
            raise SystemExit(f"checkpoint {ck}: no such file")
        row = score(C.load(None if ck == "course" else ck), pairs, evaluator)
        print(ck, {k: round(v, 3) for k, v in row.items()}, flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
