"""The generator fitted to real capture: the stored table, and the pieces of tools/fit_styles.py on known answers."""
import json

import numpy as np
import pytest

from mslib.data import body, styles
from mslib.data.fitted import FITTED_FILE, load_fitted
from mslib.data.mocap_skeleton import to_bvh_motion
from mslib.data.retarget import register_motion
from mslib.data.synth import GENERATOR_VERSION, generate_clips
from mslib.evaluation.cues import CUES
from tools import fit_styles as F


@pytest.fixture(scope="module")
def table():
    if not FITTED_FILE.is_file():
        pytest.fail(f"{FITTED_FILE} is missing: the package ships the fitted table (tools/fit_styles.py)")
    return json.loads(FITTED_FILE.read_text(encoding="utf-8"))


def test_the_stored_table_says_what_made_it_and_fits_the_generator(table):
    assert table["command"].startswith("python tools/fit_styles.py --real ")
    assert len(table["real"]["digest"]) == 12
    # v5–v9 are v4 plus the per-joint moment layer, fitted on top of this table (test_joint_moments.py); v8 also
    # plans jumps alike for every style (actions.py), so the jump cells of the layer were refitted for it
    assert table["generator_version"] in (GENERATOR_VERSION, 4)
    assert set(table["styles"]) == set(styles.STYLES) and table["fitted_params"] == list(F.FITTED_PARAMS)
    for style, entry in table["styles"].items():
        assert len(entry["substyles"]) == F.N_SUBSTYLES and set(entry["params"]) == set(F.FITTED_PARAMS)
        for part in ("cues", "walk"):  # the fit came closer to the real walks, in cues and among the real styles
            assert entry["gap_after"][part] < entry["gap_before"][part], (style, part)
        for params in [entry["params"], *(s["params"] for s in entry["substyles"].values())]:
            for k, v in params.items():
                assert styles.PARAMS[k][2] <= v <= styles.PARAMS[k][3], (style, k, v)
        assert sum(s["takes"] for s in entry["substyles"].values()) == entry["takes"]


def test_the_generator_uses_the_fitted_numbers(table):
    for style, entry in table["styles"].items():
        assert styles.SUBSTYLES[style] == tuple(entry["substyles"])
        mean = styles.style_mean(style)
        assert all(mean[k] == pytest.approx(v) for k, v in entry["params"].items())
        for name, sub in entry["substyles"].items():
            assert all(styles.style_mean(style, name)[k] == pytest.approx(v) for k, v in sub["params"].items())
    assert styles.NEUTRAL == styles.style_mean("neutral")
    for j, d in table["body"]["directions"].items():
        assert np.allclose(body.REST_DIRECTIONS[int(j)], np.asarray(d) / np.linalg.norm(d))
    # the hand-written table is the prior the fit started from, and it moved
    assert any(styles.hand_mean("old")[k] != pytest.approx(v) for k, v in table["styles"]["old"]["params"].items())


def test_content_fits_shift_the_style_and_keep_its_substyles(table):
    """A content fitted on its own moves its fitted parameters by (content fit − walking fit), for the
    style and each sub-style alike; other contents and other parameters keep the walking fit."""
    fitted = [(s, g, c) for s, e in table["styles"].items() for g, c in e.get("contents", {}).items()]
    assert fitted, "no content was fitted on its own"
    for style, group, c in fitted:
        assert set(c["params"]) == set(F.CONTENT_PARAMS[group]) and c["windows"] >= F.MIN_CONTENT_WINDOWS
        assert c["gap_after"] <= c["gap_before"] + 1e-9, (style, group)  # the fit never ends farther away
        walk, own = styles.style_mean(style), styles.style_mean(style, content=group)
        assert all(own[k] == pytest.approx(v) for k, v in c["params"].items())
        assert all(own[k] == walk[k] for k in walk if k not in c["params"])
        assert styles.style_mean(style, content="walk") == walk
        for sub in styles.SUBSTYLES[style]:
            a, b = styles.style_mean(style, sub), styles.style_mean(style, sub, group)
            assert all(b[k] - a[k] == pytest.approx(own[k] - walk[k]) for k in c["params"])
    with pytest.raises(ValueError, match="content"):
        styles.style_mean("old", content="somersault")


def test_a_take_draws_its_contents_means():
    """At intensity 1 and no spread a take's parameters are its content's means (clipped to the bounds)."""
    for style, e in styles.FITTED.items():
        for group in e.get("contents", {}):
            drawn = styles.sample_style(np.random.default_rng(0), style, None, 1.0, spread=0.0, content=group)
            mean = styles.style_mean(style, None, group)
            assert all(drawn[k] == pytest.approx(min(max(mean[k], styles.PARAMS[k][2]), styles.PARAMS[k][3]))
                       for k in drawn)
            return
    pytest.fail("no fitted content")


def test_without_the_file_nothing_is_fitted(tmp_path):
    assert load_fitted("styles", tmp_path / "absent.json") == {}
    bad = tmp_path / "bad.json"
    bad.write_text("{not json", encoding="utf-8")
    with pytest.raises(ValueError, match="bad.json.*refit"):
        load_fitted("styles", bad)


def _registered(specs):
    takes = generate_clips(specs)
    return [register_motion(to_bvh_motion(t.rotations, t.root, t.skeleton, fps=t.fps), "builtin").positions
            for t in takes]


def test_trunk_directions_recover_the_generators_own_body():
    """Walks of a body with the trunk held straight give back that body's trunk bones (a known answer)."""
    flat = dict(lean=0.0, chest=0.0, head=0.0, head_tilt=0.0, shoulder_raise=0.0, shoulder_back=0.0,
                sway=0.0, twist=0.0, hip_sway=0.2, tremor=0.0, head_bob=0.0)
    joints = _registered([dict(content="walk", seed=0, index=i, fps=30.0, duration=2.5, canonical=False,
                               style_params=flat) for i in range(4)])
    found = F.trunk_directions(joints)
    for j in (3, 6, 9, 12, 13, 16):  # bones no gait curve moves much
        assert np.dot(found[j], body.REST_DIRECTIONS[j]) > 0.98, j
    assert np.allclose(found[2], np.array(found[1]) * [-1, 1, 1]) and found[3][0] == 0.0


@pytest.fixture(scope="module")
def describer():
    """A Describer fitted on generated stand-ins for real takes (two styles, walks and kicks)."""
    fake = {s: {c: _registered([dict(content=c, style=s, seed=5, index=i, fps=30.0, duration=2.0, canonical=False)
                                for i in range(3)]) for c in ("walk", "kick")} for s in ("neutral", "old")}
    return F.Describer(fake)


def test_the_describer_has_a_part_per_content(describer):
    assert describer.n_dims == 1 and describer.parts["cues"] == slice(0, len(CUES))
    walks = _registered([dict(content="walk", style="old", seed=6, index=0, fps=30.0, duration=2.0, canonical=False)])
    v = describer({"walk": walks})
    assert v.shape == (len(CUES) + len(F.CONTENT_GROUPS),)
    assert np.isfinite(v[describer.parts["walk"]]).all() and np.isnan(v[describer.parts["kick"]]).all()
    assert F.content_group("07") == "walk" and F.content_group("kick") == "kick" and F.content_group("25") is None


def test_the_simulator_is_deterministic_and_sees_a_parameter(describer):
    sim = F.Simulator(describer, {"walk": 3}, duration=2.0)
    neutral = styles.style_mean("neutral")
    a, b = sim(neutral), sim(neutral)
    assert np.array_equal(a, b, equal_nan=True) and sim.calls == 2 and a.shape == (len(CUES) + len(F.CONTENT_GROUPS),)
    slower = sim({**neutral, "cadence": neutral["cadence"] * 0.8})
    assert slower[CUES.index("cadence")] < 0.9 * a[CUES.index("cadence")]


def test_fit_means_moves_toward_a_reachable_target(describer):
    """The target is the simulator's own answer at other parameters: the fit must close most of the gap."""
    sim = F.Simulator(describer, {"walk": 3}, duration=2.0)
    start = styles.style_mean("neutral")
    goal = {**start, "arm_swing": start["arm_swing"] * 1.6, "lean": start["lean"] + 10}
    target = sim(goal)
    target[len(CUES):] = np.nan  # the cues only (nothing but walks is generated)
    scale = np.ones(len(target)) * 0.05
    weights = np.ones(len(target))
    before = np.linalg.norm(np.nan_to_num((sim(start) - target) / scale))
    _, _, after, _ = F.fit_means(sim, start, target, scale, weights, start, iters=3, log=lambda *a: None)
    assert after < 0.5 * before


def test_split_takes_and_names():
    rng = np.random.default_rng(0)
    takes = [(f"t{i}", rng.normal(size=(2, len(CUES))) + i * np.eye(len(CUES))[0]) for i in range(9)]
    labels = F.split_takes(takes, np.ones(len(CUES)), 3)
    assert sorted(np.bincount(labels)) == [3, 3, 3] and list(labels[:3]) == [0, 0, 0]  # along the strong axis
    z = np.zeros(len(CUES))
    z[CUES.index("speed")], z[CUES.index("jerk")] = -2.0, 5.0
    assert F.name_cluster(z, np.zeros(len(CUES)), np.ones(len(CUES)), set(), CUES) == "slow"  # jerk names none
    assert F.name_cluster(z, np.zeros(len(CUES)), np.ones(len(CUES)), {"slow"}, CUES) != "slow"


def test_the_tool_refuses_the_test_grid(tmp_path):
    (tmp_path / "joints").mkdir()
    (tmp_path / "meta.json").write_text(json.dumps({"source": "data_prep.bvh from xia_grid", "format_version": 1}),
                                       encoding="utf-8")
    (tmp_path / "labels.csv").write_text("clip_id,split,style,substyle,content,caption,n_frames,source_file\n",
                                         encoding="utf-8")
    with pytest.raises(ValueError, match="test grid"):
        F.real_takes(tmp_path, progress=False)
    from tools.realism_gap import measure  # the gap diagnosis refuses it too, before reading anything
    with pytest.raises(ValueError, match="test grid"):
        measure(tmp_path, progress=False)
