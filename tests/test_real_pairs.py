"""The benchmark on real pairs (mslib.evaluation.real_pairs, `bench --real-style`): which pairs, drawn how,
and, with ../shared/data, the command on the real Xia grid and HumanML3D-format motions."""
import json
from collections import Counter

import numpy as np
import pytest

from mslib.cli import main
from mslib.data.dataset_folder import DatasetWriter
from mslib.data.synth import generate_clip
from mslib.evaluation import real_pairs as RP
from mslib.motion.features import encode

STYLES = ("neutral", "angry", "old")
CONTENTS = ("walk", "run")


@pytest.fixture(scope="module")
def grid(tmp_path_factory):
    """A tiny 'grid': three styles × two contents, one take each, as data_prep would write it."""
    path = tmp_path_factory.mktemp("real") / "grid"
    w = DatasetWriter(path, name="grid", source="test")
    for s in STYLES:
        for k, c in enumerate(CONTENTS):
            p = generate_clip(c, s, seed=1, index=k, duration=1.5).positions
            w.add(f"{s}_{c}", p, encode(p), "test", style=s, content=c, source_file=f"{s}_{c}.bvh")
    w.close()
    return path


@pytest.fixture(scope="module")
def long_walk(tmp_path_factory):
    """A 263-d .npy content longer than MAX_FRAMES rows."""
    p = generate_clip("walk", "neutral", seed=2, index=0, duration=12.0).positions
    path = tmp_path_factory.mktemp("files") / "long_walk.npy"
    np.save(path, encode(p).astype(np.float32))
    return path


def test_every_content_meets_every_style_but_itself(grid, long_walk):
    pairs = RP.real_pairs(grid, [f"{long_walk}=walk"])
    contents = {c["clip_id"] for c, _ in pairs}
    assert contents == {"neutral_walk", "neutral_run", "long_walk"}  # the neutral takes, then the files
    n_styles = len(STYLES) * len(CONTENTS)
    assert len(pairs) == 3 * n_styles - 2  # a neutral take is not its own style reference
    assert all(c["clip_id"] != s["clip_id"] for c, s in pairs)
    assert Counter(s["clip_id"] for _, s in pairs)["angry_walk"] == 3
    walk = next(c for c, _ in pairs if c["clip_id"] == "long_walk")
    assert walk["content"] == "walk" and walk["style"] == ""
    assert walk["features"].shape == (RP.MAX_FRAMES, 263) and len(walk["joints"]) == RP.MAX_FRAMES + 1


def test_a_draw_takes_styles_in_turn_without_repeats_and_is_reproducible(grid):
    everything = RP.real_pairs(grid)
    a, b = RP.real_pairs(grid, n_pairs=6, seed=1), RP.real_pairs(grid, n_pairs=6, seed=1)
    ids = lambda ps: [(c["clip_id"], s["clip_id"]) for c, s in ps]  # noqa: E731
    assert ids(a) == ids(b) and ids(a) != ids(RP.real_pairs(grid, n_pairs=6, seed=2))
    assert [s["style"] for _, s in a] == sorted(STYLES) * 2  # styles in turn, by name
    assert len(set(ids(a))) == 6 and set(ids(a)) <= set(ids(everything))
    assert len(RP.real_pairs(grid, n_pairs=10 ** 6)) == len(everything)


def test_a_split_keeps_only_its_takes(tmp_path):
    """`split` pairs the takes of one split among themselves: the held-out takes of a folder stay held out."""
    path = tmp_path / "two_splits"
    w = DatasetWriter(path, name="two_splits", source="test")
    for k, (s, split) in enumerate([("neutral", "train"), ("angry", "train"), ("neutral", "test"), ("old", "test")]):
        p = generate_clip("walk", s, seed=3, index=k, duration=1.5).positions
        w.add(f"{s}_{split}", p, encode(p), split, style=s, content="walk", source_file=f"{s}_{split}.bvh")
    w.close()
    pairs = RP.real_pairs(path, split="test")
    assert [(c["clip_id"], s["clip_id"]) for c, s in pairs] == [("neutral_test", "old_test")]
    assert len(RP.real_pairs(path)) == 2 * 4 - 2
    with pytest.raises(ValueError, match=r"no clip of the val split has a style label"):
        RP.real_pairs(path, split="val")


def test_bad_inputs_name_the_argument(grid, tmp_path):
    with pytest.raises(ValueError, match=r"--real-style .*nope: no such folder"):
        RP.real_pairs(tmp_path / "nope")
    with pytest.raises(ValueError, match=r"--real-content 'x.txt': expected a .npy or .bvh"):
        RP.real_pairs(grid, ["x.txt"])
    with pytest.raises(ValueError, match=r"--real-content .*missing.npy"):
        RP.real_pairs(grid, [str(tmp_path / "missing.npy")])
    assert RP.parse_content_spec("a/b.npy=jump") == (RP.Path("a/b.npy"), "jump")
    assert main(["bench", "--method", "identity", "--real-content", "x.npy"]) == 2
    assert main(["bench", "--method", "identity", "--real-style", str(grid), "--content", str(grid)]) == 2


def test_cli_scores_the_real_pairs(grid, capsys):
    assert main(["bench", "--method", "identity,copy_style", "--real-style", str(grid), "--json"]) == 0
    rows = {r["method"]: r for r in map(json.loads, capsys.readouterr().out.strip().splitlines())}
    n = len(STYLES) * len(CONTENTS) * 2 - 2
    assert rows["identity"]["pairs"] == rows["copy_style"]["pairs"] == n
    assert rows["identity"]["tsi"] < 1e-6 and rows["copy_style"]["tsi"] > 0.1
    assert rows["copy_style"]["sra"] > rows["identity"]["sra"]


def test_real_bench_on_the_xia_grid(shared_data, tmp_path, capsys):
    """The documented command on a draw of real pairs: the Xia grid's takes as styles, its neutral takes and
    a HumanML3D-format walk as contents, judged by the packaged evaluator."""
    from data_prep.bvh import convert
    grid_dir = tmp_path / "xia_grid"
    assert convert(shared_data / "xia_grid", grid_dir, "auto", "xia", progress=False)["failed"] == 0
    walk = shared_data / "humanml3d_format" / "walk_circle.npy"
    assert main(["bench", "--method", "identity,copy_style", "--real-style", str(grid_dir),
                 "--real-content", f"{walk}=walk", "--pairs", "16", "--json"]) == 0
    rows = {r["method"]: r for r in map(json.loads, capsys.readouterr().out.strip().splitlines())}
    assert rows["identity"]["pairs"] == 16 and rows["identity"]["tsi"] < 1e-6
    assert rows["copy_style"]["sra"] > rows["identity"]["sra"]  # the judge sees the style takes' styles
    pairs = RP.real_pairs(grid_dir, [f"{walk}=walk"])
    assert len(pairs) == 6 * 40 - 5 and {s["style"] for _, s in pairs} == {
        "angry", "childlike", "depressed", "neutral", "old", "proud", "sexy", "strutting"}
    assert {c["content"] for c, _ in pairs} == {"walk", "run", "jump", "punch", "kick"}
