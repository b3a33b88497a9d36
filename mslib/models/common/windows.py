"""A model trained on short crops, run over a longer motion: overlapping windows of its training length.

Layers that normalise over time (instance norm, AdaIN, a time mean) make a model's output depend on how many
frames it sees at once; one trained on 32-frame crops has never seen the statistics of a 200-frame clip. So the
clip is cut into windows of `window` rows that overlap by half, each window goes through the model on its own,
and each output row is the weighted mean of the windows that hold it, the weights rising linearly to a window's
middle and falling to its ends (a triangular cross-fade, so no seam shows where one window hands over).
"""
from __future__ import annotations

import numpy as np


def window_starts(n_rows: int, window: int) -> list:
    """Starts of `window`-row windows over `n_rows` rows, half a window apart, the last one ending at n_rows."""
    if window < 2:
        raise ValueError(f"window: need at least 2 rows, got {window}")
    if n_rows <= window:
        return [0]
    starts = list(range(0, n_rows - window + 1, window // 2))
    if starts[-1] != n_rows - window:
        starts.append(n_rows - window)
    return starts


def overlap_blend(fn, x: np.ndarray, window: int) -> np.ndarray:
    """fn applied to overlapping `window`-row windows of x (T, D), cross-faded back to (T, D); fn(x) itself when
    window is 0 or T ≤ window. fn maps a (t, D) array to a (t, D') array."""
    x = np.asarray(x)
    if window == 0 or len(x) <= window:
        return np.asarray(fn(x))
    starts = window_starts(len(x), window)
    ramp = np.minimum(np.arange(1, window + 1), np.arange(window, 0, -1)).astype(np.float64)[:, None]  # (W, 1)
    total = weight = None
    for s in starts:
        out = np.asarray(fn(x[s:s + window]), np.float64)  # (W, D')
        if total is None:
            total, weight = np.zeros((len(x), out.shape[1])), np.zeros((len(x), 1))
        total[s:s + window] += ramp * out
        weight[s:s + window] += ramp
    return total / weight
