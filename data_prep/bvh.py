"""Convert a folder of BVH files into a dataset folder (mslib/data/dataset_folder.py) through the registration pipeline.

    python -m data_prep.bvh IN_DIR OUT_DIR [--dialect NAME|auto] [--labels RULE] [--windows] [--force]

RULE is `xia` (the Xia/Aberman file names: STYLE_CONTENT_TAKE.bvh), a regular expression with named
groups among style, substyle, content, take (matched against the file name without .bvh), or a
CSV file with a `file` column and any of style, substyle, content, caption, split.
"""
from __future__ import annotations

import argparse
import csv
import re
import sys
import time
from pathlib import Path

from tqdm.auto import tqdm

from mslib.data.dataset_folder import DatasetWriter, split_for
from mslib.data.joint_maps import DIALECTS
from mslib.data.retarget import cut_windows, register_bvh
from mslib.motion.features import encode

# Xia content ids (Aberman et al.'s file names) → the action: 01–12 walks (straight and turning), 13–15 runs,
# 16–17 jumps, 18–21 punches, 22–23 kicks, 24–28 transitions between them
XIA_CONTENTS = {f"{i:02d}": name for name, ids in (("walk", range(1, 13)), ("run", range(13, 16)),
                                                   ("jump", (16, 17)), ("punch", range(18, 22)),
                                                   ("kick", (22, 23)), ("transition", range(24, 29)))
                for i in ids}
XIA_RULE = r"(?P<style>[a-z]+)_(?P<content>\d+)_(?P<take>\d+)"


def label_rule(rule):
    """A function file name → label dict, from `xia`, a regex with named groups, or a CSV path."""
    if rule is None:
        return lambda stem: {}
    if rule == "xia":
        rx = re.compile(XIA_RULE)

        def xia(stem):
            m = rx.fullmatch(stem)
            if not m:
                return {}
            labels = m.groupdict()
            labels["content"] = XIA_CONTENTS.get(labels["content"], labels["content"])
            return labels
        return xia
    if Path(rule).is_file():
        with open(rule, newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
        if not rows or "file" not in rows[0]:
            raise ValueError(f"--labels {rule}: a label CSV needs a 'file' column and at least one row")
        table = {Path(r["file"]).stem: {k: v for k, v in r.items() if k != "file"} for r in rows}
        return lambda stem: dict(table.get(stem, {}))
    try:
        rx = re.compile(rule)
    except re.error as e:
        raise ValueError(f"--labels {rule!r}: neither 'xia', a CSV file nor a valid regex ({e})") from None
    return lambda stem: (rx.search(stem).groupdict() if rx.search(stem) else {})


def caption_for(labels) -> str:
    """A template caption naming the style and content when they are known."""
    style, content = labels.get("style") or "", labels.get("content") or "moves"
    article = "an" if style[:1].lower() in "aeiou" else "a"
    who = f"{article} {style} person" if style and style != "neutral" else "a person"
    return f"{who} {content}s" if content != "moves" else f"{who} moves"


def convert(in_dir, out_dir, dialect="auto", labels=None, windows=False, mirror=False, force=False,
            progress=True) -> dict:
    """Convert every BVH under IN_DIR; returns the summary (converted, skipped, failed with reasons)."""
    in_dir = Path(in_dir)
    if not in_dir.is_dir():
        raise ValueError(f"IN_DIR {in_dir}: no such folder")
    files = sorted(p for p in in_dir.rglob("*") if p.suffix.lower() == ".bvh")
    if not files:
        raise ValueError(f"IN_DIR {in_dir}: no .bvh files found")
    rule = label_rule(labels)
    writer = DatasetWriter(out_dir, name=in_dir.name, source=f"data_prep.bvh from {in_dir.name}",
                           force=force, dialect=str(dialect), windows=bool(windows))
    t0 = time.time()
    done, skipped, failed, clips, too_short = 0, 0, {}, 0, []
    for path in tqdm(files, desc="registering", unit="file", disable=not progress):
        stem = path.stem
        lab = rule(stem)
        take = lab.pop("take", None) or stem
        split = lab.pop("split", None) or split_for(f"{lab.get('style', '')}/{lab.get('content', '')}/{take}"
                                                    if lab else stem)
        lab.setdefault("caption", caption_for(lab))
        first_id = f"{stem}_w000" if windows else stem
        if writer.has(first_id):
            skipped += 1
            continue
        try:
            reg = register_bvh(path, dialect, mirror=mirror)
            pieces = cut_windows(reg.positions) if windows else [reg.positions]
            if not pieces:
                too_short.append(path.name)  # shorter than one 32-frame window at 20 fps
            for k, joints in enumerate(pieces):
                clip_id = f"{stem}_w{k:03d}" if windows else stem
                feats = reg.features if not windows else encode(joints)
                writer.add(clip_id, joints, feats, split, source_file=path.name, **lab)
                clips += 1
            done += 1
        except ValueError as e:
            failed[path.name] = str(e)
    meta = writer.close()
    return {"files": len(files), "converted": done, "skipped": skipped, "failed": len(failed),
            "failures": failed, "too_short": too_short, "clips": clips, "total_clips": meta["n_clips"], "splits": meta["splits"],
            "seconds": round(time.time() - t0, 1), "out_dir": str(out_dir)}


def main(argv=None) -> int:
    """Command-line entry point."""
    p = argparse.ArgumentParser(prog="python -m data_prep.bvh", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("in_dir", metavar="IN_DIR")
    p.add_argument("out_dir", metavar="OUT_DIR")
    p.add_argument("--dialect", default="auto", help=f"joint names: auto or one of {', '.join(DIALECTS)}")
    p.add_argument("--labels", default=None, metavar="RULE", help="xia, a regex with named groups, or a CSV")
    p.add_argument("--windows", action="store_true", help="cut 32-frame windows with 8-frame overlap (A §4.1)")
    p.add_argument("--mirror", action="store_true", help="mirror every motion (negate X, swap sides)")
    p.add_argument("--force", action="store_true", help="write into a non-empty OUT_DIR (converted files are skipped)")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON line")
    args = p.parse_args(argv)
    try:
        s = convert(args.in_dir, args.out_dir, args.dialect, args.labels, args.windows, args.mirror,
                    args.force, progress=not args.json)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.json:
        import json
        print(json.dumps(s, sort_keys=True))
    else:
        print(f"converted {s['converted']} of {s['files']} files into {s['total_clips']} clips "
              f"({s['splits']}) in {s['seconds']} s; skipped {s['skipped']} already converted; "
              f"failed {s['failed']}; {len(s['too_short'])} shorter than one window")
        for name, why in s["failures"].items():
            print(f"  failed: {name}: {why}")
    return 0 if not s["failed"] else 1


if __name__ == "__main__":
    sys.exit(main())
