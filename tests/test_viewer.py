"""mslib.viz.viewer (the 3-D viewer's state and HTML page) and mslib.viz.widget (MotionViewer), on made-up walks.

The drawing itself runs in the browser: tests/test_browser_viewer.py opens the page in headless Chromium."""
import base64
import json
import re

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from mslib import viz  # noqa: E402
from mslib.motion.skeleton import HUMANML3D, KINEMATIC_CHAINS, PARENTS  # noqa: E402
from mslib.viz import viewer  # noqa: E402


def made_up_walk(T: int = 200, fps: float = 20.0) -> np.ndarray:
    """The rest pose carried along +Z at 1 m/s, (T, 22, 3): each foot swings 1 m in half a second (lifted
    10 cm), then stands still on the floor for half a second while the other swings (left first)."""
    rest = HUMANML3D.rest_positions()
    rest[:, 1] -= rest[:, 1].min()
    m = np.repeat(rest[None], T, axis=0)
    t = np.arange(T) / fps
    m[:, :, 2] += t[:, None]
    for foot, delay in (((7, 10), 0.0), ((8, 11), 0.5)):
        k, u = np.divmod(np.maximum(t - delay, 0.0), 1.0)              # completed cycles, phase in the cycle
        swing = u < 0.5
        z = k + np.where(swing, u / 0.5, 1.0) - delay                   # swing: 2 m/s, stance: still
        m[:, list(foot), 2] = rest[list(foot), 2] + z[:, None]
        m[:, list(foot), 1] += np.where(swing, 0.1 * np.sin(np.pi * u / 0.5), 0.0)[:, None]
    return m


@pytest.fixture(scope="module")
def walk():
    return made_up_walk()


# ---------------------------------------------------------------- the state
def test_state_shapes_and_float32_round_trip(walk):
    state = viz.viewer_state([walk, walk[:50]], titles=["long", "short"], fps=20)
    assert state["format"] == viewer.FORMAT and state["fps"] == 20 and state["step"] == 1
    assert state["parents"] == list(PARENTS) and state["chains"] == [list(c) for c in KINEMATIC_CHAINS]
    assert state["sides"] == ["right", "left", "centre", "right", "left"]
    assert state["colours"] == viz.SIDE_COLOURS and not state["overlay"]
    long, short = state["motions"]
    assert (long["title"], long["frames"], long["joints"], short["frames"]) == ("long", 200, 22, 50)
    back = viz.decode_positions(long)
    assert back.dtype == np.float32 and back.shape == (200, 22, 3)
    np.testing.assert_array_equal(back, walk.astype(np.float32))     # float32, exactly
    assert len(base64.b64decode(long["positions"])) == 200 * 22 * 3 * 4
    json.dumps(state)                                                  # JSON-able as it is


def test_int16_encoding_is_half_the_size_and_within_half_a_millimetre(walk):
    f32 = viz.viewer_state(walk)
    i16 = viz.viewer_state(walk, encoding="int16")
    assert i16["motions"][0]["encoding"] == "int16"
    assert np.abs(viz.decode_positions(i16["motions"][0]) - walk).max() <= 0.0005 + 1e-6
    assert viz.state_size(i16) < 0.55 * viz.state_size(f32)
    far = walk + np.array([40.0, 0.0, 0.0])                          # past ±32.7 m: float32 instead
    assert viz.viewer_state(far, encoding="int16")["motions"][0]["encoding"] == "float32"


def test_state_of_a_200_frame_motion_is_a_few_tens_of_kilobytes(walk):
    size = viz.state_size(viz.viewer_state(walk))
    # 200 × 22 × 3 float32 = 52.8 kB raw, 70.4 kB as base64, plus the skeleton and the contacts
    assert 70_400 < size < 73_000, size
    assert viz.state_size(viz.viewer_state(walk, encoding="int16")) < 37_000


def test_decimation_to_max_fps_and_max_frames(walk):
    s = viz.viewer_state(walk, fps=60)                                 # 60 fps → every 3rd frame, 20 fps
    assert s["step"] == 3 and s["fps"] == 20 and s["motions"][0]["frames"] == 67
    np.testing.assert_array_equal(viz.decode_positions(s["motions"][0]), walk[::3].astype(np.float32))
    s = viz.viewer_state([walk, walk[:30]], max_frames=50)             # one step for all: they stay in sync
    assert s["step"] == 4 and [m["frames"] for m in s["motions"]] == [50, 8]
    assert [m["source_frames"] for m in s["motions"]] == [200, 30]
    assert s["fps"] == 5
    assert viz.viewer_state(walk, fps=25)["step"] == 2                 # never above max_fps


def test_contacts_follow_the_static_figures_rule(walk):
    s = viz.viewer_state(walk)
    left, right = s["motions"][0]["contacts"]
    expected = viz.auto_contacts(walk, (10, 11), 20)
    assert left == "".join("1" if c else "0" for c in expected[:, 0])
    assert right == "".join("1" if c else "0" for c in expected[:, 1])
    assert "0" in left and "1" in left and "0" in right and "1" in right
    given = np.zeros((200, 2), bool)
    given[5, 1] = True
    s = viz.viewer_state(walk, contacts=given)
    assert s["motions"][0]["contacts"] == ["0" * 200, "0" * 5 + "1" + "0" * 194]
    assert "contacts" not in viz.viewer_state(walk, contacts=None)["motions"][0]


def test_follow_camera_starts_on_for_long_paths(walk):
    assert viz.viewer_state(walk)["follow"] is True                   # 10 m of travel
    assert viz.viewer_state(walk[:20])["follow"] is False              # 1 m
    assert viz.viewer_state(walk, follow=False)["follow"] is False


def test_overlay_titles_and_size(walk):
    s = viz.viewer_state([walk, walk], overlay=True, width=500, height=300)
    assert s["overlay"] and (s["width"], s["height"]) == (500, 300)
    assert [m["title"] for m in s["motions"]] == ["motion 0", "motion 1"]
    assert viz.viewer_state(walk)["motions"][0]["title"] == "motion"
    assert viz.viewer_state([walk] * 3)["width"] == 3 * viewer.PANEL_WIDTH


@pytest.mark.parametrize("kwargs, argument", [
    (dict(motions=np.zeros((10, 22))), "motions"),
    (dict(motions=np.zeros((10, 21, 3))), "motions"),
    (dict(motions=[]), "motions"),
    (dict(motions=np.full((10, 22, 3), np.nan)), "motions"),
    (dict(titles=["a", "b"]), "titles"),
    (dict(fps=0), "fps"),
    (dict(fps="fast"), "fps"),
    (dict(max_fps=-1), "max_fps"),
    (dict(max_frames=1), "max_frames"),
    (dict(max_frames=2.5), "max_frames"),
    (dict(overlay="yes"), "overlay"),
    (dict(contacts="sometimes"), "contacts"),
    (dict(contacts=np.zeros((199, 2))), "contacts[0]"),
    (dict(follow="maybe"), "follow"),
    (dict(encoding="float16"), "encoding"),
    (dict(width=10), "width"),
    (dict(parents=(0, 0)), "parents"),
])
def test_bad_input_names_the_argument(walk, kwargs, argument):
    kwargs = {"motions": walk, **kwargs}
    with pytest.raises(ValueError, match=rf"^{re.escape(argument)}"):
        viz.viewer_state(**kwargs)


def test_torch_tensors_and_other_skeletons(walk):
    torch = pytest.importorskip("torch")
    s = viz.viewer_state(torch.tensor(walk[:10]))
    assert s["motions"][0]["frames"] == 10
    chain = viz.viewer_state(np.zeros((5, 3, 3)), parents=(-1, 0, 1), names=("root", "l_knee", "l_foot"))
    assert chain["chains"] == [[0, 1, 2]] and chain["sides"] == ["left"]
    assert "contacts" not in chain["motions"][0]                       # no joints 10/11: no feet to light


# ---------------------------------------------------------------- the standalone page
def test_html_page_is_self_contained(walk):
    page = viz.viewer_html([walk, walk[:40]], titles=["content </script>", "output"], page_title="A & B")
    assert page.startswith("<!DOCTYPE html>") and "<title>A &amp; B</title>" in page
    assert not re.search(r"https?://|//cdn|\bsrc=|<link\b|\bimport\s*\(|\bimport\s+[\w{*]", page)
    assert viewer.viewer_js() in page                                   # the JavaScript, inline
    data = re.search(r'<script type="application/json" id="mslib-viewer-data">(.*?)</script>', page, re.S)
    state = json.loads(data.group(1))
    assert [m["title"] for m in state["motions"]] == ["content </script>", "output"]
    assert "content </script>" not in page                             # "</" never closes the data script
    np.testing.assert_array_equal(viz.decode_positions(state["motions"][0]), walk.astype(np.float32))
    assert page.count("</script>") == 2


def test_transfer_writes_the_viewer_page(tmp_path, capsys, walk):
    """`python -m mslib transfer … --out OUT.html`: content, output and style side by side; --force as for .bvh."""
    from mslib.cli import main
    np.save(tmp_path / "content.npy", walk[:40])
    np.save(tmp_path / "style.npy", walk[:30])
    out = tmp_path / "o.html"
    args = ["transfer", "--method", "identity", "--content", str(tmp_path / "content.npy"),
            "--style", str(tmp_path / "style.npy"), "--out", str(out), "--json"]
    assert main(args) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["kind"] == "html" and summary["frames"] == 39
    page = out.read_text(encoding="utf-8")
    state = json.loads(re.search(r'id="mslib-viewer-data">(.*?)</script>', page, re.S).group(1))
    assert [m["title"] for m in state["motions"]] == ["content content", "identity", "style style"]
    assert [m["frames"] for m in state["motions"]] == [40, 39, 30]
    assert not re.search(r"https?://", page)
    out.write_text("keep me")
    assert main(args) == 2 and "--force" in capsys.readouterr().err and out.read_text() == "keep me"
    assert main(args + ["--force"]) == 0 and out.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["content.npy", "o.html", "style.npy"]   # no temporaries


def test_the_module_is_package_data():
    import tomllib
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    data = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["mslib"]
    assert "viz/*.js" in data
    js = viewer.JS_PATH.read_text()
    assert "export default { render }" in js and "</script" not in js and "import " not in js


# ---------------------------------------------------------------- the widget
def test_widget_state_repr_and_static_picture(walk):
    pytest.importorskip("anywidget", reason="anywidget is in the notebooks extra")
    w = viz.MotionViewer([walk, walk[::-1]], titles=["forward", "backward"])
    assert w.data == viz.viewer_state([walk, walk[::-1]], titles=["forward", "backward"])
    assert 140_000 < w.state_bytes < 146_000
    assert repr(w) == "MotionViewer(2 motion(s): 'forward' 200 frames, 'backward' 200 frames)"
    data, _ = w._repr_mimebundle_()
    assert data["application/vnd.jupyter.widget-view+json"]["model_id"] == w.model_id
    png = base64.b64decode(data["image/png"])
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and 5_000 < len(png) < 150_000
    assert "image/png" not in viz.MotionViewer(walk, static_image=False)._repr_mimebundle_()[0]
    w.update(walk[:20], titles=["short"])
    assert w.data["motions"][0]["frames"] == 20 and w._png is None
    with pytest.raises(ValueError, match="^titles"):
        viz.MotionViewer(walk, titles=["a", "b"])


def test_old_single_module_names_still_work():
    for name in ("plot_pose", "plot_strip", "plot_trajectory", "animate", "animation_html", "auto_contacts",
                 "plot_curves", "save_png", "skeleton_chains", "SIDE_COLOURS", "PATH_COLOURS", "HTMLString",
                 "_check_positions", "_motion_list"):
        assert getattr(viz, name) is getattr(viz.static, name)
    with pytest.raises(AttributeError):
        viz.no_such_name
