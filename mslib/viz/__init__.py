"""Pictures of motions: the static figures (static.py, matplotlib) and the 3-D viewer (viewer.py, viewer.js,
widget.py — a Canvas 2D player in the browser, as a notebook widget or a self-contained HTML page).

`from mslib import viz; viz.plot_strip(...)` keeps working for every name the single-file viz module had.
`viz.MotionViewer` needs the notebooks extra (anywidget) and is imported only when first used, so the
command line and the static figures never load ipywidgets. Only `mslib.motion` is imported from the library.
"""
from __future__ import annotations

from . import static
from .static import (DPI, PATH_COLOURS, SIDE_COLOURS, SIDE_LABELS, VIEWS_2D, HTMLString, animate,
                     animation_html, auto_contacts, plot_curves, plot_pose, plot_strip, plot_trajectory,
                     save_png, skeleton_chains)
from .viewer import decode_positions, state_size, viewer_html, viewer_state

__all__ = ["DPI", "PATH_COLOURS", "SIDE_COLOURS", "SIDE_LABELS", "VIEWS_2D", "HTMLString", "animate",
           "animation_html", "auto_contacts", "plot_curves", "plot_pose", "plot_strip", "plot_trajectory",
           "save_png", "skeleton_chains", "decode_positions", "state_size", "viewer_html", "viewer_state",
           "MotionViewer"]


def __getattr__(name: str):
    """`viz.MotionViewer` on first use (needs anywidget); any other name of the old module from static.py."""
    if name == "MotionViewer":
        from .widget import MotionViewer
        return MotionViewer
    try:
        return getattr(static, name)
    except AttributeError:
        raise AttributeError(f"module 'mslib.viz' has no attribute {name!r}") from None
