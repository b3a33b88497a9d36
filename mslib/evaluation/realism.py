"""The realism report: how far the built-in (generated) styles are from real motion capture.

    python -m mslib data realism --real DIR [--grid DIR] [--out JSON] [--plot PNG] [--json] [--force]

DIR is a dataset folder made by data_prep (e.g. `python -m data_prep.bvh XIA_BVH DIR --dialect auto
--labels xia`). With `--grid`, the whole of `--real` is the training data and the grid folder the
test data; without it, `--real`'s own train and test splits are used. The report has three parts:

1. Cues (cues.py): per style, the mean and spread over walking windows of the real clips against
   the built-in style clips, and a one-number gap per style — the mean over cues of
   |real mean − built-in mean| / real spread.
2. Real → built-in: a standardised logistic regression on per-window means and spreads of body-frame
   joint positions, velocities and accelerations (leg lengths, facing +Z) is fitted on real train
   windows only (its C picked by take-grouped cross-validation on them), checked on real test
   windows (its strength), then asked to name the style of every built-in style test window. A
   built-in style that looked real would be recognised about as well as the real test windows.
3. Built-in → real: the packaged style evaluator (trained on built-in data only) names the style of
   the real test takes, whole (its window-averaged score) and per 32-frame window, and of the real
   training takes (it never saw them either); its accuracy on built-in test clips is the reference.
   Beside it, part 2's recipe the other way round — fitted on built-in style train windows, read on the
   same real takes — tells how much of the gap is the data's and how much the evaluator network's.

Windows are of two lengths because real takes are short (Xia's are mostly 1–2 s at 20 fps): cues need
about one gait cycle (24 frames = 1.2 s), the classifier works on 16 frames (0.8 s) so that most
takes give one; built-in 32-frame windows are cut the same way. A real punch, kick or run take is a
single action cut from a longer performance and often lasts less than 16 frames (every neutral punch
of the train split does): the classifier takes such a take of SHORT_TAKE frames or more whole, as one
window, so that it knows every style's actions (its means and spreads are defined for any length).
Takes too short for a part's windows (cues: 24 frames; classifier: SHORT_TAKE; evaluator windows: 32,
while its whole-take score pads a short take) are left out of that part and counted. Everything is
deterministic: no random draw is made.
"""
from __future__ import annotations

import hashlib
import json
import warnings
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from ..data.dataset_folder import read_labels, read_meta
from ..data.retarget import cut_windows
from ..fileio import atomic_write_bytes, check_writable
from .cues import CUE_GROUPS, CUES, FPS, UNITS, cue_table
from .judge_windows import (CLASSIFIER_WINDOW, HOP, SHORT_TAKE, Windows, as_windows, classifier_windows,  # noqa: F401
                            take_features, window_features, windowed as _windowed, windows)

CUE_WINDOW = 24  # frames at 20 fps (a gait cycle); windows start every HOP frames
EVALUATOR_WINDOW, EVALUATOR_OVERLAP = 32, 8  # the evaluator's windows (A §4.1, as data_prep --windows cuts them)
# walks: "walk", and the raw Xia ids 01–12 of folders converted before data_prep named every Xia content
WALKS = {"walk"} | {f"{i:02d}" for i in range(1, 13)}
C_CHOICES = (0.01, 0.1, 1.0, 10.0)  # inverse regularisation strengths tried by cross-validation
DIGITS = 4  # significant digits stored


# ---------------------------------------------------------------- reading
def folder_digest(folder) -> str:
    """12 hex digits of SHA-256 over the sorted joints/ file names and sizes and the labels.csv bytes."""
    folder = Path(folder)
    h = hashlib.sha256()
    for f in sorted((folder / "joints").glob("*.npy")):
        h.update(f"{f.name}\0{f.stat().st_size}\n".encode())
    h.update((folder / "labels.csv").read_bytes())
    return h.hexdigest()[:12]


def read_clips(folder, arg: str = "--real", split=None, progress: bool = False) -> list:
    """(label row, joints (T, 22, 3)) of a dataset folder's styled clips (one split, or all)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"{arg} {folder}: no such folder (make one with `python -m data_prep.bvh IN_DIR OUT_DIR`)")
    try:
        read_meta(folder)
        rows = read_labels(folder)
    except ValueError as e:
        raise ValueError(f"{arg} {folder}: {e}") from None
    rows = [r for r in rows if r.get("style") and (split is None or r["split"] == split)]
    if not rows:
        raise ValueError(f"{arg} {folder}: no clips with a style label{'' if split is None else f' in split {split!r}'}")
    return [(r, np.load(folder / "joints" / f"{r['clip_id']}.npy").astype(np.float64))
            for r in tqdm(rows, desc=f"reading {folder.name}", unit="clip", disable=not progress)]


def is_walk(content: str) -> bool:
    return str(content) in WALKS


def builtin_info(style_folder) -> dict:
    """The built-in generator's version, source fingerprint and seed (from the build's build.json)."""
    build = Path(style_folder).parent / "build.json"
    info = json.loads(build.read_text(encoding="utf-8")) if build.is_file() else {}
    return {"folder": Path(style_folder).parent.name, "generator_version": info.get("generator_version"),
            "fingerprint": info.get("fingerprint"), "seed": info.get("seed"), "digest": folder_digest(style_folder)}


# ---------------------------------------------------------------- 1. cues
def _by_style(clips, length: int, keep=lambda row: True) -> dict:
    out: dict = {}
    for row, joints in clips:
        if keep(row):
            out.setdefault(row["style"], []).extend(windows(joints, length))
    return out


def _round(x):
    return None if x is None or not np.isfinite(x) else float(f"{x:.{DIGITS}g}")


def cue_comparison(real_clips, builtin_clips, progress: bool = False) -> dict:
    """Per style, mean and spread of every cue over real and built-in walking windows, and the gap."""
    real = _by_style(real_clips, CUE_WINDOW, lambda r: is_walk(r["content"]))
    built = _by_style(builtin_clips, CUE_WINDOW, lambda r: is_walk(r["content"]))
    styles = sorted(s for s in set(real) & set(built) if real[s] and built[s])
    if not styles:
        raise ValueError(f"no style has walking windows of {CUE_WINDOW} frames in both the real and the "
                         f"built-in data (real styles with walks: {sorted(real)}, built-in: {sorted(built)})")
    table = {}
    for s in tqdm(styles, desc="cues", unit="style", disable=not progress):
        r, b = cue_table(real[s]), cue_table(built[s])  # (N, len(CUES))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # a cue undetermined in every window → NaN
            rm, rs, bm, bs = np.nanmean(r, 0), np.nanstd(r, 0), np.nanmean(b, 0), np.nanstd(b, 0)
        gaps = [abs(rm[k] - bm[k]) / rs[k] for k in range(len(CUES)) if rs[k] > 0 and np.isfinite(rm[k] - bm[k])]
        table[s] = {"n_real": len(r), "n_builtin": len(b), "gap_sd": _round(np.mean(gaps)) if gaps else None,
                    "cues": {c: {"real": _round(rm[k]), "real_sd": _round(rs[k]), "builtin": _round(bm[k]),
                                 "builtin_sd": _round(bs[k])} for k, c in enumerate(CUES)}}
    return {"content": "walk", "window_frames": CUE_WINDOW, "hop_frames": HOP, "fps": FPS, "units": UNITS,
            "groups": CUE_GROUPS, "styles": styles, "table": table}


# ---------------------------------------------------------------- 2. real → built-in
def scores(true, pred, classes) -> dict:
    """Accuracy (%), counts, chance, per-style accuracy and most common reading, confusion counts."""
    true, pred = np.asarray(true), np.asarray(pred)
    per = []
    for s in [c for c in classes if (true == c).any()]:
        mine = pred[true == s]
        names, counts = np.unique(mine, return_counts=True)
        top = int(np.argmax(counts))
        per.append({"style": s, "n": int(len(mine)), "accuracy": _round(100.0 * np.mean(mine == s)),
                    "read_as": str(names[top]), "read_as_share": _round(100.0 * counts[top] / len(mine))})
    confusion = [[int(((true == a) & (pred == b)).sum()) for b in classes] for a in classes]
    return {"n": int(len(true)), "accuracy": _round(100.0 * np.mean(true == pred)) if len(true) else None,
            "chance": _round(100.0 / len(classes)), "per_style": per,
            "confusion": {"rows_true_cols_predicted": list(classes), "counts": confusion}}


def fit_window_classifier(X, y, groups, seed: int = 0):
    """StandardScaler + multinomial logistic regression; C by take-grouped k-fold CV on (X, y) only."""
    from sklearn.linear_model import LogisticRegression
    from sklearn.model_selection import GroupKFold, cross_val_score
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    def model(C):
        return make_pipeline(StandardScaler(), LogisticRegression(C=C, max_iter=5000, random_state=seed))
    folds = min(5, len(set(groups)))
    cv = {}
    if folds >= 2 and len(set(y)) >= 2:
        for C in C_CHOICES:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # tiny folds may miss a class
                cv[C] = float(cross_val_score(model(C), X, y, groups=groups, cv=GroupKFold(folds)).mean())
    best = max(C_CHOICES, key=lambda C: (cv.get(C, 0.0), -C)) if cv else 1.0  # ties: the stronger regulariser
    return model(best).fit(X, y), {"C": best, "cv_accuracy": {str(C): _round(100 * a) for C, a in cv.items()},
                                   "cv_folds": folds}


def fit_judge(clips, what: str, seed: int = 0) -> tuple:
    """`fit_window_classifier` on every classifier window of the clips (or their `Windows`):
    (model, {C, CV scores, "train": counts})."""
    X, y, groups, _, short = as_windows(clips)
    if len(set(y)) < 2:
        raise ValueError(f"{what} train data: need windows of {CLASSIFIER_WINDOW} frames from at least two styles, "
                         f"got {sorted(set(y))}")
    clf, choice = fit_window_classifier(X, y, groups, seed)
    return clf, {**choice, "train": {"windows": int(len(y)), "takes": int(len(set(groups))), "takes_too_short": short}}


def real_to_builtin(train_clips, test_clips, builtin_test_clips, seed: int = 0, progress: bool = False,
                    builtin_train_clips=None) -> dict:
    """Fit on real train windows; score real test windows and takes, and built-in style test windows (and, given
    them, the built-in train windows: five times as many takes, none of which any generator setting was chosen on).
    The built-in clips may be given as their `Windows`."""
    clf, fitted = fit_judge(as_windows(train_clips, desc="real train windows", progress=progress), "real", seed)
    classes = list(clf.classes_)
    import sklearn
    out = {"model": f"StandardScaler + LogisticRegression (scikit-learn {sklearn.__version__}, lbfgs)", **fitted,
           "features": "mean and std over time of body-frame joint positions, velocities, accelerations (396)",
           "window_frames": CLASSIFIER_WINDOW, "hop_frames": HOP, "short_take_frames": SHORT_TAKE, "classes": classes}
    test = linear_scores(clf, test_clips)
    if test:
        out["real_test_windows"], out["real_test_by_content"], out["real_test_takes"] = (
            test["windows"], test["by_content"], test["takes"])
    for split, clips in (("test", builtin_test_clips), ("train", builtin_train_clips)):
        if clips is None:
            continue
        Xb, yb, _, content_b, short_b = as_windows(clips, set(classes), f"built-in {split} windows", progress)
        if len(yb):
            pred_b = clf.predict(Xb)
            out[f"builtin_{split}_windows"] = {**scores(yb, pred_b, classes), "takes_too_short": short_b}
            walk = np.array([is_walk(c) for c in content_b])
            out[f"builtin_{split}_walk_windows"] = scores(yb[walk], pred_b[walk], classes)
            out[f"builtin_{split}_by_content"] = by_content(yb, pred_b, content_b)
    return out


def linear_scores(clf, clips) -> dict:
    """A window classifier's `scores` on the classifier windows of clips with a style it knows, per window,
    per content and per take (the take's window probabilities averaged); {} if no window."""
    classes = list(clf.classes_)
    X, y, take, content, short = _windowed(clips, set(classes))
    if not len(y):
        return {}
    pred, proba, takes = clf.predict(X), clf.predict_proba(X), sorted(set(take))
    mean_p = np.stack([proba[take == t].mean(0) for t in takes])
    return {"windows": {**scores(y, pred, classes), "takes_too_short": short},
            "by_content": by_content(y, pred, content),
            "takes": scores([y[take == t][0] for t in takes], np.array(classes)[mean_p.argmax(1)], classes)}


def by_content(true, pred, content) -> dict:
    """{content: {"n": windows, "accuracy": %}}: each window counted once, under its content."""
    return {str(c): {"n": int((content == c).sum()), "accuracy": _round(100 * np.mean(pred[content == c] == true[content == c]))}
            for c in sorted(set(content))}


# ---------------------------------------------------------------- 3. built-in → real
def take_scores(model, clips) -> dict | None:
    """`scores` of a style classifier on whole clips (window-averaged logits) with a style it knows; None if none."""
    classes = list(model.classes)
    clips = [(r, j) for r, j in clips if r["style"] in classes]
    if not clips:
        return None
    logits, _ = model.score([j for _, j in clips])
    return scores([r["style"] for r, _ in clips], np.array(classes)[logits.argmax(1)], classes)


def builtin_to_real(test_clips, train_clips=None, builtin_folder=None, evaluator=None) -> dict:
    """The packaged style evaluator on real takes (whole and per 32-frame window); reference: built-in test."""
    from ..checkpoints import checkpoint_digest
    from .evaluator import load_classifier, test_accuracy
    model = evaluator or load_classifier("style")
    out = {"model": "packaged evaluator_style (temporal conv net, trained on built-in data only)",
           "checkpoint": checkpoint_digest("evaluator_style") if evaluator is None else "given",
           "classes": list(model.classes), "real_test_takes": take_scores(model, test_clips)}
    ws = [(r, w) for r, j in test_clips for w in cut_windows(j, EVALUATOR_WINDOW, EVALUATOR_OVERLAP)]
    out["real_test_windows"] = take_scores(model, ws) if ws else None
    if out["real_test_windows"] is not None:
        out["real_test_windows"]["window_frames"] = EVALUATOR_WINDOW
    if train_clips is not None:
        out["real_train_takes"] = take_scores(model, train_clips)
    if builtin_folder is not None:
        out["builtin_test_clips_accuracy"] = _round(test_accuracy(model, builtin_folder, "test"))
    return out


def builtin_linear_to_real(builtin_train_clips, test_clips, train_clips=None, seed: int = 0) -> dict:
    """Part 2's recipe the other way round: fitted on built-in style train windows, read on real takes. Beside
    the packaged evaluator it separates the gap of the data from the gap of the evaluator's own network.
    builtin_train_clips: clips or their `Windows`."""
    clf, fitted = fit_judge(builtin_train_clips, "built-in", seed)
    test = linear_scores(clf, test_clips)
    out = {**fitted, "real_test_windows": test.get("windows"), "real_test_takes": test.get("takes")}
    if train_clips is not None:
        out["real_train_takes"] = linear_scores(clf, train_clips).get("takes")
    return out


# ---------------------------------------------------------------- the report
def realism_report(real, grid=None, builtin=None, seed: int = 0, evaluator=None, progress: bool = True) -> dict:
    """All three parts for a real dataset folder (and its test grid) against the built-in style corpus.

    builtin: a style dataset folder (default: the built-in corpus, built into the cache if needed)."""
    real_all = read_clips(real, "--real", progress=progress)  # the user's folders first: fail fast
    if grid is not None:
        train, test = real_all, read_clips(grid, "--grid", progress=progress)
        shared = {r["source_file"] for r, _ in train if r["source_file"]} & {r["source_file"] for r, _ in test}
        if shared:
            raise ValueError(f"--grid {grid}: shares {len(shared)} source file(s) with --real {real} "
                             f"(e.g. {sorted(shared)[0]}); the test grid must be held out")
    else:
        train = [(r, j) for r, j in real_all if r["split"] == "train"]
        test = [(r, j) for r, j in real_all if r["split"] == "test"]
        if not train or not test:
            raise ValueError(f"--real {real}: without --grid it needs train and test clips, has "
                             f"{len(train)} train and {len(test)} test")
    if builtin is None:
        from ..data.corpora import load_builtin
        builtin = load_builtin(progress=progress)["style"]
    built = read_clips(builtin, "builtin", progress=progress)
    built_test = [(r, j) for r, j in built if r["split"] == "test"]
    built_train = as_windows([(r, j) for r, j in built if r["split"] == "train"], desc="built-in train windows",
                             progress=progress)  # cut once: read by both linear judges
    report = {
        "real": {**_provenance(real), "takes": len(real_all)},
        "grid": None if grid is None else {**_provenance(grid), "takes": len(test)},
        "builtin": {**builtin_info(builtin), "style_clips": len(built), "style_test_clips": len(built_test)},
        "cues": cue_comparison(real_all, built, progress),
        "real_to_builtin": real_to_builtin(train, test, built_test, seed, progress, built_train),
        "builtin_to_real": builtin_to_real(test, train if grid is not None else None, builtin, evaluator),
        "builtin_linear_to_real": builtin_linear_to_real(built_train, test, train if grid is not None else None, seed),
    }
    return report


def _provenance(folder) -> dict:
    meta = read_meta(folder)
    return {"folder": Path(folder).name, "digest": folder_digest(folder), "made_by": meta.get("source"),
            "dialect": meta.get("dialect")}


def command_line(real, grid=None, out=None, plot=None, force=False) -> str:
    """The command that makes a report (stored with it; folders by name: where they are is the user's)."""
    parts = ["python -m mslib data realism", f"--real {Path(real).name}"]
    parts += [f"--grid {Path(grid).name}"] if grid else []
    parts += [f"--out {out}"] if out else []
    parts += [f"--plot {Path(plot).name}"] if plot else []
    return " ".join(parts + (["--force"] if force else []))


def save_report(report: dict, path, force: bool = False) -> Path:
    """The report as indented JSON, atomically; refuses an existing file unless `force`."""
    path = check_writable(path, force, "--out")
    atomic_write_bytes(path, (json.dumps(report, indent=1, sort_keys=False) + "\n").encode("utf-8"))
    return path


def _pair(cue, x) -> str:
    return "—" if x is None else f"{x:.0f}" if cue in ("jerk", "trunk_pitch") else f"{x:.2f}"


def _score(s) -> str:
    return "—" if not s else f"{s['accuracy']:.0f} % of {s['n']}"


def format_report(report: dict) -> str:
    """The cue table (real/built-in per style) and the cross scores, as text."""
    cues = report["cues"]
    styles = cues["styles"]
    width = max(13, *(len(s) + 2 for s in styles))
    b = report["builtin"]
    lines = [f"real {report['real']['folder']} (digest {report['real']['digest']}) vs built-in generator "
             f"v{b['generator_version']}-{b['fingerprint']} seed {b['seed']}",
             f"cues on walking windows of {cues['window_frames']} frames, real/built-in:",
             f"{'cue':<24}" + "".join(f"{s:>{width}}" for s in styles)]
    for c in CUES:
        lines.append(f"{c + ' (' + UNITS[c] + ')':<24}" + "".join(
            f"{_pair(c, cues['table'][s]['cues'][c]['real']) + '/' + _pair(c, cues['table'][s]['cues'][c]['builtin']):>{width}}"
            for s in styles))
    lines.append(f"{'windows':<24}" + "".join(f"{str(cues['table'][s]['n_real']) + '/' + str(cues['table'][s]['n_builtin']):>{width}}"
                                         for s in styles))
    lines.append(f"{'gap (real sd)':<24}" + "".join(f"{_pair('', cues['table'][s]['gap_sd']):>{width}}" for s in styles))
    lines += ["", format_cross_scores(report)]
    return "\n".join(lines)


def format_cross_scores(report: dict) -> str:
    """The cross scores (real → built-in; built-in → real by the evaluator and by the linear recipe), as text."""
    rb, br = report["real_to_builtin"], report["builtin_to_real"]
    chance = rb.get("real_test_windows", {}).get("chance")
    def contents(key):
        return ["    by content: " + ", ".join(f"{c} {v['accuracy']:.0f} % of {v['n']}" for c, v in rb[key].items())
                ] if rb.get(key) else []
    whole = (f", takes of {rb['short_take_frames']}–{rb['window_frames'] - 1} frames whole"
             if rb.get("short_take_frames") else "")
    lines = [f"real → built-in: logistic regression (C={rb['C']}) fitted on {rb['train']['windows']} real train "
             f"windows of {rb['window_frames']} frames{whole}; chance {chance} %",
             f"  real test windows {_score(rb.get('real_test_windows'))}, takes {_score(rb.get('real_test_takes'))}",
             *contents("real_test_by_content"),
             f"  built-in style test windows {_score(rb.get('builtin_test_windows'))} "
             f"(walks {_score(rb.get('builtin_test_walk_windows'))})",
             *contents("builtin_test_by_content")]
    for p in (rb.get("builtin_test_windows") or {}).get("per_style", []):
        lines.append(f"    {p['style']:<10} {p['accuracy']:5.0f} %  read as {p['read_as']} ({p['read_as_share']:.0f} %)")
    if rb.get("builtin_train_windows"):
        lines += [f"  built-in style train windows {_score(rb['builtin_train_windows'])} "
                  f"(walks {_score(rb.get('builtin_train_walk_windows'))}): more takes, so a steadier figure",
                  *contents("builtin_train_by_content")]
    lines += [f"built-in → real: packaged style evaluator ({br.get('builtin_test_clips_accuracy')} % on built-in test clips)",
              f"  real test takes {_score(br.get('real_test_takes'))}, 32-frame windows {_score(br.get('real_test_windows'))}"
              + (f", real train takes {_score(br.get('real_train_takes'))}" if br.get("real_train_takes") else "")]
    for p in (br.get("real_test_takes") or {}).get("per_style", []):
        lines.append(f"    {p['style']:<10} {p['accuracy']:5.0f} %  read as {p['read_as']} ({p['read_as_share']:.0f} %)")
    bl = report.get("builtin_linear_to_real")
    if bl:
        lines += [f"built-in → real, the real → built-in recipe the other way round: logistic regression (C={bl['C']}) "
                  f"fitted on {bl['train']['windows']} built-in style train windows",
                  f"  real test takes {_score(bl.get('real_test_takes'))}, windows {_score(bl.get('real_test_windows'))}"
                  + (f", real train takes {_score(bl.get('real_train_takes'))}" if bl.get("real_train_takes") else "")]
    return "\n".join(lines)


def realism_figure(report: dict, dpi: int = 80):
    """One panel per cue (real ● vs built-in ■ per style, ± one spread) and the two cross scores."""
    import matplotlib.pyplot as plt
    cues, styles = report["cues"], report["cues"]["styles"]
    fig, axes = plt.subplots(4, 4, figsize=(13, 10.5))
    x = np.arange(len(styles))
    for ax, c in zip(axes.flat, CUES):
        for dx, who, mark, colour in ((-0.15, "real", "o", "tab:blue"), (0.15, "builtin", "s", "tab:orange")):
            m = [cues["table"][s]["cues"][c][who] for s in styles]
            sd = [cues["table"][s]["cues"][c][who + "_sd"] for s in styles]
            m = np.array([np.nan if v is None else v for v in m])
            sd = np.array([0 if v is None else v for v in sd])
            ax.errorbar(x + dx, m, sd, fmt=mark, color=colour, capsize=2, label="real" if who == "real" else "built-in")
        group = next(g for g, cs in CUE_GROUPS.items() if c in cs)
        ax.set_title(f"{group}: {c} ({UNITS[c]})", fontsize=10)
        ax.set_xticks(x, styles, fontsize=8, rotation=30)
        ax.grid(alpha=0.3)
    axes.flat[0].legend(fontsize=8)
    panels = ((report["real_to_builtin"].get("builtin_test_windows"), report["real_to_builtin"].get("real_test_windows"),
               "real → built-in: real-trained classifier", "built-in test windows", "real test windows",
               ("tab:orange", "tab:blue")),
              (report["builtin_to_real"].get("real_test_takes"), report["builtin_to_real"].get("real_train_takes"),
               "built-in → real: packaged evaluator", "real test takes", "real train takes",
               ("tab:blue", "lightsteelblue")))
    for ax, (a, b, title, la, lb, colours) in zip(axes.flat[len(CUES):], panels):
        chance = 100.0 / len(styles)
        for dx, s, lab, colour in ((-0.2, a, la, colours[0]), (0.2, b, lb, colours[1])):
            if s:
                acc = {p["style"]: p["accuracy"] for p in s["per_style"]}
                ax.bar(x + dx, [acc.get(st, 0) for st in styles], 0.4, color=colour,
                       label=f"{lab} ({s['accuracy']:.0f} %)")
                chance = s["chance"]
        ax.axhline(chance, color="k", ls="--", lw=1, label=f"chance {chance:.1f} %")
        ax.set_title(title, fontsize=10)
        ax.set_ylim(0, 175), ax.set_yticks(range(0, 101, 20)), ax.set_ylabel("% recognised", fontsize=8)
        ax.set_xticks(x, styles, fontsize=8, rotation=30)
        ax.legend(fontsize=6.5, loc="upper left", ncol=1, frameon=False)
    ax = axes.flat[len(CUES) + 2]
    ax.axis("off")
    b = report["builtin"]
    ax.text(0, 1, f"real: {Path(report['real']['folder']).name} ({report['real']['digest']})\n"
                  f"built-in: v{b['generator_version']}-{b['fingerprint']} seed {b['seed']}\n"
                  f"cues: walking windows of {cues['window_frames']} frames,\n"
                  "mean ± std over windows; L = leg length\n\n"
                  "gap per style: mean over cues of\n|real − built-in| / real std\n"
                  + "\n".join(f"  {s:<10} {cues['table'][s]['gap_sd']:.1f}" for s in styles
                              if cues["table"][s]["gap_sd"] is not None),
            va="top", fontsize=9, family="monospace")
    fig.suptitle("Realism report: real motion capture vs the built-in styles", fontsize=13)
    fig.tight_layout()
    fig.set_dpi(dpi)
    return fig


def plot_report(report: dict, path, force: bool = False) -> Path:
    """The realism figure saved as a PNG, atomically; refuses an existing file unless `force`."""
    import io
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    path = check_writable(path, force, "--plot")
    fig = realism_figure(report)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())
    return path


def run(real, grid=None, out=None, plot=None, force: bool = False, progress: bool = True) -> dict:
    """The `data realism` command: the report, with its command, saved to `out` and drawn to `plot`."""
    for p, arg in ((out, "--out"), (plot, "--plot")):
        if p is not None:
            check_writable(p, force, arg)  # fail before the work, not after
    report = {"command": command_line(real, grid, out, plot, force), **realism_report(real, grid, progress=progress)}
    if out is not None:
        save_report(report, out, force)
    if plot is not None:
        plot_report(report, plot, force)
    return report
