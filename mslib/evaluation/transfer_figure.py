"""A transfer shown so that a student sees what moved: the strip of content, style clip and output, and beside
it the style cues over time (head height, trunk pitch, arm swing; `cues.cue_tracks`) of the three motions."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from .. import viz
from .cues import FPS, TRACKS, cue_tracks

ROLE_COLOURS = {"content": "0.55", "style": "tab:orange", "output": "tab:blue"}


def _cue_panels(axes, series, fps: float) -> None:
    """One panel per cue of TRACKS: every series (label, tracks, line style as plot kwargs) over time in seconds;
    the labels go on the first panel only, for the figure's legend."""
    for i, (ax, (cue, title)) in enumerate(zip(axes, TRACKS.items())):
        for label, tracks, style in series:
            y = tracks[cue]
            ax.plot(np.arange(len(y)) / fps, y, label=label if i == 0 else None, **style)
        ax.set_title(title, fontsize=9)
        ax.tick_params(labelsize=7)


def plot_transfer(content, style, output, titles=None, n_frames: int = 5, fps: float = FPS, before=None,
                  before_title: str = "before") -> Figure:
    """Strip rows (content, style clip, output) with the cue tracks of all three beside them; positions (T, 22, 3).
    `before`: another output (e.g. before a correction), drawn as a dashed cue track only."""
    motions = {"content": content, "style": style, "output": output}
    tracks = {role: cue_tracks(m) for role, m in motions.items()}  # validates every motion
    titles = list(titles) if titles is not None else list(motions)
    if len(titles) != 3:
        raise ValueError(f"titles: three needed (content, style, output), got {len(titles)}")
    fig = plt.figure(figsize=(10, 5.6), dpi=viz.DPI)  # pyplot's: a notebook shows it at the end of the cell
    grid = fig.add_gridspec(3, 2, width_ratios=(2.3, 1), wspace=0.28, hspace=0.55)
    strip_axes = [fig.add_subplot(grid[i, 0]) for i in range(3)]
    viz.plot_strip(list(motions.values()), n_frames=n_frames, view="side", titles=titles, axes=strip_axes)
    for ax, role in zip(strip_axes, motions):
        ax.title.set_color(ROLE_COLOURS[role] if role != "content" else "0.3")
    series = [(title, tracks[role], {"color": ROLE_COLOURS[role], "lw": 2 if role == "output" else 1.3})
              for role, title in zip(motions, titles)]
    if before is not None:
        series.append((before_title, cue_tracks(before), {"color": ROLE_COLOURS["output"], "lw": 1, "ls": "--",
                                                          "alpha": 0.8}))
    cue_axes = [fig.add_subplot(grid[i, 1]) for i in range(len(TRACKS))]
    _cue_panels(cue_axes, series, fps)
    cue_axes[-1].set_xlabel("time (s)", fontsize=8)
    fig.legend(loc="upper right", fontsize=7, frameon=False, ncol=4, bbox_to_anchor=(0.99, 1.0))
    fig.subplots_adjust(left=0.06, right=0.98, top=0.9, bottom=0.08)
    return fig


def plot_cue_comparison(content, style, outputs: dict, fps: float = FPS) -> Figure:
    """The cue tracks of the content, the style clip and several outputs ({name: positions}), a panel per cue."""
    if not outputs:
        raise ValueError("outputs: at least one {name: positions} entry needed")
    fig = plt.figure(figsize=(11, 3.2), dpi=viz.DPI)
    styles = [("content", content, {"color": ROLE_COLOURS["content"], "lw": 1.3}),
              ("style clip", style, {"color": ROLE_COLOURS["style"], "lw": 1.3})]
    styles += [(name, m, {"color": f"C{k + 2}", "lw": 1.6}) for k, (name, m) in enumerate(outputs.items())]
    axes = [fig.add_subplot(1, len(TRACKS), i + 1) for i in range(len(TRACKS))]
    _cue_panels(axes, [(name, cue_tracks(m), kw) for name, m, kw in styles], fps)
    for ax in axes:
        ax.set_xlabel("time (s)", fontsize=8)
    fig.legend(loc="lower center", fontsize=7, frameon=False, ncol=len(styles), bbox_to_anchor=(0.5, 0.0))
    fig.subplots_adjust(left=0.05, right=0.99, top=0.88, bottom=0.3, wspace=0.25)
    return fig
