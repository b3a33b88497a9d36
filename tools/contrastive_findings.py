"""Paper C, design checks on the VALIDATION split (never the benchmark's test pairs).

    .venv/bin/python tools/contrastive_findings.py train VARIANT OUT.pt   # one training recipe
    .venv/bin/python tools/contrastive_findings.py val course OUT.pt       # H, CRA, SRA on a val draw
    .venv/bin/python tools/contrastive_findings.py strength                # the course model at several w
    .venv/bin/python tools/contrastive_findings.py window                  # … at several transfer windows
    .venv/bin/python tools/contrastive_findings.py ceiling [LABEL=PATH]    # what the evaluator reads (below)
    .venv/bin/python tools/contrastive_findings.py seeds A.pt B.pt         # the course recipe, other seeds (COURSE_RUN)
    .venv/bin/python tools/contrastive_findings.py styles [LABEL=PATH ...]  # SRA and CRA style by style

`train` trains one variant of the course preset, saving OUT every 1000 second-phase steps (`--resume` continues
a run that was cut from there). The recipes were compared at the course's earlier, shorter
schedule, 2500 autoencoder steps + 2500 steps of C Eq. 5 (`SHORT`), and keep it so their rows reproduce.
Every recipe but `course` and `course_views` pins `style_views` δ = 0, as the course preset had it when they
were compared (`PLAIN`). All draw M^T and M^S from content ∪ style (C's one set X), as the library does:
    union_short  the two phases: the autoencoder, then E_s frozen and all of C Eq. 5;
    union_mid    `union_short` with the second phase twice as long;
    plain        the course recipe before it took up `style_views`: `union_short` with a longer second phase
                 (the preset's steps);
    course_long  `plain` with the second phase twice as long (20000 steps of C Eq. 5);
    course_views `plain` with a judge trained to recognise recordings (`style_views` δ = 0.3, C's β and γ): in the
                 autoencoder phase, InfoNCE between E_s codes of two windows of one recording, the other recordings
                 in the batch its negatives (no labels), so the frozen E_s tells styles apart, not only what G needs;
                 adopted: the course preset since (the same config as `course`);
    course       the course recipe: the course preset as it is.
The recipe table also holds rows of variants that needed options since removed from the library (they
served these experiments only): `literal` (no content skip, no final instance norm of E_c), `joint`,
`autoencoder`, `across` (M^T from the content corpus, M^S from the style corpus), `d_real_both` (C Eq. 2's
D shown target clips as real too), `skip_adain` (the skip's movement rescaled by a σ from the style code),
`course_gain` (the skip's movement scaled by exp(A·(E_s(M^S) − E_s(M^T)))) and `course_negatives` (C Eq. 4
also against the batch's other sources). Their rows keep their numbers, commands and commits; they
reproduce at commit 3748be4 (`git checkout 3748be4`, then the row's command, `train VARIANT` for the models).

`val` scores checkpoints ("course" = the packaged one) with the independent evaluator on 200
(content, style) pairs drawn from the val splits, styles in turn, and reports how often the predicted
content is the *style* clip's content (content leaking through the style code), all at C's transfer
(style strength w = 1). `strength` scores the packaged checkpoint on the same pairs at several w
(E_s(M^T) + w·(E_s(M^S) − E_s(M^T))), w > 1 included: would another w than C's do better? `window` scores it
at several transfer windows (WINDOWS; the built-in half of how the course's `transfer_window` is chosen,
tools/real_val.py adds real val pairs). `ceiling`
scores, on the same pairs, transfers that learn nothing: the target's features with their time
mean moved a fraction w_μ toward the style clip's and their movement scaled per dimension by
(σ_style/σ_target)^w_σ, i.e. A Eq. 2 applied to the raw features; then it splits the packaged model's
transfer into its time mean (the posture) and the movement around it, swapping each for the target's own,
and measures how far the posture moves toward the style clip's; paper A's course model (notebook 02) is
scored and measured the same way, for comparison (`ceiling LABEL=PATH` does it for another checkpoint and
saves it as `ceiling_LABEL`). `seeds` scores the packaged checkpoint beside the
course recipe trained with the other seeds (`COURSE_RUN --seed N --out OUT`), at C's transfer (w = 1, as the
recipe rows; also at the course style strength if that is not 1): how much of a difference between two
recipes one training run's luck can make, and which seed's run is packaged (SEED_RULE). With `--save` each writes its part of
notebooks/data/03_contrastive_recipes.json, which notebook 03 reads, with the command and the commit that made
it; `val --save` replaces the rows of the labels it scores (keeping the others, each row with its own command
and commit). The findings (a)–(d) themselves: `python tools/contrastive_analysis.py`.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tools.common import DATA_DIR, ROOT, current_commit, score_outputs, update_json, val_pairs  # noqa: E402

from mslib.checkpoints import course_path, trained_seed  # noqa: E402
from mslib.data.corpora import load_builtin, take_of  # noqa: E402
from mslib.evaluation.bench import Evaluator, by_style  # noqa: E402
from mslib.evaluation.embedding import nearest_neighbour_purity  # noqa: E402
from mslib.models import contrastive as C  # noqa: E402
from mslib.models.adain import load_adain  # noqa: E402
from mslib.motion.features import BLOCKS, TRAJECTORY_DIMS, decode  # noqa: E402

RECIPES_JSON = DATA_DIR / "03_contrastive_recipes.json"
SHORT = dict(pretrain_steps=2500, steps=2500)  # the schedule the recipes were compared at (autoencoder + C Eq. 5)
PLAIN = dict(style_views=0.0)  # every recipe compared before the course preset took up `style_views`
VARIANTS = {  # overrides of the course preset (the removed variants: module docstring)
    "union_short": dict(**SHORT, **PLAIN),
    "union_mid": dict(pretrain_steps=SHORT["pretrain_steps"], steps=2 * SHORT["steps"], **PLAIN),
    "course_long": dict(steps=20000, **PLAIN),
    "plain": dict(**PLAIN),
    "course_views": dict(style_views=0.3),
    "course": {},
}


# How the course runs were trained (single-threaded: two at a time on a 2-core machine).
COURSE_RUN = "OMP_NUM_THREADS=1 python -m mslib train contrastive --preset course"


def merge_rows(saved: dict, rows: list, command: str, commit: str) -> list:
    """The saved recipe rows with `rows` (scored by `command` at `commit`) in place of the rows of the same
    labels; new labels go before the `course` row."""
    merged = list(saved.get("rows", []))
    at = {r["variant"]: i for i, r in enumerate(merged)}
    for row in rows:
        row = {**row, "command": command, "commit": commit}
        if row["variant"] in at:
            merged[at[row["variant"]]] = row
        else:
            merged.insert(at.get("course", len(merged)), row)
            at = {r["variant"]: i for i, r in enumerate(merged)}
    return merged


def rounded(row: dict) -> dict:
    """A row of metrics with its numbers rounded for the JSON."""
    return {k: round(float(v), 4) for k, v in row.items()}


def best_seed(rows, strength: float) -> int:
    """SEED_RULE: the seed of the row with the highest H among those at `strength`."""
    at = [r for r in rows if r["strength"] == strength]
    if not at:
        raise ValueError(f"seeds: no row at the course style strength {strength}")
    return max(at, key=lambda r: r["h"])["seed"]


def score(model, pairs, evaluator, strength=None, window=None) -> dict:
    """Bench metrics on the pairs, plus the share of outputs classified as the style clip's content (`strength`
    and `window`: the transfer's, default the model's config)."""
    outs = [decode(model.transfer_features(c["features"], s["features"], strength, window)) for c, s in pairs]
    row = score_outputs(outs, pairs, evaluator)
    c_logits = evaluator.score(outs)[0]
    pred = [evaluator.content.classes[i] for i in c_logits.argmax(1)]
    leak = np.mean([p == s["content"] != c["content"] for p, (c, s) in zip(pred, pairs)])
    return {"h": row["h"], "cra": row["cra"], "sra": row["sra"], "fmd": row["fmd"],
            "content_from_style_clip": 100.0 * float(leak)}


SEED_RULE = "package the seed with the highest H on the val pairs at the course style strength"
STRENGTHS = (0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.2, 1.4)
WINDOWS = (0, 32, 48, 64, 96)  # transfer windows (rows; 0: the whole clip, C's own) of the `window` sweep
STATS_MIXES = ((0.0, 0.0), (1.0, 0.0), (0.5, 0.0), (0.5, 0.5))  # (w_μ, w_σ) of the no-learning transfers; (0, 0): identity


def stats_mix(content: np.ndarray, style: np.ndarray, w_mean: float, w_std: float) -> np.ndarray:
    """A Eq. 2 on the raw (T, D) features, partway: (c − μ(c))·(σ(s)/σ(c))^w_σ + μ(c) + w_μ·(μ(s) − μ(c));
    the root trajectory (TRAJECTORY_DIMS) stays the content's. w_σ = 0, w_μ = 1: c's movement on s's posture."""
    mu_c, mu_s = content.mean(0), style.mean(0)
    gain = ((style.std(0) + 1e-3) / (content.std(0) + 1e-3)) ** w_std
    out = (content - mu_c) * gain + mu_c + w_mean * (mu_s - mu_c)
    out[:, TRAJECTORY_DIMS] = content[:, TRAJECTORY_DIMS]
    return out


def posture_moved(out: np.ndarray, content: np.ndarray, style: np.ndarray) -> float:
    """How far the time mean of the root-relative joints (the ric block) moved from the content's toward
    the style clip's: the projection ⟨μ(out) − μ(c), μ(s) − μ(c)⟩ / ‖μ(s) − μ(c)‖² (0: not at all, 1: all the way)."""
    ric = BLOCKS["ric"]
    d_out, d_s = out[:, ric].mean(0) - content[:, ric].mean(0), style[:, ric].mean(0) - content[:, ric].mean(0)
    return float(d_out @ d_s / max(d_s @ d_s, 1e-12))


def ceiling(model, pairs, evaluator) -> dict:
    """The no-learning transfers, the packaged model's transfer split into posture and movement, and its posture shift."""
    def row(label, feats):
        r = score_outputs([decode(f) for f in feats], pairs, evaluator)
        out = {"transfer": label, **rounded({k: r[k] for k in ("h", "cra", "sra", "fmd")})}
        print(out, flush=True)
        return out
    cs = [(c["features"].astype(np.float64), s["features"].astype(np.float64)) for c, s in pairs]
    rows = [row(f"statistics, w_mean={wm}, w_std={ws}", [stats_mix(c, s, wm, ws) for c, s in cs])
            for wm, ws in STATS_MIXES]
    outs = [model.transfer_features(c, s) for c, s in cs]  # root trajectory: the content's
    rows.append(row("course model", outs))
    rows.append(row("course model's posture, target's movement", [stats_mix(c, o, 1.0, 0.0) for o, (c, _) in zip(outs, cs)]))
    rows.append(row("target's posture, course model's movement", [stats_mix(o, c, 1.0, 0.0) for o, (c, _) in zip(outs, cs)]))
    moved = [posture_moved(o, c, s) for o, (c, s) in zip(outs, cs)]
    adain = load_adain()  # for comparison: paper A's course model (notebook 02), a transfer of feature statistics
    a_outs = [adain.transfer_features(c, s) for c, s in cs]
    rows.append(row("paper A course model", a_outs))
    a_moved = [posture_moved(o, c, s) for o, (c, s) in zip(a_outs, cs)]
    return {"rows": rows, "strength": model.cfg.style_strength,
            "posture_moved_median": round(float(np.median(moved)), 4),
            "adain_posture_moved_median": round(float(np.median(a_moved)), 4)}


def labelled_models(checkpoints) -> list:
    """(label, model) for each `course` (the packaged checkpoint), PATH (labelled by its stem) or LABEL=PATH;
    every path is checked before any is loaded."""
    found = [arg.rpartition("=")[::2] if "=" in arg else (Path(arg).stem, arg) for arg in checkpoints]
    for _, ck in found:
        if ck != "course" and not Path(ck).is_file():
            raise SystemExit(f"checkpoint {ck}: no such file")
    return [(label, C.load(None if ck == "course" else ck)) for label, ck in found]


def styles(pairs, evaluator, checkpoints=()) -> list:
    """`by_style` rows of the packaged model, the half-posture mix and each checkpoint (`labelled_models`, w = 1);
    for a model also how often a style clip's nearest style code from another take (E_s, the pairs' clips) shares its style."""
    models = [("course model", C.load()), *labelled_models(checkpoints)]
    mix = ("statistics, w_mean=0.5, w_std=0.0", None)  # no model: A Eq. 2 on the raw features, the posture halfway
    out = []
    for label, model in [models[0], mix, *models[1:]]:
        feats = [model.transfer_features(c["features"], s["features"], 1.0) if model is not None
                 else stats_mix(c["features"].astype(np.float64), s["features"].astype(np.float64), 0.5, 0.0)
                 for c, s in pairs]
        rows = [{**r, **rounded({k: r[k] for k in ("sra", "cra", "read_as_share")})}
                for r in by_style([decode(f) for f in feats], pairs, evaluator)]
        if model is not None:  # can its own judge, E_s, tell the style clips apart?
            clips = list({s["clip_id"]: s for _, s in pairs}.values())  # each style clip once
            codes, labels = model.style_codes([s["features"] for s in clips]), [s["style"] for s in clips]
            takes = [take_of(s["clip_id"]) for s in clips]  # a neighbour from another recording, not a window of the same
            for r in rows:
                r["es_nn_purity"] = round(100.0 * nearest_neighbour_purity(codes, labels, r["style"], takes), 4)
                r["es_clips"] = labels.count(r["style"])  # the purity a code with no style in it would get: about n/N
                r["es_chance"] = round(100.0 * r["es_clips"] / len(labels), 4)
        out.append({"transfer": label, "rows": rows})
        for r in rows:
            print(label, r, flush=True)
    return out


def _command(argv) -> str:
    return " ".join(["python tools/contrastive_findings.py", *(argv if argv is not None else sys.argv[1:])])


def save(sections: dict) -> None:
    """Replace `sections` of the JSON notebook 03 reads, keeping the sections not re-run (written atomically)."""
    print(update_json(RECIPES_JSON, sections))


def _made(command: str) -> dict:
    """A section's provenance: the command that made it and the commit it ran at."""
    return {"command": command, "commit": current_commit()}


def main(argv=None) -> int:
    """Command line (module docstring)."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("train")
    t.add_argument("variant", choices=sorted(VARIANTS))
    t.add_argument("out")
    t.add_argument("--seed", type=int, default=0)
    t.add_argument("--checkpoint-every", type=int, default=1000, metavar="N",
                   help="save OUT every N second-phase steps (0: only at the end)")
    t.add_argument("--resume", action="store_true", help="continue from OUT, saved by a run that was cut")
    w = sub.add_parser("strength", help="the packaged checkpoint at several style strengths on the val pairs")
    w.add_argument("--save", action="store_true")
    n = sub.add_parser("window", help="the packaged checkpoint at several transfer windows on the val pairs")
    n.add_argument("--save", action="store_true")
    g = sub.add_parser("ceiling", help="no-learning transfers and the packaged model's posture and movement")
    g.add_argument("checkpoint", nargs="?", default="course", help="`course` (the packaged one) or LABEL=PATH")
    g.add_argument("--save", action="store_true")
    d = sub.add_parser("seeds", help=f"the course recipe trained with other seeds ({COURSE_RUN} --seed N --out OUT), "
                                     "scored beside the packaged checkpoint at w = 1 (and the course style strength)")
    d.add_argument("checkpoints", nargs="+", help=f"checkpoints made by {COURSE_RUN} --seed N --out OUT")
    d.add_argument("--save", action="store_true")
    y = sub.add_parser("styles", help="SRA and CRA style by style: the packaged model, the half-posture mix, checkpoints")
    y.add_argument("checkpoints", nargs="*", help="`course`, a path, or LABEL=PATH")
    y.add_argument("--save", action="store_true")
    v = sub.add_parser("val")
    v.add_argument("checkpoints", nargs="+", help="`course`, a path, or LABEL=PATH")
    v.add_argument("--save", action="store_true", help=f"write the rows to {RECIPES_JSON.relative_to(ROOT)}")
    args = p.parse_args(argv)
    if args.cmd == "train":
        paths = load_builtin(progress=False)
        cfg = C.ContrastiveConfig.preset("course", **VARIANTS[args.variant])
        if args.resume and not Path(args.out).is_file():
            raise SystemExit(f"--resume: {args.out} does not exist")
        C.train(cfg, paths["content"], paths["style"], seed=args.seed, out=args.out,
                resume=args.out if args.resume else None, checkpoint_every=args.checkpoint_every)
        print(args.out)
        return 0
    pairs, evaluator = val_pairs(200), Evaluator()
    if args.cmd == "ceiling":
        if args.checkpoint != "course" and "=" not in args.checkpoint:
            raise SystemExit(f"ceiling: expected `course` or LABEL=PATH, got {args.checkpoint!r}")
        [(label, model)] = labelled_models([args.checkpoint])
        part = ceiling(model, pairs, evaluator)
        print("posture moved (median):", part["posture_moved_median"])
        if args.save:
            save({"ceiling" if label == "course" else f"ceiling_{label}": {**_made(_command(argv)), **part}})
        return 0
    if args.cmd == "seeds":
        models, trained = {}, []
        for ck in [None, *args.checkpoints]:  # check every checkpoint before scoring any
            if ck is not None and not Path(ck).is_file():
                raise SystemExit(f"checkpoint {ck}: no such file")
            model = C.load(ck)
            course = C.ContrastiveConfig.preset("course")  # the transfer window is inference only: not compared
            if dataclasses.replace(model.cfg, transfer_window=course.transfer_window) != course:
                raise SystemExit(f"checkpoint {ck or 'packaged'}: not trained with the course preset")
            seed = trained_seed(ck or course_path(C.NAME), C.NAME)
            if seed in models:
                raise SystemExit(f"checkpoint {ck}: seed {seed} twice")
            models[seed] = model
            if ck is not None:
                trained.append(f"{COURSE_RUN} --seed {seed} --out {Path(ck).name}")
        rows, packaged_seed = [], next(iter(models))  # the packaged checkpoint is read (and scored) first
        window = models[packaged_seed].cfg.transfer_window  # every seed at the packaged transfer window
        for seed, model in models.items():
            for st in sorted({1.0, model.cfg.style_strength}):  # C's transfer (the recipe table's w) and the course w
                rows.append({"seed": seed, "strength": st, "window": window,
                             **rounded(score(model, pairs, evaluator, st, window))})
                print(rows[-1], flush=True)
        if args.save:  # the command as a reader reruns it: train each seed, then score
            names = " ".join(Path(ck).name for ck in args.checkpoints)
            save({"seeds": {**_made(" && ".join([*trained, f"python tools/contrastive_findings.py seeds {names} --save"])),
                            "rows": rows, "packaged_seed": packaged_seed, "rule": SEED_RULE,
                            "best_seed": best_seed(rows, C.ContrastiveConfig.preset("course").style_strength)}})
        return 0
    if args.cmd == "styles":
        part = {**_made(_command(argv)), "transfers": styles(pairs, evaluator, args.checkpoints)}
        if args.save:
            save({"styles": part})
        return 0
    if args.cmd == "window":
        model = C.load()
        sweep = []
        for n_rows in WINDOWS:
            sweep.append({"window": n_rows, **rounded(score(model, pairs, evaluator, window=n_rows))})
            print(sweep[-1], flush=True)
        if args.save:
            save({"window": {**_made(_command(argv)), "course_window": model.cfg.transfer_window, "rows": sweep}})
        return 0
    if args.cmd == "strength":
        model = C.load()
        sweep = []
        for st in STRENGTHS:
            sweep.append({"strength": st, **rounded(score(model, pairs, evaluator, st))})
            print(sweep[-1], flush=True)
        if args.save:
            save({"strength": {**_made(_command(argv)), "course_strength": model.cfg.style_strength, "rows": sweep}})
        return 0
    rows = []
    for label, model in labelled_models(args.checkpoints):
        row = {"variant": label, **rounded(score(model, pairs, evaluator, 1.0)),
               "steps": [model.cfg.pretrain_steps, model.cfg.steps], "pairs": "union"}  # M^T, M^S ~ content ∪ style
        rows.append(row)
        print(row, flush=True)
    if args.save:
        saved = json.loads(RECIPES_JSON.read_text()) if RECIPES_JSON.is_file() else {}
        if saved.get("val_pairs", len(pairs)) != len(pairs):
            raise SystemExit(f"{RECIPES_JSON}: rows scored on {saved['val_pairs']} pairs, these on {len(pairs)}")
        save({"val_pairs": len(pairs), "rows": merge_rows(saved, rows, _command(argv), current_commit())})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
