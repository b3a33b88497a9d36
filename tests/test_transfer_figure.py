"""The cue tracks beside a transfer strip: known answers frame by frame, and the figure's shape and errors."""
import numpy as np
import pytest

from mslib import viz
from mslib.evaluation import cues as C
from mslib.evaluation.transfer_figure import plot_transfer
from tests.test_realism import REST, still, swinging, yaw_matrix


def test_tracks_of_a_still_rest_pose_are_constant_and_upright():
    tracks = C.cue_tracks(still(12))
    assert set(tracks) == set(C.TRACKS) and all(t.shape == (12,) for t in tracks.values())
    assert np.ptp(tracks["head_height"]) < 1e-9 and tracks["head_height"][0] > 1.5  # the head well above the floor
    assert abs(tracks["trunk_pitch"]).max() < 5  # the rest pose stands upright
    assert abs(tracks["arm_swing"]).max() < 1e-9  # both wrists level


def test_tracks_are_the_window_cues_frame_by_frame_and_ignore_heading():
    walk = swinging(T=60, f=1.0, arm=0.5)
    tracks, window = C.cue_tracks(walk), C.cues(walk)
    assert tracks["head_height"].mean() == pytest.approx(window["head_height"])
    assert tracks["trunk_pitch"].mean() == pytest.approx(window["trunk_pitch"])
    swing = tracks["arm_swing"]
    assert swing.max() > 0.1 and swing.min() < -0.1  # the wrists take turns in front
    turned = walk @ yaw_matrix(0.7).T + np.array([3.0, 0.0, -2.0])
    for name, t in C.cue_tracks(turned).items():
        np.testing.assert_allclose(t, tracks[name], atol=1e-6, err_msg=name)


def test_leaning_forward_raises_the_trunk_pitch():
    lean = still(10).copy()
    upper = [3, 6, 9, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21]
    pivot = lean[:, 0:1]
    a = np.radians(30)
    rot_x = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])  # +Y toward +Z
    lean[:, upper] = (lean[:, upper] - pivot) @ rot_x.T + pivot
    assert C.cue_tracks(lean)["trunk_pitch"].mean() == pytest.approx(C.cue_tracks(still(10))["trunk_pitch"].mean()
                                                                      + 30, abs=1.0)


def test_plot_transfer_draws_three_strip_rows_and_three_cue_panels():
    walk = swinging(T=40, arm=0.5)
    fig = plot_transfer(still(40), walk, walk, titles=["content", "style: old", "output"])
    assert len(fig.axes) == 6 and fig.dpi >= 100
    cue_axes = fig.axes[3:]
    assert [ax.get_title() for ax in cue_axes] == list(C.TRACKS.values())
    assert all(len(ax.get_lines()) == 3 for ax in cue_axes)  # content, style clip, output
    with_before = plot_transfer(still(40), walk, walk, before=still(40), before_title="stage 1")
    assert all(len(ax.get_lines()) == 4 for ax in with_before.axes[3:])  # and the dashed 'before' track
    with pytest.raises(ValueError, match="titles: three needed"):
        plot_transfer(walk, walk, walk, titles=["a", "b"])
    with pytest.raises(ValueError, match="positions"):
        plot_transfer(walk[:, :5], walk, walk)


def test_plot_strip_into_given_axes_checks_their_number():
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 1)
    assert viz.plot_strip([still(8), still(8)], n_frames=3, axes=axes) is fig
    with pytest.raises(ValueError, match="axes: one per motion"):
        viz.plot_strip([still(8)], n_frames=3, axes=axes)
    plt.close(fig)


def test_plot_cue_comparison_draws_every_output_in_every_panel():
    from mslib.evaluation.transfer_figure import plot_cue_comparison
    walk = swinging(T=40, arm=0.5)
    fig = plot_cue_comparison(still(40), walk, {"a": walk, "b": still(30)})
    assert len(fig.axes) == 3 and all(len(ax.get_lines()) == 4 for ax in fig.axes)
    with pytest.raises(ValueError, match="outputs: at least one"):
        plot_cue_comparison(walk, walk, {})
