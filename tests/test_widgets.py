"""The slider explorer: argument checks and one cached figure per value (the browser test moves it)."""
import matplotlib
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from mslib.widgets import slider_figure  # noqa: E402


def test_slider_draws_each_value_once():
    calls = []

    def render(v):
        calls.append(v)
        fig, ax = plt.subplots()
        ax.plot([0, 1], [0, v])
        return fig

    box = slider_figure(render, [0.0, 1.0, 2.5], start=1.0)
    slider = box.children[0]
    assert calls == [1.0] and "mslib-slider-figure" in box._dom_classes
    slider.value = 2.5
    slider.value = 1.0
    slider.value = 2.5
    assert calls == [1.0, 2.5]


@pytest.mark.parametrize("values,start,word", [([1.0], None, "at least two"), ([2.0, 1.0], None, "increasing"),
                                               ([0.0, 1.0], 0.5, "start")])
def test_bad_slider_arguments_are_named(values, start, word):
    with pytest.raises(ValueError, match=word):
        slider_figure(lambda v: plt.figure(), values, start=start)
