"""The command line: `python -m mslib COMMAND …` (DESIGN.md §8). `--json` ends stdout with one JSON line."""
from __future__ import annotations

import argparse
import json
import sys


def _print_json(obj) -> None:
    print(json.dumps(obj, sort_keys=True))


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
    if args.json:
        _print_json(summary)
    else:
        for key, value in summary.items():
            print(f"{key:>20}: {value}")
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

    d = sub.add_parser("data", help="the built-in stylized mocap corpora")
    dsub = d.add_subparsers(dest="data_command", required=True)
    db = dsub.add_parser("build", help="build (or reuse the cached) content and style corpora")
    db.add_argument("--seed", type=int, default=0)
    db.add_argument("--out", default=None, help="output folder (default: the cache, see MSLIB_CACHE)")
    db.add_argument("--force", action="store_true", help="rebuild even if a cached build exists")
    db.add_argument("--json", action="store_true")
    db.set_defaults(run=_data_build)
    return p


def main(argv=None) -> int:
    """Run one command; a ValueError becomes a one-line message and exit status 2."""
    args = build_parser().parse_args(argv)
    try:
        return args.run(args)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
