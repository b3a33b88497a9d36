"""Paper C's training pairs: a target M^T and a source M^S, drawn at random and never labelled."""
from __future__ import annotations

import numpy as np
import torch
from torch.utils.data import Dataset

from ...data.corpora import take_of
from ...data.datasets import MotionFolder


class PairedClips(Dataset):
    """Random (target, source) pairs, unlabelled, both normalised with the content corpus's statistics:
    item i = a `crop`-row window of clip i and of a random clip, both of the content ∪ style corpus (C's one
    set X: M^T, M^S ~ X).

    exclude_styles: styles to leave out of both corpora (the unseen-style experiment, C Fig. 3: every
    clip labelled with them is dropped; the labels are read only for this filter).
    views: each item also holds "source_view", another window of the source's recording: another crop of
    the same clip, or for a style clip (itself one window of a take) another window of its take, if the
    split holds one (`corpora.take_of`; no label is read)."""

    def __init__(self, content_folder, style_folder, split: str = "train", crop: int = 31,
                 exclude_styles=(), mean=None, std=None, views: bool = False):
        self.views = bool(views)
        self.content = MotionFolder(content_folder, split, normalize=False, labels=())
        style = MotionFolder(style_folder, split, normalize=False, labels=("style",))
        drop = set(exclude_styles)
        keep = [i for i, r in enumerate(style.rows) if r.get("style") not in drop]
        self.content_index = [i for i, r in enumerate(self.content.rows) if r.get("style") not in drop]
        if not keep or not self.content_index:
            raise ValueError(f"exclude_styles: {list(exclude_styles)} leaves no style or no content clips")
        self.style, self.style_index = style, keep
        self.crop = int(crop)
        self.mean = self.content.mean if mean is None else np.asarray(mean, np.float32)
        self.std = self.content.std if std is None else np.asarray(std, np.float32)
        takes: dict = {}  # take → positions in `_clip`'s numbering of its windows
        for k, i in enumerate(keep):
            takes.setdefault(take_of(style.rows[i]["clip_id"]), []).append(len(self.content_index) + k)
        self.same_take = {j: [o for o in group if o != j] for group in takes.values() for j in group}

    def __len__(self) -> int:
        return len(self.content_index) + len(self.style_index)

    def _clip(self, i: int) -> np.ndarray:
        """Features of clip i of content + style clips: the content clips first, then the style clips."""
        n = len(self.content_index)
        if i < n:
            return self.content._arrays(self.content_index[i])[0]
        return self.style._arrays(self.style_index[i - n])[0]

    def _window(self, f: np.ndarray) -> np.ndarray:
        """A random `crop`-row window of (T, D) features (short clips padded with their last row)."""
        if len(f) < self.crop:  # edge-pad short clips
            return np.concatenate([f, np.repeat(f[-1:], self.crop - len(f), 0)])
        s = np.random.randint(len(f) - self.crop + 1)
        return f[s:s + self.crop]

    def __getitem__(self, i: int) -> dict:
        tgt = self._window(self._clip(i))
        j = np.random.randint(len(self))  # M^T, M^S ~ X
        src = self._window(self._clip(j))
        norm = lambda a: torch.from_numpy(((a - self.mean) / self.std).astype(np.float32))  # noqa: E731
        item = {"target": norm(tgt), "source": norm(src)}
        if self.views:  # another window of the source's recording: the same clip, or another window of its take
            others = self.same_take.get(j)
            k = others[np.random.randint(len(others))] if others else j
            item["source_view"] = norm(self._window(self._clip(k)))
        return item
