"""`MotionViewer`: the 3-D skeleton viewer (viewer.js) as a notebook widget, on anywidget.

    from mslib.viz import MotionViewer
    MotionViewer([content, output, style], titles=["content", "output", "style"])   # positions (T, 22, 3)

The widget has one synced trait, `data` (viewer.viewer_state: float32 base64 positions, decimated), so a saved
notebook stays small. Its display also carries an image/png — a side-view strip of each motion drawn by
static.plot_strip — which GitHub and nbviewer show, since they render no widgets. JupyterLab with a running
kernel prefers the widget; JupyterLab without a kernel shows "model not found" unless the notebook was saved
with its widget state (Settings → Save Widget State Automatically; that state holds the ES module's source
besides the data), a limitation of ipywidgets itself.
Needs the notebooks extra (`pip install anywidget`); `viewer.viewer_html` does not.
"""
from __future__ import annotations

import base64
import io

import anywidget
import traitlets

from ..motion.skeleton import PARENTS
from .static import plot_strip
from .viewer import JS_PATH, decode_positions, state_size, viewer_state

STRIP_FRAMES = 6
STRIP_DPI = 72


class MotionViewer(anywidget.AnyWidget):
    """Orbit / zoom / play / scrub several motions (T, J, 3) side by side, or overlaid in one panel."""

    _esm = JS_PATH
    data = traitlets.Dict().tag(sync=True)

    def __init__(self, motions, titles=None, fps: float = 20, overlay: bool = False, contacts="auto",
                 static_image: bool = True, **options):
        """Arguments as viewer.viewer_state (options: max_fps, max_frames, parents, names, width, height);
        static_image=False leaves the picture for GitHub/nbviewer out of the display."""
        state = viewer_state(motions, titles=titles, fps=fps, overlay=overlay, contacts=contacts, **options)
        super().__init__(data=state)
        self.static_image = bool(static_image)
        self._png = None
        self._skeleton = (options.get("parents", PARENTS), options.get("names"))

    def update(self, motions, titles=None, fps: float = 20, overlay: bool = False, contacts="auto", **options):
        """Show other motions in the same widget (the camera stays where it is)."""
        self.data = viewer_state(motions, titles=titles, fps=fps, overlay=overlay, contacts=contacts, **options)
        self._png = None
        self._skeleton = (options.get("parents", PARENTS), options.get("names"))

    @property
    def state_bytes(self) -> int:
        """Size of the synced state as compact JSON, in bytes."""
        return state_size(self.data)

    def static_png(self) -> bytes:
        """The stand-in picture: a side-view strip of the motions as sent to the browser (PNG bytes)."""
        if self._png is None:
            import matplotlib.pyplot as plt
            motions = [decode_positions(m) for m in self.data["motions"]]
            parents, names = self._skeleton
            fig = plot_strip(motions, n_frames=STRIP_FRAMES, view="side",
                             titles=[m["title"] for m in self.data["motions"]], parents=parents, names=names,
                             fps=self.data["fps"])
            buf = io.BytesIO()
            fig.savefig(buf, format="png", dpi=STRIP_DPI, bbox_inches="tight")
            plt.close(fig)
            self._png = buf.getvalue()
        return self._png

    def __repr__(self) -> str:
        ms = self.data.get("motions", [])
        return (f"MotionViewer({len(ms)} motion(s): " + ", ".join(f"{m['title']!r} {m['frames']} frames"
                                                                   for m in ms) + ")")

    def _repr_mimebundle_(self, **kwargs):
        bundle = super()._repr_mimebundle_(**kwargs)
        if bundle is None or not self.static_image:
            return bundle
        data, metadata = bundle
        data = {**data, "image/png": base64.b64encode(self.static_png()).decode("ascii")}
        return data, metadata
