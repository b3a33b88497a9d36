"""The benchmark on real motion capture, judged twice; writes notebooks/data/07_real_bench.json.

    python tools/real_bench.py --xia-train XIA_TRAIN_BVH --xia-grid XIA_GRID_BVH \\
        --content HML_DIR/walk_circle.npy=walk HML_DIR/jump.npy=jump ... [--workdir DIR] [--methods all]

1. Converts both Xia splits with `python -m data_prep.bvh DIR OUT --dialect auto --labels xia` into the
   work folder (a second run reuses them).
2. Trains the *real judges* on the Xia train split only — the style classifier and the content classifier of
   the packaged evaluator's recipe (`python -m mslib train evaluator_style --style WORK/xia_train`, and
   `evaluator_content --content WORK/xia_train`), seed 0. The test grid is never trained on.
3. Runs every method on the real pairs (`mslib.evaluation.real_pairs`: the grid's 40 takes as styles; its
   neutral takes and the `--content` files as contents) and scores the same outputs twice: with the
   packaged evaluator (trained on built-in data only) and with the real judges.

The stored JSON names the data by digest, not by path (a reader's copies live elsewhere), and the
checkpoints by digest; `tools/update_docs.py readme` prints its tables into the README.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from mslib.cpu_paths import pin_cpu_code_paths  # noqa: E402

pin_cpu_code_paths()  # before numpy and torch load: the code path of the tests, so `make bench` sees these numbers
from tools.common import DATA_DIR, current_commit, update_json  # noqa: E402

OUT = DATA_DIR / "07_real_bench.json"
# The real contents of the stored table, relative to the folder that holds the real data (its README names
# their sources): CMU motions of MCM-LDM's demo, two 100STYLE forward walks, HumanML3D's sample (no label).
CONTENT_FILES = ("humanml3d_format/walk_circle.npy=walk", "humanml3d_format/jump.npy=jump", "humanml3d_format/old.npy=walk",
                 "humanml3d_format/Aeroplane_FW_00_feat.npy=walk", "humanml3d_format/Chicken_FW_00_feat.npy=walk",
                 "humanml3d/new_joint_vecs/012314.npy")
JUDGES = ("packaged", "real")


def convert_once(src, out) -> Path:
    """A data_prep.bvh conversion of `src` into `out`, unless `out` already holds one."""
    from data_prep.bvh import convert
    out = Path(out)
    if not (out / "labels.csv").is_file():
        summary = convert(src, out, "auto", "xia", progress=True)
        if summary["failed"]:
            raise ValueError(f"{src}: {summary['failed']} BVH file(s) failed to convert")
    return out


def train_judges(xia_train: Path, workdir: Path) -> dict:
    """The real style and content classifiers (the packaged recipe, seed 0), trained on the Xia train split."""
    from mslib.evaluation.evaluator import train_classifier
    paths = {}
    for kind in ("style", "content"):
        path = workdir / f"real_{kind}.pt"
        if not path.is_file():
            train_classifier(kind, xia_train, "course", seed=0, out=path, progress=True)
        paths[kind] = path
    return paths


def score_real_pairs(xia_train_bvh, xia_grid_bvh, content_specs, workdir, methods, n_pairs=None) -> dict:
    """Convert both Xia splits and train the real judges into `workdir` (once), then every method on the real pairs,
    scored by both judges: {"rows": {judge: [bench rows]}, "by_content" and "by_content_clip": {judge: {method:
    rows}}, "pairs", "grid", "train", "judges"}. One torch thread
    (restored after): the models are small, and every digit is then independent of the cores."""
    import torch
    from mslib.evaluation.bench import Evaluator, bench_row, by_content, by_content_clip, transfer_pairs
    from mslib.evaluation.real_pairs import real_pairs
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        work = Path(workdir)
        work.mkdir(parents=True, exist_ok=True)
        train = convert_once(xia_train_bvh, work / "xia_train")
        grid = convert_once(xia_grid_bvh, work / "xia_grid")
        judges = train_judges(train, work)
        pairs = real_pairs(grid, content_specs, n_pairs)
        evaluators = {"packaged": Evaluator(), "real": Evaluator(judges["content"], judges["style"])}
        rows, contents, clips = {j: [] for j in JUDGES}, {j: {} for j in JUDGES}, {j: {} for j in JUDGES}
        for method in methods:
            outputs, seconds = transfer_pairs(method, pairs, progress=True)
            for judge, ev in evaluators.items():
                scored = ev.score(outputs)  # once per judge: the row and both breakdowns read it
                rows[judge].append(bench_row(method, 0, outputs, pairs, ev, seconds, scored))
                contents[judge][method] = by_content(outputs, pairs, ev, scored)
                clips[judge][method] = by_content_clip(outputs, pairs, ev, scored)
    finally:
        torch.set_num_threads(threads)
    return {"rows": rows, "by_content": contents, "by_content_clip": clips, "pairs": pairs, "grid": grid,
            "train": train, "judges": judges}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--xia-train", required=True, metavar="DIR", help="the Xia train split's BVH files")
    ap.add_argument("--xia-grid", required=True, metavar="DIR", help="the Xia test grid's BVH files (40 takes)")
    ap.add_argument("--content", nargs="*", default=[], metavar="FILE[=CONTENT]", help="more real content motions")
    ap.add_argument("--workdir", default="real_bench_work", metavar="DIR",
                    help="converted folders and the real judges (kept for the next run)")
    ap.add_argument("--methods", default="all", help="comma-separated, or all")
    ap.add_argument("--pairs", type=int, default=None, help="a draw of this many pairs (default: all of them)")
    ap.add_argument("--no-save", action="store_true", help="print only; leave the stored JSON alone")
    args = ap.parse_args(argv)
    from mslib.checkpoints import checkpoint_digest
    from mslib.evaluation.bench import format_table, known_methods
    from mslib.evaluation.evaluator import load_classifier, test_accuracy
    from mslib.evaluation.real_pairs import parse_content_spec
    from mslib.evaluation.realism import folder_digest
    from mslib.fileio import file_digest

    methods = known_methods() if args.methods == "all" else args.methods.split(",")
    run = score_real_pairs(args.xia_train, args.xia_grid, args.content, args.workdir, methods, args.pairs)
    rows, pairs, grid, judges = run["rows"], run["pairs"], run["grid"], run["judges"]
    for judge in JUDGES:
        print(f"judged by the {judge} evaluator:\n{format_table(rows[judge])}", flush=True)
    judge_acc = {kind: round(test_accuracy(load_classifier(kind, judges[kind]), grid, split=None), 1)
                 for kind in ("style", "content")}
    contents = sorted({c["clip_id"]: c["content"] for c, _ in pairs}.items())
    files = [parse_content_spec(s)[0] for s in args.content]
    section = {
        "rows": rows, "by_content": run["by_content"], "by_content_clip": run["by_content_clip"], "pairs": len(pairs),
        "contents": [{"clip": k, "content": v} for k, v in contents],
        "styles": len({s["clip_id"] for _, s in pairs}),
        "judges_on_the_grid": {"real_style_accuracy": judge_acc["style"], "real_content_accuracy": judge_acc["content"]},
        "data": {"xia_train": folder_digest(run["train"]), "xia_grid": folder_digest(grid),
                 "content_files": {f.name: file_digest(f) for f in files}},
        "checkpoints": {m: checkpoint_digest(m) for m in ("adain", "dsdn", "contrastive", "mcm_ldm", "clusterstyle",
                                                            "evaluator_style", "evaluator_content")},
        # the data by role and file name (FILE=CONTENT keeps its label), not by this machine's paths
        "command": ("python tools/real_bench.py --xia-train XIA_TRAIN_BVH --xia-grid XIA_GRID_BVH --content "
                    + " ".join(Path(s).name for s in args.content) + (f" --pairs {args.pairs}" if args.pairs else "")),
        "commit": current_commit(), "when": time.strftime("%Y-%m-%d"),
    }
    if not args.no_save:
        print(update_json(OUT, {"real_pairs": section}))
    else:
        print(json.dumps(section["judges_on_the_grid"]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
