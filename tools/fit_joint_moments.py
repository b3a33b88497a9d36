"""Fit the generator's per-joint moment layer (mslib/data/joint_moments.py) to the Xia train split.

    python tools/fit_joint_moments.py --real DIR [--out mslib/data/fitted_joint_moments.json] [--jobs 2] [--force]

DIR is a dataset folder made by data_prep from the Xia *train* split (as for tools/fit_styles.py,
whose fitted styles this layer sits on top of: refit the layer whenever they change). Never point
it at the test grid: the realism report checks the fit there.

What is matched. A real-style judge reads per-window means and spreads of body-frame joint
positions, velocities and accelerations (the realism report's 396 features). For every
(style, content) cell with at least MIN_WINDOWS real windows, the layer's 96 numbers are fitted so
that the generated windows of that cell fall, on average, where the real ones do in the
discriminant space of the real styles: a linear discriminant analysis (shrinkage) of the
standardised features of every real train window, its 7 directions. That is the space in which
styles differ, and the one fit_styles' Describer uses; matching all 396 means instead (plainly or
whitened) moves the cheap features and leaves the telling ones, and a judge then reads little
difference. The report's judge itself (a logistic regression) is not used here, so the report
still checks the fit with a model it was not fitted to.

How. Levenberg–Marquardt on the 7 residuals per cell plus a pull of every number toward zero
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
START_SPREAD = 2.0  # degrees: the first guess of every spread (at 0, |s| has a kink), unless no layer is closer


def real_cells(folder):
    """Standardised features, styles and content groups of every real train window, and the judge space."""
    from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
    from sklearn.preprocessing import StandardScaler

    from mslib.evaluation import realism
    from tools.fit_styles import check_train_split, content_group
    check_train_split(folder)
    X, y, _, content, _ = realism._windowed(realism.read_clips(folder, "--real"))
    scaler = StandardScaler().fit(X)
    Z = scaler.transform(X)
    lda = LinearDiscriminantAnalysis(solver="eigen", shrinkage="auto").fit(Z, y)
    directions = lda.scalings_[:, :len(lda.classes_) - 1].T  # (7, 396)
    return scaler, directions, Z, y, np.array([content_group(c) for c in content])


def generated_features(style: str, content: str, theta) -> np.ndarray:
    """(N, 396) features of TAKES generated clips of the cell with the layer's numbers `theta`."""
    from mslib.data import synth
    from mslib.evaluation import realism
    from tools.fit_styles import registered_positions
    table = {(style, content): np.asarray(theta)}
    specs = [dict(content=content, style=style, seed=FIT_SEED, index=FIRST_INDEX + i, fps=30.0, duration=DURATION,
                  canonical=False) for i in range(TAKES)]
    saved = jm.FITTED
    jm.FITTED = table  # only this cell's numbers (the layer of neutral is not mixed in: intensity 1)
    try:
        clips = synth.generate_clips(specs)
    finally:
        jm.FITTED = saved
    return np.array([realism.window_features(w) for c in clips
                     for w in realism.windows(registered_positions(c), realism.CLASSIFIER_WINDOW)])


def fit_cell(style: str, content: str, target, scaler, directions, iters: int = ITERS) -> dict:
    """Levenberg–Marquardt of one cell's numbers on directions · (mean generated − real), pulled toward 0."""
    def residual(th):
        return directions @ (scaler.transform(generated_features(style, content, th)).mean(0) - target)

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
    style, content, n, target, scaler, directions, iters = job
    t0 = time.time()
    out = fit_cell(style, content, target, scaler, directions, iters)
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
    scaler, directions, Z, y, group = real_cells(real)
    work = []
    for style in styles.STYLES:
        for content in CONTENT_GROUPS:
            mine = (y == style) & (group == content)
            if mine.sum() >= MIN_WINDOWS and (only is None or content in only):
                work.append((style, content, int(mine.sum()), Z[mine].mean(0), scaler, directions, iters))
    done = {}
    with ProcessPoolExecutor(max(1, jobs)) as pool:
        for style, content, cell in tqdm(pool.map(_fit_job, work), total=len(work), desc="cells",
                                         disable=not progress):
            done[f"{style}:{content}"] = cell
    fitted_styles = Path(jm.__file__).with_name("fitted_styles.json")
    return {"command": None, "real": {"folder": Path(real).name, "digest": folder_digest(real)},
            "fitted_styles_digest": hashlib.sha256(fitted_styles.read_bytes()).hexdigest()[:12]
            if fitted_styles.is_file() else None,
            "generator_version": GENERATOR_VERSION,
            "metric": "LDA directions (7) of standardised real window features, cell mean generated − real",
            "min_windows": MIN_WINDOWS, "takes_per_evaluation": TAKES, "iterations": iters,
            "seconds": round(time.time() - t0, 1),
            "cells": {k: c.pop("theta") for k, c in done.items()}, "fit": done}


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
