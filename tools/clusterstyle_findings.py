"""Paper D's two findings on the built-in data; writes notebooks/data/06_clusterstyle_findings.json.

    python tools/clusterstyle_findings.py [--only fig5,table3,bench,guidance] [--sma-steps 400] [--pairs 100]
    python tools/clusterstyle_findings.py --only seeds --checkpoints A.pt,B.pt

fig5   D Fig. 5's claim: for each style, two reference clips each with a content walk (all from the *val*
       splits, not the benchmark's test pairs); outputs that use the style's global prototypes as the style
       feature and guidance target (with one seed, and with seed k for prototype k) against outputs with the
       reference's own feature and K seeds (`fig5` says which measures). Measured for SDEdit transfer
       (t0 = 600) and for generation from a caption.
table3 D Table 3, first row: the style encoder with a learnable classification head and cross-entropy
       instead of prototype clustering. Short runs of the same recipe (style stage 300 steps, then the
       SMA stage `--sma-steps` steps from the packaged t2m model), scored by the independent evaluator on
       the first `--pairs` default benchmark pairs; the style encoder's own held-out accuracy is reported too.
bench  the default bench draw (seed 0, 200 pairs) of `clusterstyle`, `identity` and `copy_style` — the rows
       `python -m mslib bench --method clusterstyle,identity,copy_style --json` prints — stored so that
       notebook 06 need not spend minutes re-running 200 SDEdit transfers.
guidance  the choice of the course inference settings: style guidance weight w (D Eq. 15, for t < 300) and
       the style CFG strength s_s, scored on 96 pairs from the *val* splits with the packaged model. When the
       best w lies at the edge of the grid, the grid is widened past it (GUIDANCE_GRID's last rows).
seeds  the SMA stage's course recipe trained again with other seeds (`python -m mslib train clusterstyle
       --preset course --seed N --out FILE`, passed as `--checkpoints`), each scored beside the packaged model
       on 200 *val* pairs at the course guidance: how the packaged seed is chosen (SEED_RULE).
Sections not re-run are kept; each section records the command and the commit that made it, the VAE latent
and the digest of the checkpoint it measured.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tools.common import DATA_DIR, current_commit, recorded_command, score_outputs, update_json, val_pairs  # noqa: E402

OUT = DATA_DIR / "06_clusterstyle_findings.json"
SECTIONS = ("fig5", "table3", "bench", "guidance", "seeds")
SEED_RULE = "package the seed with the highest H on 200 val pairs at the course guidance"


def val_examples(paths, per_style: int = 2) -> list:
    """`per_style` (content, style) pairs per style from the val splits: the style's first clips, each with a walk."""
    from mslib.data.datasets import ContentClips, StyleClips
    from mslib.data.styles import STYLES
    content = ContentClips(paths["content"], "val", normalize=False)
    style = StyleClips(paths["style"], "val", normalize=False, joints=False)
    walks = [i for i, r in enumerate(content.rows) if r["content"] == "walk"]
    out = []
    for k, s in enumerate(STYLES):
        clips = [i for i, r in enumerate(style.rows) if r["style"] == s][:per_style]
        for n, j in enumerate(clips):
            c = content[walks[(k * per_style + n) % len(walks)]]
            out.append((s, c["features"].numpy(), c["caption"], style[j]["features"].numpy()))
    return out


FIG5_SETS = ("prototypes_one_seed", "prototypes_paired_seeds", "seeds")
FIG5_MEASURES = ("pose_cm", "diversity", "style_diversity")


def fig5(paths) -> dict:
    """D Fig. 5's claim, three output sets of K per example, K = the style's number of global prototypes:
    prototypes_one_seed      prototype k as style feature and guidance target, seed 0 for all;
    prototypes_paired_seeds  prototype k with seed k (prototype variation on top of seed variation);
    seeds                    the reference's own feature (and guidance), seeds 0..K−1 — D's "fixed feature".
    Measures: pose_cm (`pose_diversity`), diversity (the field's Diversity: mean distance between the
    evaluator's features, as the bench's column), style_diversity (the same on the style classifier's features only);
    and hit_rate: % of prototype outputs whose global style feature is nearest the prototype used."""
    import numpy as np
    from mslib.evaluation import metrics as M
    from mslib.evaluation.bench import Evaluator
    from mslib.models.clusterstyle import load_pipeline, pose_diversity
    from mslib.motion.features import decode
    pipe, ev = load_pipeline(), Evaluator()
    K = pipe.model.style_cfg.k_global

    def measures(outs) -> dict:
        pos = [decode(o) for o in outs]
        feats, style_feats = ev.score(pos)[2], ev.style.score(pos)[1]
        return {"pose_cm": pose_diversity(outs), "diversity": M.diversity(feats), "style_diversity": M.diversity(style_feats)}

    rows = []
    for style, content, caption, ref in val_examples(paths):
        row = {"style": style}
        c = pipe.style_of(pipe.style_tokens(ref))
        for mode in ("transfer", "generate"):
            kw = dict(caption=caption, mode=mode, length=len(content))
            sets = {"prototypes_one_seed": pipe.variants(content, ref, kind="global", seed=0, **kw),
                    "prototypes_paired_seeds": pipe.variants(content, ref, kind="global", seed=list(range(K)), **kw),
                    "seeds": pipe.seed_variants(content, ref, seeds=tuple(range(K)), **kw)}
            row[mode] = {name: {k: round(v, 3) for k, v in measures(outs).items()} for name, outs in sets.items()}
            hits = [pipe.nearest_global_prototype(pipe.style_tokens(o)) == (c, k)
                    for name in FIG5_SETS[:2] for k, o in enumerate(sets[name])]
            row[mode]["hit_rate"] = round(100.0 * float(np.mean(hits)), 1)
        rows.append(row)
        print(style, json.dumps({m: {n: row[m][n]["pose_cm"] for n in FIG5_SETS} for m in ("transfer", "generate")}),
              flush=True)
    summary = {}
    for mode in ("transfer", "generate"):
        summary[mode] = {name: {m: round(float(np.mean([r[mode][name][m] for r in rows])), 3) for m in FIG5_MEASURES}
                         for name in FIG5_SETS}
        summary[mode]["paired_beats_seeds"] = {m: int(sum(r[mode]["prototypes_paired_seeds"][m] > r[mode]["seeds"][m]
                                                          for r in rows)) for m in FIG5_MEASURES}
        summary[mode]["hit_rate"] = round(float(np.mean([r[mode]["hit_rate"] for r in rows])), 1)
        summary[mode]["examples"] = len(rows)
    return {"prototypes_per_style": K, "chance_hit_rate": round(100.0 / K, 1), "rows": rows, "summary": summary}


GUIDANCE_GRID = ((0.0, 2.5), (0.0, 1.0), (500.0, 1.0), (1500.0, 1.0), (3000.0, 1.0), (1500.0, 2.5), (1500.0, 0.0),
                 (3000.0, 0.0), (5000.0, 1.0), (5000.0, 0.0), (8000.0, 1.0), (8000.0, 0.0))


def scored_transfers(pipe, pairs, ev, keys=("cra", "sra", "h"), **transfer) -> dict:
    """SDEdit transfers of (content, style) `pairs` (seed 0, the content's caption; `transfer` passed on to
    `pipe.transfer`) scored by the evaluator `ev`: {key: value} for `keys`, rounded."""
    from mslib.motion.features import decode
    outs = [decode(pipe.transfer(c["features"], s["features"], caption=c.get("caption") or None, seed=0, **transfer))
            for c, s in pairs]
    r = score_outputs(outs, pairs, ev)
    return {k: round(float(r[k]), 4) for k in keys}


def guidance(n_pairs: int = 96) -> dict:
    """H, CRA, SRA of SDEdit transfers on a val draw for (w, s_s) in GUIDANCE_GRID (t0 600, s_t 2.5)."""
    from mslib.evaluation.bench import Evaluator
    from mslib.models.clusterstyle import load_pipeline
    pairs, ev, pipe = val_pairs(n_pairs), Evaluator(), load_pipeline()
    rows = []
    for w, ss in GUIDANCE_GRID:
        rows.append({"weight": w, "cfg_style": ss,
                     **scored_transfers(pipe, pairs, ev, ("cra", "sra", "h", "fsf", "tsi"), weight=w, cfg_style=ss)})
        print(rows[-1], flush=True)
    return {"pairs": n_pairs, "split": "val", "rows": rows}


def seeds(checkpoints, n_pairs: int = 200) -> dict:
    """The packaged model and the same recipe at other seeds (`checkpoints`), scored on val pairs at the course
    guidance; the best by SEED_RULE."""
    from mslib.checkpoints import course_path, trained_seed
    from mslib.evaluation.bench import Evaluator
    from mslib.models.clusterstyle import load_pipeline
    paths, seen = [course_path("clusterstyle"), *checkpoints], {}
    for path in paths:  # before any scoring: every run must be another seed's
        seed = trained_seed(path, "clusterstyle")
        if seed in seen:
            raise ValueError(f"--checkpoints: {path} was trained with seed {seed}, as {seen[seed]} was")
        seen[seed] = path
    pairs, ev, rows = val_pairs(n_pairs), Evaluator(), []
    course = None  # every seed at the packaged guidance (read first), whatever its own file stores
    for seed, path in seen.items():
        pipe = load_pipeline(path=path)
        course = course or pipe.cfg
        rows.append({"seed": seed, "file": Path(path).name, "guide_weight": course.guide_weight,
                     **scored_transfers(pipe, pairs, ev, weight=course.guide_weight, cfg_style=course.cfg_style)})
        print(rows[-1], flush=True)
    return {"pairs": n_pairs, "split": "val", "rows": rows, "rule": SEED_RULE,
            "trained_with": [f"python -m mslib train clusterstyle --preset course --seed {r['seed']} --out {r['file']}"
                             for r in rows[1:]],
            "packaged_seed": rows[0]["seed"], "best_seed": max(rows, key=lambda r: r["h"])["seed"]}


def encoder_accuracy(path, paths) -> float:
    """Held-out (test split) style accuracy of a trained style model, in percent."""
    from mslib.data.datasets import StyleClips
    from mslib.models.clusterstyle.prototypes import load_style_model
    from mslib.models.clusterstyle.train import NormalizedClips
    from mslib.motion.features import Normalizer
    model = load_style_model(path)
    norm = Normalizer.load(paths["content"])
    ds = NormalizedClips(StyleClips(paths["style"], "test", normalize=False, joints=False), norm.mean, norm.std)
    right = 0
    for i in range(len(ds)):
        it = ds[i]
        right += int(model.predict_style(it["features"][None])[0]) == it["style_index"]
    return 100.0 * right / len(ds)


def table3(paths, workdir: Path, sma_steps: int, n_pairs: int) -> dict:
    """Clustering (prototypes) vs a learnable classification head with CE: short runs, SRA by the evaluator."""
    from mslib.evaluation.bench import Evaluator, load_pairs
    from mslib.models import clusterstyle as C
    from mslib.models.clusterstyle import Pipeline
    from mslib.models.common.vae import load_vae
    pairs = load_pairs(seed=0, n_pairs=n_pairs)
    ev, vae = Evaluator(), load_vae()
    rows = []
    for head in ("classifier", "prototypes"):
        t0 = time.time()
        style_pt, sma_pt = workdir / f"style_{head}.pt", workdir / f"sma_{head}.pt"
        C.run_style("course", paths["content"], paths["style"], seed=0, out=style_pt, progress=False, head=head)
        C.run_sma("course", paths["content"], paths["style"], seed=0, out=sma_pt, steps=sma_steps, progress=False,
                  style_path=style_pt, vae=vae)
        pipe = Pipeline(C.load_clusterstyle(sma_pt), vae)
        rows.append({"head": head, "encoder_acc": round(encoder_accuracy(style_pt, paths), 2),
                     **scored_transfers(pipe, pairs, ev, ("sra", "sra_top3", "cra", "h", "fmd")),
                     "seconds": round(time.time() - t0, 1)})
        print(rows[-1], flush=True)
    return {"sma_steps": sma_steps, "pairs": n_pairs, "rows": rows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default=",".join(SECTIONS[:-1]),
                    help=f"comma-separated sections of {', '.join(SECTIONS)} (default: all but seeds)")
    ap.add_argument("--sma-steps", type=int, default=400)
    ap.add_argument("--pairs", type=int, default=100)
    ap.add_argument("--workdir", default="/tmp/clusterstyle_findings")
    ap.add_argument("--checkpoints", default="", help="seeds: comma-separated clusterstyle checkpoints of other seeds")
    args = ap.parse_args(argv)
    todo = args.only.split(",")
    unknown = sorted(set(todo) - set(SECTIONS))
    if unknown:
        ap.error(f"--only: unknown sections {unknown}; expected some of {', '.join(SECTIONS)}")
    import torch
    from mslib.data.corpora import load_builtin
    torch.manual_seed(0)
    paths = load_builtin(progress=False)
    workdir = Path(args.workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    result = {}
    if "fig5" in todo:
        t0 = time.time()
        result["fig5"] = fig5(paths)
        print("fig5", json.dumps(result["fig5"]["summary"]), f"{time.time() - t0:.0f} s", flush=True)
    if "table3" in todo:
        result["table3"] = table3(paths, workdir, args.sma_steps, args.pairs)
    if "guidance" in todo:
        result["guidance"] = guidance()
    if "seeds" in todo:
        result["seeds"] = seeds([c for c in args.checkpoints.split(",") if c])
    if "bench" in todo:
        from mslib.evaluation.bench import run_bench
        result["bench"] = {"rows": [run_bench(m) for m in ("clusterstyle", "identity", "copy_style")]}
        print("bench", json.dumps(result["bench"]), flush=True)
    command = recorded_command("clusterstyle_findings", argv if argv is not None else sys.argv[1:])
    from mslib.checkpoints import checkpoint_digest
    from mslib.models.common.vae import load_vae
    vae_cfg = load_vae().cfg
    for key, section in result.items():  # which run wrote it, on which course VAE latent and ClusterStyle checkpoint
        section.update(command=command, commit=current_commit(), vae_latent=[vae_cfg.latent_tokens, vae_cfg.latent_dim],
                       checkpoint=checkpoint_digest("clusterstyle_t2m" if key == "table3" else "clusterstyle"))
    update_json(OUT, result)  # the sections not re-run stay as they are (a parallel run's included)
    print(json.dumps({k: v for k, v in result.items() if k != "fig5"} | {"fig5": result.get("fig5", {}).get("summary")}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
