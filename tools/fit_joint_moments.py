"""Fit the generator's per-joint moment layer (mslib/data/joint_moments.py) to the Xia train split.

    python tools/fit_joint_moments.py --real DIR [--out mslib/data/fitted_joint_moments.json] [--jobs 2] [--force]

DIR is a dataset folder made by data_prep from the Xia *train* split (as for tools/fit_styles.py,
whose fitted styles this layer sits on top of: refit the layer whenever they change). Never point
it at the test grid: the realism report checks the fit there.

What is matched. A real-style judge reads per-window means and spreads of body-frame joint
positions, velocities and accelerations (the realism report's 396 features). For every
(style, content) cell with at least MIN_WINDOWS real windows, the layer's 96 numbers are fitted so
that the generated windows of that cell fall, on average, where the real ones do — along 14
directions of the standardised features and in every feature, each in units of the real windows'
spread about their style's mean:
- the 7 discriminant directions of the real styles (a linear discriminant analysis with shrinkage
  of every real train window): where real styles differ, so a judge of real styles reads the
  built-in ones as their names (real → built-in). Matching all 396 means instead (plainly or
  whitened) moves the cheap features and leaves the telling ones;
- the 7 discriminant directions of the built-in styles, as the generator makes them with the layer
  it has loaded when the tool starts (BUILTIN_TAKES takes per cell; the digest of that layer file is
  stored): where a judge trained on built-in data looks. If real cells sit elsewhere along them, such a
  judge — the packaged evaluator — misreads real takes (built-in → real), however well the first 7 match;
- every one of the 396 feature means, each in units of its real within-style spread, as one block
  (weight ALL_MEANS_WEIGHT), and the 66 mean body-frame positions once more as a block of their own
  (POSE_WEIGHT): a conv net trained on built-in clips reads the mean pose of a cell far more than a
  linear judge does (tools/realism_gap.py `reverse_network`: matching the cells' mean poses alone
  lifts such a net from about 62 % to 78 % of held-out real takes), and 14 directions leave the pose
  free wherever the judges' directions do not look;
- for walking cells, also the walking cues (mslib/evaluation/cues.py), in the real style's spread,
  jerk weighted less as in fit_styles: aimed at the judges' directions alone, the layer is free to
  shorten an old walker's steps or add jerk that real walks do not have.
The blocks pull against the 7 real directions; where they win, a real judge loses the built-in
styles of that content. `--real-weight` weighs those 7 directions more; the shipped layer is made
in steps (data_prep/README.md): every cell at the default weights, then some contents refitted from
it (`--warm`, `--only`) with the real directions weighing 4 (on the real train takes and the
built-in val windows this won back the real judge's jumps, kicks, punches and walks and kept the
evaluator's gain: tools/realism_gap.py and the realism report measure both).
The report's judge itself (a logistic regression) is not used here, so the report still checks the
fit with a model it was not fitted to. Because the second set of directions depends on the layer in
place, refitting is one step of an iteration; the stored "builtin_directions_from" says which step.

How. Levenberg–Marquardt on the residuals of each cell plus a pull of every number toward zero
(PRIOR_WEIGHT, in units of PRIOR_SCALE: 15° for offsets, 0.5 for log gains, 6° for spreads), the
Jacobian by forward differences with common random numbers (the same TAKES generated takes, by
index, at every evaluation, so the objective is smooth). Cells run in parallel (--jobs).
Stored: the numbers per cell, each cell's residual before and after, the command (and, after an
`--only` refit, the earlier commands whose cells it kept), the weights, the digests of the real
folder and of the fitted styles it was fitted on top of. Nothing of the real data.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from dataclasses import asdict, dataclass
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
POSE_WEIGHT = 56.0  # the 66 mean body-frame positions, as one block, against one direction's 1
ALL_MEANS_WEIGHT = 14.0  # all 396 feature means, as one block, against one direction's 1
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


@dataclass(frozen=True)
class Weights:
    """What each part of a cell's residual weighs (one discriminant direction weighs 1)."""
    real: float = 1.0  # each of the 7 real styles' discriminant directions (the first 7 rows of `directions`)
    pose_means: float = POSE_WEIGHT  # the 66 mean positions (the pos_mean features), as one block
    all_means: float = ALL_MEANS_WEIGHT  # all 396 feature means, as one block


def fit_cell(style: str, content: str, target, scaler, directions, cue_target=None, cue_scale=None,
             iters: int = ITERS, within=None, weights: Weights = Weights(), start=None) -> dict:
    """Levenberg–Marquardt of one cell's numbers on directions · (mean generated − real), the feature means'
    (mean generated − real) / within (each feature's real spread about its style's mean; default 1) and, for a
    walk, the walking cues' (mean generated − real) / real spread; all pulled toward 0. start: numbers to start
    from (the layer in place) when they beat the default start."""
    from mslib.evaluation.cues import CUES
    from tools.fit_styles import CUE_WEIGHT
    with_cues = cue_target is not None
    cue_w = np.sqrt([CUE_WEIGHT.get(c, 1.0) for c in CUES]) / cue_scale if with_cues else None
    within = np.ones(len(target)) if within is None else np.asarray(within)
    row_w = np.sqrt(np.where(np.arange(len(directions)) < 7, weights.real, 1.0))[:, None]
    n_pose = 66  # the pos_mean features come first (realism.window_features)

    def residual(th):
        # only this cell's numbers (the layer of neutral is not mixed in: intensity 1)
        f, cues = generated_windows(style, content, {(style, content): th}, with_cues=with_cues)
        gap = scaler.transform(f).mean(0) - target  # (396,)
        r = [(row_w * directions) @ gap,
             np.sqrt(weights.all_means / len(gap)) * gap / within,
             np.sqrt(weights.pose_means / n_pose) * gap[:n_pose] / within[:n_pose]]
        r = np.concatenate(r)
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
    if start is not None:
        start = np.asarray(start, np.float64)
        r_start = residual(start)
        if cost(r_start, start) < cost(r, theta):
            theta, r = start, r_start
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


def _fit_job(job: dict):
    n = job.pop("real_windows")
    t0 = time.time()
    out = fit_cell(**job)
    return job["style"], job["content"], {**out, "real_windows": n, "seconds": round(time.time() - t0, 1)}


def fit(real, jobs: int = 1, iters: int = ITERS, only=None, progress: bool = True, weights: Weights = Weights(),
        warm: bool = False) -> dict:
    """{'cells': {'style:content': numbers}, 'fit': {...}} for every cell with ≥ MIN_WINDOWS real windows (only
    the content groups in `only`, if given: the other cells are kept from the layer in place). warm: start each
    cell from the layer in place."""
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
    within = within_spread(Z, y)  # (396,): each feature's real spread about its style's mean
    within = np.where(within > 0, within, 1.0)
    kept = json.loads(jm.MOMENTS_FILE.read_text(encoding="utf-8")) if (warm or only) and jm.MOMENTS_FILE.is_file() else {}
    in_place = kept.get("cells", {})
    work = []
    for style in styles.STYLES:
        for content in CONTENT_GROUPS:
            mine = (y == style) & (group == content)
            if mine.sum() >= MIN_WINDOWS and (only is None or content in only):
                walk = content in CUE_CONTENTS and style in cues
                cue_target = np.nanmean(cues[style], 0) if walk else None
                cue_scale = np.where(np.nanstd(cues[style], 0) > 0, np.nanstd(cues[style], 0), 1.0) if walk else None
                work.append(dict(style=style, content=content, real_windows=int(mine.sum()), target=Z[mine].mean(0),
                                 scaler=scaler, directions=directions, cue_target=cue_target, cue_scale=cue_scale,
                                 iters=iters, within=within, weights=weights,
                                 start=in_place.get(f"{style}:{content}") if warm else None))
    done = {}
    with ProcessPoolExecutor(max(1, jobs)) as pool:
        for style, content, cell in tqdm(pool.map(_fit_job, work), total=len(work), desc="cells",
                                         disable=not progress):
            done[f"{style}:{content}"] = cell
    cells = {k: c.pop("theta") for k, c in done.items()}
    earlier = []
    if only:  # the cells not refitted stay as the layer in place has them
        cells = {**in_place, **cells}
        done = {**kept.get("fit", {}), **done}
    if kept.get("command"):  # a warm start or a partial refit builds on the commands that made the layer in place
        earlier = kept.get("earlier_commands", []) + [kept["command"]]
    fitted_styles = Path(jm.__file__).with_name("fitted_styles.json")
    return {"command": None, "earlier_commands": earlier,
            "real": {"folder": Path(real).name, "digest": folder_digest(real)},
            "fitted_styles_digest": _digest(fitted_styles),
            "builtin_directions_from": _digest(jm.MOMENTS_FILE),
            "generator_version": GENERATOR_VERSION,
            "metric": "cell mean generated − real along the 7 LDA directions of the real styles and the 7 of the "
                      "built-in styles, and every feature mean (all in real within-style spreads); walks also their "
                      "walking cues",
            "weights": asdict(weights), "warm": warm, "min_windows": MIN_WINDOWS, "takes_per_evaluation": TAKES,
            "iterations": iters, "seconds": round(time.time() - t0, 1), "cells": cells, "fit": done}


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
    ap.add_argument("--only", help="comma-separated content groups to refit (default all); the other cells are "
                                   "kept from the layer in place")
    ap.add_argument("--warm", action="store_true", help="start every cell from the layer in place")
    ap.add_argument("--real-weight", type=float, default=1.0,
                    help="weight of each of the 7 real discriminant directions (default 1)")
    ap.add_argument("--pose-means", type=float, default=POSE_WEIGHT,
                    help=f"weight of the 66 mean positions, as a block (default {POSE_WEIGHT:g})")
    ap.add_argument("--all-means", type=float, default=ALL_MEANS_WEIGHT,
                    help=f"weight of all 396 feature means, as a block (default {ALL_MEANS_WEIGHT:g})")
    ap.add_argument("--force", action="store_true", help="overwrite --out")
    args = ap.parse_args(argv)
    from mslib.fileio import atomic_write_bytes, check_writable
    out = check_writable(args.out, args.force, "--out")
    weights = Weights(args.real_weight, args.pose_means, args.all_means)
    table = fit(args.real, args.jobs, args.iters, args.only.split(",") if args.only else None, weights=weights,
                warm=args.warm)
    table["command"] = (f"python tools/fit_joint_moments.py --real {Path(args.real).name} --out {args.out}"
                        + (f" --iters {args.iters}" if args.iters != ITERS else "")
                        + (f" --only {args.only}" if args.only else "") + (" --warm" if args.warm else "")
                        + "".join(f" {flag} {value:g}" for flag, value, default in (
                            ("--real-weight", args.real_weight, 1.0), ("--pose-means", args.pose_means, POSE_WEIGHT),
                            ("--all-means", args.all_means, ALL_MEANS_WEIGHT)) if value != default))
    atomic_write_bytes(out, (json.dumps(table, indent=1) + "\n").encode("utf-8"))
    for key, cell in table["fit"].items():
        print(f"{key:<18} {cell['real_windows']:3d} real windows: residual {cell['residual_before']} → "
              f"{cell['residual_after']} ({cell['seconds']} s)")
    print(f"{len(table['cells'])} cells in {table['seconds']} s → {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
