"""`python -m mslib transfer`: inputs (clip ids, .npy, .bvh), outputs (.bvh round trip, .npy, .gif), errors."""
import json
import shutil
import subprocess

import numpy as np
import pytest

from mslib.cli import main
from mslib.data.dataset_folder import read_labels
from mslib.evaluation.bench import loop_features
from mslib.evaluation.transfer_io import builtin_folders, load_motion
from mslib.motion import features as F
from mslib.motion.bvh import read_bvh
from mslib.motion.skeleton import JOINT_NAMES

CM = 0.01


@pytest.fixture(scope="module")
def clips():
    """(content test clip id, style test clip id) of the built-in corpora."""
    folders = builtin_folders()
    pick = {k: next(r["clip_id"] for r in read_labels(f) if r["split"] == "test") for k, f in folders.items()}
    return pick["content"], pick["style"]


def transfer(tmp_path, capsys, *args):
    """Run the command with --json; (exit status, summary or None, stderr)."""
    rc = main(["transfer", *map(str, args), "--json"])
    cap = capsys.readouterr()
    return rc, (json.loads(cap.out.strip().splitlines()[-1]) if rc == 0 else None), cap.err


def bvh_positions(path) -> np.ndarray:
    """Template-ordered joint positions (T, 22, 3) of a BVH file: the project's reader + FK."""
    m = read_bvh(path)
    return m.global_positions()[:, [m.skeleton.names.index(n) for n in JOINT_NAMES]]


def max_error(a, b) -> float:
    return float(np.linalg.norm(np.asarray(a) - np.asarray(b), axis=-1).max())


# ---------------------------------------------------------------- .bvh
def test_bvh_round_trip_builtin_clip(tmp_path, capsys, clips):
    content_id, style_id = clips
    out = tmp_path / "out.bvh"
    rc, summary, _ = transfer(tmp_path, capsys, "--method", "identity", "--content", content_id,
                              "--style", style_id, "--out", out)
    assert rc == 0 and summary["kind"] == "bvh" and summary["units"] == "m"
    expected = load_motion(content_id)["joints"][:-1]  # a method returns features: all but the last frame
    assert max_error(bvh_positions(out), expected) < 1 * CM
    text = out.read_text()
    assert text.startswith("HIERARCHY\nROOT pelvis\n") and "\nMOTION\nFrames: %d\nFrame Time: 0.05\n" % len(expected) in text
    assert text.count("CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation") == 1
    assert text.count("CHANNELS 3 Zrotation Yrotation Xrotation") == 21 and text.count("End Site") == 5


def test_bvh_round_trip_of_a_method_output(tmp_path, capsys, clips):
    content_id, style_id = clips
    out = tmp_path / "out.bvh"
    rc, summary, _ = transfer(tmp_path, capsys, "--method", "copy_style", "--content", content_id,
                              "--style", style_id, "--out", out)
    assert rc == 0
    c, s = load_motion(content_id), load_motion(style_id)
    expected = F.decode(loop_features(s["features"], len(c["features"])))  # what copy_style returns
    assert max_error(bvh_positions(out), expected) < 1 * CM
    assert summary["frames"] == len(expected) and summary["bvh_fit_error_cm"] < 1


def test_bvh_round_trip_real_humanml3d(tmp_path, capsys, shared_data, clips):
    hml = shared_data / "humanml3d"
    positions = np.load(hml / "new_joints" / "012314.npy")
    for name, src in (("pos.bvh", hml / "new_joints" / "012314.npy"), ("vec.bvh", hml / "new_joint_vecs" / "012314.npy")):
        rc, summary, err = transfer(tmp_path, capsys, "--method", "identity", "--content", src,
                                    "--style", clips[1], "--out", tmp_path / name)
        assert rc == 0, err
        back = bvh_positions(tmp_path / name)
        n = min(len(back), len(positions))  # features give the positions of all but the last frame
        assert n >= len(positions) - 1 and max_error(back[:n], positions[:n]) < 1 * CM
    # the written BVH is an input too: auto dialect, registration, the same motion back
    again = load_motion(tmp_path / "pos.bvh", "--content")
    assert again["joints"].shape == positions[:-1].shape and max_error(again["joints"], positions[:-1]) < 1 * CM


BLENDER_SCRIPT = """
import builtins, json, sys
import bpy
import io_anim_bvh.import_bvh as importer
# Debian's Blender 3.4 opens the file with mode "rU", which Python 3.11 no longer accepts
importer.open = lambda f, mode="r", *a, **k: builtins.open(f, mode.replace("U", ""), *a, **k)
path, out, n = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_anim.bvh(filepath=path, global_scale=1.0, frame_start=1, use_fps_scale=False,
                        rotate_mode="NATIVE", axis_forward="-Z", axis_up="Y")
arm = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"][0]
frames = []
for f in range(1, int(n) + 1):
    bpy.context.scene.frame_set(f)
    frames.append({b.name: list(arm.matrix_world @ b.head) for b in arm.pose.bones})
json.dump(frames, open(out, "w"))
"""


@pytest.mark.skipif(shutil.which("blender") is None, reason="Blender is not installed (apt-get install blender)")
def test_blender_imports_the_bvh(tmp_path, capsys, clips):
    """Blender's own BVH importer (Z up) gives back the joint positions, so the file opens in Blender."""
    out = tmp_path / "out.bvh"
    assert transfer(tmp_path, capsys, "--method", "identity", "--content", clips[1], "--style", clips[1],
                    "--out", out)[0] == 0
    expected = load_motion(clips[1])["joints"]
    (tmp_path / "read.py").write_text(BLENDER_SCRIPT)
    subprocess.run(["blender", "-b", "--factory-startup", "--python", str(tmp_path / "read.py"), "--",
                    str(out), str(tmp_path / "pose.json"), str(len(expected))],
                   check=True, capture_output=True, timeout=300)
    frames = json.loads((tmp_path / "pose.json").read_text())
    heads = np.array([[f[name] for name in JOINT_NAMES] for f in frames])  # Blender: X, −Z(bvh), Y(bvh)
    got = np.stack([heads[..., 0], heads[..., 2], -heads[..., 1]], -1)
    assert max_error(got, expected) < 1 * CM


# ---------------------------------------------------------------- .npy, .gif
def test_npy_output_is_the_263d_vector(tmp_path, capsys, clips):
    content_id, style_id = clips
    rc, summary, _ = transfer(tmp_path, capsys, "--method", "identity", "--content", content_id,
                              "--style", style_id, "--out", tmp_path / "o.npy")
    feats = np.load(tmp_path / "o.npy")
    joints = load_motion(content_id)["joints"]
    assert rc == 0 and feats.shape == (len(joints) - 1, 263) == tuple(summary["shape"])
    assert max_error(F.decode(feats.astype(np.float64)), joints[:-1]) < 1e-3


def test_npy_inputs_features_and_positions(tmp_path, capsys, clips):
    # a content clip, whose lowest joint is on the floor: a positions .npy is floored on loading, and a style
    # window keeps its take's floor (its lowest joint may be a millimetre above it)
    m = load_motion(clips[0])
    np.save(tmp_path / "f.npy", m["features"].astype(np.float32))
    np.save(tmp_path / "p.npy", m["joints"].astype(np.float32))
    for name in ("f.npy", "p.npy"):
        got = load_motion(tmp_path / name, "--style")
        assert len(got["joints"]) == len(got["features"]) + 1 and got["clip_id"] == name[0]
        n = len(got["features"])
        np.testing.assert_allclose(got["features"], m["features"][:n], atol=1e-5)
        assert max_error(got["joints"][:n], m["joints"][:n]) < 1e-3


def test_gif_output(tmp_path, capsys, clips):
    from PIL import Image
    np.save(tmp_path / "short.npy", load_motion(clips[1])["joints"][:12])  # a short clip keeps it quick
    rc, summary, _ = transfer(tmp_path, capsys, "--method", "identity", "--content", tmp_path / "short.npy",
                              "--style", clips[1], "--out", tmp_path / "o.gif")
    assert rc == 0 and summary["frames"] == 11  # 12 positions → 11 feature rows → 11 frames
    with Image.open(tmp_path / "o.gif") as im:
        assert im.format == "GIF" and im.is_animated and im.n_frames == summary["frames"]


# ---------------------------------------------------------------- --force and errors
def test_refuses_to_overwrite_without_force(tmp_path, capsys, clips):
    out = tmp_path / "o.bvh"
    out.write_bytes(b"keep me")
    args = ("--method", "identity", "--content", clips[0], "--style", clips[1], "--out", out)
    rc, _, err = transfer(tmp_path, capsys, *args)
    assert rc == 2 and "--out" in err and "--force" in err and out.read_bytes() == b"keep me"
    rc, _, _ = transfer(tmp_path, capsys, *args, "--force")
    assert rc == 0 and read_bvh(out).n_frames > 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.bvh"]  # no temporary files left


@pytest.mark.parametrize("change, words", [
    ({"--content": "no_such_clip"}, ["--content", "no_such_clip", "labels.csv"]),
    ({"--style": "BAD_NPY"}, ["--style", "(10, 22)", "263"]),
    ({"--content": "motion.csv"}, ["--content", ".npy", ".bvh"]),
    ({"--style": "missing.bvh"}, ["--style", "no such file"]),
    ({"--out": "o.txt"}, ["--out", ".txt", ".bvh, .npy, .gif"]),
    ({"--method": "no_such_method"}, ["--method", "no_such_method", "identity", "copy_style"]),
])
def test_errors_name_the_argument(tmp_path, capsys, clips, change, words):
    np.save(tmp_path / "bad.npy", np.zeros((10, 22)))
    args = {"--method": "identity", "--content": clips[0], "--style": clips[1], "--out": "o.bvh", **change}
    args = {k: (str(tmp_path / "bad.npy") if v == "BAD_NPY" else str(tmp_path / v) if k == "--out"
                or v.endswith((".bvh", ".csv")) else v) for k, v in args.items()}
    rc, _, err = transfer(tmp_path, capsys, *[x for kv in args.items() for x in kv])
    assert rc == 2 and all(w in err for w in words), err
    assert not (tmp_path / "o.bvh").exists()
