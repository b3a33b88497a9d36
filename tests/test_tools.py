"""tools/: every tool answers `--help` and imports as `tools.NAME`; the shared helpers of tools/common.py."""
import importlib
import json
import os
import re
import subprocess
import sys
import types
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


def test_mcm_seed_search_trains_the_seeds_that_did_not_make_the_packaged_model():
    from tools.mcm_ldm_ablations import seeds_to_train
    assert seeds_to_train(1) == [0, 2] and seeds_to_train(0) == [1, 2] and seeds_to_train(7) == [0, 1, 2]
    assert seeds_to_train(1, [3, 0]) == [3, 0]
    with pytest.raises(ValueError, match="seed 1 made the packaged checkpoint"):
        seeds_to_train(1, [0, 1])


def test_clusterstyle_seed_search_refuses_a_second_run_of_a_seed_before_scoring(monkeypatch):
    import tools.clusterstyle_findings as F
    from mslib.checkpoints import course_path
    monkeypatch.setattr(F, "val_pairs", lambda n: pytest.fail("scored before the seeds were checked"))
    with pytest.raises(ValueError, match=r"--checkpoints: .*clusterstyle.pt was trained with seed \d+, as .* was"):
        F.seeds([course_path("clusterstyle")])


def test_clusterstyle_seed_search_scores_every_seed_at_the_packaged_guidance(monkeypatch):
    import mslib.checkpoints as CK
    import mslib.evaluation.bench as B
    import mslib.models.clusterstyle as MC
    import tools.clusterstyle_findings as F
    own = {"packaged": (0, 1500.0), "a.pt": (1, 3000.0), "b.pt": (2, 5000.0)}  # seed, the guidance its file stores
    key = lambda path: "packaged" if path is None or str(path) == str(CK.course_path("clusterstyle")) else str(path)  # noqa: E731
    monkeypatch.setattr(CK, "trained_seed", lambda path, name=None: own[key(path)][0])
    monkeypatch.setattr(MC, "load_pipeline", lambda path=None: types.SimpleNamespace(
        cfg=types.SimpleNamespace(guide_weight=own[key(path)][1], cfg_style=1.0)))
    monkeypatch.setattr(B, "Evaluator", lambda: None)
    monkeypatch.setattr(F, "val_pairs", lambda n: [])
    seen = []
    monkeypatch.setattr(F, "scored_transfers", lambda pipe, pairs, ev, **kw: seen.append(kw) or {"h": 0.5})
    got = F.seeds(["a.pt", "b.pt"])
    assert seen == [{"weight": 1500.0, "cfg_style": 1.0}] * 3
    assert [r["guide_weight"] for r in got["rows"]] == [1500.0] * 3 and got["packaged_seed"] == 0


def test_mcm_seed_search_scores_every_seed_at_the_packaged_scale_and_steps(monkeypatch, tmp_path):
    import mslib.checkpoints as CK
    import mslib.data.corpora as corpora
    import tools.mcm_ldm_ablations as T
    own = {None: (2.0, 20), "seed1.pt": (1.25, 50)}  # the λ and steps each file stores
    model = lambda path: types.SimpleNamespace(model=types.SimpleNamespace(  # noqa: E731
        cfg=types.SimpleNamespace(cfg_scale=own[path][0], ddim_steps=own[path][1])))
    P = types.SimpleNamespace(load_mcm_ldm=lambda path=None: model(None if path is None else Path(path).name),
                              prepare=lambda *a, **k: None, run=lambda *a, **k: {"seconds": 1.0})
    monkeypatch.setattr(CK, "trained_seed", lambda path, name=None: 0)
    monkeypatch.setattr(CK, "checkpoint_digest", lambda name: "digest")
    monkeypatch.setattr(corpora, "source_fingerprint", lambda: "corpus")
    monkeypatch.setattr(T, "val_pairs", lambda n: [])
    monkeypatch.setattr(T, "OUT", tmp_path / "none.json")
    seen = []
    monkeypatch.setattr(T, "scored", lambda tr, pairs, ev, **knob: seen.append(knob) or {"h": 0.5})
    got = T.seed_rows(P, {"content": None, "style": None}, [1], tmp_path, None, "cmd", "abc")
    assert seen == [{"scale": 2.0, "steps": 20}] * 2 and [r["seed"] for r in got["rows"]] == [0, 1]


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


def test_adain_recipe_rule_adopts_only_a_clear_winner_and_keeps_a_better_packaged_model():
    from tools.adain_variants import apply_recipe_rule
    rows = [{"recipe": n, "seed": s, "strength": w, "h": h} for n, s, w, h in (
        ("course", 0, 0.55, 0.60), ("course", 1, 0.55, 0.64), ("course", 1, 0.5, 0.90),  # another w: ignored
        ("wide", 0, 0.55, 0.61), ("wide", 1, 0.55, 0.64),  # mean +0.005: not a clear winner
        ("content1", 0, 0.55, 0.70))]  # seed 1 missing: not comparable
    got = apply_recipe_rule(rows, 0.55, packaged_h=0.63)
    assert got["adopted"] == "course" and got["best_seed"] == 1 and got["keep_packaged"] is False
    assert set(got["mean_h"]) == {"course", "wide"}
    rows += [{"recipe": "content1", "seed": 1, "strength": 0.55, "h": 0.66}]  # mean 0.68 ≥ 0.62 + 0.02
    got = apply_recipe_rule(rows, 0.55, packaged_h=0.75)
    assert got["adopted"] == "content1" and got["best_seed"] == 0 and got["keep_packaged"] is True
    assert apply_recipe_rule(rows, 0.6) == {}  # no course row at that strength


def test_real_val_seed_rule_takes_the_best_mean_and_keeps_the_packaged_seed_on_a_tie():
    from tools.real_val import choose_seed
    rows = [{"seed": 1, "mean_h": 0.50}, {"seed": 0, "mean_h": 0.52}, {"seed": 2, "mean_h": 0.51}]
    assert choose_seed(rows) == 0
    assert choose_seed([{"seed": 1, "mean_h": 0.52}, {"seed": 0, "mean_h": 0.52}]) == 1  # the packaged (first) row
    with pytest.raises(ValueError, match="no seed"):
        choose_seed([])


def test_real_val_refuses_a_seed_spec_it_cannot_compare_before_any_work(tmp_path, capsys):
    from tools.real_val import main
    for spec, message in (("dsdn=a.pt", "METHOD one of adain, contrastive, mcm_ldm, clusterstyle"),
                          ("adain", "expected METHOD=A.pt"),
                          (f"adain={tmp_path / 'missing.pt'}", "no such checkpoint")):
        with pytest.raises(SystemExit):
            main(["--xia-train", str(tmp_path / "no_bvh_here"), "--methods", "", "--seeds", spec])
        assert message in capsys.readouterr().err
    assert not (tmp_path / "no_bvh_here").exists()  # refused before converting anything


def test_real_val_style_scale_sweep_is_the_guidance_grid_at_the_packaged_weight():
    """ClusterStyle's two knobs read one stored guidance grid: they meet at the packaged (w, s_s)."""
    from tools.real_val import POLICY, builtin_sweeps
    sweeps = builtin_sweeps()
    _, w, by_weight = sweeps["clusterstyle"]
    knob, ss, by_scale = sweeps["clusterstyle_style_scale"]
    assert knob == "s_s" and len(by_scale) >= 2 and ss in by_scale
    assert by_scale[ss] == by_weight[w]
    assert "clusterstyle_style_scale" in POLICY  # reported, not chosen


def test_real_val_rule_takes_the_best_mean_of_both_val_sets_and_the_smaller_value_on_a_tie():
    from tools.real_val import choose
    real = [{"value": v, "h": h} for v, h in ((0.5, 0.30), (0.6, 0.40), (0.7, 0.44), (0.9, 0.99))]
    got = choose(real, {0.5: 0.60, 0.6: 0.55, 0.7: 0.47})  # means 0.45, 0.475, 0.455; 0.9 has no built-in row
    assert got["chosen"] == 0.6 and [r["value"] for r in got["rows"]] == [0.5, 0.6, 0.7]
    assert got["rows"][1]["builtin_h"] == 0.55 and got["rows"][1]["mean_h"] == 0.475
    tie = choose([{"value": 2.0, "h": 0.5}, {"value": 1.0, "h": 0.4}], {1.0: 0.6, 2.0: 0.5})
    assert tie["chosen"] == 1.0
    with pytest.raises(ValueError, match="no knob value"):
        choose(real, {3.0: 0.5})


# ---------------------------------------------------------------- tools/realism_gap.py
def test_evaluator_augment_adopts_only_a_gain_larger_than_the_seed_spread():
    from tools.evaluator_augment import SEEDS, summarise
    assert SEEDS == (0, 1)

    def rows(name, real, val=100.0):
        return [{"candidate": name, "seed": s, "builtin_val": val, "builtin_test": 100.0, "real_train_takes": r,
                 "grid_takes": None} for s, r in zip(SEEDS, real)]
    close = summarise(rows("none", (60, 62)) + rows("mirror", (62, 64)) + rows("all", (70, 72), val=90.0))
    assert close["chosen"] == "mirror" and close["gain"] == 2 and close["spread"] == 2 and not close["adopted"]
    assert "grid_takes" not in close["summary"]["none"]  # the grid is reported only when it was scored
    clear = summarise(rows("none", (60, 62)) + rows("mirror", (70, 71)))
    assert clear["chosen"] == "mirror" and clear["gain"] == 9.5 and clear["adopted"]
    assert not summarise(rows("none", (60, 62)))["adopted"]  # nothing beats doing nothing


def test_realism_gap_moves_each_cell_to_the_real_mean_and_only_what_it_names():
    import numpy as np
    from tools.realism_gap import GROUPS, columns, shifted
    assert list(columns(["vel_mean"])) == list(range(66, 132)) and len(columns(GROUPS)) == 396
    rng = np.random.default_rng(0)
    Xb, X = rng.normal(size=(12, 396)), rng.normal(3.0, 1.0, size=(9, 396))
    yb, cb = np.array(list("aabb") * 3), np.array(["jump"] * 8 + ["kick"] * 4)
    y, c = np.array(list("aaabbbaaa")), np.array(["jump"] * 6 + ["None"] * 3)  # no real kick: kicks stay
    cols = columns(["pos_std"])
    moved = shifted(Xb, yb, cb, X, y, c, cols, 1.0, "cell")
    for s in "ab":
        mb, mr = (yb == s) & (cb == "jump"), (y == s) & (c == "jump")
        assert np.allclose(moved[mb][:, cols].mean(0), X[mr][:, cols].mean(0))  # the real cell's mean
        assert np.allclose(moved[mb] - moved[mb].mean(0), Xb[mb] - Xb[mb].mean(0))  # its own spread kept
    other = np.setdiff1d(np.arange(396), cols)
    assert np.array_equal(moved[:, other], Xb[:, other]) and np.array_equal(moved[cb == "kick"], Xb[cb == "kick"])
    half = shifted(Xb, yb, cb, X, y, c, cols, 0.5, "cell")
    assert np.allclose(half, (Xb + moved) / 2)
    free = shifted(Xb, yb, cb, X, y, c, cols, 1.0, "content")  # one shift for both styles
    d = free - Xb
    assert np.allclose(d[cb == "jump"], d[cb == "jump"][0]) and np.allclose(
        free[cb == "jump"][:, cols].mean(0), X[c == "jump"][:, cols].mean(0))



def test_realism_gap_rescaled_gives_each_cell_the_real_mean_and_spread():
    import numpy as np
    from tools.realism_gap import rescaled
    rng = np.random.default_rng(2)
    Xb, X = rng.normal(size=(12, 5)), rng.normal(4.0, 3.0, size=(9, 5))
    Xb[:, 4] = 1.0  # a feature without spread in the built-in cells stays flat
    yb, cb = np.array(list("aabb") * 3), np.array(["jump"] * 8 + ["kick"] * 4)
    y, c = np.array(list("aaabbbaaa")), np.array(["jump"] * 6 + ["None"] * 3)
    out = rescaled(Xb, yb, cb, X, y, c)
    for s in "ab":
        mb, mr = (yb == s) & (cb == "jump"), (y == s) & (c == "jump")
        assert np.allclose(out[mb][:, :4].mean(0), X[mr][:, :4].mean(0))
        assert np.allclose(out[mb][:, :4].std(0), X[mr][:, :4].std(0))
        assert np.allclose(out[mb][:, 4], X[mr][:, 4].mean())
    assert np.array_equal(out[cb == "kick"], Xb[cb == "kick"])  # no real kick: untouched


def test_realism_gap_reverse_bound_undoes_swapped_built_in_styles():
    """Built-in cells labelled the wrong way round: a judge trained on them reads every real take wrong, and
    one trained on them with the cell means moved to the real ones reads every take right."""
    import numpy as np
    from mslib.evaluation import realism as R
    from mslib.motion.skeleton import HUMANML3D
    from tools.realism_gap import reverse_bound
    rng = np.random.default_rng(3)
    rest = HUMANML3D.rest_positions() + np.array([0.0, 0.95, 0.0])  # standing on the floor
    clips = []
    for i in range(48):
        style = "ab"[i % 2]
        joints = rest + rng.normal(0.0, 1e-4, size=(40, 22, 3))
        joints[:, [9, *range(12, 22)], 2] += 0.15 if style == "a" else -0.05  # chest, arms and head: leaning forward for a, back for b
        clips.append(({"clip_id": f"t{i}", "style": style, "content": "walk"}, joints))
    X, y, _, _, _ = R._windowed(clips)
    yb = np.where(y == "a", "b", "a")  # swapped
    out = reverse_bound(clips, X, yb, np.array(["walk"] * len(y)), C=1.0, splits=1)
    rows = {r["judge trained on"]: r for r in out["rows"]}
    assert rows["built-in as generated"]["takes"] == 0.0 and rows["built-in as generated"]["walk takes"] == 0.0
    assert rows["built-in, cell means matched"]["takes"] == 100.0 and rows["real takes (the ceiling)"]["takes"] == 100.0
    assert rows["built-in, cell means and spreads matched"]["takes"] == 100.0
    assert rows["built-in as generated"]["other takes"] is None  # no other content: no score, not a zero


def test_realism_gap_moved_inputs_give_each_cell_the_real_frames_mean_and_spread():
    import numpy as np
    from tools.realism_gap import moved_inputs
    rng = np.random.default_rng(4)
    inputs = [rng.normal(size=(10, 3)).astype(np.float32) for _ in range(4)]
    keys = [("a", "walk"), ("a", "walk"), ("b", "walk"), ("b", "kick")]
    real = {("a", "walk"): rng.normal(5.0, 2.0, size=(30, 3)), ("b", "walk"): rng.normal(-1.0, 0.5, size=(7, 3))}
    for spread in (False, True):
        out = moved_inputs(inputs, keys, real, spread)
        a = np.concatenate(out[:2])
        assert np.allclose(a.mean(0), real[("a", "walk")].mean(0), atol=1e-5)
        assert np.allclose(a.std(0), real[("a", "walk")].std(0) if spread else np.concatenate(inputs[:2]).std(0), atol=1e-5)
        assert np.allclose(out[2].mean(0), real[("b", "walk")].mean(0), atol=1e-5)
        assert out[3] is inputs[3]  # no real kick of b: untouched


def test_realism_gap_reverse_network_undoes_swapped_built_in_styles(monkeypatch):
    """As test_realism_gap_reverse_bound_undoes_swapped_built_in_styles, for the evaluator's recipe (a short run)."""
    import numpy as np
    from mslib.evaluation import evaluator as E
    from mslib.motion.skeleton import HUMANML3D
    from tools.realism_gap import reverse_network
    monkeypatch.setitem(E.PRESETS, "course", {**E.PRESETS["course"], "steps": 60, "val_every": 60})
    rng = np.random.default_rng(5)
    rest = HUMANML3D.rest_positions() + np.array([0.0, 0.95, 0.0])

    def clip(i, style, split=None, swap=False):
        joints = rest + rng.normal(0.0, 1e-3, size=(40, 22, 3))
        joints[:, [9, *range(12, 22)], 2] += 0.15 if style == "a" else -0.05
        label = {"a": "b", "b": "a"}[style] if swap else style
        return {"clip_id": f"{split or 'r'}{i}", "style": label, "content": "walk", "split": split}, joints
    real = [clip(i, "ab"[i % 2]) for i in range(24)]
    built = [clip(i, "ab"[i % 2], "train" if i < 16 else "val", swap=True) for i in range(24)]
    rows = {r["judge trained on"]: r for r in reverse_network(real, built)["rows"]}
    assert rows["built-in as generated"]["takes"] < 20 and rows["built-in as generated"]["other takes"] is None
    assert rows["built-in, cell mean poses matched"]["takes"] > 80

# ---------------------------------------------------------------- tools/train_all.py
def test_train_all_plans_every_checkpoint_after_what_it_reads():
    from tools import train_all as T
    order = T.plan(list(T.COURSE))
    assert sorted(order) == sorted(T.COURSE)
    for name in order:
        assert all(order.index(dep) < order.index(name) for dep in T.COURSE[name][1]), name
    assert T.plan(["dsdn", "adain"]) == ["adain", "dsdn"] and T.plan(["dsdn"]) == ["dsdn"]
    with pytest.raises(ValueError, match="unknown checkpoints.*'adian'"):
        T.plan(["adian"])


def test_train_all_seeds_are_the_packaged_checkpoints():
    """The table's seeds made the packaged checkpoints."""
    from mslib.checkpoints import course_path, trained_seed
    from tools import train_all as T
    for name, (seed, _, _) in T.COURSE.items():
        stored = trained_seed(course_path(name), name)
        assert stored == seed, (name, stored, seed)


def test_train_all_runs_a_job_only_after_the_ones_it_needs(tmp_path, monkeypatch):
    from tools import train_all as T
    monkeypatch.setattr(T, "POLL_SECONDS", 0.05)
    monkeypatch.setattr(T, "command", lambda name: [sys.executable, "-c", f"import time; time.sleep(0.3); print('{name}')"])
    done = T.run(["dsdn", "adain", "vae"], jobs=2, logs=tmp_path)
    assert set(done) == {"adain", "dsdn", "vae"} and all(d["returncode"] == 0 for d in done.values())
    assert done["dsdn"]["started"] >= done["adain"]["started"] + 0.3  # dsdn reads the trained adain
    assert done["vae"]["started"] < done["adain"]["started"] + 0.3  # the second lane did not wait
    assert (tmp_path / "dsdn.log").read_text().strip() == "dsdn"
    monkeypatch.setattr(T, "command", lambda name: [sys.executable, "-c", "raise SystemExit(3)"])
    done = T.run(["adain", "dsdn"], jobs=1, logs=tmp_path)
    assert done == {"adain": {**done["adain"], "returncode": 3}}  # no job after a failure


def test_realism_gap_spread_ratios_read_a_cell_twice_as_wide_as_two():
    import numpy as np
    from tools.realism_gap import spread_ratios
    rng = np.random.default_rng(1)
    y, c = np.repeat(["a", "b"], 30), np.array(["walk"] * 60)
    X = rng.normal(size=(60, 6)) + np.where(y == "a", 0.0, 3.0)[:, None]  # two real styles, one content
    mean = {s: X[y == s].mean(0) for s in "ab"}
    Xb = np.stack([mean[s] + 2.0 * (x - mean[s]) for x, s in zip(X, y)])  # each cell twice as wide, same mean
    out = spread_ratios(X, y, c, Xb, y, c, min_windows=10)
    for part in ("real_directions", "builtin_directions"):
        assert set(out[part]["cells"]) == {"a:walk", "b:walk"}
        assert np.allclose(list(out[part]["cells"].values()), 2.0) and out[part]["median"] == 2.0
    assert spread_ratios(X, y, c, Xb, y, c, min_windows=31)["real_directions"] == {"median": None, "cells": {}}
