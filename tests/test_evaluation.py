"""The evaluator's classifiers and the bench runner (independent of every method)."""
import numpy as np
import pytest
import torch

from mslib.data.dataset_folder import DatasetWriter
from mslib.evaluation import bench
from mslib.evaluation import evaluator as E
from mslib.motion import features as F
from mslib.motion import rotations as rot
from mslib.motion.skeleton import mirror_positions
from tests.test_features import synthetic_motion


def test_classifier_input_ignores_where_the_motion_is():
    p = synthetic_motion(T=40)
    moved = p + np.array([2.0, 0.0, -3.0])
    np.testing.assert_allclose(E.classifier_input(moved), E.classifier_input(p), atol=1e-9)
    turned = p @ rot.axis_angle_to_matrix(np.array([0, 1.2, 0])).T
    # frames 1.. are in the body's facing frame (frame 0 is the identity by the vector's convention)
    np.testing.assert_allclose(E.classifier_input(turned)[1:], E.classifier_input(p)[1:], atol=1e-6)
    x = E.classifier_input(p)
    assert x.shape == (40, 64)
    np.testing.assert_allclose(x[:-1, 1:], F.encode(p)[:, F.BLOCKS["ric"]], atol=1e-6)


def test_windows_cover_short_and_long_sequences():
    assert E.windows_of(np.zeros((10, 64))).shape == (1, 32, 64)
    w = E.windows_of(np.arange(70)[:, None] * np.ones((1, 64)))
    assert w.shape[1:] == (32, 64) and w[0, 0, 0] == 0 and w[-1, -1, 0] == 69


def test_replay_at_changes_the_tempo_and_keeps_the_path():
    x = np.arange(41, dtype=float)[:, None] * np.ones((1, 3))
    fast, slow = E.replay_at(x, 2.0), E.replay_at(x, 0.5)
    assert len(fast) == 20 and len(slow) == 82
    for y in (fast, slow):  # the same straight path, end to end, at another speed
        assert y[0, 0] == 0 and y[-1, 0] == 40 and np.all(np.diff(y[:, 0]) > 0)
    np.testing.assert_allclose(E.replay_at(x, 1.0), x)
    assert E.replay_at(x[:1], 0.5).shape == (2, 3)  # a single frame is held


def test_augmented_windows_mirror_replay_and_add_noise():
    p = synthetic_motion(T=60)
    p[:, 16::2, 0] += 0.3  # the left arm held out to the side: mirroring must move it to the right
    plain = E.WindowDataset([p], [0], seed=0)
    mirrored = E.WindowDataset([p], [0], seed=0, augment=E.Augment(mirror=1.0))
    np.testing.assert_allclose(mirrored.mirrored[0], E.classifier_input(mirror_positions(p)), atol=1e-5)
    assert not np.allclose(mirrored.mirrored[0], plain.inputs[0], atol=1e-3)
    noisy = E.WindowDataset([p], [0], seed=0, augment=E.Augment(noise=0.5))
    w_plain, w_noisy = plain[0][0].numpy(), noisy[0][0].numpy()
    assert w_noisy.shape == w_plain.shape == (32, 64) and not np.allclose(w_noisy, w_plain)
    tempo = E.WindowDataset([p], [0], seed=3, augment=E.Augment(tempo=1.0))
    assert tempo[0][0].shape == (32, 64)
    with pytest.raises(ValueError, match="augment"):
        E.Augment(mirror=1.5)


def toy_folder(path, n_per=12):
    """Two 'styles' with an obvious difference (arms raised or not), three splits."""
    writer = DatasetWriter(path, name="toy", source="test")
    for k in range(3 * n_per):
        for style, lift in (("calm", 0.0), ("wild", 1.0)):
            p = synthetic_motion(T=40, seed=k)
            p[:, 16:22, 1] += lift  # the whole arms raised by a metre
            split = ("train", "val", "test")[k % 3]
            writer.add(f"{style}{k:02d}", p, F.encode(p), split, style=style, content="walk")
    writer.close()
    return path


def test_train_classifier_learns_and_checkpoints(tmp_path):
    folder = toy_folder(tmp_path / "toy")
    model, history = E.train_classifier("style", folder, seed=0, out=tmp_path / "s.pt", progress=False,
                                        steps=200, batch_size=16, val_every=100)
    assert model.classes == ["calm", "wild"] and history["step"][-1] == 200
    assert E.test_accuracy(model, folder, "test") == 100.0
    again = E.load_classifier("style", tmp_path / "s.pt")
    logits, feats = again.score([synthetic_motion(T=50)])
    assert logits.shape == (1, 2) and feats.shape == (1, 128)
    ref_logits, _ = model.score([synthetic_motion(T=50)])
    np.testing.assert_allclose(logits, ref_logits, atol=1e-5)
    with pytest.raises(ValueError, match="expected 'evaluator_content'"):
        E.load_classifier("content", tmp_path / "s.pt")
    with pytest.raises(ValueError, match="kind"):
        E.train_classifier("mood", folder)


def test_train_classifier_net_sizes_reach_the_checkpoint(tmp_path):
    folder = toy_folder(tmp_path / "toy")
    model, _ = E.train_classifier("style", folder, seed=0, out=tmp_path / "n.pt", progress=False, steps=20,
                                  batch_size=16, val_every=10, net={"width": 16, "feature_dim": 8, "dropout": 0.5})
    again = E.load_classifier("style", tmp_path / "n.pt")
    assert (again.cfg.width, again.cfg.feature_dim, again.cfg.dropout) == (16, 8, 0.5)
    assert again.score([synthetic_motion(T=50)])[1].shape == (1, 8)
    with pytest.raises(ValueError, match=r"net: \['depth'\] cannot be changed"):
        E.train_classifier("style", folder, net={"depth": 3})


def test_unknown_method_lists_the_known_ones():
    with pytest.raises(ValueError, match="known methods: .*copy_style.*identity"):
        bench.get_method("nope")


def test_reference_rows_do_what_they_say():
    content = {"features": F.encode(synthetic_motion(T=61)), "joints": synthetic_motion(T=61)}
    style_pos = synthetic_motion(T=33, seed=5)
    style = {"features": F.encode(style_pos), "joints": style_pos}
    out = bench.get_method("identity")(content, style)
    np.testing.assert_array_equal(out, content["features"])  # every method returns features
    np.testing.assert_allclose(bench.positions(out), content["joints"][:-1], atol=1e-5)
    copied = bench.positions(bench.get_method("copy_style")(content, style))
    assert copied.shape == (60, 22, 3)
    # its first 32 frames are the style motion itself (decoded from its own vector)
    np.testing.assert_allclose(copied[:32], F.decode(style["features"]), atol=1e-5)
    assert len(bench.loop_features(np.arange(5)[:, None], 12)) == 12


def test_by_style_known_answers():
    """Per-style SRA, CRA and the style most outputs are read as, from a stand-in evaluator's logits."""
    class Stub:  # reads output k as style read[k] and content cread[k]
        style = type("C", (), {"classes": ["calm", "proud", "sexy"]})
        content = type("C", (), {"classes": ["jump", "walk"]})

        def score(self, outputs):
            eye_s, eye_c = np.eye(3), np.eye(2)
            return eye_c[[o[1] for o in outputs]], eye_s[[o[0] for o in outputs]], None

    # (style read, content read) per output; pairs: 3 × proud, 2 × sexy
    outputs = [(1, 1), (1, 0), (0, 1), (1, 1), (0, 0)]
    pairs = [({"content": "walk"}, {"style": "proud"})] * 3 + [({"content": "jump"}, {"style": "sexy"})] * 2
    rows = bench.by_style(outputs, pairs, Stub())
    assert [r["style"] for r in rows] == ["proud", "sexy"] and [r["n"] for r in rows] == [3, 2]
    proud, sexy = rows
    assert proud["sra"] == pytest.approx(200 / 3) and proud["cra"] == pytest.approx(200 / 3)
    assert (proud["read_as"], proud["read_as_share"]) == ("proud", pytest.approx(200 / 3))
    assert sexy["sra"] == 0.0 and sexy["cra"] == 50.0
    assert (sexy["read_as"], sexy["read_as_share"]) == ("calm", 50.0)  # a tie goes to the first name: calm, proud
    with pytest.raises(ValueError, match="one per pair"):
        bench.by_style(outputs[:2], pairs, Stub())
    # the same outputs per content, and a sixth pair whose content the classifier does not know
    rows = bench.by_content(outputs + [(2, 1)], pairs + [({"content": ""}, {"style": "sexy"})], Stub())
    assert [r["content"] for r in rows] == ["jump", "walk"] and [r["n"] for r in rows] == [2, 3]
    jump, walk = rows
    assert jump["cra"] == 50.0 and jump["sra"] == 0.0 and (jump["read_as"], jump["read_as_share"]) == ("jump", 50.0)
    assert walk["cra"] == pytest.approx(200 / 3) and (walk["read_as"], walk["read_as_share"]) == ("walk", pytest.approx(200 / 3))
    named = [({**c, "clip_id": k}, s) for (c, s), k in zip(pairs + [({"content": ""}, {"style": "sexy"})],
                                                         ["w1", "w1", "w2", "j1", "j1", "x"])]
    rows = bench.by_content_clip(outputs + [(2, 1)], named, Stub())
    assert [(r["clip"], r["content"], r["n"]) for r in rows] == [("w1", "walk", 2), ("w2", "walk", 1),
                                                                 ("j1", "jump", 2), ("x", "", 1)]
    assert [r["cra"] for r in rows] == [50.0, 100.0, 50.0, None]  # no label the classifier knows: no CRA
    assert rows[1]["read_as"] == "walk" and rows[3]["read_as"] == "walk" and rows[3]["sra"] == 100.0
    # given the outputs' scores, every breakdown and the row read them instead of scoring again
    calls = []

    class Counting(Stub):
        def score(self, outputs):
            calls.append(len(outputs))
            return super().score(outputs)
    ev = Counting()
    scored = ev.score(outputs)
    for breakdown in (bench.by_style, bench.by_content):
        assert breakdown(outputs, pairs, ev, scored) == breakdown(outputs, pairs, Stub())
    assert calls == [5]


# ---------------------------------------------------------------- the packaged evaluator on the built-in data
@pytest.fixture(scope="module")
def builtin():
    from mslib.data.corpora import load_builtin
    return load_builtin(seed=0, progress=False)


def test_packaged_classifiers_reach_the_bar(builtin):
    style = E.load_classifier("style")
    content = E.load_classifier("content")
    assert len(style.classes) == 8 and len(content.classes) >= 8
    assert E.test_accuracy(style, builtin["style"]) >= 95.0
    assert E.test_accuracy(content, builtin["content"]) >= 95.0


def test_bench_json_row_and_calibration(builtin, capsys):
    import json
    from mslib.cli import main
    assert main(["bench", "--method", "identity", "--pairs", "40", "--json"]) == 0
    row = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert tuple(sorted(row)) == tuple(sorted(bench.JSON_KEYS)) and row["pairs"] == 40
    assert row["cra"] >= 95 and row["tsi"] < 1e-6 and 0 <= row["h"] <= 1
    assert main(["bench", "--method", "copy_style", "--pairs", "40", "--json"]) == 0
    copy = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert copy["sra"] >= 90 and copy["cra"] < 50 and copy["tsi"] > 0.5
    other = bench.load_pairs(seed=1, n_pairs=40)
    same = bench.load_pairs(seed=0, n_pairs=40)
    assert [c["clip_id"] for c, _ in same] != [c["clip_id"] for c, _ in other]
    assert main(["bench", "--method", "nope"]) == 2
    assert "known methods" in capsys.readouterr().err
