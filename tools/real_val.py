"""The course knobs on REAL validation pairs: each method tool's strength sweep, run again on held-out Xia takes
and judged by the real judges; writes notebooks/data/07_real_val.json.

    OMP_NUM_THREADS=1 python tools/real_val.py --xia-train XIA_TRAIN_BVH [--workdir DIR] \\
        [--methods adain,dsdn,contrastive,mcm_ldm,clusterstyle] [--pairs 200]

Every knob of the course presets (adain's style strength w, DSDN's correction strength κ, MCM-LDM's guidance
scale λ, ClusterStyle's style guidance weight) was first chosen on built-in val pairs only. Real motion capture
is the yardstick now, so the knobs are also scored on real pairs that no judge and no choice has seen:

- **the real val takes**: `data_prep.bvh` puts each take of the Xia *train* split into its own train, val or
  test split. The real judges (tools/real_bench.py's: the packaged evaluator's recipe, seed 0) train on its
  train split and stop on its val split, so its *test* split is unseen by them. Contents: its neutral takes;
  styles: all its takes (`real_pairs(..., split="test")`, a draw of `--pairs`, styles in turn). The Xia test
  grid is never read here.
- **the sweep**: each knob at the values its tool swept on built-in val pairs (read from the tool's stored
  JSON), the other knobs as packaged (MCM-LDM at its packaged DDIM steps, ClusterStyle at its packaged s_s).
- **the rule** (RULE, fixed before any real val pair was scored): the value with the highest mean of its
  built-in val H and its real val H. ContrastiveStyle's w is a policy (C's transfer, w = 1), so its rows are
  reported, not used to choose.

The choices are applied by hand (the preset and the packaged checkpoint's stored config), as each tool's are.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from mslib.cpu_paths import pin_cpu_code_paths  # noqa: E402

pin_cpu_code_paths()  # before numpy and torch load, as tools/real_bench.py
from tools.common import DATA_DIR, current_commit, update_json  # noqa: E402

OUT = DATA_DIR / "07_real_val.json"
METHODS = ("adain", "dsdn", "contrastive", "mcm_ldm", "clusterstyle")
POLICY = {"contrastive": "C's own transfer, w = 1"}
RULE = ("the knob value with the highest mean of its built-in val H (the method tool's stored sweep) and its real "
        "val H, among the values both scored (fixed before any real val pair was scored)")


def _stored(name: str) -> dict:
    path = DATA_DIR / name
    if not path.is_file():
        raise ValueError(f"{path}: no such file; run the method tool's sweep first")
    return json.loads(path.read_text())


def builtin_sweeps() -> dict:
    """method → (knob, packaged value, {value: built-in val H}) from each tool's stored sweep."""
    from mslib.checkpoints import read_checkpoint, course_path
    adain, dsdn = _stored("02_adain_variants.json")["strength"], _stored("05_dsdn_ablation.json")["strength"]
    contrastive = _stored("03_contrastive_recipes.json")["strength"]
    mcm = _stored("04_ablations.json")["choose"]
    cs_cfg = read_checkpoint(course_path("clusterstyle"), "clusterstyle")["config"]["model"]
    cs = [r for r in _stored("06_clusterstyle_findings.json")["guidance"]["rows"]
          if r["cfg_style"] == cs_cfg["cfg_style"]]
    mcm_cfg = read_checkpoint(course_path("mcm_ldm"), "mcm_ldm")["config"]
    dsdn_cfg = read_checkpoint(course_path("dsdn"), "dsdn")["config"]
    adain_cfg = read_checkpoint(course_path("adain"), "adain")["config"]
    return {
        "adain": ("w", adain_cfg["style_strength"], {r["strength"]: r["h"] for r in adain["rows"]}),
        "dsdn": ("κ", dsdn_cfg["correction_strength"], {r["strength"]: r["h"] for r in dsdn["rows"]}),
        "contrastive": ("w", contrastive["course_strength"], {r["strength"]: r["h"] for r in contrastive["rows"]}),
        "mcm_ldm": ("λ", mcm_cfg["cfg_scale"], {r["scale"]: r["h"] for r in mcm["rows"]}),
        "clusterstyle": ("guide_weight", cs_cfg["guide_weight"], {r["weight"]: r["h"] for r in cs}),
    }


def real_sweep(method: str, values, pairs, ev) -> list:
    """Rows {value, h, cra, sra} of `method` on the pairs at each knob value, judged by `ev`."""
    from tools import adain_variants, clusterstyle_findings, contrastive_findings, dsdn_ablation, mcm_ldm_ablations
    keys = ("h", "cra", "sra")
    if method == "adain":
        from mslib.models.adain import load_adain
        model = load_adain()
        rows = [adain_variants.score(model, pairs, ev, v) for v in values]
    elif method == "dsdn":
        rows = dsdn_ablation.strength_sweep(kappas=tuple(values), pairs=pairs, ev=ev)
    elif method == "contrastive":
        from mslib.models import contrastive as C
        model = C.load(None)
        rows = [contrastive_findings.score(model, pairs, ev, v) for v in values]
    elif method == "mcm_ldm":
        from mslib.models import mcm_ldm as P
        tr = P.load_mcm_ldm()
        rows = [mcm_ldm_ablations.scored(tr, pairs, ev, scale=v) for v in values]
    elif method == "clusterstyle":
        from mslib.models.clusterstyle import load_pipeline
        pipe = load_pipeline()
        ss = pipe.cfg.cfg_style  # the packaged s_s (its guidance rows were swept at it)
        rows = [clusterstyle_findings.scored_transfers(pipe, pairs, ev, keys, weight=v, cfg_style=ss) for v in values]
    else:
        raise ValueError(f"--methods: unknown method {method!r}; expected some of {', '.join(METHODS)}")
    out = [{"value": v, **{k: round(float(r[k]), 4) for k in keys}} for v, r in zip(values, rows)]
    for row in out:
        print(method, json.dumps(row), flush=True)
    return out


def choose(rows: list, builtin: dict) -> dict:
    """RULE on one method's real rows and its built-in val H by value: each row gains builtin_h and mean_h; the
    chosen value (a tie goes to the first, i.e. the smallest value)."""
    both = [r for r in rows if r["value"] in builtin]
    if not both:
        raise ValueError("no knob value was scored on both the built-in and the real val pairs")
    for r in both:
        r["builtin_h"] = builtin[r["value"]]
        r["mean_h"] = round((r["h"] + r["builtin_h"]) / 2, 4)
    best = max(sorted(both, key=lambda r: r["value"]), key=lambda r: r["mean_h"])
    return {"rows": both, "chosen": best["value"]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--xia-train", required=True, metavar="DIR", help="the Xia train split's BVH files")
    ap.add_argument("--workdir", default="real_bench_work", metavar="DIR",
                    help="converted folders and the real judges (tools/real_bench.py's; kept for the next run)")
    ap.add_argument("--methods", default=",".join(METHODS), help="comma-separated")
    ap.add_argument("--pairs", type=int, default=200, help="a draw of this many real val pairs")
    ap.add_argument("--no-save", action="store_true", help="print only; leave the stored JSON alone")
    args = ap.parse_args(argv)
    methods = [m for m in args.methods.split(",") if m]
    unknown = sorted(set(methods) - set(METHODS))
    if unknown:
        ap.error(f"--methods: unknown {unknown}; expected some of {', '.join(METHODS)}")
    import torch
    from mslib.checkpoints import checkpoint_digest
    from mslib.evaluation.bench import Evaluator
    from mslib.evaluation.real_pairs import real_pairs
    from mslib.evaluation.realism import folder_digest
    from tools.real_bench import convert_once, train_judges
    torch.set_num_threads(1)
    work = Path(args.workdir)
    work.mkdir(parents=True, exist_ok=True)
    train = convert_once(args.xia_train, work / "xia_train")
    judges = train_judges(train, work)
    pairs = real_pairs(train, n_pairs=args.pairs, split="test")
    ev = Evaluator(judges["content"], judges["style"])
    sweeps = builtin_sweeps()
    sections = {}
    for method in methods:
        knob, packaged, builtin = sweeps[method]
        t0 = time.time()
        part = choose(real_sweep(method, sorted(builtin), pairs, ev), builtin)
        if method in POLICY:
            part = {**part, "chosen": packaged, "policy": POLICY[method], "best_by_rule": part["chosen"]}
        sections[method] = {"knob": knob, "packaged": packaged, **part, "seconds": round(time.time() - t0, 1),
                            "checkpoint": checkpoint_digest("dsdn" if method == "dsdn" else method)}
        print(method, knob, "packaged", packaged, "chosen", sections[method]["chosen"], flush=True)
    if not args.no_save:
        update_json(OUT, {"rule": RULE, "pairs": len(pairs), "split": "test split of the converted Xia train split",
                          "contents": sorted({c["clip_id"] for c, _ in pairs}), "styles": len({s["clip_id"] for _, s in pairs}),
                          "data": {"xia_train": folder_digest(train)},
                          "command": f"python tools/real_val.py --xia-train XIA_TRAIN_BVH --pairs {args.pairs}",
                          "commit": current_commit(), **sections})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
