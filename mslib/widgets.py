"""ipywidgets explorers for the notebooks: a slider that redraws a matplotlib figure.

Each explorer has a static twin (`render(value)` called directly) so nbval still checks the logic;
the widget cell itself carries `# NBVAL_IGNORE_OUTPUT`. The browser test
(tests/test_browser_widgets.py) moves the slider of notebook 04 in headless Chromium.
"""
from __future__ import annotations

from typing import Callable, Sequence


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
    import ipywidgets as W
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
