"""Where the real → built-in gap lies: the realism judge on built-in windows moved part of the way to real ones.

    python tools/realism_gap.py --real XIA_TRAIN_DIR [--out notebooks/data/00_realism_gap.json] [--force]

XIA_TRAIN_DIR is a dataset folder made by data_prep from the Xia *train* split (the test grid is never read).
The judge is the realism report's real → built-in classifier (mslib.evaluation.realism: a standardised logistic
regression on the means and spreads over its windows — 16 frames, or a short take whole — of body-frame joint
positions, velocities and accelerations, 6 groups × 66 features), trained on every real train window. Each row scores the built-in test
windows after shifting some of their features by the gap between the real and the built-in mean:

- per cell: every (style, content) cell of built-in windows by (real cell mean − built-in cell mean), where the
  real train split has windows of that cell; the built-in spread within the cell is kept;
- style-free: every content by (real content mean − built-in content mean), pooled over styles — the same
  correction for every style, as a better "punch" or "jump" in general would give.

It also stores `spreads`: for every (style, content) cell with at least SPREAD_MIN_WINDOWS real and built-in
windows, the spread of the built-in windows over that of the real ones along the discriminant directions of the
real styles (where a judge of real styles looks) and of the built-in styles (where a judge trained on built-in
data looks), the mean over the 7 directions of each, and its median over cells. A built-in cell tighter than
the real one along the second set (ratio < 1) lets a judge trained on built-in data learn clusters narrower than
the real windows it will read: one way it misreads real takes even where the cell means match.

And `reverse`, the same question for the other cross score (built-in → real): the realism recipe turned round —
a logistic regression trained on built-in *train* windows, as `realism.builtin_linear_to_real` does — trained on
the windows as generated, with every cell's means moved to the real cell's (all six groups), and with its means
and per-feature spreads moved, x' = μ_real + (x − μ_built)·σ_real/σ_built. The real cell means and spreads are
estimated on one half of the real train takes and the judge reads the other half (takes, window probabilities
averaged; REVERSE_SPLITS random halves, each both ways), walks and the other contents apart; the real judge
trained on the first half is the ceiling. It says how far a built-in corpus that matched real cells could take
a judge trained on it alone. `reverse_network` asks the same of the packaged evaluator's own recipe (the conv net
on 64-d frames: root height and root-relative joints), on the first of those halves both ways: trained on the
built-in style train clips as generated, with every cell's frames moved to the real cell's mean pose, and to its
mean and spread, frame dimension by frame dimension.

This is a diagnosis, not a generator: the real means are those of the very windows the judge learned from, so a
full per-cell shift is an upper bound of what matching means could do. It answers which feature groups a
generator must get right per style to be read as real, and whether getting a content right for all styles at
once would help.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

GROUPS = ("pos_mean", "vel_mean", "acc_mean", "pos_std", "vel_std", "acc_std")  # realism.window_features' order
ROWS = (  # (label, groups shifted, share of the gap closed, per cell or style-free)
    *((g, (g,), 1.0, "cell") for g in GROUPS),
    ("posture + amplitude (pos_mean, pos_std)", ("pos_mean", "pos_std"), 1.0, "cell"),
    ("+ vel_std, acc_std", ("pos_mean", "pos_std", "vel_std", "acc_std"), 1.0, "cell"),
    ("all six groups", GROUPS, 1.0, "cell"),
    ("all six groups, half-way", GROUPS, 0.5, "cell"),
    ("all six groups, style-free", GROUPS, 1.0, "content"),
)
DEFAULT_OUT = "notebooks/data/00_realism_gap.json"
REVERSE_SPLITS = 3  # random halves of the real train takes for `reverse` (each used both ways)
SPREAD_MIN_WINDOWS = 10  # real (and built-in) windows a cell needs for its spreads to be compared


def columns(groups) -> "np.ndarray":
    """Feature indices (of the 396) of the named groups."""
    import numpy as np
    return np.concatenate([np.arange(66 * GROUPS.index(g), 66 * (GROUPS.index(g) + 1)) for g in groups])


def shifted(Xb, yb, cb, X, y, c, cols, share: float, mode: str):
    """Built-in features Xb with `cols` moved by `share` of the real − built-in mean gap, per cell or per content."""
    import numpy as np
    out = Xb.copy()
    for k in np.unique(cb):
        for s in (np.unique(yb) if mode == "cell" else [None]):
            mb = (cb == k) if s is None else (cb == k) & (yb == s)
            mr = (c == k) if s is None else (c == k) & (y == s)
            if mr.any() and mb.any():
                out[np.ix_(mb, cols)] += share * (X[mr][:, cols].mean(0) - Xb[mb][:, cols].mean(0))
    return out


def spread_ratios(X, y, c, Xb, yb, cb, min_windows: int = SPREAD_MIN_WINDOWS) -> dict:
    """Per (style, content) cell: std(built-in) / std(real) of the windows along the real and the built-in
    styles' discriminant directions (mean over the directions), and the median over cells."""
    import numpy as np
    from sklearn.preprocessing import StandardScaler
    from tools.fit_joint_moments import discriminant_directions
    scaler = StandardScaler().fit(X)
    Z, Zb = scaler.transform(X), scaler.transform(Xb)
    out = {}
    for name, (ZZ, yy) in (("real_directions", (Z, y)), ("builtin_directions", (Zb, yb))):
        D = discriminant_directions(ZZ, yy)  # (styles − 1, features): a ratio per direction needs no scaling
        P, Pb = Z @ D.T, Zb @ D.T
        cells = {}
        for s in sorted(set(y)):
            for k in sorted(set(cb)):
                m, mb = (y == s) & (c == k), (yb == s) & (cb == k)
                if m.sum() >= min_windows and mb.sum() >= min_windows:
                    cells[f"{s}:{k}"] = round(float((Pb[mb].std(0) / P[m].std(0)).mean()), 3)
        out[name] = {"median": round(float(np.median(list(cells.values()))), 3) if cells else None, "cells": cells}
    return out


def take_rows(got: dict) -> list:
    """{judge: [[all, walks, others] per half]} → rows of mean accuracies (None where no half had such takes)."""
    import numpy as np

    def mean(v):
        v = np.asarray(v, float)
        return round(float(np.nanmean(v)), 1) if np.isfinite(v).any() else None
    return [{"judge trained on": n, **{part: mean([g[i] for g in halves])
                                       for i, part in enumerate(("takes", "walk takes", "other takes"))}}
            for n, halves in got.items()]


def to_real(built, real, spread: bool):
    """Rows of `built` moved to the mean of the rows of `real` and, with `spread`, to their per-column spread too
    (x' = μ_real + (x − μ_built)·σ_real/σ_built; a column flat in `built` keeps its own)."""
    import numpy as np
    sb = built.std(0)
    scale = np.where(sb > 0, real.std(0) / np.where(sb > 0, sb, 1.0), 1.0) if spread else 1.0
    return real.mean(0) + (built - built.mean(0)) * scale


def rescaled(Xb, yb, cb, X, y, c):
    """Built-in features Xb with every cell moved to the real cell's mean and per-feature spread (cells with ≥ 2 of each)."""
    import numpy as np
    out = Xb.copy()
    for k in np.unique(cb):
        for s in np.unique(yb):
            mb, mr = (cb == k) & (yb == s), (c == k) & (y == s)
            if mr.sum() >= 2 and mb.sum() >= 2:
                out[mb] = to_real(Xb[mb], X[mr], spread=True)
    return out


def halves(clips, rng) -> list:
    """Two halves of the clips, at random."""
    order = rng.permutation(len(clips))
    return [[clips[i] for i in order[:len(order) // 2]], [clips[i] for i in order[len(order) // 2:]]]


def walks_and_others(clips) -> tuple:
    """The walk takes and the jump, run, punch and kick takes among the clips (transitions in neither)."""
    from tools.fit_styles import content_group
    return ([k for k in clips if content_group(k[0]["content"]) == "walk"],
            [k for k in clips if content_group(k[0]["content"]) not in ("walk", None)])


def reverse_bound(real_clips, Xb, yb, cb, C: float, splits: int = REVERSE_SPLITS, seed: int = 0) -> dict:
    """Real held-out take accuracy (%) of linear judges trained on built-in windows as generated, with cell means
    moved to real ones, with means and spreads moved, and of the real judge itself; walks and other contents apart."""
    import numpy as np
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler
    from mslib.evaluation import realism as R
    from tools.fit_styles import content_group

    def judge(X, y):
        return make_pipeline(StandardScaler(), LogisticRegression(C=C, max_iter=5000, random_state=seed)).fit(X, y)

    def read(clf, clips):
        return [(R.linear_scores(clf, part).get("takes") or {"accuracy": np.nan})["accuracy"]
                for part in (clips, *walks_and_others(clips))]
    names = ("built-in as generated", "built-in, cell means matched", "built-in, cell means and spreads matched",
             "real takes (the ceiling)")
    got = {n: [] for n in names}
    rng = np.random.default_rng(seed)
    for _ in range(splits):
        split = halves(real_clips, rng)
        for fit_half, read_half in (split, split[::-1]):
            X, y, _, c, _ = R._windowed(fit_half)
            c = np.array([str(content_group(x)) for x in c])
            moved_means = shifted(Xb, yb, cb, X, y, c, columns(GROUPS), 1.0, "cell")
            for name, (XX, yy) in zip(names, ((Xb, yb), (moved_means, yb), (rescaled(Xb, yb, cb, X, y, c), yb), (X, y))):
                got[name].append(read(judge(XX, yy), read_half))
    return {"C": C, "splits": splits, "rows": take_rows(got)}


def moved_inputs(inputs, keys, real_by_cell: dict, spread: bool) -> list:
    """Each clip's (T, 64) evaluator input moved so that its cell's frames (cell = keys[i]) take the real cell's
    mean (and, with `spread`, per-dimension spread); cells without real frames stay as they are."""
    import numpy as np
    out = list(inputs)
    for key in set(keys):
        if key not in real_by_cell:
            continue
        mine = [i for i, k in enumerate(keys) if k == key]
        moved = to_real(np.concatenate([inputs[i] for i in mine]), real_by_cell[key], spread).astype(np.float32)
        for i, part in zip(mine, np.split(moved, np.cumsum([len(inputs[i]) for i in mine])[:-1])):
            out[i] = part
    return out


def reverse_network(real_clips, builtin_clips, seed: int = 0) -> dict:
    """Real held-out take accuracy (%) of the style evaluator's recipe trained on built-in train clips as generated,
    with cell mean poses moved to real ones, and with their means and spreads moved (one random half both ways)."""
    import numpy as np
    import torch
    from mslib.evaluation import evaluator as E
    from mslib.evaluation.realism import take_scores
    from tools.fit_styles import content_group
    train = [(r, j) for r, j in builtin_clips if r["split"] == "train"]
    val = [(r, j) for r, j in builtin_clips if r["split"] == "val"]
    classes = sorted({r["style"] for r, _ in train})
    index = {c: i for i, c in enumerate(classes)}
    keys = [(r["style"], r["content"]) for r, _ in train]
    names = ("built-in as generated", "built-in, cell mean poses matched", "built-in, cell pose means and spreads matched")
    got = {n: [] for n in names}
    split = halves(real_clips, np.random.default_rng(seed))  # reverse_bound's first halves
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        for fit_half, read_half in (split, split[::-1]):
            real_by_cell: dict = {}
            for r, j in fit_half:
                if content_group(r["content"]) is not None:
                    real_by_cell.setdefault((r["style"], content_group(r["content"])), []).append(E.classifier_input(j))
            real_by_cell = {k: np.concatenate(v) for k, v in real_by_cell.items()}
            walks, others = walks_and_others(read_half)
            val_set = E.WindowDataset([j for _, j in val], [index[r["style"]] for r, _ in val], seed=seed + 1)
            for name, spread in zip(names, (None, False, True)):
                train_set = E.WindowDataset([j for _, j in train], [index[y] for y, _ in keys], seed=seed,
                                            short=E.SHORT_SHARE)
                if spread is not None:
                    train_set.inputs = moved_inputs(train_set.inputs, keys, real_by_cell, spread)
                model, _ = E.fit_classifier("style", train_set, val_set, classes, seed=seed, progress=False)
                got[name].append([take_scores(model, part)["accuracy"] if part else np.nan
                                  for part in (read_half, walks, others)])
    finally:
        torch.set_num_threads(threads)
    return {"recipe": "the packaged style evaluator's (course preset)", "seed": seed, "rows": take_rows(got)}


def accuracy_by_content(pred, yb, cb) -> dict:
    """Accuracy (%) per content (the realism report's by_content) and over all windows."""
    import numpy as np
    from mslib.evaluation.realism import by_content
    per = {k: v["accuracy"] for k, v in by_content(yb, pred, cb).items()}
    return {**per, "all": round(100.0 * float(np.mean(pred == yb)), 2)}


def measure(real, progress: bool = True) -> dict:
    """The table: the judge's accuracy on built-in test windows, as generated and with each shift of ROWS."""
    import numpy as np
    from mslib.data.corpora import load_builtin
    from mslib.evaluation import realism as R
    from tools.fit_styles import check_train_split, content_group
    check_train_split(real)
    real_clips = R.read_clips(real, "--real")
    X, y, g, c, _ = R._windowed(real_clips)
    c = np.array([str(content_group(x)) for x in c])  # transitions ("None") train the judge, shift nothing
    judge, C = R.fit_window_classifier(X, y, g)  # (model, its C and CV scores): the realism report's judge, on every real train window
    builtin = load_builtin(progress=progress)["style"]
    built = R.read_clips(builtin, "--builtin")
    Xb, yb, _, cb, _ = R._windowed([(r, j) for r, j in built if r["split"] == "test"])
    rows = [{"shift": "none (the built-in windows as generated)", **accuracy_by_content(judge.predict(Xb), yb, cb)}]
    for label, groups, share, mode in ROWS:
        moved = shifted(Xb, yb, cb, X, y, c, columns(groups), share, mode)
        rows.append({"shift": label, "groups": list(groups), "share": share, "mode": mode,
                     **accuracy_by_content(judge.predict(moved), yb, cb)})
        if progress:
            print(rows[-1], flush=True)
    cells = {k: {s: int(((c == k) & (y == s)).sum()) for s in sorted(set(y))} for k in sorted(set(cb))}
    Xt, yt, gt, ct, _ = R._windowed([(r, j) for r, j in built if r["split"] == "train"])
    _, Ct = R.fit_window_classifier(Xt, yt, gt)  # C of the reversed judge, chosen once on the windows as generated
    reverse = reverse_bound(real_clips, Xt, yt, ct, Ct["C"])
    if progress:
        print("training the style evaluator's recipe six times for reverse_network …", flush=True)
    reverse["network"] = reverse_network(real_clips, built)
    return {"rows": rows, "spreads": spread_ratios(X, y, c, Xb, yb, cb), "reverse": reverse, "judge": C,
            "real": {"folder": Path(real).name, "digest": R.folder_digest(real)},
            "builtin": R.builtin_info(builtin), "real_windows_per_cell": cells}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--real", required=True, help="dataset folder of the Xia train split (made by data_prep.bvh)")
    ap.add_argument("--out", default=DEFAULT_OUT, help=f"where the table goes (default {DEFAULT_OUT})")
    ap.add_argument("--force", action="store_true", help="overwrite --out")
    args = ap.parse_args(argv)
    from mslib.fileio import check_writable
    from tools.common import current_commit, update_json
    out = check_writable(args.out, args.force, "--out")
    t0 = time.time()
    table = measure(args.real)
    command = f"python tools/realism_gap.py --real {Path(args.real).name}"
    update_json(out, {**table, "command": command, "commit": current_commit(), "seconds": round(time.time() - t0, 1)})
    for r in table["rows"]:
        print(f"{r['shift']:<44} " + "  ".join(f"{k} {v:5.1f}" for k, v in r.items() if k not in
                                                 ("shift", "groups", "share", "mode")))
    sp = table["spreads"]
    print(f"spread of built-in / real windows per cell (median over {len(sp['real_directions']['cells'])} cells): "
          f"along the real styles' directions {sp['real_directions']['median']}, along the built-in styles' "
          f"{sp['builtin_directions']['median']}")
    for judge, rows in (("linear judge", table["reverse"]["rows"]), ("evaluator's net", table["reverse"]["network"]["rows"])):
        for r in rows:
            print(f"built-in → real, {judge} trained on {r['judge trained on']:<46} real held-out takes {r['takes']}  "
                  f"walks {r['walk takes']}  other contents {r['other takes']}")
    print(f"→ {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
