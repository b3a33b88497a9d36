"""Paper B Table 2 on the built-in data: short MCM-LDM runs with one switch flipped, and a λ sweep of the
packaged model, scored by the independent evaluator on benchmark pairs; writes notebooks/data/04_ablations.json.

    python tools/mcm_ldm_ablations.py [--steps 3000] [--pairs 100] [--only full,no_remover,...]

The JSON records the packaged VAE's latent (arch, tokens, width); rows measured through another VAE are stale.
Variants: full (short run, the reference for the switches), no_remover (use_remover=False), no_traj
(use_traj=False), scratch_style (pretrained_style=False); sweep: the packaged course model at
λ ∈ {0, 1, 2.5, 5} (B's λ claim, on the benchmark pairs); choose: the packaged model at λ ∈ VAL_SCALES on
200 VALIDATION pairs — the built-in half of how the course preset's `cfg_scale` is chosen (tools/real_val.py
adds real val pairs) — and then, at the course λ, at DDIM steps ∈ VAL_STEPS: how `ddim_steps` is chosen (the
fewest steps whose val H is within STEPS_TOLERANCE of the most steps'; fewer steps are proportionally faster),
stored as the section "choose"; seeds: the course recipe trained again with other seeds (`--seeds`; by default
those of 0–2 that did not make the packaged model), each scored beside the packaged model (labelled by the seed
it stores) on the same 200 val pairs at the course λ and steps — how the packaged seed is chosen (SEED_RULE),
stored as the section "seeds". Rows already in the JSON are kept unless re-run. Every row names its "commit": HEAD
when this tool measured it (the table itself lands in a later commit); rows stored before rows carried
one name the commit that stored them.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tools.common import (DATA_DIR, current_commit, recorded_command, score_outputs, update_json,  # noqa: E402
                          val_pairs)

VARIANTS = {"full": {}, "no_remover": {"use_remover": False}, "no_traj": {"use_traj": False},
            "scratch_style": {"pretrained_style": False}}
LABELS = {"full": "full (short run)", "no_remover": "w/o StyleRemover", "no_traj": "w/o trajectory",
          "scratch_style": "style extractor from scratch"}
OUT = DATA_DIR / "04_ablations.json"
VAL_SCALES = (1.0, 1.25, 1.5, 2.0, 2.5, 3.0)
VAL_STEPS = (20, 30, 40, 50)
STEPS_TOLERANCE = 0.01
SEED_RULE = "package the seed with the highest H on 200 val pairs at the course λ and DDIM steps"
DEFAULT_SEEDS = (0, 1, 2)
METRICS = ("cra", "sra", "h", "tsi", "fsf", "fmd")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--pairs", type=int, default=100)
    ap.add_argument("--only", default="full,no_remover,no_traj,scratch_style,sweep",
                    help="comma-separated: full, no_remover, no_traj, scratch_style, sweep, choose, seeds")
    ap.add_argument("--seeds", default=None,
                    help="seeds section: comma-separated seeds to train besides the packaged one's (default: the rest of 0,1,2)")
    ap.add_argument("--workdir", default="/tmp/mcm_ldm_ablations")
    args = ap.parse_args(argv)
    from mslib.checkpoints import checkpoint_digest
    from mslib.data.corpora import load_builtin
    from mslib.evaluation.bench import Evaluator, load_pairs
    from mslib.models import mcm_ldm as P
    from mslib.models.common.vae import load_vae

    paths = load_builtin(progress=False)
    pairs = load_pairs(seed=0, n_pairs=args.pairs)
    ev = Evaluator()
    rows = {}
    todo = args.only.split(",")
    prepared = None
    Path(args.workdir).mkdir(parents=True, exist_ok=True)
    command = recorded_command("mcm_ldm_ablations", argv if argv is not None else sys.argv[1:])
    commit = current_commit()

    def score(tr, scale=None):
        return scored(tr, pairs, ev, scale=scale)

    for key in (k for k in VARIANTS if k in todo):
        if prepared is None:
            prepared = P.prepare(paths["content"], paths["style"], windows=True)
        out = Path(args.workdir) / f"{key}.pt"
        t0 = time.time()
        summary = P.run("course", paths["content"], paths["style"], seed=0, out=out, steps=args.steps,
                        progress=False, overrides=VARIANTS[key], prepared=prepared)
        tr = P.load_mcm_ldm(out)
        rows[key] = {"key": key, "variant": LABELS[key], **score(tr), "steps": summary["steps"],
                     "train_seconds": summary["seconds"], "wall_seconds": round(time.time() - t0, 1),
                     "command": command, "commit": commit}
        print(json.dumps(rows[key]), flush=True)
    if "sweep" in todo:
        tr = P.load_mcm_ldm()
        for lam in (0.0, 1.0, 2.5, 5.0):
            key = f"lambda_{lam}"
            rows[key] = {"key": key, "variant": f"course model, λ = {lam}", **score(tr, lam),
                         "command": command, "commit": commit, "checkpoint": checkpoint_digest("mcm_ldm")}
            print(json.dumps(rows[key]), flush=True)
    if "choose" in todo:
        tr, vpairs = P.load_mcm_ldm(), val_pairs(200)

        def val_row(**knob):
            row = {**knob, **scored(tr, vpairs, ev, **knob)}
            print(json.dumps(row), flush=True)
            return row
        val = [val_row(scale=lam, steps=max(VAL_STEPS)) for lam in VAL_SCALES]
        best = max(val, key=lambda r: r["h"])["scale"]
        course = tr.model.cfg.cfg_scale  # the packaged λ (chosen on built-in and real val pairs)
        steps_rows = [val_row(scale=course, steps=n) for n in VAL_STEPS]
        most = next(r["h"] for r in steps_rows if r["steps"] == max(VAL_STEPS))
        best_steps = min(r["steps"] for r in steps_rows if r["h"] >= most - STEPS_TOLERANCE)
        update_json(OUT, {"choose": {"rows": val, "best_scale": best, "rule": "the highest H on 200 val pairs",
                                     "steps_rows": steps_rows, "best_steps": best_steps,
                                     "steps_rule": f"the fewest DDIM steps with val H within {STEPS_TOLERANCE} of "
                                                   f"{max(VAL_STEPS)} steps' (at the course λ)",
                                     "steps_scale": course,
                                     "val_pairs": 200, "checkpoint": checkpoint_digest("mcm_ldm"),
                                     "command": command, "commit": commit}})
    if "seeds" in todo:
        seeds = None if args.seeds is None else [int(x) for x in args.seeds.split(",")]
        update_json(OUT, {"seeds": seed_rows(P, paths, seeds, Path(args.workdir), ev, command, commit)})
    if set(todo) <= {"choose", "seeds"}:
        return 0
    old = json.loads(OUT.read_text())["rows"] if OUT.is_file() else []  # re-read: parallel runs merge
    rows = {**{r["key"]: r for r in old}, **rows}
    order = list(VARIANTS) + [f"lambda_{x}" for x in (0.0, 1.0, 2.5, 5.0)]
    vcfg = load_vae().cfg  # the VAE every row was measured through (the notebook checks it still matches)
    update_json(OUT, {"command": command, "commit": commit, "pairs": args.pairs,
                      "rows": [dict(sorted(rows[k].items())) for k in order if k in rows], "seed": 0,
                      "steps": args.steps,
                      "vae": {"arch": vcfg.arch, "latent_dim": vcfg.latent_dim, "latent_tokens": vcfg.latent_tokens}})
    return 0


def scored(tr, pairs, ev, **knob) -> dict:
    """METRICS (rounded) of a transfer function's outputs on (content, style) pairs; `knob`: scale, steps."""
    from mslib.evaluation.bench import positions
    r = score_outputs([positions(tr(c["features"], s["features"], **knob)) for c, s in pairs], pairs, ev)
    return {k: round(r[k], 4) for k in METRICS}


def seeds_to_train(packaged_seed: int, seeds=None) -> list:
    """The seeds the seeds section trains: `seeds`, or by default DEFAULT_SEEDS but the packaged model's."""
    seeds = [s for s in DEFAULT_SEEDS if s != packaged_seed] if seeds is None else list(seeds)
    if packaged_seed in seeds:
        raise ValueError(f"--seeds: seed {packaged_seed} made the packaged checkpoint (scored as it is); name others")
    return seeds


def seed_rows(P, paths, seeds, workdir: Path, ev, command: str, commit: str) -> dict:
    """The packaged model and the course recipe at other seeds, scored on val pairs at the course λ and steps."""
    from mslib.checkpoints import checkpoint_digest, course_path, trained_seed
    from mslib.data.corpora import source_fingerprint
    vpairs, corpus = val_pairs(200), source_fingerprint()

    def val_h(tr, seed, **extra):  # every seed at the packaged λ and steps, whatever its own file stores
        knob = {"scale": packaged.model.cfg.cfg_scale, "steps": packaged.model.cfg.ddim_steps}
        row = {"seed": seed, **scored(tr, vpairs, ev, **knob), "corpus": corpus, "commit": commit, **extra}
        print(json.dumps(row), flush=True)
        return row
    packaged_seed = trained_seed(course_path("mcm_ldm"), "mcm_ldm")
    seeds = seeds_to_train(packaged_seed, seeds)
    packaged = P.load_mcm_ldm()
    rows = {packaged_seed: val_h(packaged, packaged_seed, checkpoint=checkpoint_digest("mcm_ldm"))}
    prepared = P.prepare(paths["content"], paths["style"], windows=True) if seeds else None
    for seed in seeds:
        out = workdir / f"seed{seed}.pt"
        summary = P.run("course", paths["content"], paths["style"], seed=seed, out=out, progress=False,
                        prepared=prepared)
        rows[seed] = val_h(P.load_mcm_ldm(out), seed, train_seconds=summary["seconds"])
    old = json.loads(OUT.read_text()).get("seeds", {}).get("rows", []) if OUT.is_file() else []
    rows = {**{r["seed"]: r for r in old if r.get("corpus") == corpus}, **rows}  # parallel runs merge
    ordered = [rows[k] for k in sorted(rows)]
    return {"rows": ordered, "rule": SEED_RULE, "best_seed": max(ordered, key=lambda r: r["h"])["seed"],
            "scale": packaged.model.cfg.cfg_scale, "ddim_steps": packaged.model.cfg.ddim_steps, "val_pairs": 200,
            "command": command}


if __name__ == "__main__":
    raise SystemExit(main())
