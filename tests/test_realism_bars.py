"""The realism bars (make bench): the built-in styles against real Xia capture, read from ../shared/data.

real → built-in: a classifier trained on the real train split recognises built-in style test windows
(≥ 85 %; the same recipe reaches about 94 % on real test windows). built-in → real: the packaged style
evaluator, trained on built-in data only, recognises the real test grid's takes (≥ 80 %). Both as the
realism report (`python -m mslib data realism`) computes them; the grid is only ever scored here.
"""
import pytest

from mslib.evaluation import realism as R

pytestmark = pytest.mark.bench

REAL_TO_BUILTIN, BUILTIN_TO_REAL, BUILTIN_SEPARABLE = 85.0, 80.0, 95.0


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    from data_prep.bvh import convert
    from tests.conftest import SHARED_DATA
    if not (SHARED_DATA / "xia_train").is_dir() or not (SHARED_DATA / "xia_grid").is_dir():
        pytest.skip(f"real Xia takes not found at {SHARED_DATA}/xia_train and xia_grid "
                    "(only developers and CI have ../shared)")
    root = tmp_path_factory.mktemp("xia")
    for name in ("xia_train", "xia_grid"):
        summary = convert(SHARED_DATA / name, root / name, "auto", "xia", progress=False)
        assert summary["failed"] == 0, summary
    return R.realism_report(root / "xia_train", root / "xia_grid", progress=False)


@pytest.mark.xfail(strict=True, reason="bar not met yet: the built-in styles (generator v9: knees bend forward, the "
                   "per-joint layer refitted) reach about 81 % of built-in test windows (walks 96 %, runs 96 %, kicks 76 %, "
                   "punches 76 %, jumps 62 %: the layer matches where a cell's windows fall on average, not the shape of a "
                   "punch or a jump) and 80 % of the five times as many train windows (v8: 77 % and 77 %)")
def test_a_judge_of_real_styles_recognises_the_builtin_ones(report):
    rb = report["real_to_builtin"]
    assert rb["real_test_windows"]["accuracy"] >= 80  # the judge itself is good on real test windows
    assert rb["builtin_test_windows"]["accuracy"] >= REAL_TO_BUILTIN, R.format_report(report)


@pytest.mark.xfail(strict=True, reason="bar not met yet: the packaged evaluator, retrained on the v9 corpora, "
                   "recognises 78 % of the real test takes (v8: 75 %) and 79 % of the real train takes (v8: 79 %); it "
                   "misses most often the neutral, angry and proud takes (60 % each)")
def test_the_packaged_evaluator_recognises_real_styles(report):
    br = report["builtin_to_real"]
    assert br["builtin_test_clips_accuracy"] >= BUILTIN_SEPARABLE  # the built-in styles stay separable
    assert br["real_test_takes"]["n"] == 40
    assert br["real_test_takes"]["accuracy"] >= BUILTIN_TO_REAL, R.format_report(report)
