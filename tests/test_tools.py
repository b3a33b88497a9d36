"""tools/: every tool answers `--help` and imports as `tools.NAME`; the shared helpers of tools/common.py."""
import importlib
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tools import common

ROOT = Path(__file__).resolve().parents[1]
TOOLS = sorted(p.stem for p in (ROOT / "tools").glob("*.py") if p.stem != "__init__")


@pytest.fixture(scope="module")
def helps(tmp_path_factory):
    """`python tools/NAME.py --help` of every tool, run side by side from a folder outside the repository."""
    cwd = tmp_path_factory.mktemp("elsewhere")
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    procs = {name: subprocess.Popen([sys.executable, str(ROOT / "tools" / f"{name}.py"), "--help"], cwd=cwd, env=env,
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for name in TOOLS}
    return {name: (p.wait(timeout=120), *p.communicate()) for name, p in procs.items()}


def test_the_tools_are_the_ones_the_package_lists():
    listed = re.findall(r"^    (\w+) ", importlib.import_module("tools").__doc__, re.M)
    assert sorted(listed) == TOOLS and "common" in TOOLS


@pytest.mark.parametrize("name", TOOLS)
def test_tool_answers_help(name, helps):
    rc, out, err = helps[name]
    assert rc == 0, err
    assert f"{name}.py" in out, f"tools/{name}.py --help printed no usage naming the tool: {out[:200]!r}"


@pytest.mark.parametrize("name", TOOLS)
def test_tool_imports_as_a_module(name):
    module = importlib.import_module(f"tools.{name}")
    assert module.__doc__ and Path(module.__file__).parent == ROOT / "tools"


# ---------------------------------------------------------------- tools/common.py
def test_paths():
    assert common.ROOT == ROOT and (ROOT / "mslib").is_dir()
    assert common.DATA_DIR == ROOT / "notebooks" / "data" and common.DATA_DIR.is_dir()


def test_update_json_replaces_its_sections_and_keeps_the_others(tmp_path):
    path = tmp_path / "new" / "table.json"
    assert common.update_json(path, {"a": 1, "b": {"x": [1, 2]}}) == path  # made, with its folder
    common.update_json(path, {"b": {"y": 2.5}, "c": None})
    want = {"a": 1, "b": {"y": 2.5}, "c": None}
    assert json.loads(path.read_text()) == want
    assert path.read_text() == json.dumps(want, indent=1) + "\n"  # order kept, indent=1, final newline


def test_update_json_refuses_a_file_that_is_not_an_object(tmp_path):
    path = tmp_path / "list.json"
    path.write_text("[1, 2]\n")
    with pytest.raises(ValueError, match="JSON object"):
        common.update_json(path, {"a": 1})
    assert path.read_text() == "[1, 2]\n"


def test_update_json_that_fails_leaves_the_old_file(tmp_path, monkeypatch):
    path = tmp_path / "table.json"
    common.update_json(path, {"kept": [1, 2, 3]})
    before = path.read_bytes()
    with pytest.raises(TypeError):  # a value JSON cannot hold: nothing is written
        common.update_json(path, {"kept": 0, "bad": object()})
    assert path.read_bytes() == before

    def broken_replace(src, dst):
        raise OSError("disk full")
    monkeypatch.setattr(os, "replace", broken_replace)  # the write fails at the last step
    with pytest.raises(OSError, match="disk full"):
        common.update_json(path, {"kept": 0})
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.json"]  # no temporary file left behind


def test_val_pairs_come_from_the_val_splits():
    from mslib.data.corpora import load_builtin
    from mslib.data.dataset_folder import read_labels
    from mslib.evaluation.bench import load_pairs
    paths = load_builtin(progress=False)
    split = {r["clip_id"]: r["split"] for side in ("content", "style") for r in read_labels(paths[side])}
    pairs = common.val_pairs(8)
    assert len(pairs) == 8
    assert {split[item["clip_id"]] for pair in pairs for item in pair} == {"val"}
    ids = [(c["clip_id"], s["clip_id"]) for c, s in pairs]
    assert ids == [(c["clip_id"], s["clip_id"]) for c, s in common.val_pairs(8)]  # a fixed draw
    assert ids != [(c["clip_id"], s["clip_id"]) for c, s in common.val_pairs(8, seed=1)]
    assert not set(ids) & {(c["clip_id"], s["clip_id"]) for c, s in load_pairs(0, 8)}  # not the test pairs


def test_score_outputs_of_identity_keep_the_content():
    from mslib.evaluation.bench import Evaluator, evaluate, positions
    pairs, ev = common.val_pairs(8), Evaluator()
    outs = [positions(c["features"]) for c, _ in pairs]
    row = common.score_outputs(outs, pairs, ev)
    assert row["cra"] >= 87.5 and row["tsi"] < 1e-6  # the content itself: recognised (one miss at most), on its path
    assert row == pytest.approx(evaluate(outs, pairs, ev), nan_ok=True)
    assert all(type(v) is float for v in row.values())
    with pytest.raises(ValueError, match="one output per pair"):
        common.score_outputs(outs[:-1], pairs, ev)
    with pytest.raises(ValueError, match="joint positions"):
        common.score_outputs([c["features"] for c, _ in pairs], pairs, ev)  # features, not positions


def test_recorded_command_leaves_out_scratch_folders():
    argv = ["--steps", "3000", "--workdir", "/tmp/x", "--only", "full", "--keep=/tmp/y"]
    assert common.recorded_command("mcm_ldm_ablations", argv) == "python tools/mcm_ldm_ablations.py --steps 3000 --only full"
    assert common.recorded_command("t", []) == "python tools/t.py"


def test_current_commit(monkeypatch, tmp_path):
    commit = common.current_commit()
    assert commit == "unknown" or re.fullmatch(r"[0-9a-f]{7,40}", commit)
    monkeypatch.setattr(common, "ROOT", tmp_path)  # not a git checkout
    assert common.current_commit() == "unknown"


def test_notebook_shape_counts_cells_prose_and_points():
    import nbformat
    from tools.update_docs import READING_WPM, notebook_shape
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell("one two three"), nbformat.v4.new_code_cell("x = 1"),
                nbformat.v4.new_code_cell("assert x", metadata={"nbgrader": {"grade": True, "points": 2}}),
                nbformat.v4.new_markdown_cell("four five")]
    shape = notebook_shape(nb)
    assert shape == {"cells": 4, "words": 5, "minutes": 5 / READING_WPM, "points": 2}
