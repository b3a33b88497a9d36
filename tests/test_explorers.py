"""The explorers (mslib/explorers.py): each static twin on fixed choices, each widget answering a change of its
controls, and the errors. The packaged checkpoints; ~20 s (one load of each model, the samplers run a few times)."""
import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from mslib import explorers as E  # noqa: E402
from mslib.motion.features import N_JOINTS  # noqa: E402

CONTENT = "c00000"   # the first test walk of the content corpus


def check_view(view, kind: str, n_motions: int):
    assert view.kind == kind and len(view.motions) == len(view.titles) == len(view.roles) == n_motions
    for m in view.motions:
        assert m.ndim == 3 and m.shape[1:] == (N_JOINTS, 3) and np.isfinite(m).all()
    assert view.probabilities.shape == (n_motions, len(view.classes)) == (n_motions, len(E.style_labels()))
    np.testing.assert_allclose(view.probabilities.sum(1), 1.0, atol=1e-6)
    assert set(view.targets) <= set(view.classes)
    text = view.summary()
    assert text.splitlines()[0] == view.title and "P(style | output)" in text
    for t in view.targets:
        assert f"P({t}): " in text


def test_transfer_view_shows_content_output_style():
    view = E.transfer_view(CONTENT, "old", "adain")
    check_view(view, "transfer", 3)
    assert view.roles == ("content", "output", "style") and view.targets == ("old",)
    assert view.facts["moved from the content (cm)"] > 1.0            # a learned method changes the motion
    same = E.transfer_view(CONTENT, "old", "identity")
    assert same.facts["moved from the content (cm)"] == 0.0
    assert not np.array_equal(view.output, same.output)
    again = E.transfer_view(CONTENT, "old", "adain")
    assert again.cached and np.array_equal(again.output, view.output)
    assert again.summary() == view.summary()                          # what nbval compares
    # a style clip id works like its label; a style label stands for the first test clip of that style
    clip = E.style_clip("old")
    assert E.resolve_style(clip) == (clip, "old")
    assert np.array_equal(E.transfer_view(CONTENT, clip, "adain").output, view.output)


def test_outputs_are_deterministic_without_the_cache():
    first = E.transfer_view(CONTENT, "proud", "contrastive")
    E.clear_cache()
    second = E.transfer_view(CONTENT, "proud", "contrastive")
    assert not second.cached and np.array_equal(first.output, second.output)
    np.testing.assert_array_equal(first.probabilities, second.probabilities)


def test_interpolation_ends_are_c_transfers_with_each_style():
    ends = [E.interpolation_view(CONTENT, "depressed", "proud", w) for w in (0.0, 1.0)]
    for view in ends:
        check_view(view, "interpolation", 4)
        assert view.targets == ("depressed", "proud")
    assert np.array_equal(ends[0].output, E.transfer_view(CONTENT, "depressed", "contrastive").output)
    assert np.array_equal(ends[1].output, E.transfer_view(CONTENT, "proud", "contrastive").output)
    middle = E.interpolation_view(CONTENT, "depressed", "proud", 0.3000000000000004)   # a slider's float
    assert middle.facts["w"] == 0.3
    assert not np.array_equal(middle.output, ends[0].output) and not np.array_equal(middle.output, ends[1].output)


def test_guidance_scale_changes_the_output():
    from mslib.models.mcm_ldm.model import MCMConfig
    course = MCMConfig.preset("course").cfg_scale
    views = {lam: E.guidance_view(CONTENT, "angry", lam) for lam in (0.0, course)}
    for view in views.values():
        check_view(view, "guidance", 3)
    assert not np.array_equal(views[0.0].output, views[course].output)
    k = views[0.0].classes.index("angry")
    assert views[course].output_probabilities[k] > views[0.0].output_probabilities[k]
    # the course preset's λ is the registry method's, and the explorer's default
    assert np.array_equal(views[course].output, E.transfer_view(CONTENT, "angry", "mcm_ldm").output)
    assert E.guidance_view(CONTENT, "angry").facts["λ"] == course


def test_a_prototype_choice_changes_the_generated_motion():
    views = [E.prototype_view("old", k) for k in (0, 1)]
    for view in views:
        check_view(view, "prototypes", 2)
        assert view.roles == ("style", "output") and len(view.output) == 63
    assert not np.array_equal(views[0].output, views[1].output)
    for view in views:  # the output stays in its style's region of D's feature space
        assert view.facts["nearest global prototype of the output"].startswith("old ")
    reference = E.prototype_view("old", "reference")
    assert not np.array_equal(reference.output, views[0].output)
    transfer = E.prototype_view("old", 1, content=CONTENT)
    check_view(transfer, "prototypes", 3)
    assert transfer.roles == ("content", "output", "style") and len(transfer.output) == 83


# ---------------------------------------------------------------- the widgets
@pytest.mark.parametrize("explore, control, value, word", [
    (E.explore_transfer, "method", "contrastive", "contrastive"),
    (E.explore_transfer, "style", "proud", "proud"),
    (E.explore_interpolation, "weight", 0.8, "w = 0.8"),
    (E.explore_prototypes, "prototype", 2, "prototype 2"),
    (E.explore_prototypes, "content", CONTENT, "content c00000"),
    (E.explore_guidance, "scale", 0.0, "λ = 0"),
])
def test_each_widget_answers_a_change_of_its_controls(explore, control, value, word):
    box = explore()
    assert "mslib-explorer" in box._dom_classes and box.viewer in box.children and box.bars in box.children
    before, bars_before = box.viewer.data, list(box.bars.probabilities.values())
    box.controls[control].value = value
    assert box.viewer.data != before and word in box.view.title and word in box.status.value
    assert [m["title"] for m in box.viewer.data["motions"]] == box.view.titles
    bars = list(box.bars.probabilities.values())
    np.testing.assert_allclose(bars, box.view.output_probabilities)
    assert bars != bars_before or control == "style"   # (a style change may leave the output's bars alike)
    bundle, _ = box._repr_mimebundle_()
    assert "image/png" in bundle and "application/vnd.jupyter.widget-view+json" in bundle


def test_a_bad_choice_in_a_widget_keeps_the_last_view_and_says_why():
    box = E.explore_prototypes()
    view, data = box.view, box.viewer.data
    box.controls["caption"].value = "   "
    assert box.view is view and box.viewer.data == data and "caption" in box.status.value


# ---------------------------------------------------------------- errors
@pytest.mark.parametrize("call, words", [
    (lambda: E.transfer_view(CONTENT, "old", "nope"), ["method 'nope' is unknown", "adain", "mcm_ldm"]),
    (lambda: E.transfer_view("c99999x", "old", "adain"), ["'c99999x'", "clip id"]),
    (lambda: E.transfer_view(CONTENT, "grumpy", "adain"), ["'grumpy'", "angry", "strutting"]),
    (lambda: E.interpolation_view(CONTENT, "old", "proud", 1.5), ["weight", "[0, 1]"]),
    (lambda: E.guidance_view(CONTENT, "old", -1), ["scale"]),
    (lambda: E.guidance_view(CONTENT, "old", "big"), ["scale", "number"]),
    (lambda: E.prototype_view("old", 7), ["prototype", "0…2", "reference"]),
    (lambda: E.prototype_view("old", True), ["prototype"]),
    (lambda: E.explore_transfer(method="adain", methods=["identity"]), ["'adain'", "identity"]),
    (lambda: E.explore_transfer(style="grumpy"), ["'grumpy'"]),
    (lambda: E.explore_guidance(scales=(2.0, 1.0)), ["increasing"]),
])
def test_unknown_choices_are_named_with_the_known_ones(call, words):
    with pytest.raises(ValueError) as e:
        call()
    for w in words:
        assert w in str(e.value)


def test_the_cache_keeps_the_last_outputs_only(monkeypatch):
    monkeypatch.setattr(E, "CACHE_SIZE", 2)
    E.clear_cache()
    for style in ("old", "proud", "angry"):
        E.transfer_view(CONTENT, style, "identity")
    assert len(E._CACHE) == 2 and not E.transfer_view(CONTENT, "old", "identity").cached
