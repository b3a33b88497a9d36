"""How codes group: silhouettes, nearest-neighbour accuracy and purity, t-SNE (the measures of C Fig. 2 and
of every style space the notebooks look at). Neighbour measures can leave out a code's own recording, so a
window of the same take never counts as a neighbour."""
from __future__ import annotations

import numpy as np

from ..data.corpora import take_of
from ..data.datasets import MotionFolder


def style_clips(style_folder, split: str = "test", with_content: bool = False) -> tuple:
    """Unnormalised style-corpus clips (list of (31, 263)) and their style labels (and content labels and
    the take each clip was cut from, for neighbour measures that must not count a window of the same take)."""
    ds = MotionFolder(style_folder, split, normalize=False, labels=("style",))
    out = [ds._arrays(i)[0] for i in range(len(ds))], np.array([r["style"] for r in ds.rows])
    if not with_content:
        return out
    return out + (np.array([r["content"] for r in ds.rows]), np.array([take_of(r["clip_id"]) for r in ds.rows]))


def silhouette(codes: np.ndarray, labels) -> float:
    """Mean silhouette of codes (N, l) grouped by label (scikit-learn, Euclidean)."""
    from sklearn.metrics import silhouette_score
    labels = np.asarray(labels)
    if len(codes) != len(labels) or len(set(labels.tolist())) < 2:
        raise ValueError("codes/labels: need one label per code and at least two labels")
    return float(silhouette_score(codes, labels))


def silhouette_per_label(codes: np.ndarray, labels) -> dict:
    """Mean silhouette of each label's codes."""
    from sklearn.metrics import silhouette_samples
    labels = np.asarray(labels)
    s = silhouette_samples(codes, labels)
    return {str(k): float(s[labels == k].mean()) for k in sorted(set(labels.tolist()))}


def nearest_neighbour_purity(codes: np.ndarray, labels, label: str, groups=None) -> float:
    """Fraction of `label`'s codes whose nearest other code (Euclidean) has the same label; with `groups`
    (e.g. the recording each clip was cut from) a code's own group is not searched."""
    labels = np.asarray(labels)
    own = labels == label
    return float((labels[_nearest_other(codes, groups)[own]] == label).mean())


def _nearest_other(codes: np.ndarray, groups=None) -> np.ndarray:
    """Index of each code's nearest other code (Euclidean), outside its own group if `groups` is given."""
    d = ((codes[:, None] - codes[None]) ** 2).sum(-1)
    np.fill_diagonal(d, np.inf)
    if groups is not None:
        groups = np.asarray(groups)
        d[groups[:, None] == groups[None]] = np.inf
    return d.argmin(1)


def nn_accuracy(codes: np.ndarray, labels, groups=None) -> float:
    """Leave-one-out 1-nearest-neighbour accuracy: how often a code's nearest other code (outside its group) shares its label."""
    labels = np.asarray(labels)
    return float((labels[_nearest_other(codes, groups)] == labels).mean())


def tsne_2d(codes: np.ndarray, seed: int = 0) -> np.ndarray:
    """Codes (N, l) → (N, 2) with scikit-learn's t-SNE (PCA initialisation, perplexity 30)."""
    from sklearn.manifold import TSNE
    return TSNE(2, perplexity=min(30.0, (len(codes) - 1) / 3), init="pca", random_state=seed).fit_transform(
        np.asarray(codes, np.float64))


def code_scores(codes: np.ndarray, labels: np.ndarray, contents: np.ndarray, takes=None) -> dict:
    """How the style codes group: silhouette and 1-NN accuracy by style label (the neighbour from another
    take, if `takes` are given), silhouette by content label."""
    return {"silhouette": silhouette(codes, labels), "nn_accuracy": nn_accuracy(codes, labels, takes),
            "silhouette_by_content": silhouette(codes, contents)}
