"""ipywidgets machinery for the notebooks: a slider that redraws a matplotlib figure (`slider_figure`), and the
explorer box (`Explorer`: controls, the 3-D viewer, the style evaluator's probabilities as bars) that the
explorers of mslib/explorers.py are built from.

Each explorer has a static twin (`render(value)`, or explorers.py's `*_view(...)`, called directly) so nbval still
checks the logic; the widget cell itself carries `# NBVAL_IGNORE_OUTPUT`. The browser tests
(tests/test_browser_widgets.py, tests/test_browser_explorers.py) operate them in headless Chromium.
"""
from __future__ import annotations

import base64
import html
import time
from typing import Callable, Sequence

import ipywidgets as W


def _check_values(values: Sequence[float], argument: str) -> list:
    values = [float(v) for v in values]
    if len(values) < 2:
        raise ValueError(f"{argument}: need at least two slider values, got {len(values)}")
    if sorted(values) != values or len(set(values)) != len(values):
        raise ValueError(f"{argument}: slider values must be strictly increasing, got {values}")
    return values


def slider_figure(render: Callable, values: Sequence[float], description: str = "λ", start=None):
    """A slider over `values`; each move calls `render(value) -> matplotlib Figure` and shows it.

    Returns the widget box (slider above an Output area). The figure of each value is drawn once and
    cached, so moving back and forth is instant."""
    import matplotlib.pyplot as plt
    from IPython.display import display

    values = _check_values(values, "values")
    start = values[0] if start is None else float(start)
    if start not in values:
        raise ValueError(f"start: {start} is not one of the slider values {values}")
    slider = W.SelectionSlider(options=[(f"{v:g}", v) for v in values], value=start,
                               description=description, continuous_update=False,
                               layout=W.Layout(width="420px"))
    out = W.Output()
    cache: dict = {}

    def show(value):
        if value not in cache:
            fig = render(value)
            plt.close(fig)  # keep it out of the inline backend's automatic display
            cache[value] = fig
        out.clear_output(wait=True)
        with out:
            display(cache[value])

    slider.observe(lambda change: show(change["new"]), names="value")
    show(start)
    box = W.VBox([slider, out])
    box.add_class("mslib-slider-figure")  # the browser test finds the widget by this class
    return box


# ---------------------------------------------------------------- explorers: controls + viewer + bars
BAR_COLOURS = {"target": "#2e7d32", "other": "#4c78a8"}
BAR_WIDTH = 160  # pixels for P = 1
EXPLORER_WIDTH, PANEL_WIDTH = 900, 300  # the viewer's width in pixels: a panel per motion, within a notebook column


class ProbabilityBars(W.HTML):
    """The style evaluator's P(style | motion) as one horizontal bar per class (in two columns, one HTML
    widget: one message per update); the asked-for style(s) in green."""

    def __init__(self, heading: str = "style evaluator: P(style | output)"):
        super().__init__()
        self.heading = heading
        self.probabilities: dict = {}  # class → the probability shown
        self.add_class("mslib-explorer-bars")

    def show(self, classes: Sequence[str], probabilities: Sequence[float], targets: Sequence[str] = ()) -> None:
        self.probabilities = {c: float(p) for c, p in zip(classes, probabilities)}
        cells = []
        for c, p in self.probabilities.items():
            colour = BAR_COLOURS["target" if c in targets else "other"]
            cells.append(f"<span>{html.escape(c)}</span>"
                         f"<span class='mslib-bar' data-class='{html.escape(c)}' data-p='{p:.4f}' style='display:"
                         f"inline-block;width:{BAR_WIDTH}px;height:10px;background:#eee'><span style='display:"
                         f"block;width:{round(BAR_WIDTH * p)}px;height:10px;background:{colour}'></span></span>"
                         f"<span style='font-variant-numeric:tabular-nums'>{p:.2f}</span>")
        self.value = (f"<div style='font-size:12px;line-height:16px'><b>{html.escape(self.heading)}</b>"
                      "<div style='display:grid;grid-template-columns:repeat(2, max-content max-content "
                      "max-content);column-gap:8px;row-gap:2px;align-items:center'>" + "".join(cells) + "</div></div>")


class Explorer(W.VBox):
    """Controls above a MotionViewer, the style evaluator's probabilities below.

    compute(**choices) → a view (mslib.explorers.View: .motions, .titles, .title, .classes, .output_probabilities,
    .targets, .cached); `choices` maps each control's name to its value. Each change of a control computes the
    new view and shows it in the same viewer (the camera stays); a ValueError is shown in the status line and the
    last good view stays. `busy(choices)` → a message shown while computing (e.g. for a diffusion sampler), or
    None. The display carries a PNG (the viewer's side-view strip) for GitHub/nbviewer, which render no widgets."""

    def __init__(self, kind: str, compute: Callable, controls: dict, busy: Callable | None = None,
                 viewer_options: dict | None = None):
        from .viz.widget import MotionViewer
        self.kind, self.controls, self._compute, self._busy = kind, dict(controls), compute, busy
        self._viewer_options = dict(viewer_options or {})
        self.status = W.HTML()
        self.status.add_class("mslib-explorer-status")
        self.bars = ProbabilityBars()
        self.view = self._timed(self.choices)
        self.viewer = MotionViewer(self.view.motions, titles=self.view.titles, static_image=False,
                                   **self._options(self.view))
        self._show()
        super().__init__([W.HBox(list(self.controls.values()), layout=W.Layout(flex_flow="row wrap")),
                          self.status, self.viewer, self.bars])
        self.add_class("mslib-explorer")
        self.add_class(f"mslib-explorer-{kind}")
        for name, control in self.controls.items():
            control.add_class(f"mslib-explorer-{name}")  # the browser test finds a control by this class
            control.observe(lambda change: self.refresh(), names="value")

    def _options(self, view) -> dict:
        """The viewer's options; its width by the number of panels, at most EXPLORER_WIDTH (a notebook column)."""
        return {"width": min(EXPLORER_WIDTH, PANEL_WIDTH * len(view.motions)), **self._viewer_options}

    @property
    def choices(self) -> dict:
        return {name: control.value for name, control in self.controls.items()}

    def _timed(self, choices: dict):
        t0 = time.perf_counter()
        view = self._compute(**choices)
        self.seconds = time.perf_counter() - t0
        return view

    def _show(self) -> None:
        v = self.view
        self.bars.show(v.classes, v.output_probabilities, v.targets)
        took = "cached" if v.cached else f"{1000 * self.seconds:.0f} ms"
        self.status.value = f"{html.escape(v.title)} <span style='color:#888'>({took})</span>"

    def refresh(self) -> None:
        """Compute the view of the controls' current values and show it."""
        choices = self.choices
        message = self._busy(choices) if self._busy else None
        if message:
            self.status.value = f"<span style='color:#b60'>⏳ {html.escape(message)}</span>"
        try:
            self.view = self._timed(choices)
        except ValueError as e:
            self.status.value = f"<span style='color:#c00'>{html.escape(str(e))}</span>"
            return
        self.viewer.update(self.view.motions, titles=self.view.titles, **self._options(self.view))
        self._show()

    def __repr__(self) -> str:
        return f"Explorer({self.kind}: {self.view.title})"

    def _repr_mimebundle_(self, **kwargs):
        bundle = super()._repr_mimebundle_(**kwargs)  # ipywidgets: the data dict only
        if bundle is None:
            return bundle
        data, metadata = bundle if isinstance(bundle, tuple) else (bundle, {})
        return {**data, "image/png": base64.b64encode(self.viewer.static_png()).decode("ascii")}, metadata
