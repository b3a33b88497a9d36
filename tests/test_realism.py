"""The realism report: known answers of the style cues, the report's structure, and real Xia takes."""
import json

import numpy as np
import pytest

from mslib.cli import main
from mslib.data.dataset_folder import DatasetWriter
from mslib.data.synth import generate_clip
from mslib.evaluation import cues as C
from mslib.evaluation import realism as R
from mslib.motion import rotations as rot
from mslib.motion import skeleton as sk
from mslib.motion.features import encode

FPS = 20
REST = sk.HUMANML3D.rest_positions()  # (22, 3), facing +Z, +X the body's left
LEG = {side: np.linalg.norm(REST[k] - REST[h]) + np.linalg.norm(REST[a] - REST[k]) for side, (h, k, a) in
       zip("lr", C.LEGS)}
L = LEG["r"]  # the unit: the right leg, as registration measures it
UPPER = (3, 6, 9, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21)


def still(T=40):
    return np.repeat(REST[None], T, 0)


def yaw_matrix(a):
    return rot.axis_angle_to_matrix(np.array([0.0, a, 0.0]))


def swinging(T=60, f=1.0, hip=0.4, arm=0.0):
    """FK legs (and arms) swinging in antiphase about X at f Hz: the answer of cadence and stride is known."""
    t = np.arange(T) / FPS
    aa = np.zeros((T, 22, 3))
    aa[:, 1, 0], aa[:, 2, 0] = hip * np.sin(2 * np.pi * f * t), -hip * np.sin(2 * np.pi * f * t)
    aa[:, 16, 0], aa[:, 17, 0] = -arm * np.sin(2 * np.pi * f * t), arm * np.sin(2 * np.pi * f * t)
    return sk.forward_kinematics(sk.HUMANML3D, rot.axis_angle_to_matrix(aa), np.zeros((T, 3)))


def walk(style="neutral", index=0, duration=2.0):
    return generate_clip("walk", style, seed=3, index=index, duration=duration).positions


# ---------------------------------------------------------------- known answers
def test_still_pose_has_no_motion_and_its_posture():
    c = C.cues(still())
    for k in ("speed", "arm_swing", "stride", "knee_lift", "cadence", "bounce", "sway", "jerk"):
        assert abs(c[k]) < 1e-9, k
    floor = REST[list(C.FEET), 1].min()
    assert c["head_height"] == pytest.approx((REST[15, 1] - floor) / L)
    assert c["trunk_pitch"] == pytest.approx(0.0, abs=1e-9)  # the rest spine is vertical
    assert c["head_ahead"] == pytest.approx((REST[15, 2] - REST[0, 2]) / L)
    assert c["hand_spread"] == pytest.approx(abs(REST[20, 0] - REST[21, 0]) / L)
    assert c["shoulder_height"] == pytest.approx((REST[[16, 17], 1].mean() - REST[12, 1]) / L)


def test_cues_ignore_placement_heading_and_body_size():
    p = walk("old", duration=1.6)
    base = C.cues(p)
    moved = p @ yaw_matrix(1.1).T + np.array([3.0, 0.5, -2.0])
    for q in (moved, 1.7 * p, 0.6 * moved):
        for k, v in C.cues(q).items():
            assert v == pytest.approx(base[k], rel=1e-6, abs=1e-9), k
    np.testing.assert_allclose(R.window_features(moved), R.window_features(p), atol=1e-8)
    np.testing.assert_allclose(C.body_frame(moved), C.body_frame(p), atol=1e-9)


def test_body_frame_faces_plus_z_from_any_heading():
    turned = still() @ yaw_matrix(-2.0).T + np.array([1.0, 0.0, 4.0])
    expect = REST - REST[0] * np.array([1, 0, 1])
    expect[:, 1] -= REST[list(C.FEET), 1].min()
    np.testing.assert_allclose(C.body_frame(turned)[0], expect / L, atol=1e-9)
    assert C.facing_yaw(turned) == pytest.approx(np.full(40, -2.0))


def test_cadence_stride_knee_lift_and_arm_swing_of_a_known_swing():
    hip, arm, f = 0.4, 0.3, 1.0
    c = C.cues(swinging(60, f, hip, arm))
    assert c["cadence"] == pytest.approx(2 * f, rel=0.02)  # the ankles pass each other twice a cycle
    assert c["stride"] == pytest.approx(np.mean([2 * np.sin(hip) * LEG[s] for s in "lr"]) / L, rel=1e-3)
    thigh = np.mean([np.linalg.norm(REST[k] - REST[h]) for h, k, _ in C.LEGS])
    assert c["knee_lift"] == pytest.approx(thigh * (1 - np.cos(hip)) / L, rel=1e-3)
    t = np.arange(60) / FPS
    arm_len = np.linalg.norm(REST[18] - REST[16]) + np.linalg.norm(REST[20] - REST[18])
    arm_len_r = np.linalg.norm(REST[19] - REST[17]) + np.linalg.norm(REST[21] - REST[19])
    z = np.sin(arm * np.sin(2 * np.pi * f * t))
    assert c["arm_swing"] == pytest.approx((arm_len + arm_len_r) / 2 * z.std() / L, rel=1e-3)
    assert C.cues(swinging(60, 1.5, hip))["cadence"] == pytest.approx(3.0, rel=0.02)
    assert np.isnan(C.cues(swinging(12, 0.5, hip))["cadence"])  # one step seen: undetermined


def test_speed_sway_bounce_and_jerk_of_known_paths():
    T, v, A, B = 60, 1.2, 0.05, 0.03
    t = np.arange(T) / FPS
    path = np.stack([A * np.sin(2 * np.pi * t), B * np.sin(4 * np.pi * t), v * t], -1)  # 1 Hz sway, 2 Hz bounce
    c = C.cues(still(T) + path[:, None])
    assert c["sway"] == pytest.approx(A / np.sqrt(2) / L, rel=0.05)
    assert c["bounce"] == pytest.approx(B / np.sqrt(2) / L, rel=0.02)
    c = C.cues(still(T) + np.stack([0 * t, 0 * t, v * t], -1)[:, None] @ yaw_matrix(0.7).T)
    assert c["speed"] == pytest.approx(v / L) and abs(c["jerk"]) < 1e-6 and abs(c["sway"]) < 1e-9
    k = 0.4  # y = k t³ → third derivative 6k everywhere
    c = C.cues(still(T) + np.stack([0 * t, k * t ** 3, 0 * t], -1)[:, None])
    assert c["jerk"] == pytest.approx(6 * k / L, rel=1e-6)


def test_trunk_pitch_and_head_ahead_of_a_forward_lean():
    p = still()
    lean = rot.axis_angle_to_matrix(np.array([np.radians(20), 0, 0]))  # +Y toward +Z: forward
    p[:, UPPER] = (p[:, UPPER] - p[:, :1]) @ lean.T + p[:, :1]
    c = C.cues(p)
    assert c["trunk_pitch"] == pytest.approx(20.0, abs=0.01)  # the shoulders are not quite level
    assert c["head_ahead"] == pytest.approx(((REST[15] - REST[0]) @ lean.T)[2] / L, rel=1e-3)


def test_bad_windows_and_folders_are_named(tmp_path, capsys):
    with pytest.raises(ValueError, match="4 frames"):
        C.cues(still(3))
    with pytest.raises(ValueError, match=r"--real .*nope: no such folder"):
        R.read_clips(tmp_path / "nope")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match=r"--grid .*empty: .*not a dataset folder"):
        R.read_clips(tmp_path / "empty", "--grid")
    assert main(["data", "realism", "--real", str(tmp_path / "nope")]) == 2
    assert "nope" in capsys.readouterr().err


def test_classifier_windows_keep_a_short_take_whole_and_cut_a_long_one():
    w = walk(duration=2.0)  # 40 frames
    long = R.classifier_windows(w)
    assert [len(x) for x in long] == [R.CLASSIFIER_WINDOW] * 4  # starts 0, 8, 16, 24
    np.testing.assert_allclose(long[1], R.windows(w, R.CLASSIFIER_WINDOW)[1])
    short = R.classifier_windows(w[3:15])  # 12 frames: one action take, one window of its own
    assert len(short) == 1 and short[0].shape == (12, 22, 3)
    np.testing.assert_allclose(short[0][:, :, 1], w[3:15, :, 1])  # re-centred and re-faced; the floor kept
    assert R.classifier_windows(w[:R.SHORT_TAKE - 1]) == []
    assert len(R.classifier_windows(w[:R.SHORT_TAKE])) == 1
    assert np.isfinite(R.window_features(short[0])).all()


def test_take_features_stack_every_judge_window_take_by_take():
    w = walk(duration=2.0)
    f = R.take_features([w, w[3:15], w[:R.SHORT_TAKE - 1]])  # 4 windows, 1 whole short take, 0 from the too-short one
    assert f.shape == (5, 6 * 66)
    np.testing.assert_allclose(f[1], R.window_features(R.classifier_windows(w)[1]))
    np.testing.assert_allclose(f[4], R.window_features(R.classifier_windows(w[3:15])[0]))
    assert R.take_features([w[:R.SHORT_TAKE - 1]]).shape == (0, 6 * 66)


# ---------------------------------------------------------------- the report on tiny folders
def make_folder(path, clips):
    """A dataset folder from (clip_id, style, content, split, positions) tuples."""
    w = DatasetWriter(path, name=path.name, source="test")
    for cid, style, content, split, p in clips:
        w.add(cid, p, encode(p), split, style=style, content=content, source_file=f"{cid}.bvh")
    w.close()
    return path


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    root = tmp_path_factory.mktemp("realism")
    styles = ("neutral", "old")
    real = make_folder(root / "real", [(f"{s}_{k}", s, "walk", "train", walk(s, k)) for s in styles for k in range(4)])
    grid = make_folder(root / "grid", [(f"{s}_g{k}", s, "walk", "test", walk(s, 10 + k)) for s in styles for k in range(2)])
    built = make_folder(root / "style", [(f"t{k}_{s}", s, c, "test" if k % 2 else "train", walk(s, 20 + k, 1.6))
                                         for s in styles for k, c in enumerate(("walk", "walk", "walk", "run"))])
    return root, real, grid, built


def test_a_judge_needs_two_styles_and_says_whose_data_lacks_them(tiny):
    root, real, grid, built = tiny
    one = [(r, j) for r, j in R.read_clips(built, "b") if r["style"] == "old"]
    with pytest.raises(ValueError, match="built-in train data: need windows .* at least two styles"):
        R.fit_judge(one, "built-in")
    clf, fitted = R.fit_judge(R.read_clips(real, "--real"), "real")
    assert list(clf.classes_) == ["neutral", "old"] and fitted["train"]["takes"] == 8 and fitted["C"] in R.C_CHOICES
    # windows cut once give the same judge as the clips; kept to some styles, only their windows remain
    cut = R.as_windows(R.read_clips(real, "--real"))
    again, refitted = R.fit_judge(cut, "real")
    assert refitted == fitted and np.array_equal(again.predict(cut.X), clf.predict(cut.X))
    old = R.as_windows(cut, {"old"})
    assert set(old.y) == {"old"} and len(old.X) == len(old.take) == (cut.y == "old").sum() > 0


def test_report_structure_save_and_plot(tiny):
    root, real, grid, built = tiny
    report = R.realism_report(real, grid, builtin=built, progress=False)
    assert report["real"]["digest"] == R.folder_digest(real) and len(report["real"]["digest"]) == 12
    assert report["builtin"]["style_clips"] == 8 and report["grid"]["takes"] == 4
    table = report["cues"]["table"]
    assert sorted(table) == ["neutral", "old"] and set(table["old"]["cues"]) == set(C.CUES)
    assert table["old"]["n_real"] > 0 and table["old"]["n_builtin"] > 0 and table["old"]["gap_sd"] >= 0
    rb, br = report["real_to_builtin"], report["builtin_to_real"]
    assert rb["classes"] == ["neutral", "old"] and rb["real_test_windows"]["chance"] == 50.0
    assert rb["builtin_test_windows"]["n"] > 0 and rb["C"] in R.C_CHOICES
    assert rb["builtin_train_windows"]["n"] > 0  # the train clips are read too: the steadier figure
    assert sum(map(sum, rb["builtin_test_windows"]["confusion"]["counts"])) == rb["builtin_test_windows"]["n"]
    for which in ("builtin_test", "real_test", "builtin_train"):  # every window counted once, under its content
        by_content, whole = rb[f"{which}_by_content"], rb[f"{which}_windows"]
        assert sum(v["n"] for v in by_content.values()) == whole["n"]
        assert sum(v["n"] * v["accuracy"] for v in by_content.values()) / whole["n"] == \
            pytest.approx(whole["accuracy"], abs=0.1)
    assert br["real_test_takes"]["n"] == 4 and br["real_test_takes"]["chance"] == 12.5
    assert br["real_train_takes"]["n"] == 8 and 0 <= br["builtin_test_clips_accuracy"] <= 100
    bl = report["builtin_linear_to_real"]  # the linear recipe fitted on the built-in train clips (2 per style)
    assert bl["train"]["takes"] == 4 and bl["C"] in R.C_CHOICES
    assert bl["real_test_takes"]["n"] == 4 and bl["real_train_takes"]["n"] == 8
    assert bl["real_test_windows"]["n"] == rb["real_test_windows"]["n"]  # the same real windows as part 2's
    text = R.format_report(report)
    assert "head_height" in text and "real → built-in" in text and "built-in → real" in text
    assert "the other way round" in text
    out = R.save_report(report, root / "r.json")
    assert json.loads(out.read_text()) == json.loads(json.dumps(report))
    with pytest.raises(ValueError, match="already exists"):
        R.save_report(report, out)
    png = R.plot_report(report, root / "r.png")
    assert png.read_bytes()[:4] == b"\x89PNG"
    again = R.realism_report(real, grid, builtin=built, progress=False)
    assert json.dumps(again) == json.dumps(report)  # deterministic


def test_without_grid_uses_the_splits_and_refuses_overlap(tiny):
    root, real, grid, built = tiny
    with pytest.raises(ValueError, match="train and test clips"):
        R.realism_report(real, builtin=built, progress=False)  # every real clip is train
    with pytest.raises(ValueError, match="shares 8 source file"):
        R.realism_report(real, real, builtin=built, progress=False)


def test_cli_stores_json_and_plot_and_never_overwrites(tiny, monkeypatch, capsys):
    import mslib.data.corpora
    root, real, grid, built = tiny
    monkeypatch.setattr(mslib.data.corpora, "load_builtin", lambda progress=True: {"style": built})
    out, png = root / "cli" / "realism.json", root / "cli" / "realism.png"
    args = ["data", "realism", "--real", str(real), "--grid", str(grid), "--out", str(out), "--plot", str(png)]
    assert main(args + ["--json"]) == 0
    printed = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    stored = json.loads(out.read_text())
    assert stored == printed and stored["command"].startswith("python -m mslib data realism --real ")
    assert png.is_file() and stored["builtin"]["digest"] == R.folder_digest(built)
    before = out.read_bytes()
    assert main(args) == 2 and "already exists" in capsys.readouterr().err and out.read_bytes() == before


# ---------------------------------------------------------------- real takes (../shared/data)
def test_real_xia_subset(shared_data, tmp_path, tiny):
    from data_prep.bvh import convert
    _, _, _, built = tiny
    for name, files in (("train", ["neutral_01_003", "neutral_02_000", "neutral_07_000", "neutral_08_000",
                                   "old_02_001", "old_02_000", "old_07_000", "old_08_000"]),
                        ("grid", ["neutral_01_000", "old_01_000", "neutral_13_000", "old_13_000"])):
        (tmp_path / f"bvh_{name}").mkdir()
        src = shared_data / ("xia_train" if name == "train" else "xia_grid")
        for f in files:  # links, not copies
            (tmp_path / f"bvh_{name}" / f"{f}.bvh").symlink_to(src / f"{f}.bvh")
        summary = convert(tmp_path / f"bvh_{name}", tmp_path / name, "auto", "xia", progress=False)
        assert summary["failed"] == 0
    clips = R.read_clips(tmp_path / "train")
    by_style = {s: C.cue_table([w for r, j in clips if r["style"] == s for w in R.windows(j, R.CUE_WINDOW)])
                for s in ("neutral", "old")}
    neutral, old = (np.nanmean(by_style[s], 0) for s in ("neutral", "old"))
    i = {c: k for k, c in enumerate(C.CUES)}
    assert 1.8 < neutral[i["head_height"]] < 2.05 and 0.8 < neutral[i["speed"]] < 2.0  # a person walking
    assert 1.2 < neutral[i["cadence"]] < 2.4 and neutral[i["jerk"]] < 200
    assert old[i["trunk_pitch"]] > neutral[i["trunk_pitch"]] + 10 and old[i["head_ahead"]] > neutral[i["head_ahead"]]
    report = R.realism_report(tmp_path / "train", tmp_path / "grid", builtin=built, progress=False)
    assert report["real_to_builtin"]["real_test_windows"]["accuracy"] >= 75  # old vs neutral is easy on real data
    assert report["builtin_to_real"]["real_test_takes"]["n"] == 4


@pytest.mark.parametrize("name, remake", [
    ("00_realism.json", "python -m mslib data realism … --out notebooks/data/00_realism.json"),
    ("00_realism_gap.json", "python tools/realism_gap.py --real XIA_TRAIN_DIR --force")])
def test_the_stored_report_is_of_this_generator_and_names_no_machine_paths(name, remake):
    """notebooks/data/00_realism.json (notebook 00 reads it) and the gap diagnosis: remade whenever the generator changes."""
    from mslib.data.corpora import source_fingerprint
    from mslib.data.synth import GENERATOR_VERSION
    from mslib.notebook import FINDINGS_DIR
    text = (FINDINGS_DIR / name).read_text(encoding="utf-8")
    report = json.loads(text)
    assert report["builtin"]["fingerprint"] == source_fingerprint(), f"the generator changed since {name} was made: {remake}"
    assert report["builtin"]["generator_version"] == GENERATOR_VERSION
    assert "/work/" not in text and "/tmp/" not in text and "/home/" not in text
    if name == "00_realism.json":
        assert report["command"].startswith("python -m mslib data realism --real ")
        assert {"real_to_builtin", "builtin_to_real", "builtin_linear_to_real", "cues"} <= set(report)
    else:  # the first row is the report's own real → built-in score (same judge, same windows)
        assert report["command"].startswith("python tools/realism_gap.py --real ")
        stored = json.loads((FINDINGS_DIR / "00_realism.json").read_text(encoding="utf-8"))
        assert report["rows"][0]["all"] == pytest.approx(stored["real_to_builtin"]["builtin_test_windows"]["accuracy"], abs=0.05)
