"""data_prep converters: BVH folders and HumanML3D folders → dataset folders."""
import json
import shutil

import numpy as np
import pytest

from data_prep import bvh as prep_bvh
from data_prep import humanml3d as prep_h3d
from mslib.data.dataset_folder import read_labels, read_meta
from mslib.motion import features as F
from mslib.motion import skeleton as sk


@pytest.fixture(scope="module")
def xia_folder(tmp_path_factory, shared_data):
    """The 40 Xia clips converted once with the named dialect."""
    out = tmp_path_factory.mktemp("xia") / "out"
    summary = prep_bvh.convert(shared_data / "xia_grid", out, dialect="xia", labels="xia", progress=False)
    assert summary["converted"] == 40 and summary["failed"] == 0
    return out


def test_bvh_folder_converts_with_labels(xia_folder):
    rows = read_labels(xia_folder)
    meta = read_meta(xia_folder)
    assert len(rows) == 40 and meta["fps"] == 20 and meta["n_clips"] == 40
    assert {r["content"] for r in rows} == {"walk", "run", "jump", "punch", "kick"}
    assert {r["style"] for r in rows} == {"angry", "childlike", "depressed", "neutral", "old", "proud", "sexy", "strutting"}
    assert any(r["caption"] == "an old person walks" for r in rows)
    for r in rows[:5]:
        j = np.load(xia_folder / "joints" / f"{r['clip_id']}.npy")
        f = np.load(xia_folder / "features" / f"{r['clip_id']}.npy")
        assert j.dtype == np.float32 and f.shape == (len(j) - 1, 263) and int(r["n_frames"]) == len(j)
        bones = sk.positions_bone_lengths(j, sk.PARENTS)[:, 1:]
        assert np.abs(bones - sk.REFERENCE_BONE_LENGTHS).max() < 1e-4
    assert np.load(xia_folder / "mean.npy").shape == (263,)


def test_auto_dialect_gives_the_same_folder(tmp_path, xia_folder, shared_data):
    out = tmp_path / "auto"
    prep_bvh.convert(shared_data / "xia_grid", out, dialect="auto", labels="xia", progress=False)
    for r in read_labels(xia_folder)[:8]:
        a = np.load(out / "joints" / f"{r['clip_id']}.npy")
        np.testing.assert_array_equal(a, np.load(xia_folder / "joints" / f"{r['clip_id']}.npy"))


def test_refuses_non_empty_output_and_resumes_with_force(tmp_path, shared_data):
    src = tmp_path / "in"
    src.mkdir()
    for f in sorted((shared_data / "xia_grid").glob("*.bvh"))[:3]:
        shutil.copy(f, src / f.name)
    (src / "broken.bvh").write_text("HIERARCHY\nROOT Hips\n{\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    with pytest.raises(ValueError, match="not empty"):
        prep_bvh.convert(src, out, progress=False)
    s = prep_bvh.convert(src, out, force=True, windows=True, progress=False)
    assert s["converted"] == 3 and s["failed"] == 1 and "broken.bvh" in s["failures"]
    assert (out / "keep.txt").read_text() == "mine"
    wins = [r for r in read_labels(out)]
    assert all(int(r["n_frames"]) == 32 for r in wins) and len(wins) == 2  # 60 frames → 2 windows
    assert len(s["too_short"]) == 2  # the 24- and 27-frame clips hold no 32-frame window
    again = prep_bvh.convert(src, out, force=True, windows=True, progress=False)
    assert again["skipped"] == 1 and len(read_labels(out)) == 2
    assert prep_bvh.main([str(src), str(tmp_path / "o2"), "--json"]) == 1  # a failed file → exit 1


def test_bad_arguments(tmp_path):
    with pytest.raises(ValueError, match="no such folder"):
        prep_bvh.convert(tmp_path / "missing", tmp_path / "o")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="no .bvh"):
        prep_bvh.convert(tmp_path / "empty", tmp_path / "o")
    with pytest.raises(ValueError, match="regex"):
        prep_bvh.label_rule("(unclosed")


def test_humanml3d_folder_is_indexed_by_links(tmp_path, shared_data):
    src = tmp_path / "HumanML3D"
    for sub in ("new_joint_vecs", "new_joints", "texts"):
        (src / sub).mkdir(parents=True)
    for sub in ("new_joint_vecs", "new_joints"):
        (src / sub / "012314.npy").symlink_to(shared_data / "humanml3d" / sub / "012314.npy")
    np.save(src / "new_joint_vecs" / "bad.npy", np.zeros((5, 200), np.float32))
    (src / "texts" / "012314.txt").write_text("a person walks in a circle#a/DET#0.0#0.0\n")
    (src / "test.txt").write_text("012314\n")
    for name in ("Mean.npy", "Std.npy"):
        (src / name).symlink_to(shared_data / "humanml3d" / name)
    out = tmp_path / "out"
    s = prep_h3d.convert(src, out, progress=False)
    assert s["clips"] == 1 and "bad" in s["problems"]
    rows = read_labels(out)
    assert rows[0]["split"] == "test" and rows[0]["caption"] == "a person walks in a circle"
    assert (out / "features" / "012314.npy").is_symlink()
    f = np.load(out / "features" / "012314.npy")
    np.testing.assert_allclose(F.decode(f), np.load(out / "joints" / "012314.npy"), atol=1e-4)
    assert F.Normalizer.load(out).mean.shape == (263,)
    assert json.loads((out / "meta.json").read_text())["format_version"] == 1
    with pytest.raises(ValueError, match="not empty"):
        prep_h3d.convert(src, out, progress=False)
    with pytest.raises(ValueError, match="new_joint_vecs"):
        prep_h3d.convert(tmp_path, tmp_path / "o3", progress=False)
