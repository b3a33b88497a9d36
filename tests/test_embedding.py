"""How codes group (mslib.evaluation.embedding): known answers of the silhouette and neighbour measures."""
import numpy as np
import pytest

from mslib.evaluation import embedding as E


def test_silhouette_purity_and_neighbours_known_answers():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(20, 4)) * 0.01, rng.normal(size=(20, 4)) * 0.01 + 5
    codes, labels = np.concatenate([a, b]), np.array(["x"] * 20 + ["y"] * 20)
    assert E.silhouette(codes, labels) > 0.99
    assert E.nearest_neighbour_purity(codes, labels, "x") == 1.0
    assert E.nn_accuracy(codes, labels) == 1.0
    alternating = np.array(["p", "q"] * 20)  # a label that ignores the two clusters
    scores = E.code_scores(codes, labels, alternating)
    assert scores["silhouette"] > 0.99 and scores["silhouette_by_content"] < 0.1
    line = np.array([0.0, 1, 3, 4, 7, 8])[:, None]  # nearest neighbours pair up: (0, 1), (3, 4), (7, 8)
    assert E.nn_accuracy(line, np.array(list("aabbaa"))) == pytest.approx(1.0)
    assert E.nn_accuracy(line, np.array(list("ababab"))) == 0.0
    # groups: a code's own group is not searched. Two "a" windows of one recording (0, 0.5), a "b" at 1.2, an "a" at 5:
    pts, lab, rec = np.array([[0.0], [0.5], [1.2], [5.0]]), np.array(list("aaba")), np.array(list("gghk"))
    assert E.nearest_neighbour_purity(pts, lab, "a") == pytest.approx(2 / 3)  # 0 ↔ 0.5 find each other, 5 finds b
    assert E.nearest_neighbour_purity(pts, lab, "a", rec) == 0.0  # outside their recording, 0 and 0.5 find b too
    mixed = rng.normal(size=(40, 4))
    assert abs(E.silhouette(mixed, labels)) < 0.1
    with pytest.raises(ValueError, match="labels"):
        E.silhouette(codes, ["x"] * 40)
