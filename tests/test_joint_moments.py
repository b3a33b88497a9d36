"""The per-joint moment layer of the generator (mslib/data/joint_moments.py) and its fitting tool."""
import hashlib
import json

import numpy as np
import pytest

from mslib.data import joint_moments as jm
from mslib.data import styles
from mslib.data.synth import GENERATOR_VERSION, generate_clip
from tools import fit_joint_moments as F
from tools.fit_styles import CONTENT_GROUPS


def test_unpack_mirrors_left_onto_right_and_zero_is_the_identity():
    theta = np.arange(jm.N_PARAMS, dtype=float) / 100
    offset, gain, spread = jm.unpack(theta)
    assert offset.shape == gain.shape == spread.shape == (22, 3)
    for left, right in jm.PAIRED:
        np.testing.assert_allclose(offset[right], offset[left] * [1, -1, -1])
        np.testing.assert_allclose(gain[right], gain[left])
        np.testing.assert_allclose(spread[right], spread[left])
    for j in jm.MIDLINE:
        assert offset[j, 1] == offset[j, 2] == 0  # a midline joint leans forward/back only
    untouched = [j for j in range(22) if j not in jm.MIDLINE and all(j not in p for p in jm.PAIRED)]
    assert untouched and not offset[untouched].any() and (gain[untouched] == 1).all() and not spread[untouched].any()
    offset, gain, spread = jm.unpack(np.zeros(jm.N_PARAMS))
    assert not offset.any() and (gain == 1).all() and not spread.any()
    with pytest.raises(ValueError, match="96 numbers"):
        jm.unpack(np.zeros(5))


def test_the_layer_sets_mean_spread_and_adds_band_limited_variation():
    rng = np.random.default_rng(0)
    fps, T = 30.0, 600
    a = 10 * np.sin(np.linspace(0, 20, T))[:, None, None] + rng.normal(size=(1, 22, 3))  # (T, 22, 3)
    np.testing.assert_allclose(jm.apply_moments(a, np.zeros(jm.N_PARAMS), fps, rng), a, atol=1e-12)
    theta = np.zeros(jm.N_PARAMS)
    theta[0] = 7.0  # pelvis pitch offset
    theta[jm.N_OFFSET:jm.N_OFFSET + 3] = np.log(2.0)  # pelvis gain ×2 on every axis
    out = jm.apply_moments(a, theta, fps, rng)
    np.testing.assert_allclose(out[:, 0].mean(0), a[:, 0].mean(0) + [7, 0, 0], atol=1e-9)
    np.testing.assert_allclose(out[:, 0].std(0), 2 * a[:, 0].std(0), rtol=1e-9)
    np.testing.assert_allclose(out[:, 3:], a[:, 3:])  # nothing else moved
    n = jm.variation(T * 4, fps, np.random.default_rng(1))  # (4T, 22, 3)
    assert abs(n.std() - 1) < 0.1 and abs(n.mean()) < 0.05
    power = np.abs(np.fft.rfft(n[:, 0, 0])) ** 2
    freq = np.fft.rfftfreq(len(n), 1 / fps)
    inside = (freq >= jm.BAND_HZ[0] - 0.05) & (freq <= jm.BAND_HZ[1] + 0.05)
    assert power[inside].sum() > 0.95 * power.sum()


def test_a_cell_without_numbers_takes_the_walking_ones_and_intensity_interpolates():
    walk, punch, neutral_walk = np.full(jm.N_PARAMS, 1.0), np.full(jm.N_PARAMS, 2.0), np.full(jm.N_PARAMS, -1.0)
    table = {("old", "walk"): walk, ("old", "punch"): punch, ("neutral", "walk"): neutral_walk}
    np.testing.assert_allclose(jm.cell_moments("old", "punch", table=table), punch)
    np.testing.assert_allclose(jm.cell_moments("old", "kick", table=table), walk)
    np.testing.assert_allclose(jm.cell_moments("old", "kick", 0.5, table=table), 0.5 * (walk + neutral_walk))
    np.testing.assert_allclose(jm.cell_moments("proud", "kick", table=table), neutral_walk)
    assert jm.cell_moments("old", "walk", table={}) is None


def test_clip_to_limits():
    t = jm.clip_to_limits(np.full(jm.N_PARAMS, 100.0))
    assert (t[:jm.N_OFFSET] == jm.OFFSET_LIMIT).all() and (t[jm.N_OFFSET:jm.N_OFFSET + jm.N_GAIN] == jm.LOG_GAIN_LIMIT).all()
    assert (t[-jm.N_GAIN:] == jm.SPREAD_LIMIT).all() and (jm.clip_to_limits(-t)[-jm.N_GAIN:] == 0).all()


@pytest.fixture(scope="module")
def stored():
    if not jm.MOMENTS_FILE.is_file():
        pytest.fail(f"{jm.MOMENTS_FILE} is missing: the package ships the fitted layer (tools/fit_joint_moments.py)")
    return json.loads(jm.MOMENTS_FILE.read_text(encoding="utf-8"))


def test_the_stored_layer_says_what_made_it_and_sits_on_the_shipped_styles(stored):
    assert stored["command"].startswith("python tools/fit_joint_moments.py --real ")
    assert stored["generator_version"] == GENERATOR_VERSION
    styles_file = jm.MOMENTS_FILE.with_name("fitted_styles.json")
    assert stored["fitted_styles_digest"] == hashlib.sha256(styles_file.read_bytes()).hexdigest()[:12], \
        "the styles were refitted after the layer: rerun tools/fit_joint_moments.py"
    assert stored["cells"] and set(stored["cells"]) == set(stored["fit"])
    for key, theta in stored["cells"].items():
        style, content = key.split(":")
        assert style in styles.STYLES and content in CONTENT_GROUPS
        assert len(theta) == jm.N_PARAMS
        np.testing.assert_allclose(jm.clip_to_limits(theta), theta)
        fit = stored["fit"][key]
        assert fit["real_windows"] >= F.MIN_WINDOWS and fit["residual_after"] <= fit["residual_before"], key
    assert set(jm.FITTED) == {tuple(k.split(":")) for k in stored["cells"]}


def test_the_generator_applies_the_layer_and_stays_deterministic():
    a = generate_clip("punch", "old", seed=3, index=1, fps=20.0)
    b = generate_clip("punch", "old", seed=3, index=1, fps=20.0)
    np.testing.assert_array_equal(a.positions, b.positions)
    saved = jm.FITTED
    try:
        jm.FITTED = {}
        bare = generate_clip("punch", "old", seed=3, index=1, fps=20.0)
    finally:
        jm.FITTED = saved
    assert a.positions.shape == bare.positions.shape
    assert np.abs(a.positions - bare.positions).max() > 0.01  # metres: the fitted layer moves the body
    np.testing.assert_allclose(a.skeleton.bone_lengths(), bare.skeleton.bone_lengths())


def test_fit_cell_closes_a_reachable_gap(monkeypatch):
    """With features and cues linear in the numbers, the fit lands near a target that some numbers reach."""
    from mslib.evaluation.cues import CUES
    rng = np.random.default_rng(0)
    A = rng.normal(size=(jm.N_PARAMS, 20)) * 0.05
    C = rng.normal(size=(jm.N_PARAMS, len(CUES))) * 0.02
    base, cue_base = rng.normal(size=20), rng.normal(size=len(CUES))

    def fake(style, content, table, with_cues=False):  # windows whose mean moves linearly with the cell's numbers
        theta = np.asarray(table[(style, content)])
        cues = cue_base + theta @ C + np.zeros((3, 1)) if with_cues else None
        return base + theta @ A + np.zeros((4, 1)), cues
    monkeypatch.setattr(F, "generated_windows", fake)

    class Identity:
        @staticmethod
        def transform(X):
            return X
    truth = jm.clip_to_limits(np.concatenate([rng.normal(0, 5, jm.N_OFFSET), rng.normal(0, 0.2, jm.N_GAIN),
                                              rng.uniform(0, 5, jm.N_GAIN)]))
    directions = rng.normal(size=(7, 20))
    out = F.fit_cell("old", "punch", base + truth @ A, Identity, directions, iters=3, weights=F.Weights(1, 0, 0))
    assert out["residual_after"] < 0.01 * out["residual_before"]
    assert len(out["theta"]) == jm.N_PARAMS
    walk = F.fit_cell("old", "walk", base + truth @ A, Identity, directions, cue_base + truth @ C,
                      np.full(len(CUES), 0.1), iters=3, weights=F.Weights(1, 0, 0))  # a walk matches its cues too
    assert walk["residual_after"] < 0.01 * walk["residual_before"]
    assert walk["residual_before"] > out["residual_before"]  # the cue gap counts in the residual


def test_fit_cell_weighs_its_blocks_and_starts_warm(monkeypatch):
    """The residual's parts weigh what Weights says (known answers at the numbers 0), and a warm start from
    numbers that already fit keeps them."""
    rng = np.random.default_rng(2)
    A, base = rng.normal(size=(jm.N_PARAMS, 80)), rng.normal(size=80)
    monkeypatch.setattr(F, "generated_windows",
                        lambda style, content, table, with_cues=False: (base + table[(style, content)] @ A
                                                                         + np.zeros((4, 1)), None))

    class Identity:
        @staticmethod
        def transform(X):
            return X
    directions, target, within = rng.normal(size=(14, 80)), rng.normal(size=80), rng.uniform(0.5, 2, 80)
    gap = base - target  # at the numbers 0
    before = {w: F.fit_cell("old", "kick", target, Identity, directions, iters=0, within=within,
                            weights=F.Weights(*w))["residual_before"] for w in [(1, 0, 0), (4, 0, 0), (1, 2, 3)]}
    d = directions @ gap
    assert before[1, 0, 0] == pytest.approx((d ** 2).sum(), rel=1e-3)
    assert before[4, 0, 0] == pytest.approx(4 * (d[:7] ** 2).sum() + (d[7:] ** 2).sum(), rel=1e-3)
    z = gap / within
    assert before[1, 2, 3] == pytest.approx((d ** 2).sum() + 2 * (z[:66] ** 2).sum() / 66 + 3 * (z ** 2).mean(),
                                            rel=1e-3)
    truth = jm.clip_to_limits(rng.normal(0, 0.5, jm.N_PARAMS))
    warm = F.fit_cell("old", "kick", base + truth @ A, Identity, directions, iters=0, within=within, start=truth)
    np.testing.assert_allclose(warm["theta"], truth, rtol=1e-3, atol=1e-3)
    assert warm["residual_after"] < 1e-6 < warm["residual_before"]


def test_the_discriminant_directions_are_in_units_of_the_within_style_spread():
    rng = np.random.default_rng(1)
    y = np.repeat(np.array(["a", "b", "c"]), 200)
    Z = rng.normal(size=(600, 6)) + (y == "b")[:, None] * [3, 0, 0, 0, 0, 0] + (y == "c")[:, None] * [0, 0, 2, 0, 0, 0]
    D = F.discriminant_directions(Z, y)
    assert D.shape == (2, 6)
    np.testing.assert_allclose(F.within_spread(Z @ D.T, y), 1.0, rtol=0.05)  # LDA scalings: unit within-class spread
    assert np.abs(D[:, [1, 3, 4, 5]]).max() < 0.3 * np.abs(D[:, [0, 2]]).max()  # it reads the telling features


def test_refitting_some_contents_keeps_the_other_cells_and_says_how_they_were_made(monkeypatch, tmp_path):
    """`fit(only=...)` refits those contents (warm: from the layer in place) and keeps every other cell, its fit
    record and the command that made it."""
    real = tmp_path / "real"
    real.mkdir()
    (real / "labels.csv").write_text("clip_id,style\n")
    y = np.array(["old"] * 3 + ["proud"] * 3)
    group = np.array(["kick", "kick", "walk"] * 2)  # two kick windows per style (MIN_WINDOWS), one walk
    monkeypatch.setattr(F, "real_cells", lambda folder: (None, np.eye(6, 396), y, group, {}))
    monkeypatch.setattr(F, "builtin_directions", lambda scaler, Z, y: np.zeros((7, 396)))

    def fake_fit_cell(style, content, start=None, **kw):  # (runs in a worker process) ends where it started, or at 1
        return {"theta": list(start) if start is not None else [1.0] * jm.N_PARAMS, "residual_before": 2.0,
                "residual_after": 1.0}
    monkeypatch.setattr(F, "fit_cell", fake_fit_cell)
    layer = tmp_path / "layer.json"
    old = {"cells": {"old:walk": [0.5] * jm.N_PARAMS, "old:kick": [0.25] * jm.N_PARAMS},
           "fit": {"old:walk": {"real_windows": 3}, "old:kick": {"real_windows": 3}},
           "command": "python tools/fit_joint_moments.py --real xia_train", "earlier_commands": []}
    layer.write_text(json.dumps(old))
    monkeypatch.setattr(jm, "MOMENTS_FILE", layer)
    table = F.fit(real, only=["kick"], progress=False, warm=True)
    assert table["earlier_commands"] == [old["command"]] and set(table["cells"]) == {"old:walk", "old:kick", "proud:kick"}
    assert table["cells"]["old:walk"] == old["cells"]["old:walk"]  # kept
    assert table["cells"]["old:kick"] == old["cells"]["old:kick"]  # refitted, warm: from the layer's numbers
    assert table["cells"]["proud:kick"] == [1.0] * jm.N_PARAMS  # refitted: the layer had no numbers for it
    assert table["fit"]["old:walk"] == {"real_windows": 3} and table["fit"]["old:kick"]["residual_after"] == 1.0
    assert table["weights"] == {"real": 1.0, "pose_means": F.POSE_WEIGHT, "all_means": F.ALL_MEANS_WEIGHT}
