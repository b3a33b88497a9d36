"""mslib.viz (pictures, animations) and mslib.notebook (setup_notebook) on a tiny made-up walk."""
import gc
import os
import random
import re

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import torch  # noqa: E402

from mslib import viz  # noqa: E402
from mslib.motion.skeleton import HUMANML3D, PARENTS  # noqa: E402
from mslib.notebook import setup_notebook  # noqa: E402

T = 20


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def rest():
    """The template rest pose with the feet on the floor (y = 0)."""
    p = HUMANML3D.rest_positions().copy()
    assert p.shape == (22, 3) and np.allclose(p[0], 0)
    p[:, 1] -= p[:, 1].min()
    return p


@pytest.fixture(scope="module")
def walk(rest):
    """The rest pose carried 1 m along +Z over 20 frames (a 'walk' at 1 m/s)."""
    m = np.repeat(rest[None], T, axis=0)
    m[:, :, 2] += np.linspace(0.0, 0.95, T)[:, None]
    return m


def bones(ax):
    return [ln for ln in ax.lines if ln.get_gid() == "bone"]


def screen_x(ax, line, k):
    """Screen (display) x of the k-th point of a 2-D line."""
    return ax.transData.transform(np.asarray(line.get_xydata()[k]))[0]


# ---------------------------------------------------------------- plot_pose
@pytest.mark.parametrize("view", ["front", "side", "top", "3d"])
def test_plot_pose_views(rest, view):
    fig = viz.plot_pose(None, rest, view=view, title=f"rest, {view}")
    assert isinstance(fig, matplotlib.figure.Figure)
    (ax,) = fig.axes
    assert len(bones(ax)) == 5                                # the five kinematic chains
    assert ax.get_title() == f"rest, {view}"
    colours = {matplotlib.colors.to_hex(ln.get_color()) for ln in bones(ax)}
    assert colours == {viz.SIDE_COLOURS[s] for s in ("left", "right", "centre")}
    if view != "3d":
        assert ax.get_xlabel() and ax.get_ylabel()
    assert fig.dpi >= 100 and max(fig.get_size_inches()) <= 6


def test_front_view_puts_left_hip_on_viewers_right(rest):
    fig = viz.plot_pose(None, rest, view="front")
    ax = fig.axes[0]
    left_leg, right_leg = bones(ax)[1], bones(ax)[0]          # chains (0,1,4,7,10), (0,2,5,8,11)
    fig.canvas.draw()
    # point 1 of each leg chain is the hip; the character's left hip (+X) is on the viewer's right
    assert screen_x(ax, left_leg, 1) > screen_x(ax, right_leg, 1)
    assert screen_x(ax, left_leg, 1) > screen_x(ax, left_leg, 0)  # left hip right of the pelvis


def test_side_view_forward_is_screen_right_and_top_view_left_is_screen_left(rest):
    ax = viz.plot_pose(None, rest, view="side").axes[0]
    left_leg = bones(ax)[1]
    ax.figure.canvas.draw()
    assert screen_x(ax, left_leg, 4) > screen_x(ax, left_leg, 3)   # toe (+Z) ahead of the ankle
    ax = viz.plot_pose(None, rest, view="top").axes[0]
    left_leg = bones(ax)[1]
    ax.figure.canvas.draw()
    assert screen_x(ax, left_leg, 1) < screen_x(ax, left_leg, 0)   # from above: its left on left


def test_plot_pose_other_skeleton_colours_by_name():
    names = ("Hips", "LHipJoint", "LeftUpLeg", "RHipJoint", "RightUpLeg", "LowerBack", "Head")
    parents = (-1, 0, 1, 0, 3, 0, 5)
    pos = np.array([[0, 1, 0], [.1, 1, 0], [.1, .5, 0], [-.1, 1, 0], [-.1, .5, 0], [0, 1.3, 0],
                    [0, 1.6, 0]], float)
    ax = viz.plot_pose(None, pos, parents=parents, names=names, view="front").axes[0]
    got = sorted(matplotlib.colors.to_hex(ln.get_color()) for ln in bones(ax))
    assert got == sorted(viz.SIDE_COLOURS[s] for s in ("left", "right", "centre"))
    with pytest.raises(ValueError, match="positions"):
        viz.plot_pose(None, pos[:5], parents=parents)        # joint count ≠ parents


def test_plot_pose_into_given_axes(rest):
    fig, axes = plt.subplots(1, 2)
    assert viz.plot_pose(axes[1], rest, view="side") is fig
    assert len(bones(axes[1])) == 5 and not bones(axes[0])
    with pytest.raises(ValueError, match="ax"):
        viz.plot_pose(axes[0], rest, view="3d")


# ---------------------------------------------------------------- plot_strip
def test_plot_strip_rows_and_frames(walk, rest):
    in_place = np.repeat(rest[None], 12, axis=0)
    fig = viz.plot_strip([walk, in_place], n_frames=4, titles=["walk", "in place"],
                         row_labels=["content", "style"])
    assert len(fig.axes) == 2
    assert [ax.get_title() for ax in fig.axes] == ["walk", "in place"]
    for ax in fig.axes:
        assert len(bones(ax)) == 4 * 5 and len(ax.get_xticks()) == 4
        assert ax.get_xlim() == fig.axes[0].get_xlim() and ax.get_ylim() == fig.axes[0].get_ylim()
    assert "content" in fig.axes[0].get_ylabel()
    # the walk travels: its poses spread further than the in-place ones
    spread = [np.ptp(ax.get_xticks()) for ax in fig.axes]
    assert spread[0] > spread[1] + 0.5
    fixed = viz.plot_strip(walk, n_frames=4, spacing="fixed")
    assert np.ptp(fixed.axes[0].get_xticks()) == pytest.approx(spread[1])


def test_plot_strip_short_motion_and_views(rest):
    fig = viz.plot_strip(rest[None], n_frames=6, view="front")   # 1 frame → 1 pose
    assert len(fig.axes) == 1 and len(bones(fig.axes[0])) == 5
    with pytest.raises(ValueError, match="view"):
        viz.plot_strip(rest[None], view="3d")
    with pytest.raises(ValueError, match="titles"):
        viz.plot_strip([rest[None], rest[None]], titles=["only one"])


# ---------------------------------------------------------------- plot_trajectory
def test_plot_trajectory_contacts(walk, rest):
    in_place = np.repeat(rest[None], T, axis=0)
    fig = viz.plot_trajectory([walk, in_place], labels=["walk", "stand"], contacts="auto")
    (ax,) = fig.axes
    gids = [ln.get_gid() for ln in ax.lines]
    assert gids.count("path") == 2 and gids.count("start") == 2
    assert ax.get_xlim()[0] > ax.get_xlim()[1]               # top view: X runs right → left
    path = [ln for ln in ax.lines if ln.get_gid() == "path"][0]
    assert np.allclose(path.get_ydata(), walk[:, 0, 2])
    # the walk slides at 1 m/s (> 0.6): no contacts; the standing pose: both feet every frame
    n_contacts = sum(len(ln.get_xdata()) for ln in ax.lines if ln.get_gid() == "contact")
    assert n_contacts == 2 * T
    explicit = np.zeros((T, 4), bool)
    explicit[:5, 1] = True
    ax = viz.plot_trajectory(walk, contacts=explicit).axes[0]
    pts = [ln for ln in ax.lines if ln.get_gid() == "contact"]
    assert sum(len(ln.get_xdata()) for ln in pts) == 5
    assert ax.get_title() and ax.get_xlabel() and ax.get_ylabel()
    with pytest.raises(ValueError, match="contacts"):
        viz.plot_trajectory(walk, contacts=np.zeros((T, 3), bool))


def test_auto_contacts(rest):
    m = np.repeat(rest[None], 5, axis=0)
    assert viz.auto_contacts(m).shape == (5, 2) and viz.auto_contacts(m).all()
    m[:, :, 1] += 0.2
    assert not viz.auto_contacts(m).any()


# ---------------------------------------------------------------- animate / animation_html
def test_animation_html(walk, rest):
    html = viz.animation_html([walk, np.repeat(rest[None], 8, 0)], titles=["a", "b"],
                              max_frames=6, dpi=30)
    assert isinstance(html, str) and "<script" in html and html._repr_html_() == html
    assert len(repr(html)) < 80                               # short text/plain in the notebook
    assert 1 <= html.count(";base64,") <= 6
    assert not plt.get_fignums()                              # closed: no static copy


@pytest.mark.filterwarnings("ignore:Animation was deleted")
def test_animate_subsamples(walk):
    anim = viz.animate(walk, max_frames=7, view="side", dpi=30)
    assert anim.n_frames <= 7 and anim.n_frames == int(np.ceil(T / np.ceil(T / 7)))
    assert not plt.get_fignums()
    anim._draw_next_frame(anim.n_frames - 1, blit=False)     # the last frame draws without error
    assert anim._fig.texts[0].get_text().startswith("t = ")
    del anim                       # never rendered as a whole: let its warning fire here, filtered
    gc.collect()


# ---------------------------------------------------------------- plot_curves, save_png
def test_plot_curves_and_save_png(tmp_path):
    fig = viz.plot_curves({"train": [1.0, 0.5, 0.25], "val": [1.2, 0.8, 0.6]}, "losses", logy=True)
    (ax,) = fig.axes
    assert len(ax.lines) == 2 and ax.get_title() == "losses" and ax.get_yscale() == "log"
    assert ax.get_xlabel() == "step" and ax.get_ylabel() == "loss"
    path = viz.save_png(fig, tmp_path / "sub" / "curves.png")
    assert path.read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(ValueError, match="path"):
        viz.save_png(fig, tmp_path / "curves.jpg")
    with pytest.raises(ValueError, match="logy"):
        viz.plot_curves({"x": [1.0, 0.0]}, "t", logy=True)


# ---------------------------------------------------------------- input validation
def _trajectory(m):
    return viz.plot_trajectory(m)


@pytest.mark.parametrize("call, arg", [
    (lambda m: viz.plot_pose(None, m[0]), "positions"),
    (lambda m: viz.plot_strip(m), "motions"),
    (_trajectory, "motions"),
    (lambda m: viz.animate(m), "motions"),
])
def test_bad_motions_raise(walk, call, arg):
    with pytest.raises(ValueError, match=rf"^{arg}.*last axis"):
        call(walk[..., :2])
    bad = walk.copy()
    bad[3, 5, 1] = np.nan
    with pytest.raises(ValueError, match=rf"^{arg}.*NaN"):
        call(bad if arg != "positions" else bad[3:])
    if call is not _trajectory:                               # the others know the skeleton
        with pytest.raises(ValueError, match=rf"^{arg}.*21 joints"):
            call(walk[:, :21])                                # 21 joints for 22 parents
    if arg != "positions":
        with pytest.raises(ValueError, match=r"at least 1 frame"):
            call(walk[:0])
    assert not plt.get_fignums()                              # validated before any figure


def test_bad_other_arguments(walk):
    with pytest.raises(ValueError, match="view"):
        viz.plot_pose(None, walk[0], view="back")
    with pytest.raises(ValueError, match=r"motions\[1\].*Inf"):
        viz.plot_strip([walk, np.full_like(walk, np.inf)])
    with pytest.raises(ValueError, match="histories"):
        viz.plot_curves({"loss": [1.0, float("nan")]}, "t")
    plt.close("all")
    with pytest.raises(ValueError, match="contacts"):
        viz.plot_trajectory(walk, contacts="yes")
    assert not plt.get_fignums()
    with pytest.raises(ValueError, match="parents"):
        viz.plot_pose(None, walk[0], parents=(0, 0, 1))


# ---------------------------------------------------------------- setup_notebook
@pytest.fixture
def _restore_global_state():
    """Undo setup_notebook's global settings so later tests see the defaults."""
    np_opts = np.get_printoptions()
    with matplotlib.rc_context():
        yield
    np.set_printoptions(**np_opts)
    torch.set_printoptions(profile="default")


def test_setup_notebook_seeds_and_is_silent(capsys, _restore_global_state):
    backend_env = os.environ.get("MPLBACKEND")
    draws = []
    for _ in range(2):
        assert setup_notebook(0) is None
        draws.append((np.random.rand(), random.random(), torch.rand(1).item()))
    assert draws[0] == draws[1]
    setup_notebook(1)
    assert np.random.rand() != draws[0][0]
    out = capsys.readouterr()
    assert out.out == "" and out.err == ""
    assert np.get_printoptions()["precision"] == 4 and np.get_printoptions()["suppress"]
    assert re.search(r"0\.3333\b", str(torch.tensor([1 / 3])))
    assert os.environ.get("MPLBACKEND") == backend_env
    assert matplotlib.rcParams["figure.dpi"] >= 100


def test_demo_style_is_the_best_recognised_non_neutral_style():
    from mslib.notebook import demo_style
    rows = [{"style": "neutral", "sra": 100.0}, {"style": "old", "sra": 40.0}, {"style": "angry", "sra": 70.0},
            {"style": "proud", "sra": 70.0}]
    assert demo_style(rows) == "angry"  # neutral never; a tie goes to the first name
    with pytest.raises(ValueError, match="non-neutral"):
        demo_style(rows[:1])


def test_readable_command_keeps_only_file_names_of_scratch_paths():
    from mslib.notebook import readable_command
    cmd = "python tools/contrastive_findings.py val joint=/tmp/exp/var_joint.pt /work/s/b.pt --out notebooks/data/x.json"
    assert readable_command(cmd) == "python tools/contrastive_findings.py val joint=var_joint.pt b.pt --out notebooks/data/x.json"


def test_neutral_walk_is_the_first_neutral_walk_of_the_labels(tmp_path):
    from mslib.notebook import neutral_walk
    (tmp_path / "labels.csv").write_text("clip_id,content,style\nc0,walk,angry\nc1,run,neutral\nc2,walk,neutral\n"
                                         "c3,walk,neutral\n", encoding="utf-8")
    assert neutral_walk(tmp_path) == "c2"
    (tmp_path / "labels.csv").write_text("clip_id,content,style\nc0,walk,angry\n", encoding="utf-8")
    with pytest.raises(ValueError, match="no neutral walk"):
        neutral_walk(tmp_path)


def test_demo_pairs_follow_the_rule():
    from mslib.notebook import demo_pairs
    def pair(content, style, clip_content):
        return ({"content": content}, {"style": style, "content": clip_content, "joints": style})
    pairs = [pair("walk", "neutral", "run"), pair("walk", "old", "walk"), pair("run", "angry", "walk"),
             pair("jump", "old", "walk"), pair("walk", "proud", "run"), pair("kick", "old", "run")]
    read = lambda joints: {"proud": "neutral"}.get(joints, joints)  # noqa: E731  the judge misreads proud
    assert [p[1]["style"] for p in demo_pairs(pairs, read, n=2)] == ["angry", "old"]
    assert [p[0]["content"] for p in demo_pairs(pairs, read, style="old", n=2)] == ["jump", "kick"]
    with pytest.raises(ValueError, match="can show the style 'proud'"):
        demo_pairs(pairs, read, style="proud")


def test_load_findings_prefers_the_notebook_folders_own_data(tmp_path, monkeypatch):
    import json as _json
    from mslib.notebook import load_findings
    monkeypatch.chdir(tmp_path)
    stored = load_findings("07_bench")  # the repository's table, while ./data has none
    assert "builtin" in stored
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "07_bench.json").write_text(_json.dumps({"handout": True}))
    assert load_findings("07_bench") == {"handout": True}
    assert load_findings("no_such_table", required=False) == {}
    with pytest.raises(ValueError, match="no_such_table.json: no stored findings"):
        load_findings("no_such_table")
