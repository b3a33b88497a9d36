"""The command line: `python -m mslib COMMAND …`. `--json` ends stdout with one JSON line."""
from __future__ import annotations

import argparse
import json
import sys


def _print_json(obj) -> None:
    print(json.dumps(obj, sort_keys=True))


def _report(summary: dict, as_json: bool, width: int = 16) -> int:
    """Print a summary as one JSON line or as aligned `key: value` lines; exit status 0."""
    if as_json:
        _print_json(summary)
    else:
        for key, value in summary.items():
            print(f"{key:>{width}}: {value}")
    return 0


# ---------------------------------------------------------------- features
def _features(args) -> int:
    from .fileio import atomic_save_npy, load_npy
    from .motion import features as F
    data = load_npy(args.input, "IN")
    try:
        if args.action == "encode":
            out = F.encode(F.check_positions(data, f"IN {args.input}"))
        else:
            F.check_features(data, f"IN {args.input}")
            out = F.decode(data.astype("float64")).astype("float32")
    except ValueError as e:
        msg = str(e)
        raise ValueError(msg if str(args.input) in msg else f"IN {args.input}: {msg}") from None
    atomic_save_npy(args.output, out, force=args.force, arg="OUT")
    summary = {"action": args.action, "input": str(args.input), "output": str(args.output),
               "input_shape": list(data.shape), "output_shape": list(out.shape)}
    if args.json:
        _print_json(summary)
    else:
        print(f"{args.action}d {tuple(data.shape)} → {tuple(out.shape)}: {args.output}")
    return 0


# ---------------------------------------------------------------- bvh
def _bvh_info(args) -> int:
    from .motion.bvh import bvh_info
    info = bvh_info(args.file)
    if args.json:
        _print_json(info)
        return 0
    for key in ("file", "n_joints", "n_frames", "fps", "duration_s", "rotation_orders"):
        if key in info:
            print(f"{key:>16}: {info[key]}")
    if "joints" in info:
        print(f"{'joints':>16}: {', '.join(map(str, info['joints']))}")
    return 0


# ---------------------------------------------------------------- data
def _data_build(args) -> int:
    from .data.corpora import build_corpora
    summary = build_corpora(out_dir=args.out, seed=args.seed, force=args.force, progress=not args.json)
    return _report(summary, args.json, width=20)


def _data_realism(args) -> int:
    from .evaluation.realism import format_report, run
    report = run(args.real, args.grid, out=args.out, plot=args.plot, force=args.force, progress=not args.json)
    if args.json:
        _print_json(report)
    else:
        print(format_report(report))
    return 0


# ---------------------------------------------------------------- train
def _corpus_dirs(args) -> tuple:
    """The --content/--style folders, or the built-in corpora (built and cached on first use)."""
    if args.content and args.style:
        return args.content, args.style
    from .data.corpora import load_builtin
    paths = load_builtin(seed=0, progress=not getattr(args, "json", False))
    return args.content or paths["content"], args.style or paths["style"]


def _train_classifier(kind):
    def run(preset, content, style, seed=0, out=None, device="cpu", steps=None, resume=None, progress=True):
        from .checkpoints import course_path
        from .evaluation.evaluator import NAMES, test_accuracy, train_classifier
        from .training import run_summary
        folder = content if kind == "content" else style
        out = out or course_path(NAMES[kind])
        overrides = {"steps": steps} if steps else {}
        model, history = train_classifier(kind, folder, preset, seed, out=out, device=device,
                                          progress=progress, resume=resume, **overrides)
        return run_summary(NAMES[kind], out, history, val_acc=round(100 * history["val"]["acc"][-1], 2),
                           test_acc=round(test_accuracy(model, folder, "test"), 2))
    return run


def trainers() -> dict:
    """Every trainable model name → its run function: the two evaluators and the model packages' TRAINERS
    (`mslib.models.registry`), each run(preset, content, style, seed=0, out=None, device="cpu", steps=None,
    resume=None, progress=True) → a JSON-able summary."""
    from .models.registry import trainers as model_trainers
    return {"evaluator_content": _train_classifier("content"), "evaluator_style": _train_classifier("style"),
            **model_trainers()}


def _train(args) -> int:
    found = trainers()
    if args.model not in found:
        raise ValueError(f"MODEL {args.model!r} is unknown; trainable models: {', '.join(sorted(found))}")
    content, style = _corpus_dirs(args)
    summary = found[args.model](args.preset, content, style, seed=args.seed, out=args.out, device=args.device,
                                steps=args.steps, resume=args.resume, progress=not args.json)
    return _report(summary, args.json, width=12)


# ---------------------------------------------------------------- bench
def _bench(args) -> int:
    from .evaluation.bench import Evaluator, format_table, known_methods, load_pairs, run_bench
    methods = known_methods() if args.method == "all" else [m.strip() for m in args.method.split(",") if m.strip()]
    if args.real_style:
        from .evaluation.real_pairs import real_pairs
        if args.content or args.style:
            raise ValueError("--real-style: real pairs take their contents from --real-content, not --content/--style")
        pairs = real_pairs(args.real_style, args.real_content, args.pairs, args.seed)
    elif args.real_content:
        raise ValueError("--real-content: needs --real-style DIR (the real takes whose styles the contents receive)")
    else:
        pairs = load_pairs(args.seed, args.pairs or 200, args.content, args.style)
    evaluator = Evaluator(args.evaluator_content, args.evaluator_style)
    rows = [run_bench(m, seed=args.seed, pairs=pairs, device=args.device, evaluator=evaluator,
                      progress=not args.json) for m in methods]
    if args.json:
        for row in rows:
            _print_json(row)
    else:
        print(format_table(rows, markdown=args.markdown))
    return 0


# ---------------------------------------------------------------- transfer, perf
def _transfer(args) -> int:
    from .evaluation.transfer_io import run_transfer
    summary = run_transfer(args.method, args.content, args.style, args.out, force=args.force, device=args.device)
    return _report(summary, args.json)


def _perf(args) -> int:
    from .evaluation.perf import format_perf, run_perf
    methods = [m.strip() for m in args.methods.split(",") if m.strip()] if args.methods else None
    report = run_perf(methods, repeats=args.repeats, device=args.device)
    if args.json:
        _print_json(report)
    else:
        print(format_perf(report))
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser for every command."""
    p = argparse.ArgumentParser(prog="python -m mslib", description="Motion Style Workbook command line")
    sub = p.add_subparsers(dest="command", required=True)

    f = sub.add_parser("features", help="the 263-d HumanML3D vector from positions and back")
    f.add_argument("action", choices=["encode", "decode"],
                   help="encode: T×22×3 positions → (T−1)×263; decode: features → positions")
    f.add_argument("input", metavar="IN.npy")
    f.add_argument("output", metavar="OUT.npy")
    f.add_argument("--force", action="store_true", help="overwrite OUT if it exists")
    f.add_argument("--json", action="store_true", help="print one JSON summary line")
    f.set_defaults(run=_features)

    b = sub.add_parser("bvh", help="BVH files")
    bsub = b.add_subparsers(dest="bvh_command", required=True)
    bi = bsub.add_parser("info", help="joints, frames, fps and channels of a BVH file")
    bi.add_argument("file", metavar="FILE.bvh")
    bi.add_argument("--json", action="store_true")
    bi.set_defaults(run=_bvh_info)

    d = sub.add_parser("data", help="the built-in stylized mocap corpora, and how real they are")
    dsub = d.add_subparsers(dest="data_command", required=True)
    db = dsub.add_parser("build", help="build (or reuse the cached) content and style corpora")
    db.add_argument("--seed", type=int, default=0)
    db.add_argument("--out", default=None, help="output folder (default: the cache, see MSLIB_CACHE)")
    db.add_argument("--force", action="store_true", help="rebuild even if a cached build exists")
    db.add_argument("--json", action="store_true")
    db.set_defaults(run=_data_build)
    dr = dsub.add_parser("realism", help="cues and cross scores of real mocap against the built-in styles")
    dr.add_argument("--real", required=True, metavar="DIR", help="a dataset folder made by data_prep (training data)")
    dr.add_argument("--grid", default=None, metavar="DIR", help="held-out real test folder (default: --real's test split)")
    dr.add_argument("--out", default=None, metavar="JSON", help="store the report (e.g. notebooks/data/00_realism.json)")
    dr.add_argument("--plot", default=None, metavar="PNG", help="draw the cues and scores")
    dr.add_argument("--force", action="store_true", help="overwrite --out/--plot if they exist")
    dr.add_argument("--json", action="store_true")
    dr.set_defaults(run=_data_realism)

    t = sub.add_parser("train", help="train a model with the one training loop (torchrun for DDP)")
    t.add_argument("model", metavar="MODEL", help="e.g. evaluator_content, evaluator_style")
    t.add_argument("--preset", choices=["course", "paper"], default="course")
    t.add_argument("--content", default=None, metavar="DIR", help="content dataset folder (default built-in)")
    t.add_argument("--style", default=None, metavar="DIR", help="style dataset folder (default built-in)")
    t.add_argument("--seed", type=int, default=0)
    t.add_argument("--out", default=None, metavar="FILE", help="checkpoint (default: the packaged course one)")
    t.add_argument("--device", default="cpu", help="cpu, cuda, cuda:1, mps …")
    t.add_argument("--steps", type=int, default=None, help="override the preset's number of steps")
    t.add_argument("--resume", default=None, metavar="FILE", help="continue from a checkpoint of this run")
    t.add_argument("--json", action="store_true")
    t.set_defaults(run=_train)

    be = sub.add_parser("bench", help="run a method over held-out pairs and score it")
    be.add_argument("--method", required=True, help="a method, several joined by commas, or 'all'")
    be.add_argument("--seed", type=int, default=0, help="which draw of pairs")
    be.add_argument("--pairs", type=int, default=None, help="how many pairs (built-in: 200; real: all of them)")
    be.add_argument("--content", default=None, metavar="DIR")
    be.add_argument("--style", default=None, metavar="DIR")
    be.add_argument("--real-style", default=None, metavar="DIR",
                    help="real pairs: every take of this folder is a style, its neutral takes are contents "
                         "(e.g. the Xia test grid from data_prep.bvh --labels xia; see data_prep/README.md)")
    be.add_argument("--real-content", nargs="*", default=[], metavar="FILE[=CONTENT]",
                    help="real pairs: more content motions (.npy 263-d or T×22×3, .bvh), CONTENT their action")
    be.add_argument("--evaluator-content", default=None, metavar="FILE",
                    help="judge with this content classifier (default: the packaged one)")
    be.add_argument("--evaluator-style", default=None, metavar="FILE",
                    help="judge with this style classifier (default: the packaged one)")
    be.add_argument("--device", default="cpu")
    be.add_argument("--json", action="store_true", help="one JSON line per method")
    be.add_argument("--markdown", action="store_true", help="print a Markdown table (the README's)")
    be.set_defaults(run=_bench)

    tr = sub.add_parser("transfer", help="one content motion in one style, written as .bvh, .npy, .gif or .html")
    tr.add_argument("--method", required=True)
    tr.add_argument("--content", required=True, metavar="X", help="built-in clip id, .npy (263-d or T×22×3) or .bvh")
    tr.add_argument("--style", required=True, metavar="Y", help="built-in clip id, .npy (263-d or T×22×3) or .bvh")
    tr.add_argument("--out", required=True, metavar="OUT", help="OUT.bvh (metres), OUT.npy (263-d), OUT.gif or OUT.html (3-D viewer)")
    tr.add_argument("--force", action="store_true", help="overwrite OUT if it exists")
    tr.add_argument("--device", default="cpu")
    tr.add_argument("--json", action="store_true")
    tr.set_defaults(run=_transfer)

    pf = sub.add_parser("perf", help="inference ms per 64-frame clip and parameter count per method")
    pf.add_argument("--methods", default=None, metavar="A,B", help="comma-separated (default: all registered)")
    pf.add_argument("--repeats", type=int, default=20, help="timed transfers per method (median reported)")
    pf.add_argument("--device", default="cpu")
    pf.add_argument("--json", action="store_true")
    pf.set_defaults(run=_perf)
    return p


def main(argv=None) -> int:
    """Run one command; a ValueError becomes a one-line message and exit status 2."""
    args = build_parser().parse_args(argv)
    try:
        return args.run(args)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
