"""Fit the generator's per-joint moment layer (mslib/data/joint_moments.py) to the Xia train split.

    python tools/fit_joint_moments.py --real DIR [--out mslib/data/fitted_joint_moments.json] [--jobs 2] [--force]

DIR is a dataset folder made by data_prep from the Xia *train* split (as for tools/fit_styles.py,
whose fitted styles this layer sits on top of: refit the layer whenever they change). Never point
it at the test grid: the realism report checks the fit there.

What is matched. A real-style judge reads per-window means and spreads of body-frame joint
positions, velocities and accelerations (the realism report's 396 features). For every
(style, content) cell with at least MIN_WINDOWS real windows, the layer's 96 numbers are fitted so
that the generated windows of that cell fall, on average, where the real ones do along 14
directions of the standardised features, each in units of the real windows' spread about their
style's mean:
- the 7 discriminant directions of the real styles (a linear discriminant analysis with shrinkage
  of every real train window): where real styles differ, so a judge of real styles reads the
  built-in ones as their names (real → built-in). Matching all 396 means instead (plainly or
  whitened) moves the cheap features and leaves the telling ones;
- the 7 discriminant directions of the built-in styles, as the generator makes them with the layer
  it has loaded when the tool starts (BUILTIN_TAKES takes per cell; the digest of that layer file is
  stored): where a judge trained on built-in data looks. If real cells sit elsewhere along them, such a
  judge — the packaged evaluator — misreads real takes (built-in → real), however well the first 7 match;
- for walking cells, also the walking cues (mslib/evaluation/cues.py), in the real style's spread,
  jerk weighted less as in fit_styles: aimed at the judges' directions alone, the layer is free to
  shorten an old walker's steps or add jerk that real walks do not have.
The report's judge itself (a logistic regression) is not used here, so the report still checks the
fit with a model it was not fitted to. Because the second set of directions depends on the layer in
place, refitting is one step of an iteration; the stored "builtin_directions_from" says which step.

How. Levenberg–Marquardt on the residuals of each cell plus a pull of every number toward zero
(PRIOR_WEIGHT, in units of PRIOR_SCALE: 15° for offsets, 0.5 for log gains, 6° for spreads), the
Jacobian by forward differences with common random numbers (the same TAKES generated takes, by
index, at every evaluation, so the objective is smooth). Cells run in parallel (--jobs).
Stored: the numbers per cell, each cell's residual before and after, the command, the digests of
the real folder and of the fitted styles it was fitted on top of. Nothing of the real data.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from mslib.data import joint_moments as jm  # noqa: E402

DEFAULT_OUT = "mslib/data/fitted_joint_moments.json"
MIN_WINDOWS = 2  # real windows a cell needs to be fitted (else it takes the style's walking numbers)
TAKES, DURATION, FIT_SEED, FIRST_INDEX = 8, 3.0, 0, 5_000_000  # generated per evaluation (not the corpus' takes)
ITERS = 4
PRIOR_WEIGHT = 1.0
PRIOR_SCALE = np.concatenate([np.full(jm.N_OFFSET, 15.0), np.full(jm.N_GAIN, 0.5), np.full(jm.N_GAIN, 6.0)])
STEP = np.concatenate([np.full(jm.N_OFFSET, 1.0), np.full(jm.N_GAIN, 0.05), np.full(jm.N_GAIN, 1.0)])
BUILTIN_TAKES, BUILTIN_INDEX = 12, 6_000_000  # generated per cell to find the built-in styles' directions
BUILTIN_WEIGHT = 1.0  # of the built-in styles' directions, against the real styles' (weight 1)
CUE_CONTENTS = ("walk",)  # cells whose walking cues are fitted too (the cues are walking cues)
START_SPREAD = 2.0  # degrees: the first guess of every spread (at 0, |s| has a kink), unless no layer is closer


def real_cells(folder):
    """Standardised features, styles, content groups and walking cue windows of every real train window, the scaler."""
    from sklearn.preprocessing import StandardScaler

    from mslib.evaluation import realism
    from mslib.evaluation.cues import cue_table
    from tools.fit_styles import check_train_split, content_group
    check_train_split(folder)
    clips = realism.read_clips(folder, "--real")
    X, y, _, content, _ = realism._windowed(clips)
    scaler = StandardScaler().fit(X)
    cues = {}  # style → (N, len(CUES)) cues of its real walking windows
    for row, joints in clips:
        if content_group(row["content"]) == "walk" and len(joints) >= realism.CUE_WINDOW:
            cues.setdefault(row["style"], []).append(cue_table(realism.windows(joints, realism.CUE_WINDOW)))
    cues = {s: np.concatenate(c) for s, c in cues.items()}
    return scaler, scaler.transform(X), y, np.array([content_group(c) for c in content]), cues


def discriminant_directions(Z, y) -> np.ndarray:
    """(7, 396) directions of a linear discriminant analysis (shrinkage) of windows Z with styles y."""
    from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
    lda = LinearDiscriminantAnalysis(solver="eigen", shrinkage="auto").fit(Z, y)
    return lda.scalings_[:, :len(lda.classes_) - 1].T


def within_spread(P, y) -> np.ndarray:
    """Spread of projections P (N, k) about their style's mean, per column."""
    return np.concatenate([P[y == s] - P[y == s].mean(0) for s in np.unique(y)]).std(0)


def builtin_directions(scaler, Z, y, takes: int = BUILTIN_TAKES) -> np.ndarray:
    """The built-in styles' 7 discriminant directions, as the generator makes them now (with the layer
    it has loaded), each scaled to unit spread of the real windows about their style's mean."""
    from mslib.data import styles
    from tools.fit_styles import CONTENT_GROUPS
    feats, labels = [], []
    for style in styles.STYLES:
        for content in CONTENT_GROUPS:
            f, _ = generated_windows(style, content, jm.FITTED, takes, BUILTIN_INDEX)
            feats.append(f), labels.extend([style] * len(f))
    D = discriminant_directions(scaler.transform(np.concatenate(feats)), np.array(labels))
    return D / within_spread(Z @ D.T, y)[:, None]


def generated_windows(style: str, content: str, table: dict, takes: int = TAKES, first: int = FIRST_INDEX,
                      with_cues: bool = False):
    """Features (N, 396) of `takes` generated clips of the cell under the layer `table`, and the
    walking cues of their windows ((M, len(CUES)), or None)."""
    from mslib.data import synth
    from mslib.evaluation import realism
    from mslib.evaluation.cues import cue_table
    from tools.fit_styles import registered_positions
    specs = [dict(content=content, style=style, seed=FIT_SEED, index=first + i, fps=30.0, duration=DURATION,
                  canonical=False) for i in range(takes)]
    saved = jm.FITTED
    jm.FITTED = table
    try:
        joints = [registered_positions(c) for c in synth.generate_clips(specs)]
    finally:
        jm.FITTED = saved
    feats = realism.take_features(joints)
    cues = (np.concatenate([cue_table(realism.windows(j, realism.CUE_WINDOW)) for j in joints])
            if with_cues else None)
    return feats, cues


def fit_cell(style: str, content: str, target, scaler, directions, cue_target=None, cue_scale=None,
             iters: int = ITERS) -> dict:
    """Levenberg–Marquardt of one cell's numbers on directions · (mean generated − real) and, for a walk,
    the walking cues' (mean generated − real) / real spread; all pulled toward 0."""
    from mslib.evaluation.cues import CUES
    from tools.fit_styles import CUE_WEIGHT
    with_cues = cue_target is not None
    cue_w = np.sqrt([CUE_WEIGHT.get(c, 1.0) for c in CUES]) / cue_scale if with_cues else None

    def residual(th):
        # only this cell's numbers (the layer of neutral is not mixed in: intensity 1)
        f, cues = generated_windows(style, content, {(style, content): th}, with_cues=with_cues)
        r = directions @ (scaler.transform(f).mean(0) - target)
        if with_cues:
            r = np.concatenate([r, np.nan_to_num(cue_w * (np.nanmean(cues, 0) - cue_target))])
        return r

    def cost(r, th):
        return float(r @ r + PRIOR_WEIGHT * ((th / PRIOR_SCALE) ** 2).sum())
    zero = np.zeros(jm.N_PARAMS)
    r0 = residual(zero)  # the generator without the layer: the "before"
    theta = np.concatenate([np.zeros(jm.N_OFFSET + jm.N_GAIN), np.full(jm.N_GAIN, START_SPREAD)])
    r = residual(theta)
    if cost(r0, zero) <= cost(r, theta):  # start from the better of the two, so the fit never ends worse
        theta, r = zero, r0
    mu = 1e-2
    for _ in range(iters):
        J = np.stack([(residual(theta + STEP * np.eye(jm.N_PARAMS)[k]) - r) / STEP[k] for k in range(jm.N_PARAMS)], 1)
        A = J.T @ J + PRIOR_WEIGHT * np.diag(1 / PRIOR_SCALE ** 2)
        g = J.T @ r + PRIOR_WEIGHT * theta / PRIOR_SCALE ** 2
        for _ in range(4):
            new = jm.clip_to_limits(theta - np.linalg.solve(A + mu * np.diag(np.diag(A)), g))
            r_new = residual(new)
            if cost(r_new, new) < cost(r, theta):
                theta, r, mu = new, r_new, max(mu / 3, 1e-4)
                break
            mu *= 4
        else:
            break
    return {"theta": [float(f"{v:.4g}") for v in theta], "residual_before": round(float(r0 @ r0), 2),
            "residual_after": round(float(r @ r), 2)}


def _fit_job(job):
    style, content, n, target, scaler, directions, cue_target, cue_scale, iters = job
    t0 = time.time()
    out = fit_cell(style, content, target, scaler, directions, cue_target, cue_scale, iters)
    return style, content, {**out, "real_windows": n, "seconds": round(time.time() - t0, 1)}


def fit(real, jobs: int = 1, iters: int = ITERS, only=None, progress: bool = True) -> dict:
    """{'cells': {'style:content': numbers}, 'fit': {...}} for every cell with ≥ MIN_WINDOWS real windows."""
    from concurrent.futures import ProcessPoolExecutor

    from tqdm.auto import tqdm

    from mslib.data import styles
    from mslib.data.synth import GENERATOR_VERSION
    from mslib.evaluation.realism import folder_digest
    from tools.fit_styles import CONTENT_GROUPS
    t0 = time.time()
    scaler, Z, y, group, cues = real_cells(real)
    real_dirs = discriminant_directions(Z, y)  # already in units of the real within-style spread
    built_dirs = builtin_directions(scaler, Z, y)
    directions = np.concatenate([real_dirs, np.sqrt(BUILTIN_WEIGHT) * built_dirs])  # (14, 396)
    work = []
    for style in styles.STYLES:
        for content in CONTENT_GROUPS:
            mine = (y == style) & (group == content)
            if mine.sum() >= MIN_WINDOWS and (only is None or content in only):
                walk = content in CUE_CONTENTS and style in cues
                cue_target = np.nanmean(cues[style], 0) if walk else None
                cue_scale = np.where(np.nanstd(cues[style], 0) > 0, np.nanstd(cues[style], 0), 1.0) if walk else None
                work.append((style, content, int(mine.sum()), Z[mine].mean(0), scaler, directions, cue_target,
                             cue_scale, iters))
    done = {}
    with ProcessPoolExecutor(max(1, jobs)) as pool:
        for style, content, cell in tqdm(pool.map(_fit_job, work), total=len(work), desc="cells",
                                         disable=not progress):
            done[f"{style}:{content}"] = cell
    fitted_styles = Path(jm.__file__).with_name("fitted_styles.json")
    return {"command": None, "real": {"folder": Path(real).name, "digest": folder_digest(real)},
            "fitted_styles_digest": _digest(fitted_styles),
            "builtin_directions_from": _digest(jm.MOMENTS_FILE),
            "generator_version": GENERATOR_VERSION,
            "metric": "cell mean generated − real along the 7 LDA directions of the real styles and the 7 of the "
                      "built-in styles (in real within-style spreads); walks also their walking cues",
            "min_windows": MIN_WINDOWS, "takes_per_evaluation": TAKES, "iterations": iters,
            "seconds": round(time.time() - t0, 1),
            "cells": {k: c.pop("theta") for k, c in done.items()}, "fit": done}


def _digest(path: Path):
    """First 12 hex digits of a file's sha256 (None when it is absent)."""
    return hashlib.sha256(path.read_bytes()).hexdigest()[:12] if path.is_file() else None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--real", required=True, help="dataset folder of the Xia train split (made by data_prep.bvh)")
    ap.add_argument("--out", default=DEFAULT_OUT, help=f"where the fitted numbers go (default {DEFAULT_OUT})")
    ap.add_argument("--jobs", type=int, default=1, help="cells fitted at once (one core each; default 1)")
    ap.add_argument("--iters", type=int, default=ITERS, help=f"Levenberg–Marquardt iterations per cell (default {ITERS})")
    ap.add_argument("--only", help="comma-separated content groups to fit (default all)")
    ap.add_argument("--force", action="store_true", help="overwrite --out")
    args = ap.parse_args(argv)
    from mslib.fileio import atomic_write_bytes, check_writable
    out = check_writable(args.out, args.force, "--out")
    table = fit(args.real, args.jobs, args.iters, args.only.split(",") if args.only else None)
    table["command"] = (f"python tools/fit_joint_moments.py --real {Path(args.real).name} --out {args.out}"
                        + (f" --iters {args.iters}" if args.iters != ITERS else "")
                        + (f" --only {args.only}" if args.only else ""))
    atomic_write_bytes(out, (json.dumps(table, indent=1) + "\n").encode("utf-8"))
    for key, cell in table["fit"].items():
        print(f"{key:<18} {cell['real_windows']:3d} real windows: residual {cell['residual_before']} → "
              f"{cell['residual_after']} ({cell['seconds']} s)")
    print(f"{len(table['cells'])} cells in {table['seconds']} s → {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
