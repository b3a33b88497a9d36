"""Paper C's findings, measured: style-code clusters with and without the contrastive terms (C Fig. 2),
the β sweep (C Table 1) and an unseen style (C Fig. 3).

Short runs are too slow for a notebook, so `python tools/contrastive_analysis.py` trains them
once (six course-sized runs of 300 steps) and writes `notebooks/data/03_contrastive_findings.json`:
the tables, silhouettes and the t-SNE points of the held-out style codes, with the command and the
commit that made them; notebook 03 loads it if it exists, else computes it (`findings`). Labels are used
only to colour and score codes, never in training (the unseen-style run leaves the depressed clips out of
its training data).

Distances of the β sweep (our choice; C's network layers are not public, and models may not use the
evaluator): on held-out (content, style) pairs, with x the normalised "ric" block (BLOCKS["ric"],
the C = 63 root-relative joint coordinates) of a motion,
    content distance = mean over frames of ‖x_out(t) − x_content(t)‖ / √C,
    style distance   = ‖Gram(x_out) − Gram(x_style)‖_F / C, Gram(x) = xᵀx / T   (Gatys et al.).
Silhouettes and t-SNE come from scikit-learn (cosine-free, Euclidean on the style codes).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tools.common import DATA_DIR, current_commit, update_json  # noqa: E402

from mslib.data.datasets import MotionFolder  # noqa: E402
from mslib.evaluation.embedding import (code_scores, nearest_neighbour_purity, silhouette_per_label,  # noqa: E402
                                        style_clips, tsne_2d)
from mslib.models.contrastive import ContrastiveConfig, ContrastiveModel, train  # noqa: E402
from mslib.motion.features import BLOCKS  # noqa: E402

FINDINGS_JSON = DATA_DIR / "03_contrastive_findings.json"
COMMAND = "python tools/contrastive_analysis.py"
DEFAULT_STEPS = 300
BETAS = (0.0, 0.3, 0.6, 1.0)
UNSEEN = "depressed"


# ---------------------------------------------------------------- held-out data
def held_out_pairs(content_folder, style_folder, n: int = 64, seed: int = 0, split: str = "val") -> list:
    """n (content features, style features) pairs from a split (not the benchmark's test pairs)."""
    content = MotionFolder(content_folder, split, normalize=False, labels=())
    style = MotionFolder(style_folder, split, normalize=False, labels=())
    rng = np.random.default_rng([seed, 303])
    return [(content._arrays(int(rng.integers(len(content))))[0], style._arrays(int(rng.integers(len(style))))[0])
            for _ in range(int(n))]


# ---------------------------------------------------------------- measures
def _ric(model: ContrastiveModel, f: np.ndarray) -> np.ndarray:
    """The normalised ric block of unnormalised features (T, D) → (T, 63)."""
    sl = BLOCKS["ric"]
    return (f[:, sl] - model.mean.cpu().numpy()[sl]) / model.std.cpu().numpy()[sl]


def gram(x: np.ndarray) -> np.ndarray:
    """Gram matrix xᵀx / T of (T, C) features → (C, C)."""
    return x.T @ x / len(x)


def transfer_distances(model: ContrastiveModel, pairs) -> dict:
    """Mean content and style distance (module docstring) of the model's outputs on (content, style) pairs."""
    dc, ds = [], []
    for content, style in pairs:
        out = model.transfer_features(content, style)
        xo, xc, xs = _ric(model, out), _ric(model, content), _ric(model, style)
        C = xo.shape[1]
        dc.append(np.linalg.norm(xo - xc, axis=1).mean() / np.sqrt(C))
        ds.append(np.linalg.norm(gram(xo) - gram(xs)) / C)
    return {"content_distance": float(np.mean(dc)), "style_distance": float(np.mean(ds))}


# ---------------------------------------------------------------- the short runs
def short_run(content_folder, style_folder, steps: int, seed: int = 0, exclude_styles=(), **overrides):
    """A course-sized model trained jointly, as C does, for `steps` (no validation, no checkpoint).

    No autoencoder phase (`pretrain_steps=0`): with E_s frozen, C Eq. 3–4 could not shape the style
    codes whose clusters (a) and (d) measure. Nor the course preset's `style_views` (trained jointly it would
    act throughout, and the findings are C's terms alone)."""
    cfg = ContrastiveConfig.preset("course", steps=int(steps), **{"pretrain_steps": 0, "style_views": 0.0, **overrides})
    model, history = train(cfg, content_folder, style_folder, seed, progress=False,
                           exclude_styles=exclude_styles, val=False)
    return model.eval(), history


def _embedding(codes: np.ndarray, labels: np.ndarray, contents: np.ndarray, takes, seed: int) -> dict:
    """`code_scores` of the codes themselves and their 2-D t-SNE (rounded, for the JSON)."""
    return {**code_scores(codes, labels, contents, takes), "tsne": np.round(tsne_2d(codes, seed), 2).tolist()}


def run_findings(content_folder, style_folder, steps: int = DEFAULT_STEPS, seed: int = 0, n_pairs: int = 64,
                 progress: bool = True) -> dict:
    """Train the short runs and measure (a), (b), (d); returns a JSON-able dict (tables, silhouettes,
    t-SNE points of the held-out style codes, their labels)."""
    clips, labels, contents, takes = style_clips(style_folder, "test", with_content=True)
    pairs = held_out_pairs(content_folder, style_folder, n_pairs, seed)
    say = print if progress else (lambda *a, **k: None)
    results = {"command": COMMAND, "commit": current_commit(), "steps": int(steps), "seed": int(seed), "n_pairs": int(n_pairs),
               "betas": list(BETAS), "labels": labels.tolist(), "contents": contents.tolist(), "sweep": [],
               "unseen_style": UNSEEN}
    t0 = time.time()
    for beta in BETAS:  # (b) C Table 1, γ = 0.3; β = 0.3 is also (a)'s "with"
        model, _ = short_run(content_folder, style_folder, steps, seed, beta=beta)
        codes = model.style_codes(clips)
        row = {"beta": beta, **transfer_distances(model, pairs), **code_scores(codes, labels, contents, takes)}
        results["sweep"].append(row)
        if beta == 0.3:
            results["with"] = _embedding(codes, labels, contents, takes, seed)
        say(f"β={beta}: {row} ({time.time() - t0:.0f} s)")
    model, _ = short_run(content_folder, style_folder, steps, seed, beta=0.0, gamma=0.0)  # (a) "without"
    results["without"] = _embedding(model.style_codes(clips), labels, contents, takes, seed)
    say(f"without contrastive terms: silhouette {results['without']['silhouette']:.3f} ({time.time() - t0:.0f} s)")
    model, _ = short_run(content_folder, style_folder, steps, seed, exclude_styles=(UNSEEN,))  # (d)
    codes = model.style_codes(clips)
    per = silhouette_per_label(codes, labels)
    results["unseen"] = {**_embedding(codes, labels, contents, takes, seed), "per_style": per, "unseen_silhouette": per[UNSEEN],
                         "unseen_nn_purity": nearest_neighbour_purity(codes, labels, UNSEEN, takes),
                         "chance_nn_purity": float((labels == UNSEEN).mean()),
                         "unseen_nn_purity_any_take": nearest_neighbour_purity(codes, labels, UNSEEN)}
    results["seconds"] = round(time.time() - t0, 1)
    say(f"unseen {UNSEEN}: silhouette {per[UNSEEN]:.3f}, nn purity {results['unseen']['unseen_nn_purity']:.3f} "
        f"({results['seconds']} s)")
    return results


def save_findings(results: dict, path=FINDINGS_JSON) -> Path:
    """Write the findings as JSON (`tools.common.update_json`: atomically)."""
    return update_json(path, results)


def load_findings(path=FINDINGS_JSON) -> dict:
    """The stored findings; a clear message names the command when they are missing."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no stored findings; make them with `{COMMAND}`")
    return json.loads(path.read_text())


def findings(content_folder, style_folder, path=FINDINGS_JSON, **kwargs) -> dict:
    """Load the stored findings if the file exists, else compute them (about 10 CPU minutes; not saved)."""
    if Path(path).is_file():
        return load_findings(path)
    return run_findings(content_folder, style_folder, **kwargs)


def main(argv=None) -> int:
    """`python tools/contrastive_analysis.py [--steps N] [--seed S] [--pairs N] [--out FILE]`:
    the short runs of C's findings → a JSON file (by default the one notebook 03 loads)."""
    p = argparse.ArgumentParser(prog=COMMAND, description=main.__doc__)
    p.add_argument("--steps", type=int, default=DEFAULT_STEPS)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--pairs", type=int, default=64)
    p.add_argument("--out", default=str(FINDINGS_JSON))
    args = p.parse_args(argv)
    if args.steps < 1 or args.pairs < 1:
        raise SystemExit("--steps and --pairs must be positive")
    from mslib.data.corpora import load_builtin
    paths = load_builtin(progress=False)
    results = run_findings(paths["content"], paths["style"], args.steps, args.seed, args.pairs)
    print(save_findings(results, args.out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
