"""Every registered method, quickly: it runs on a few fixed test pairs, returns finite 263-d features, and
there does what neither reference row does on its own: more target styles recognised than identity (the
content returned), more contents recognised than copy_style (the style clip returned). H against both rows,
and the 200-pair bars of each method, are benchmarks (`make bench`): on 16 pairs one pair moves CRA or SRA by
6.25 points, too coarse to rank an H that needs both. (On the first 8 alone, three content clips are already
read as their pair's target style, so identity's SRA there is far from its 200-pair figure.)"""
import numpy as np
import pytest

from mslib.evaluation import bench
from mslib.models.registry import known_methods
from mslib.motion.features import N_FEATURES

N_PAIRS = 16  # the first pairs of the default draw
METHODS = [m for m in known_methods() if m not in ("identity", "copy_style")]


@pytest.fixture(scope="module")
def scored():
    """The pairs, one shared evaluator, and the rows of both references on those pairs."""
    pairs, ev = bench.load_pairs(0, N_PAIRS), bench.Evaluator()
    refs = {m: bench.run_bench(m, pairs=pairs, evaluator=ev) for m in ("identity", "copy_style")}
    return pairs, ev, refs


@pytest.mark.parametrize("method", METHODS)
def test_method_returns_features_and_does_what_neither_reference_does(method, scored):
    pairs, ev, refs = scored
    transfer = bench.get_method(method)
    for content, style in pairs[:2]:
        out = np.asarray(transfer(content, style))
        assert out.shape == (len(content["joints"]) - 1, N_FEATURES) and np.isfinite(out).all()
    row = bench.run_bench(method, pairs=pairs, evaluator=ev)
    assert row["pairs"] == N_PAIRS and np.isfinite(row["h"])
    assert row["sra"] > refs["identity"]["sra"], f"{method}: SRA {row['sra']} not above identity's"
    assert row["cra"] > refs["copy_style"]["cra"], f"{method}: CRA {row['cra']} not above copy_style's"


def test_the_evaluator_reads_one_motion_as_its_batch_scores_say(scored):
    pairs, ev, _ = scored
    motions = [c["joints"] for c, _ in pairs[:3]] + [s["joints"] for _, s in pairs[:3]]
    c_logits, s_logits, _ = ev.score(motions)
    assert [ev.read_content(m) for m in motions] == [ev.content.classes[i] for i in c_logits.argmax(1)]
    assert [ev.read_style(m) for m in motions] == [ev.style.classes[i] for i in s_logits.argmax(1)]
    assert [ev.read_style(s["joints"]) for _, s in pairs[:3]] == [s["style"] for _, s in pairs[:3]]  # held-out clips
