"""mslib.models.common.windows: where the windows start, and the cross-fade's known answers."""
import numpy as np
import pytest

from mslib.models.common.windows import overlap_blend, window_starts


def test_window_starts_cover_every_row_half_a_window_apart():
    assert window_starts(130, 48) == [0, 24, 48, 72, 82]  # the last window ends at the last row
    assert window_starts(96, 48) == [0, 24, 48]
    assert window_starts(48, 48) == [0] and window_starts(10, 48) == [0]
    for n, w in ((130, 48), (97, 32), (201, 9)):
        starts = window_starts(n, w)
        covered = np.zeros(n, bool)
        for s in starts:
            covered[s:s + w] = True
        assert covered.all() and starts[-1] + w == n and np.diff(starts).max() <= w // 2
    with pytest.raises(ValueError, match="window"):
        window_starts(10, 1)


def test_overlap_blend_known_answers():
    x = np.random.default_rng(0).normal(size=(130, 5))
    np.testing.assert_allclose(overlap_blend(lambda a: a, x, 48), x)  # the weights sum to one on every row
    np.testing.assert_allclose(overlap_blend(lambda a: 2 * a[:, :2], x, 48), 2 * x[:, :2])  # another width out
    seen = []
    whole = overlap_blend(lambda a: seen.append(len(a)) or a - a.mean(0), x, 0)  # 0: the whole clip at once
    assert seen == [130] and np.allclose(whole, x - x.mean(0))
    seen.clear()
    short = overlap_blend(lambda a: seen.append(len(a)) or a - a.mean(0), x[:40], 48)  # shorter than a window
    assert seen == [40] and np.allclose(short, x[:40] - x[:40].mean(0))


def test_overlap_blend_takes_time_statistics_per_window():
    t = np.arange(200, dtype=float)[:, None]  # a ramp: its whole-clip mean is far from any window's
    centred = lambda a: a - a.mean(0)  # noqa: E731  (what an instance norm does)
    out = overlap_blend(centred, t, 32)
    assert np.abs(out).max() <= 16  # within a window's half-length of its own window's mean
    assert np.abs(centred(t)).max() > 90
    seen = []
    overlap_blend(lambda a: seen.append(len(a)) or a, t, 32)
    assert set(seen) == {32} and len(seen) == len(window_starts(200, 32))
