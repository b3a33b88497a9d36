"""`python -m mslib` commands: features encode/decode, bvh info, errors and --json."""
import json
import subprocess
import sys

import numpy as np
import pytest

from mslib.cli import main
from mslib.motion import features as F
from tests.test_features import synthetic_motion


def test_features_encode_decode_round_trip(tmp_path, capsys):
    pos = synthetic_motion(T=30).astype(np.float32)
    np.save(tmp_path / "pos.npy", pos)
    assert main(["features", "encode", str(tmp_path / "pos.npy"), str(tmp_path / "f.npy"), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["output_shape"] == [29, 263]
    assert main(["features", "decode", str(tmp_path / "f.npy"), str(tmp_path / "p.npy")]) == 0
    back = np.load(tmp_path / "p.npy")
    np.testing.assert_allclose(back, pos[:-1], atol=1e-4)
    np.testing.assert_allclose(np.load(tmp_path / "f.npy"), F.encode(pos), atol=1e-6)


def test_never_overwrites_without_force(tmp_path, capsys):
    np.save(tmp_path / "pos.npy", synthetic_motion(T=10))
    out = tmp_path / "f.npy"
    out.write_bytes(b"keep me")
    assert main(["features", "encode", str(tmp_path / "pos.npy"), str(out)]) == 2
    assert "already exists" in capsys.readouterr().err and out.read_bytes() == b"keep me"
    assert main(["features", "encode", str(tmp_path / "pos.npy"), str(out), "--force"]) == 0
    assert np.load(out).shape == (9, 263)
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


@pytest.mark.parametrize("array, action, match", [
    (np.zeros((5, 262), np.float32), "decode", "263"),
    (np.zeros((1, 22, 3), np.float32), "encode", "2 frames"),
    (np.full((4, 22, 3), np.nan, np.float32), "encode", "NaN"),
])
def test_bad_arrays_name_the_file(tmp_path, capsys, array, action, match):
    src = tmp_path / "bad.npy"
    np.save(src, array)
    assert main(["features", action, str(src), str(tmp_path / "out.npy")]) == 2
    err = capsys.readouterr().err
    assert str(src) in err and match in err
    assert not (tmp_path / "out.npy").exists()


def test_missing_and_corrupt_inputs(tmp_path, capsys):
    assert main(["features", "encode", str(tmp_path / "nope.npy"), str(tmp_path / "o.npy")]) == 2
    assert "no such file" in capsys.readouterr().err
    (tmp_path / "junk.npy").write_bytes(b"not an array")
    assert main(["features", "encode", str(tmp_path / "junk.npy"), str(tmp_path / "o.npy")]) == 2
    assert "junk.npy" in capsys.readouterr().err


def test_module_entry_point_help():
    out = subprocess.run([sys.executable, "-m", "mslib", "--help"], capture_output=True, text=True)
    assert out.returncode == 0 and "features" in out.stdout and "bvh" in out.stdout


def test_bvh_info_json_and_text(shared_data, capsys):
    f = shared_data / "xia_grid" / "neutral_01_000.bvh"
    assert main(["bvh", "info", str(f), "--json"]) == 0
    info = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert info["n_joints"] == 31 and abs(info["fps"] - 120) < 0.01 and info["joints"][0] == "Hips"
    assert main(["bvh", "info", str(f)]) == 0
    assert "n_frames" in capsys.readouterr().out


def test_bvh_info_on_a_broken_file(tmp_path, capsys):
    bad = tmp_path / "broken.bvh"
    bad.write_text("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n")
    assert main(["bvh", "info", str(bad)]) == 2
    assert "broken.bvh" in capsys.readouterr().err


def test_train_on_a_folder_converted_from_xia(shared_data, tmp_path, capsys):
    from data_prep import bvh as prep_bvh
    folder = tmp_path / "xia"
    prep_bvh.convert(shared_data / "xia_grid", folder, dialect="auto", labels="xia", windows=True, progress=False)
    out = tmp_path / "style.pt"
    assert main(["train", "evaluator_style", "--style", str(folder), "--content", str(folder),
                 "--steps", "30", "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["steps"] == 30 and out.is_file() and 0 <= summary["test_acc"] <= 100
    from mslib.evaluation.evaluator import load_classifier
    styles = {"angry", "childlike", "depressed", "neutral", "old", "proud", "sexy", "strutting"}
    assert 2 <= len(load_classifier("style", out).classes) and set(load_classifier("style", out).classes) <= styles


def test_train_unknown_model_lists_the_known_ones(capsys):
    assert main(["train", "nope", "--content", "x", "--style", "y"]) == 2
    assert "evaluator_style" in capsys.readouterr().err
