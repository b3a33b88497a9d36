"""The benchmark: every method on the same held-out (content, style) pairs, scored by the evaluator.

Methods come from the registry in `mslib.models.registry` (each model package declares its own);
`identity` and `copy_style`, registered here, are the reference rows every method must beat on H.
Every method returns 263-d features; `positions` turns them into the joint positions that are scored.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ..motion.features import decode
from ..models.registry import DESCRIPTIONS, METHODS, get_method, known_methods, register  # noqa: F401
from . import metrics as M

JSON_KEYS = ("method", "seed", "pairs", "fmd", "cra", "sra", "sra_top3", "h", "tsi", "fsf", "fsr",
             "diversity", "ms_per_clip")


def positions(features) -> np.ndarray:
    """A method's output features ((T−1)×263, unnormalised) → joint positions (T−1, 22, 3): the one place
    the benchmark, `perf`, `transfer` and the notebooks derive positions from a transfer."""
    return decode(np.asarray(features))


# ---------------------------------------------------------------- the reference rows
@register("identity", "output = the content motion (perfect content, no style)")
def _identity(device="cpu"):
    def transfer(content, style):
        return np.asarray(content["features"], np.float64)
    transfer.n_parameters = 0
    return transfer


def loop_features(features, n_rows: int) -> np.ndarray:
    """Repeat a feature sequence (rows) cyclically to n_rows; velocities keep the root moving on."""
    f = np.asarray(features)
    return f[np.arange(n_rows) % len(f)]


@register("copy_style", "output = the style motion, looped to the content's length (all style, no content)")
def _copy_style(device="cpu"):
    def transfer(content, style):
        return loop_features(style["features"], len(content["features"])).astype(np.float64)
    transfer.n_parameters = 0
    return transfer


# ---------------------------------------------------------------- running
def load_pairs(seed: int = 0, n_pairs: int = 200, content_dir=None, style_dir=None, split: str = "test"):
    """Held-out pairs as (content item, style item) dicts with unnormalised numpy arrays; the benchmark
    draws from "test", design choices are made on a "val" draw."""
    from ..data.corpora import load_builtin
    from ..data.datasets import BenchmarkPairs
    if content_dir is None or style_dir is None:
        paths = load_builtin(progress=False)
        content_dir = content_dir or paths["content"]
        style_dir = style_dir or paths["style"]
    ds = BenchmarkPairs(content_dir, style_dir, n_pairs=n_pairs, seed=seed, split=split, normalize=False, joints=True)
    out = []
    for k in range(len(ds)):
        item = ds[k]
        out.append(tuple({key: (v.numpy().astype(np.float64) if hasattr(v, "numpy") else v)
                          for key, v in item[side].items()} for side in ("content", "style")))
    return out


class Evaluator:
    """The two packaged classifiers, scoring lists of motions."""

    def __init__(self, content_path=None, style_path=None):
        from .evaluator import load_classifier
        self.content = load_classifier("content", content_path)
        self.style = load_classifier("style", style_path)
        self._real = {}  # FMD features of real style clips, by clip id (shared across methods)

    def score(self, motions):
        """Content logits, style logits and FMD features (both penultimate layers, concatenated)."""
        c_logits, c_feat = self.content.score(motions)
        s_logits, s_feat = self.style.score(motions)
        return c_logits, s_logits, np.concatenate([c_feat, s_feat], 1)

    def read_style(self, motion) -> str:
        """The style the style classifier reads in one (T, 22, 3) motion."""
        return self.style.classes[int(self.style.score([motion])[0][0].argmax())]

    def read_content(self, motion) -> str:
        """The content the content classifier reads in one (T, 22, 3) motion."""
        return self.content.classes[int(self.content.score([motion])[0][0].argmax())]

    def real_features(self, clips) -> np.ndarray:
        """FMD features of real clips (dicts with "clip_id" and "joints"), computed once per clip."""
        todo = [c for c in clips if c["clip_id"] not in self._real]
        if todo:
            for c, f in zip(todo, self.score([c["joints"] for c in todo])[2]):
                self._real[c["clip_id"]] = f
        return np.stack([self._real[c["clip_id"]] for c in clips])


def evaluate(outputs, pairs, evaluator: Evaluator, scored=None) -> dict:
    """All metrics of a list of output motions against their (content, style) pairs (scored: the outputs'
    `Evaluator.score`, if already computed)."""
    contents = [c for c, _ in pairs]
    styles = [s for _, s in pairs]
    c_logits, s_logits, feats = evaluator.score(outputs) if scored is None else scored
    real = evaluator.real_features(styles)
    c_index = {c: i for i, c in enumerate(evaluator.content.classes)}
    s_index = {s: i for i, s in enumerate(evaluator.style.classes)}
    c_labels = np.array([c_index.get(c["content"], -1) for c in contents])
    s_labels = np.array([s_index[s["style"]] for s in styles])
    known = c_labels >= 0  # content labels the classifier knows (all, on the built-in data)
    cra = M.accuracy(c_logits[known], c_labels[known]) if known.any() else float("nan")
    sra = M.accuracy(s_logits, s_labels)
    return {
        "fmd": M.frechet_distance(feats, real) if len(outputs) > 1 else float("nan"),
        "cra": cra, "sra": sra, "sra_top3": M.accuracy(s_logits, s_labels, top_k=3),
        "h": M.harmonic_score(sra, cra),
        "tsi": float(np.mean([M.trajectory_similarity_index(o, c["joints"]) for o, c in zip(outputs, contents)])),
        "fsf": float(np.mean([M.foot_slide_fsf(o) for o in outputs])),
        "fsr": float(np.mean([M.foot_skating_ratio_fsr(o) for o in outputs])),
        "diversity": M.diversity(feats) if len(outputs) > 1 else 0.0,
    }


def by_style(outputs, pairs, evaluator: Evaluator, scored=None) -> list:
    """SRA and CRA over the pairs of each style (sorted by name), with the style its outputs are read as most often."""
    return _breakdown(outputs, pairs, evaluator, "style", scored)


def by_content(outputs, pairs, evaluator: Evaluator, scored=None) -> list:
    """SRA and CRA over the pairs of each content label the content classifier knows (sorted by name), with the
    content its outputs are read as most often: which actions a method keeps and which it turns into another."""
    return _breakdown(outputs, pairs, evaluator, "content", scored)


def by_content_clip(outputs, pairs, evaluator: Evaluator, scored=None) -> list:
    """`by_content` per content clip (in the pairs' order), each row also naming its clip's content label; CRA is
    None for a clip whose label the content classifier does not know."""
    return _breakdown(outputs, pairs, evaluator, "clip", scored)


def _breakdown(outputs, pairs, evaluator: Evaluator, key: str, scored=None) -> list:
    """Per value of the pairs' `key` label ("style": of the style clip, "content": of the content clip, "clip":
    the content clip itself); scored as in `evaluate`."""
    if len(outputs) != len(pairs) or not pairs:
        raise ValueError(f"outputs: expected one per pair ({len(pairs)} pairs, at least one), got {len(outputs)}")
    c_logits, s_logits, _ = evaluator.score(outputs) if scored is None else scored
    s_read = np.array([evaluator.style.classes[i] for i in s_logits.argmax(1)])
    c_read = np.array([evaluator.content.classes[i] for i in c_logits.argmax(1)])
    styles = np.array([s["style"] for _, s in pairs])
    contents = np.array([c["content"] for c, _ in pairs])
    if key == "style":
        labels, read_as, names = styles, s_read, sorted(set(styles))
    elif key == "content":
        labels, read_as, names = contents, c_read, sorted(set(contents) & set(evaluator.content.classes))
    else:  # each content clip, in the pairs' order
        labels = np.array([c.get("clip_id", "") for c, _ in pairs])
        read_as, names = c_read, list(dict.fromkeys(labels))
    rows = []
    for name in names:
        mine = labels == name
        seen, counts = np.unique(read_as[mine], return_counts=True)
        top = int(np.argmax(counts))  # ties: the first name alphabetically
        label = str(contents[mine][0])  # a clip's one content label: without one the classifier knows, no CRA
        known = key != "clip" or label in evaluator.content.classes
        rows.append({key: str(name), **({"content": label} if key == "clip" else {}), "n": int(mine.sum()),
                     "sra": float(100.0 * (s_read[mine] == styles[mine]).mean()),
                     "cra": float(100.0 * (c_read[mine] == contents[mine]).mean()) if known else None,
                     "read_as": str(seen[top]), "read_as_share": float(100.0 * counts[top] / mine.sum())})
    return rows


def transfer_pairs(method: str, pairs, device: str = "cpu", progress: bool = False) -> tuple[list, float]:
    """Every pair through `method`: the output positions (one (T−1, 22, 3) array per pair) and the seconds
    spent in the method (loading excluded)."""
    from tqdm.auto import tqdm
    transfer = get_method(method, device)
    outputs, seconds = [], 0.0
    for content, style in tqdm(pairs, desc=method, disable=not progress):
        t0 = time.perf_counter()
        out = positions(transfer(content, style))
        seconds += time.perf_counter() - t0
        outputs.append(np.asarray(out, np.float64))
    return outputs, seconds


def bench_row(method: str, seed: int, outputs, pairs, evaluator: Evaluator, seconds: float, scored=None) -> dict:
    """The §8 JSON row of a method's outputs on its pairs (scored as in `evaluate`)."""
    row = {"method": method, "seed": seed, "pairs": len(pairs), **evaluate(outputs, pairs, evaluator, scored),
           "ms_per_clip": 1000.0 * seconds / max(len(pairs), 1)}
    return {k: row[k] for k in JSON_KEYS}


def run_bench(method: str, seed: int = 0, n_pairs: int = 200, device: str = "cpu", pairs=None,
              evaluator: Evaluator | None = None, progress: bool = False) -> dict:
    """Transfer every pair with `method`, time it, and score the outputs; returns the §8 JSON row."""
    pairs = load_pairs(seed, n_pairs) if pairs is None else pairs
    outputs, seconds = transfer_pairs(method, pairs, device, progress)
    return bench_row(method, seed, outputs, pairs, evaluator or Evaluator(), seconds)


def format_table(rows: list, notebook: bool = False, markdown: bool = False) -> str:
    """A plain-text table of bench rows; `notebook=True` rounds for nbval and leaves out timings;
    `markdown=True` gives a Markdown table (for the README)."""
    cols = ["method", "fmd", "cra", "sra", "sra_top3", "h", "tsi", "fsf", "fsr", "diversity", "ms_per_clip"]
    fmt = {"method": "{:<12}", "fmd": "{:>8.2f}", "cra": "{:>6.1f}", "sra": "{:>6.1f}", "sra_top3": "{:>8.1f}",
           "h": "{:>6.3f}", "tsi": "{:>6.3f}", "fsf": "{:>6.2f}", "fsr": "{:>6.3f}", "diversity": "{:>9.2f}",
           "ms_per_clip": "{:>11.1f}"}
    if notebook:  # numbers stable run to run (3 significant digits), no machine-dependent timings
        cols.remove("ms_per_clip")
        fmt.update(fmd="{:>8.3g}", h="{:>6.2f}", tsi="{:>6.2f}", fsr="{:>6.2f}", diversity="{:>9.3g}")
    if markdown:
        lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
        return "\n".join(lines + ["| " + " | ".join(fmt[c].format(r[c]).strip() for c in cols) + " |" for r in rows])
    head = " ".join(f"{c:>{len(fmt[c].format(0 if c != 'method' else ''))}}" for c in cols)
    return "\n".join([head] + [" ".join(fmt[c].format(r[c]) for c in cols) for r in rows])


def save_rows(path, rows) -> Path:
    """Write bench rows as JSON lines (for the README table)."""
    import json
    from ..fileio import atomic_write_bytes
    text = "".join(json.dumps(r, sort_keys=True) + "\n" for r in rows)
    atomic_write_bytes(Path(path), text.encode())
    return Path(path)
