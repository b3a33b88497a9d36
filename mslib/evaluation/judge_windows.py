"""The judges' windows: how the realism report's linear judges cut a take and describe each window.

A window is CLASSIFIER_WINDOW frames (0.8 s at 20 fps), one every HOP frames, or a whole take of SHORT_TAKE
frames or more that is shorter than that (a real Xia punch or kick is often one action of under 16 frames).
It is described by 396 numbers: the mean and the spread over time of its body-frame joint positions,
velocities and accelerations (leg lengths, facing +Z). `Windows` holds every window of some clips with its
style, take and content, so that several judges can read clips cut once.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from tqdm.auto import tqdm

from ..data.retarget import cut_windows
from .cues import FPS, body_frame, facing_yaw, leg_length, rotate_to_facing

CLASSIFIER_WINDOW, HOP = 16, 8  # frames at 20 fps; windows start every HOP frames
SHORT_TAKE = 8  # frames: a take this long but shorter than CLASSIFIER_WINDOW is one classifier window, whole


def windows(joints, length: int) -> list:
    """Windows of `length` frames starting every HOP frames, each re-centred and re-faced."""
    return cut_windows(joints, length, length - HOP)


def classifier_windows(joints) -> list:
    """The judge's windows of a take: CLASSIFIER_WINDOW frames every HOP frames, or, for a take of SHORT_TAKE
    to CLASSIFIER_WINDOW − 1 frames (most real Xia punches and many kicks: one action each), the whole take."""
    if SHORT_TAKE <= len(joints) < CLASSIFIER_WINDOW:
        return cut_windows(joints, len(joints), 0)
    return windows(joints, CLASSIFIER_WINDOW)


def window_features(window) -> np.ndarray:
    """(396,) means and spreads over time of body-frame positions, velocities and accelerations."""
    w = np.asarray(window, np.float64)
    yaw, L = facing_yaw(w), leg_length(w)
    pos = body_frame(w, yaw)  # (T, 22, 3) L
    vel = rotate_to_facing(np.diff(w, axis=0), yaw[:-1]) * FPS / L  # (T−1, 22, 3) L/s
    acc = rotate_to_facing(np.diff(w, 2, axis=0), yaw[:-2]) * FPS ** 2 / L  # (T−2, 22, 3) L/s²
    flat = [x.reshape(len(x), -1) for x in (pos, vel, acc)]
    return np.concatenate([x.mean(0) for x in flat] + [x.std(0) for x in flat])


def take_features(takes) -> np.ndarray:
    """(N, 396) `window_features` of every judge window (`classifier_windows`) of the takes, take by take."""
    feats = [window_features(w) for joints in takes for w in classifier_windows(joints)]
    return np.array(feats).reshape(len(feats), 6 * 66)


class Windows(NamedTuple):
    """Every classifier window of some clips: features (N, 396), styles, take ids, contents (N,) and how many
    takes were too short to give one."""
    X: np.ndarray
    y: np.ndarray
    take: np.ndarray
    content: np.ndarray
    short: int


def windowed(clips, keep_style=None) -> Windows:
    """`Windows` of every classifier window of the clips (of the styles in keep_style, if given)."""
    X, y, take, content, short = [], [], [], [], 0
    for row, joints in clips:
        if keep_style is not None and row["style"] not in keep_style:
            continue
        feats = take_features([joints])
        short += not len(feats)
        X.append(feats)
        for _ in feats:
            y.append(row["style"]), take.append(row.get("take") or row["clip_id"]), content.append(row["content"])
    X = np.concatenate(X) if X else np.zeros((0, 6 * 66))
    return Windows(X, np.array(y), np.array(take), np.array(content), short)


def as_windows(data, keep_style=None, desc: str = "windows", progress: bool = False) -> Windows:
    """`windowed` of clips, or `Windows` already cut (kept to keep_style): cut once, read by several judges."""
    if not isinstance(data, Windows):
        return windowed(tqdm(data, desc=desc, disable=not progress), keep_style)
    if keep_style is None:
        return data
    keep = np.isin(data.y, list(keep_style))
    return Windows(data.X[keep], data.y[keep], data.take[keep], data.content[keep], data.short)
