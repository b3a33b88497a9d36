"""Fit the built-in generator's style parameters to real motion capture (the Xia train split).

    python tools/fit_styles.py --real DIR [--out mslib/data/fitted_styles.json] [--takes N] [--force]

DIR is a dataset folder made by data_prep from the Xia *train* split, e.g.

    python -m data_prep.bvh ../shared/data/xia_train XIA_TRAIN_DIR --dialect auto --labels xia

Never point it at the test grid: the realism report checks the fit there.

What is fitted, first the body. The generator's trunk bones (hips, spine, neck, head, collars,
shoulders) are pointed as the real actor's registered skeleton has them: the median direction of
each bone over the real neutral walking takes, in the body frame with the trunk turned upright
(so that the walking lean stays a style parameter), left and right mirrored into one. Registration
already gives real and built-in motion the same bone lengths; the directions it keeps, and without
this the built-in shoulders sit 0.07 L higher and the head 0.5 L further forward than real ones.

Then the styles. Every style's walking takes (Xia contents 01–12) are described by one vector
(`Describer`): the realism report's cues on 24-frame windows (mslib/evaluation/cues.py: posture,
amplitude, tempo, dynamics), then where its classifier windows fall in the discriminant space of the
real styles — a linear discriminant analysis of the features the report's real-style classifier
reads (means and spreads of body-frame joint positions, velocities and accelerations) over every
real train window — because matching a dozen cues leaves what they do not see (real upper bodies
move sideways about twice as much as the hand-written ones, for one). For each style the tool
finds the means of the generator parameters in FITTED_PARAMS whose generated walks are described
like the real style's: a damped Gauss–Newton fit (Levenberg–Marquardt) on the residuals in real
spreads (per style for a cue; the discriminant directions are in within-style spreads already),
the Jacobian by forward differences with common random numbers (the same generated bodies and
phases at every evaluation, so the objective is smooth), starting from the hand-written table of
styles.py, with a pull toward it (PRIOR_WEIGHT) so that a parameter nothing sees stays where it
was. Jerk is weighted less: the generator's smoothest walk still has more of it than real capture.
The walking fit sets every parameter. (A fit on all five contents at once came no closer to the
real styles and drove parameters to their bounds — an old walker with elbows bent 99° — so it was
not kept.) Then each other content is fitted on its own, from the walking fit and pulled toward it:
a style runs, jumps, punches and kicks with its own posture and vigour (a real depressed or old
person punches and jumps with nearly a neutral one's speed, while their walks are slow), and a
walk says little about that. For every content group with at least MIN_CONTENT_WINDOWS real
windows of the style, the parameters of CONTENT_PARAMS are fitted so that the generated takes of
that content fall where the real ones do in the discriminant space (its part of the Describer's
vector; the cues are walking cues). The generator applies such a content fit as a shift of the
style's (and its sub-styles') means (styles.style_mean).

Sub-styles. Paper D assumes a style varies within itself. Here the variation is the real one: the
style's walking takes (their per-take mean cues, standardised by the style's spread) are split
into thirds along their first principal component — the axis along which that style's real takes
differ most; k-means gave clusters of one or two takes on these few takes — and each third
becomes a sub-style fitted to its own mean cues (starting from the style's fit, reusing its
Jacobian), named after the cue that sets it most apart from its style (e.g. `slow`,
`long-strides`, `upright`; jerk, which the fit cannot reach, names none). Nothing of the real data is stored: only the fitted
parameter means, the cue targets they were fitted to, how close the fit came, and the digest of
the folder that was read.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

TRUNK_BONES = (1, 2, 3, 6, 9, 12, 13, 14, 15, 16, 17)  # joints whose bone (from the parent) is fitted
MIRRORED = {2: 1, 14: 13, 17: 16}  # right joint → its left twin
FITTED_PARAMS = ("lean", "chest", "head", "knee", "shoulder_raise", "shoulder_back", "arm_out", "elbow",
                 "arm_swing", "stride", "knee_lift", "cadence", "bounce", "hip_sway", "sway", "twist",
                 "width", "toe_out", "head_bob", "tremor", "jerk", "action_speed", "action_amp")
CUE_WEIGHT = {"jerk": 0.3}  # every other cue 1
DISCRIMINANT_WEIGHT = 2.0  # per discriminant direction and content group (a cue weighs 1)
CONTENT_GROUPS = {"walk": range(1, 13), "run": range(13, 16), "jump": (16, 17), "punch": range(18, 22),
                  "kick": (22, 23)}  # built-in content → the Xia content ids that are it (24–28: transitions)
TAKES_PER_EVALUATION = {"walk": 16}  # generated per evaluation: the fit is on walks (see the docstring)
_ACTION = ("lean", "chest", "head", "shoulder_raise", "shoulder_back", "arm_out", "elbow", "knee",
           "action_speed", "action_amp", "jerk")
CONTENT_PARAMS = {  # content group → the parameters fitted on it alone (see the docstring)
    "run": ("lean", "chest", "head", "shoulder_raise", "arm_out", "elbow", "arm_swing", "stride",
            "knee_lift", "cadence", "bounce", "twist"),
    "jump": _ACTION, "punch": _ACTION, "kick": _ACTION}
CONTENT_TAKES = 8  # generated takes per evaluation of a content fit
MIN_CONTENT_WINDOWS = 2  # real windows a style needs in a content for that content to be fitted
CONTENT_ITERS = 4
CONTENT_PRIOR_WEIGHT = 0.5  # pull toward the style's walking fit
N_SUBSTYLES = 3
PRIOR_WEIGHT = 0.5  # pull toward the hand table, per (10 × the parameter's per-take spread)
NAMES = {  # cue → (name when the cluster is above its style, name when below)
    "head_height": ("tall", "sunken"), "trunk_pitch": ("leaning", "upright"),
    "head_ahead": ("head-forward", "head-back"), "shoulder_height": ("shoulders-up", "shoulders-down"),
    "arm_swing": ("big-swing", "small-swing"), "stride": ("long-strides", "short-strides"),
    "knee_lift": ("high-knees", "low-knees"), "hand_spread": ("arms-wide", "arms-close"),
    "cadence": ("quick-steps", "slow-steps"), "speed": ("fast", "slow"),
    "bounce": ("bouncy", "level"), "sway": ("swaying", "steady"), "jerk": ("abrupt", "fluid"),
}
DEFAULT_OUT = "mslib/data/fitted_styles.json"


def content_group(content) -> str | None:
    """The built-in content a real Xia content is ('walk', 'run', 'jump', 'punch', 'kick'), None for a transition."""
    if content in CONTENT_GROUPS:
        return str(content)
    number = int(content) if str(content).isdigit() else -1
    return next((g for g, ids in CONTENT_GROUPS.items() if number in ids), None)


def check_train_split(folder) -> None:
    """Refuse a dataset folder made from the Xia test grid (it is for checking only)."""
    from mslib.data.dataset_folder import read_meta
    if "grid" in str(read_meta(folder).get("source", "")):
        raise ValueError(f"--real {folder}: was made from the Xia test grid; fit on the train split only")


def real_takes(folder, progress=True):
    """{style: {content group: [joints (T, 22, 3)]}} of every take of a dataset folder of the Xia train split."""
    from mslib.evaluation.realism import read_clips
    check_train_split(folder)
    out = {}
    for row, joints in read_clips(folder, "--real", progress=progress):  # every split: all of it is train
        out.setdefault(row["style"], {}).setdefault(content_group(row["content"]), []).append(joints)
    if not any(t.get("walk") for t in out.values()):
        raise ValueError(f"--real {folder}: no walking take")
    return out


def trunk_directions(takes) -> dict:
    """{joint: unit (x, y, z)} of TRUNK_BONES: medians over takes of per-take median bone directions in the
    body frame turned about X so that the pelvis → neck line is upright; left/right mirrored together."""
    import numpy as np
    from mslib.evaluation.cues import NECK, PELVIS, body_frame
    from mslib.motion.skeleton import PARENTS
    per_take = []
    for joints in takes:
        q = body_frame(joints)  # (T, 22, 3)
        spine = q[:, NECK] - q[:, PELVIS]
        a = -np.arctan2(spine[:, 2], spine[:, 1])[:, None]  # (T, 1): turn the trunk upright about X
        bones = q[:, TRUNK_BONES] - q[:, [PARENTS[j] for j in TRUNK_BONES]]  # (T, B, 3)
        y = bones[..., 1] * np.cos(a) - bones[..., 2] * np.sin(a)
        z = bones[..., 1] * np.sin(a) + bones[..., 2] * np.cos(a)
        d = np.stack([bones[..., 0], y, z], -1)
        per_take.append(np.median(d / np.linalg.norm(d, axis=-1, keepdims=True), 0))
    d = dict(zip(TRUNK_BONES, np.median(np.stack(per_take), 0)))
    for right, left in MIRRORED.items():
        both = (d[left] + d[right] * np.array([-1.0, 1.0, 1.0])) / 2
        d[left], d[right] = both, both * np.array([-1.0, 1.0, 1.0])
    for j in TRUNK_BONES:
        if j not in MIRRORED and j not in MIRRORED.values():
            d[j] = d[j] * np.array([0.0, 1.0, 1.0])  # a midline bone points straight ahead or up
    return {j: (v / np.linalg.norm(v)).round(4).tolist() for j, v in d.items()}


def use_body(directions: dict) -> None:
    """Point the generator's trunk bones this way in this process (as fitted_styles.json does at import)."""
    import numpy as np
    from mslib.data import body
    for j, v in directions.items():
        body.REST_DIRECTIONS[int(j)] = np.asarray(v) / np.linalg.norm(v)


class Describer:
    """What a style is fitted on, as one vector: the mean cues of its walks' 24-frame windows (cues.py),
    then for each content group the mean of its classifier windows (realism.classifier_windows) in the
    discriminant space of the real styles (linear discriminant analysis of the standardised classifier
    features of every real window, realism.window_features): the few directions in which real styles
    differ, each in units of the real within-style spread."""

    def __init__(self, real: dict):
        import numpy as np
        from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler
        X, y = [], []
        for style, groups in real.items():
            for takes in groups.values():
                f = self._features(takes)
                X.append(f), y.extend([style] * len(f))
        self.lda = make_pipeline(StandardScaler(), LinearDiscriminantAnalysis(solver="eigen", shrinkage="auto"))
        self.lda.fit(np.concatenate(X), y)
        self.n_dims = len(set(y)) - 1
        self.n_cues = len(_cue_names())
        self.parts = {"cues": slice(0, self.n_cues)}
        for k, g in enumerate(CONTENT_GROUPS):
            start = self.n_cues + k * self.n_dims
            self.parts[g] = slice(start, start + self.n_dims)

    @staticmethod
    def _features(takes):
        from mslib.evaluation.realism import take_features
        return take_features(takes)

    def __call__(self, groups: dict):
        """groups: {content group: [joints]} → (n_cues + 5 × n_dims,), NaN where a group has no window."""
        import numpy as np
        from mslib.evaluation.cues import cue_table
        from mslib.evaluation.realism import CUE_WINDOW, windows
        cue_ws = [w for t in groups.get("walk", []) for w in windows(t, CUE_WINDOW)]
        out = [np.nanmean(cue_table(cue_ws), 0) if cue_ws else np.full(self.n_cues, np.nan)]
        for g in CONTENT_GROUPS:
            f = self._features(groups.get(g, []))
            out.append(self.lda.transform(f).mean(0) if len(f) else np.full(self.n_dims, np.nan))
        return np.concatenate(out)


def _cue_names():
    from mslib.evaluation.cues import CUES
    return CUES


class Simulator:
    """The Describer's vector of generated takes for given parameter means (fixed random streams)."""

    def __init__(self, describe: Describer, takes: dict = None, duration: float = 3.0):
        """Each call generates takes[content] takes of every content group, `duration` s at 30 fps, and
        registers them as real takes are."""
        takes = takes or TAKES_PER_EVALUATION
        self.describe, self.calls = describe, 0
        self.specs = [dict(content=g, style="neutral", seed=0, index=3_000_000 + 1000 * k + i, fps=30.0,
                           duration=duration, canonical=False)
                      for k, g in enumerate(CONTENT_GROUPS) for i in range(takes.get(g, 0))]

    def __call__(self, means: dict):
        from mslib.data import styles, synth
        original = styles.style_mean
        styles.style_mean = lambda style, substyle=None, content=None: dict(means)
        try:
            takes = synth.generate_clips(self.specs)
        finally:
            styles.style_mean = original
        self.calls += 1
        groups = {}
        for spec, t in zip(self.specs, takes):
            groups.setdefault(spec["content"], []).append(registered_positions(t))
        return self.describe(groups)


def registered_positions(take):
    """(T, 22, 3) joints of a generated take written as a BVH and registered back, as real takes are."""
    from mslib.data.mocap_skeleton import to_bvh_motion
    from mslib.data.retarget import register_motion
    return register_motion(to_bvh_motion(take.rotations, take.root, take.skeleton, fps=take.fps), "builtin").positions


def fit_means(sim, start: dict, target, scale, weights, prior: dict, iters: int, jacobian=None,
              log=print, names=FITTED_PARAMS, prior_weight=PRIOR_WEIGHT):
    """Levenberg–Marquardt over the parameters `names` on (sim(θ) − target) / scale; returns
    (θ, cues, residual norm, J)."""
    import numpy as np
    from mslib.data.styles import PARAMS
    lo = np.array([PARAMS[k][2] for k in names], float)
    hi = np.array([PARAMS[k][3] for k in names], float)
    step = np.array([max(PARAMS[k][1], 0.02 * (PARAMS[k][3] - PARAMS[k][2])) for k in names])
    pscale = 10 * step
    theta = np.clip(np.array([start[k] for k in names], float), lo, hi)
    th_prior = np.array([prior[k] for k in names], float)

    def means(th):
        return {**start, **dict(zip(names, th.tolist()))}

    def cost(r, th):
        return float(r @ r + prior_weight * (((th - th_prior) / pscale) ** 2).sum())
    cues = sim(means(theta))  # returned as it is (NaN where nothing was generated)
    w = np.where(np.isfinite(target) & np.isfinite(cues), np.sqrt(weights) / scale, 0.0)  # no windows: no say
    target = np.nan_to_num(target)
    r = (np.nan_to_num(cues) - target) * w
    mu, J = 1e-2, jacobian
    for it in range(iters):
        if J is None or (jacobian is None and it > 0):
            J = np.empty((len(r), len(names)))
            for k in range(len(names)):
                th = theta.copy()
                h = step[k] if theta[k] + step[k] <= hi[k] else -step[k]
                th[k] += h
                J[:, k] = ((np.nan_to_num(sim(means(th))) - target) * w - r) / h
        A = J.T @ J + prior_weight * np.diag(1 / pscale ** 2)
        g = J.T @ r + prior_weight * (theta - th_prior) / pscale ** 2
        improved = False
        for _ in range(4):
            new = np.clip(theta - np.linalg.solve(A + mu * np.diag(np.diag(A)), g), lo, hi)
            c_new = sim(means(new))
            r_new = (np.nan_to_num(c_new) - target) * w
            if cost(r_new, new) < cost(r, theta):
                theta, cues, r, improved = new, c_new, r_new, True
                mu = max(mu / 3, 1e-4)
                break
            mu *= 4
        log(f"    iteration {it + 1}: residual {np.linalg.norm(r):.3f}{'' if improved else ' (no step)'}")
        if not improved:
            break
    return means(theta), cues, float(np.linalg.norm(r)), J


def split_takes(takes, scale, k: int):
    """Labels (n_takes,): k equal parts along the first principal component of per-take mean cues
    standardised by `scale` (the component's sign fixed so that its largest loading is positive)."""
    import numpy as np
    X = np.stack([np.nanmean(t, 0) for _, t in takes]) / scale
    X = np.where(np.isfinite(X), X, np.nanmean(X, 0))
    X = X - X.mean(0)
    pc = np.linalg.svd(X, full_matrices=False)[2][0]
    pc = pc * np.sign(pc[np.argmax(np.abs(pc))])
    order = np.argsort(X @ pc, kind="stable")
    labels = np.empty(len(takes), int)
    for part, idx in enumerate(np.array_split(order, k)):
        labels[idx] = part
    return labels


def name_cluster(cluster_mean, style_mean, scale, taken: set, cues) -> str:
    """The NAMES entry of the cue that sets a cluster most apart from its style, not yet taken."""
    import numpy as np
    z = (cluster_mean - style_mean) / scale
    z = np.where([c in CUE_WEIGHT for c in cues], 0.0, np.nan_to_num(z))
    for j in np.argsort(-np.abs(z), kind="stable"):
        name = NAMES[cues[j]][0 if z[j] > 0 else 1]
        if name not in taken:
            return name
    raise ValueError("no free sub-style name")


def fit(real, iters: int = 6, progress: bool = True, log=print) -> dict:
    """The fitted table of a dataset folder of the Xia train split (see the module docstring)."""
    import numpy as np
    from mslib.data import styles
    from mslib.evaluation.cues import CUES, cue_table
    from mslib.evaluation.realism import CUE_WINDOW, folder_digest, windows
    real = Path(real)
    takes = real_takes(real, progress)
    if not takes.get("neutral", {}).get("walk"):
        raise ValueError(f"--real {real}: no neutral walking take to fit the body to")
    directions = trunk_directions(takes["neutral"]["walk"])
    use_body(directions)
    describe = Describer(takes)
    sim = Simulator(describe)
    n = len(describe(takes["neutral"]))
    t0 = time.time()
    out = {}
    for style in styles.STYLES:
        walks = [j for j in takes.get(style, {}).get("walk", []) if len(j) >= CUE_WINDOW]
        if not walks:
            raise ValueError(f"--real {real}: no walking take of style {style!r}")
        target = describe(takes[style])
        cue_scale = np.nanstd(np.concatenate([cue_table(windows(j, CUE_WINDOW)) for j in walks]), 0)
        scale = np.ones(n)
        scale[describe.parts["cues"]] = np.where(cue_scale > 0, cue_scale, 1.0)
        weights = np.full(n, DISCRIMINANT_WEIGHT)
        weights[describe.parts["cues"]] = [CUE_WEIGHT.get(c, 1.0) for c in CUES]
        prior = styles.hand_mean(style)
        log(f"{style}: {len(walks)} walking takes, {sum(len(v) for v in takes[style].values())} takes in all")
        before = sim(prior)
        means, got, _, J = fit_means(sim, prior, target, scale, weights, prior, iters, log=log)
        entry = {"takes": len(walks), "params": _rounded(means), **_summary(describe, before, got, target, scale),
                 "substyles": {}}
        # sub-styles: thirds of the walks; the other contents stay where the style's fit put them
        cues = describe.parts["cues"]
        labels = split_takes([(i, cue_table(windows(j, CUE_WINDOW))) for i, j in enumerate(walks)],
                             scale[cues], N_SUBSTYLES)
        taken: set = set()
        for k in range(N_SUBSTYLES):
            members = [j for j, lab in zip(walks, labels) if lab == k]
            sub_target = got.copy()
            mine = describe({"walk": members})
            for part in ("cues", "walk"):
                sub_target[describe.parts[part]] = mine[describe.parts[part]]
            name = name_cluster(sub_target[cues], target[cues], scale[cues], taken, CUES)
            taken.add(name)
            log(f"  sub-style {name}: {len(members)} takes")
            sub, sub_got, _, _ = fit_means(sim, means, sub_target, scale, weights, means, 4, jacobian=J, log=log)
            entry["substyles"][name] = {"takes": len(members), "params": _rounded(sub),
                                        **_summary(describe, None, sub_got, sub_target, scale)}
        entry["contents"] = fit_contents(style, takes[style], describe, means, target, log)
        out[style] = entry
    return {"command": None, "real": {"folder": real.name, "digest": folder_digest(real)},
            "generator_version": _generator_version(),
            "body": {"takes": len(takes["neutral"]["walk"]), "directions": {str(j): v for j, v in directions.items()}},
            "fitted_params": list(FITTED_PARAMS), "cues": list(CUES), "content_groups": list(CONTENT_GROUPS),
            "takes_per_evaluation": {**TAKES_PER_EVALUATION, **{g: CONTENT_TAKES for g in CONTENT_PARAMS}},
            "content_params": {g: list(v) for g, v in CONTENT_PARAMS.items()},
            "evaluations": sim.calls + sum(c["evaluations"] for e in out.values() for c in e["contents"].values()),
            "seconds": round(time.time() - t0, 1), "styles": out}


def fit_contents(style: str, groups: dict, describe, means: dict, target, log=print) -> dict:
    """{content group: its own fit} of one style: CONTENT_PARAMS fitted on that content's part of the
    described vector, starting from and pulled toward the walking fit `means`."""
    import numpy as np
    out = {}
    for g, names in CONTENT_PARAMS.items():
        n_windows = len(describe._features(groups.get(g, [])))
        if n_windows < MIN_CONTENT_WINDOWS:
            log(f"  {g}: {n_windows} real windows, not fitted (takes the walking fit)")
            continue
        sim = Simulator(describe, {g: CONTENT_TAKES})
        weights = np.zeros(len(target))
        weights[describe.parts[g]] = DISCRIMINANT_WEIGHT
        log(f"  {g}: {n_windows} real windows")
        part = describe.parts[g]
        before = sim(means)
        got_means, got, _, _ = fit_means(sim, means, target, np.ones(len(target)), weights, means,
                                         CONTENT_ITERS, log=log, names=names, prior_weight=CONTENT_PRIOR_WEIGHT)
        out[g] = {"windows": n_windows, "params": _rounded(got_means, names), "evaluations": sim.calls,
                  "gap_before": _gap(before[part], target[part], 1.0),
                  "gap_after": _gap(got[part], target[part], 1.0)}
    return out


def _summary(describe, before, got, target, scale) -> dict:
    """The cue targets and fit, and the gaps (in real spreads) of the cues and of each content's position."""
    cues = describe.parts["cues"]
    out = {"target": _cues(target[cues]), "spread": _cues(scale[cues]), "fitted": _cues(got[cues])}
    for name, part in describe.parts.items():
        if before is not None:
            out.setdefault("gap_before", {})[name] = _gap(before[part], target[part], scale[part])
        out.setdefault("gap_after", {})[name] = _gap(got[part], target[part], scale[part])
    return out


def _generator_version():
    from mslib.data.synth import GENERATOR_VERSION
    return GENERATOR_VERSION


def _rounded(means: dict, names=FITTED_PARAMS) -> dict:
    return {k: float(f"{means[k]:.4g}") for k in names}


def _cues(v) -> dict:
    from mslib.evaluation.cues import CUES
    return {c: float(f"{x:.4g}") for c, x in zip(CUES, v)}  # the cue part of a described vector


def _gap(got, target, scale):
    """Mean |generated − real| in real spreads (the realism report's gap), None without real windows."""
    import numpy as np
    d = np.abs(got - target) / scale
    return float(f"{np.nanmean(d):.3g}") if np.isfinite(d).any() else None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--real", required=True, help="dataset folder of the Xia train split (made by data_prep.bvh)")
    ap.add_argument("--out", default=DEFAULT_OUT, help=f"where the fitted table goes (default {DEFAULT_OUT})")
    ap.add_argument("--iters", type=int, default=6, help="Gauss–Newton iterations per style (default 6)")
    ap.add_argument("--force", action="store_true", help="overwrite --out")
    args = ap.parse_args(argv)
    from mslib.fileio import atomic_write_bytes, check_writable
    out = check_writable(args.out, args.force, "--out")
    table = fit(args.real, args.iters)
    table["command"] = (f"python tools/fit_styles.py --real {Path(args.real).name} --out {args.out}"
                        + (f" --iters {args.iters}" if args.iters != 6 else ""))
    atomic_write_bytes(out, (json.dumps(table, indent=1) + "\n").encode("utf-8"))
    for style, e in table["styles"].items():
        subs = ", ".join(f"{n} ({s['takes']})" for n, s in e["substyles"].items())
        gaps = ", ".join(f"{k} {e['gap_before'][k]} → {e['gap_after'][k]}" for k in e["gap_after"]
                         if e["gap_after"][k] is not None)
        own = ", ".join(f"{g} {c['gap_before']} → {c['gap_after']}" for g, c in e["contents"].items())
        print(f"{style:<10} gaps in real spreads: {gaps}; sub-styles {subs}; own content fits: {own or 'none'}")
    print(f"{table['evaluations']} evaluations in {table['seconds']} s → {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
