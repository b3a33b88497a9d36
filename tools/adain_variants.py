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
          how the course preset's `style_strength` was chosen; also its SRA and CRA style by style there
          (`by_style`), from which notebook 02 picks its demo style (`mslib.notebook.demo_style`).
recipes   full course-length runs (`--recipes NAME,...`, `--seeds 0,1,2,3`), each scored on the val pairs at
          w ∈ RECIPE_STRENGTHS: how the packaged checkpoint's recipe and seed are chosen (RECIPE_RULE; rows
          merge by recipe and seed, so two processes can each train some; rows made on other corpora than
          the current build's are dropped; `--seeds ""` trains nothing and re-applies the rule to the stored
          rows, e.g. after the strength section has scored a newly packaged checkpoint):
          course         the course preset as it is (λ_content = 2: A Eq. 5 with the content path counted twice,
                         adopted over the plain weights by this search on an earlier corpus);
          wide           hidden 128 (twice the channels: a closer autoencoder keeps more content);
          content1       λ_content = 1 (A Eq. 5's weights as written).
"""
from __future__ import annotations

import argparse
import sys
import time
from dataclasses import asdict, replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tools.common import (DATA_DIR, current_commit, recorded_command, score_outputs, update_json,  # noqa: E402
                          val_pairs)

OUT = DATA_DIR / "02_adain_variants.json"

VARIANTS = {
    "separate_joint": dict(shared_encoder=False, pretrain_steps=0),
    "separate_frozen": dict(shared_encoder=False),
    "shared_frozen": dict(shared_encoder=True),
}
STRENGTHS = (0.5, 0.75, 1.0)
RECIPES = {"course": {}, "wide": dict(hidden=128), "content1": dict(lambda_content=1.0)}
RECIPE_STRENGTHS = (0.5, 0.55, 0.6)
RECIPE_RULE = ("adopt a recipe over 'course' only if its mean val H at the course strength over the same seeds beats "
               "course's by at least 0.02; package the seed of the adopted recipe with the best val H at the course "
               "strength, unless the packaged checkpoint's own val H there (section 'strength') is higher: then keep it "
               "(fixed before any run on the current corpora was scored)")


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
    from mslib.evaluation.bench import by_style, positions
    model = load_adain()
    rows = [score(model, pairs, evaluator, w) for w in (0.4, 0.45, 0.5, 0.55, 0.6, 0.7)]
    for r in rows:
        print(r, flush=True)
    outs = [positions(model.transfer_features(c["features"], s["features"])) for c, s in pairs]
    styles = [{k: (round(v, 1) if isinstance(v, float) else v) for k, v in r.items()}
              for r in by_style(outs, pairs, evaluator)]
    return {"rows": rows, "by_style": styles, "checkpoint": checkpoint_digest("adain"),
            "course_strength": model.cfg.style_strength}


def recipes(paths, pairs, evaluator, names, seeds, keep_dir=None) -> dict:
    """Train each recipe at the course length for every seed and score it on the val pairs."""
    import json
    from mslib.checkpoints import checkpoint_digest
    from mslib.data.corpora import source_fingerprint
    from mslib.models import adain as A
    corpus, course_w = source_fingerprint(), A.AdainConfig.preset("course").style_strength
    rows = {}
    for name in names:
        for seed in seeds:
            t0 = time.time()
            out = Path(keep_dir) / f"adain_{name}_s{seed}.pt" if keep_dir else None
            cfg = A.AdainConfig.preset("course", **RECIPES[name])
            model, _ = A.train_adain("course", paths["content"], paths["style"], seed=seed, out=out, progress=False,
                                     config=cfg)
            for w in RECIPE_STRENGTHS:
                rows[(name, seed, w)] = {"recipe": name, "seed": seed, **score(model, pairs, evaluator, w),
                                         "train_seconds": round(time.time() - t0, 1), "commit": current_commit(),
                                         "corpus": corpus}
                print(rows[(name, seed, w)], flush=True)
    stored = json.loads(OUT.read_text()) if OUT.is_file() else {}  # re-read: runs in parallel merge
    old = stored.get("recipes", {}).get("rows", [])
    rows = {**{(r["recipe"], r["seed"], r["strength"]): r for r in old if r.get("corpus") == corpus}, **rows}
    rows = sorted(rows.values(), key=lambda r: (r["recipe"], r["seed"], r["strength"]))
    strength = stored.get("strength", {})  # the packaged checkpoint on the same val pairs, if measured on it
    packaged = [r["h"] for r in strength.get("rows", []) if abs(r["strength"] - course_w) < 1e-9
                and strength.get("checkpoint") == checkpoint_digest("adain")]
    return {"rows": rows, "rule": RECIPE_RULE, "course_strength": course_w, "corpus": corpus,
            **apply_recipe_rule(rows, course_w, packaged[0] if packaged else None)}


def apply_recipe_rule(rows, course_w: float, packaged_h: float | None = None) -> dict:
    """RECIPE_RULE on the rows: the adopted recipe, its best seed, and whether the packaged checkpoint (val H
    `packaged_h` at the course strength) stays."""
    h = {(r["recipe"], r["seed"]): r["h"] for r in rows if abs(r["strength"] - course_w) < 1e-9}
    seeds = sorted(s for n, s in h if n == "course")
    if not seeds:
        return {}
    mean = {n: sum(h[(n, s)] for s in seeds) / len(seeds) for n in {n for n, _ in h}
            if all((n, s) in h for s in seeds)}
    adopted = max((n for n in mean if mean[n] >= mean["course"] + 0.02), key=mean.get, default="course")
    best = max(seeds, key=lambda s: h[(adopted, s)])
    out = {"adopted": adopted, "best_seed": best, "mean_h": {n: round(v, 4) for n, v in sorted(mean.items())}}
    if packaged_h is not None:
        out.update(packaged_h=packaged_h, keep_packaged=bool(packaged_h >= h[(adopted, best)]))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", default="variants,strength", help="comma-separated sections to run (variants, strength)")
    ap.add_argument("--steps", type=int, default=1500, help="decoder (and autoencoder) steps of each variant")
    ap.add_argument("--pairs", type=int, default=200, help="val pairs to score on")
    ap.add_argument("--recipes", default="course", help=f"recipes section: comma-separated, of {sorted(RECIPES)}")
    ap.add_argument("--seeds", default="0", help="recipes section: comma-separated seeds (empty: train nothing, "
                    "re-apply RECIPE_RULE to the stored rows and the stored strength section)")
    ap.add_argument("--keep", default=None, metavar="DIR", help="recipes section: keep each run's checkpoint here")
    args = ap.parse_args(argv)
    unknown = set(args.only.split(",")) - {"variants", "strength", "recipes"}
    if unknown:
        ap.error(f"--only: unknown sections {sorted(unknown)}; expected variants, strength and/or recipes")
    if set(args.recipes.split(",")) - set(RECIPES):
        ap.error(f"--recipes: unknown {sorted(set(args.recipes.split(',')) - set(RECIPES))}; known {sorted(RECIPES)}")
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
    if "recipes" in todo:
        result["recipes"] = recipes(paths, pairs, evaluator, args.recipes.split(","),
                                    [int(x) for x in args.seeds.split(",") if x.strip()], args.keep)
    command = recorded_command("adain_variants", argv if argv is not None else sys.argv[1:])
    for part in result.values():
        part.update(command=command, val_pairs=args.pairs, commit=current_commit())
    print(update_json(OUT, result))  # sections not re-run are kept
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
