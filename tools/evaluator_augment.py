"""Which training augmentation (or regularisation) lets the built-in style evaluator recognise real styles: a
search, chosen on real TRAIN takes only.

    .venv/bin/python tools/evaluator_augment.py --real XIA_TRAIN_DIR [--grid XIA_GRID_DIR] [--only NAME,...]
    .venv/bin/python tools/evaluator_augment.py --summarise

XIA_TRAIN_DIR and XIA_GRID_DIR are dataset folders made by `python -m data_prep.bvh … --labels xia`. Each
candidate (CANDIDATES) trains the style evaluator on the built-in style corpus with the course preset and one
change — an `Augment`, a shorter schedule, weight decay, a slower learning rate, more dropout or a narrower
net (regularisers that might keep it from the generator's quirks) — then scores it on the built-in val and test clips and on every real
train take (whole takes, window-averaged). Rule (RULE): the highest accuracy on the real train takes among
candidates that keep the built-in val clips ≥ BUILTIN_FLOOR %, averaged over SEEDS. The grid's takes are
scored for the record only — never read by the rule. Rows land in notebooks/data/00_evaluator_augment.json;
rows already there are kept unless re-run; `--summarise` only re-reads them.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tools.common import DATA_DIR, current_commit, update_json  # noqa: E402

OUT = DATA_DIR / "00_evaluator_augment.json"
CANDIDATES = {  # name → (Augment fields, training overrides of the course preset, network sizes)
    "none": ({}, {}, {}),
    "mirror": ({"mirror": 0.5}, {}, {}),
    "tempo": ({"tempo": 0.25}, {}, {}),
    "noise": ({"noise": 0.1}, {}, {}),
    "mirror+tempo": ({"mirror": 0.5, "tempo": 0.25}, {}, {}),
    "all": ({"mirror": 0.5, "tempo": 0.25, "noise": 0.1}, {}, {}),
    "shorter": ({}, {"steps": 400}, {}),
    "all+shorter": ({"mirror": 0.5, "tempo": 0.25, "noise": 0.1}, {"steps": 400}, {}),
    "weight-decay": ({}, {"weight_decay": 0.5}, {}),
    "slower-lr": ({}, {"lr": 5e-4}, {}),
    "dropout-0.5": ({}, {}, {"dropout": 0.5}),
    "narrow": ({}, {}, {"width": 32, "feature_dim": 32}),
}
SEEDS = (0, 1)
BUILTIN_FLOOR = 95.0
RULE = (f"the highest mean accuracy on the real TRAIN takes over seeds {list(SEEDS)}, among candidates whose "
        f"built-in val accuracy stays ≥ {BUILTIN_FLOOR:g} %; adopted for the packaged evaluator only if it beats "
        f"'none' by more than the widest seed spread of any candidate (else the difference is seed luck)")


def summarise(rows) -> dict:
    """Per-candidate means over SEEDS, the candidate RULE chooses, and whether its gain beats the seed spread."""
    summary, spread = {}, 0.0
    for name in CANDIDATES:
        mine = [r for r in rows if r["candidate"] == name and r["seed"] in SEEDS]
        if len(mine) != len(SEEDS):
            continue
        mean = lambda k: round(sum(r[k] for r in mine) / len(mine), 2)  # noqa: E731
        summary[name] = {k: mean(k) for k in ("builtin_val", "builtin_test", "real_train_takes")}
        if all(r["grid_takes"] is not None for r in mine):
            summary[name]["grid_takes"] = mean("grid_takes")
        real = [r["real_train_takes"] for r in mine]
        spread = max(spread, max(real) - min(real))
    ok = {n: s for n, s in summary.items() if s["builtin_val"] >= BUILTIN_FLOOR}
    best = max(ok, key=lambda n: ok[n]["real_train_takes"]) if ok else None
    gain = round(ok[best]["real_train_takes"] - summary["none"]["real_train_takes"], 2) \
        if best is not None and "none" in summary else None
    return {"summary": summary, "chosen": best, "gain": gain, "spread": round(spread, 2),
            "adopted": bool(best not in (None, "none") and gain is not None and gain > spread)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--real", help="the real train split, a dataset folder (fitting and choosing)")
    ap.add_argument("--grid", help="the real test grid, a dataset folder (reported only, never chosen on)")
    ap.add_argument("--only", default=",".join(CANDIDATES), help=f"comma-separated, of: {', '.join(CANDIDATES)}")
    ap.add_argument("--summarise", action="store_true", help="train nothing: re-summarise the stored rows")
    args = ap.parse_args(argv)
    todo = [] if args.summarise else args.only.split(",")
    unknown = [n for n in todo if n not in CANDIDATES]
    if unknown:
        ap.error(f"--only: unknown candidate {unknown[0]!r}; expected some of {', '.join(CANDIDATES)}")
    if not todo:
        return report()
    if not args.real:
        ap.error("--real: the real train split's dataset folder is needed to score the candidates")
    import torch
    from mslib.data.corpora import load_builtin
    from mslib.evaluation.evaluator import Augment, test_accuracy, train_classifier
    from mslib.evaluation.realism import read_clips, take_scores
    torch.set_num_threads(1)
    style = load_builtin(progress=False)["style"]
    real = read_clips(args.real, "--real")
    grid = read_clips(args.grid, "--grid") if args.grid else None
    command = (f"python tools/evaluator_augment.py --real XIA_TRAIN_DIR{' --grid XIA_GRID_DIR' if grid else ''} "
               f"--only {args.only}")  # the folders' names stay on this machine
    commit = current_commit()
    for name in todo:
        for seed in SEEDS:
            t0 = time.time()
            fields, overrides, net = CANDIDATES[name]
            model, _ = train_classifier("style", style, seed=seed, progress=False, augment=Augment(**fields),
                                        net=net, **overrides)
            row = {"candidate": name, "augment": fields, "overrides": overrides, "net": net, "seed": seed,
                   "builtin_val": round(test_accuracy(model, style, "val"), 2),
                   "builtin_test": round(test_accuracy(model, style, "test"), 2),
                   "real_train_takes": take_scores(model, real)["accuracy"],
                   "grid_takes": take_scores(model, grid)["accuracy"] if grid else None,
                   "seconds": round(time.time() - t0, 1), "command": command, "commit": commit}
            print(json.dumps(row), flush=True)
            old = json.loads(OUT.read_text())["rows"] if OUT.is_file() else []  # re-read: parallel runs merge
            keep = [r for r in old if (r["candidate"], r["seed"]) != (name, seed)]
            update_json(OUT, {"rows": keep + [row]})
    return report()


def report() -> int:
    """Summarise the stored rows into OUT and print them."""
    result = summarise(json.loads(OUT.read_text())["rows"])
    update_json(OUT, {**result, "rule": RULE})
    for n, s in result["summary"].items():
        print(f"{n:14s} " + "  ".join(f"{k} {v:6.2f}" for k, v in s.items()) + ("  ← chosen" if n == result["chosen"] else ""))
    print(f"adopted: {result['adopted']} (gain over 'none' {result['gain']}, widest seed spread {result['spread']})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
