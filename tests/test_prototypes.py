"""Paper D's prototype clustering: Sinkhorn balancing, EMA (D Eq. 8), InfoNCE (D Eq. 5–6), freezing."""
import pytest
import torch
import torch.nn.functional as F

from mslib.models.clusterstyle.prototypes import (PrototypeBank, PrototypeConfig, PrototypeStyleModel, ema_update,
                                     local_means, matched_purity, prototype_nce, sinkhorn, substyle_confusion)


def test_sinkhorn_rows_sum_to_one_and_balances_a_known_case():
    # four features all nearer prototype 0; the two with the smallest margin must move to prototype 1
    scores = torch.tensor([[0.9, 0.1], [0.8, 0.2], [0.6, 0.5], [0.55, 0.5]])
    assert (scores.argmax(1) == 0).all()  # plain argmax: prototype 1 unused
    q = sinkhorn(scores, epsilon=0.05, iters=50)
    assert torch.allclose(q.sum(1), torch.ones(4), atol=1e-5)
    assert torch.allclose(q.sum(0), torch.full((2,), 2.0), atol=1e-2)  # each used N/K = 2 times
    assert q.argmax(1).tolist() == [0, 0, 1, 1]
    q3 = sinkhorn(scores, epsilon=0.05, iters=3)  # the workbook's 3 iterations: rows exact, columns close
    assert torch.allclose(q3.sum(1), torch.ones(4), atol=1e-5)
    assert (q3.sum(0) - 2.0).abs().max() < 0.3
    assert q3.argmax(1).tolist() == [0, 0, 1, 1]


def test_sinkhorn_keeps_a_clear_assignment_and_rejects_bad_scores():
    scores = torch.eye(3).repeat(2, 1) * 0.8  # six features, two per prototype, already balanced
    assert sinkhorn(scores).argmax(1).tolist() == [0, 1, 2, 0, 1, 2]
    with pytest.raises(ValueError, match="scores"):
        sinkhorn(torch.zeros(3))


def test_ema_update_formula():
    p = torch.tensor([[1.0, 0.0]])
    mean = torch.tensor([[0.0, 1.0]])
    out = ema_update(p, mean, 0.95)
    expected = torch.tensor([[0.95, 0.05]]) / (0.95 ** 2 + 0.05 ** 2) ** 0.5
    assert torch.allclose(out, expected, atol=1e-6)
    assert torch.allclose(out.norm(dim=1), torch.ones(1))


def test_bank_update_moves_only_assigned_prototypes_and_freezes():
    bank = PrototypeBank(n_styles=2, k=2, dim=3, seed=0)
    before = bank.prototypes.clone()
    f = F.normalize(torch.tensor([[1.0, 0.0, 0.0], [1.0, 0.1, 0.0]]), dim=1)
    bank.update(f, torch.tensor([1, 1]), torch.tensor([0, 0]), momentum=0.95)
    after = bank.prototypes
    expected = ema_update(before[1, 0:1], f.mean(0, keepdim=True), 0.95)
    assert torch.allclose(after[1, 0:1], expected, atol=1e-6)
    unchanged = torch.ones(2, 2, dtype=torch.bool)
    unchanged[1, 0] = False
    assert torch.equal(after[unchanged], before[unchanged])
    bank.freeze()
    frozen = bank.prototypes.clone()
    bank.update(f, torch.tensor([0, 1]), torch.tensor([1, 1]), momentum=0.5)
    assert torch.equal(bank.prototypes, frozen)


def test_infonce_is_lower_when_the_feature_matches_its_prototype():
    torch.manual_seed(0)
    protos = F.normalize(torch.randn(3, 2, 8), dim=-1)  # 3 styles × 2 prototypes
    target = protos[1, 0]
    near = F.normalize(target + 0.05 * torch.randn(8), dim=0)[None]
    far = F.normalize(protos[2, 1] + 0.05 * torch.randn(8), dim=0)[None]
    s, k = torch.tensor([1]), torch.tensor([0])
    inter_near, intra_near = prototype_nce(near, s, k, protos, tau=0.05)
    inter_far, intra_far = prototype_nce(far, s, k, protos, tau=0.05)
    assert inter_near < inter_far and intra_near < intra_far
    assert intra_near >= inter_near  # intra has more negatives (own style's other prototype)


def test_inter_loss_ignores_own_style_negatives_but_intra_does_not():
    torch.manual_seed(1)
    protos = F.normalize(torch.randn(2, 3, 4), dim=-1)
    f = F.normalize(torch.randn(5, 4), dim=-1)
    s, k = torch.tensor([0, 0, 1, 1, 0]), torch.tensor([0, 1, 2, 0, 0])
    moved = protos.clone()
    moved[0, 2] = f[0]  # style 0's prototype 2: a negative of feature 0 within its own style
    a_inter, a_intra = prototype_nce(f[:1], s[:1], k[:1], protos)
    b_inter, b_intra = prototype_nce(f[:1], s[:1], k[:1], moved)
    assert torch.isclose(a_inter, b_inter) and b_intra > a_intra


def test_local_means_windows():
    x = torch.arange(31, dtype=torch.float32)[None, :, None].expand(2, 31, 4)
    loc = local_means(x, 10)
    assert loc.shape == (2, 3, 4)
    assert torch.allclose(loc[0, :, 0], torch.tensor([4.5, 14.5, 24.5]))
    assert local_means(x[:, :5], 10).shape == (2, 1, 4)


def test_model_features_are_unit_vectors_and_training_freezes_prototypes():
    cfg = PrototypeConfig.preset("course", dim=16, layers=1, heads=2, k_local=2, window=4, freeze_after=2, n_styles=3)
    model = PrototypeStyleModel(cfg, seed=0).train()
    x, styles = torch.randn(6, 12, 263), torch.tensor([0, 0, 1, 1, 2, 2])
    g, loc = model.features(x)
    assert g.shape == (6, 16) and loc.shape == (6, 3, 16)
    assert torch.allclose(g.norm(dim=-1), torch.ones(6), atol=1e-5)
    assert model.style_tokens(x).shape == (6, 4, 16)
    p0 = model.global_bank.prototypes.clone()
    logs = model.training_step({"features": x, "style_index": styles})
    logs["loss"].backward()
    assert not torch.equal(model.global_bank.prototypes, p0)  # EMA moved them
    assert model.encoder.inp.weight.grad is not None
    assert model.global_bank.prototypes.grad is None and not model.global_bank.prototypes.requires_grad
    model.training_step({"features": x, "style_index": styles})  # step 2: frozen from now on
    p2 = model.global_bank.prototypes.clone()
    model.training_step({"features": x, "style_index": styles})
    assert bool(model.global_bank.frozen) and torch.equal(model.global_bank.prototypes, p2)


def test_classifier_head_variant_and_bad_input():
    cfg = PrototypeConfig.preset("course", dim=16, layers=1, heads=2, head="classifier", n_styles=3)
    model = PrototypeStyleModel(cfg)
    logs = model.style_loss(torch.randn(4, 20, 263), torch.tensor([0, 1, 2, 0]))
    assert logs["loss"].ndim == 0 and not hasattr(model, "global_bank")
    with pytest.raises(ValueError, match="x"):
        model.features(torch.randn(4, 20, 10))
    with pytest.raises(ValueError, match="head"):
        PrototypeConfig(head="kmeans")


def test_substyle_confusion_counts_nearest_own_style_prototypes_and_purity():
    cfg = PrototypeConfig.preset("course", dim=16, layers=1, heads=2, n_styles=2, k_global=3)
    model = PrototypeStyleModel(cfg, seed=0).eval()
    x = torch.randn(7, 12, 263)
    styles, subs = torch.tensor([0, 0, 1, 1, 1, 0, 1]), torch.tensor([0, 1, 2, 2, 0, 1, 1])
    table = substyle_confusion(model, x, styles, subs, n_substyles=3)
    assert table.shape == (2, 3, 3) and int(table.sum()) == 7
    k = model.assign_global(x, styles)
    for i in range(7):  # each clip lands in (its style, its sub-style, its nearest own-style prototype)
        assert table[styles[i], subs[i], k[i]] >= 1
    assert table[0].sum(1).tolist() == [1, 2, 0] and table[1].sum(1).tolist() == [1, 1, 2]
    with pytest.raises(ValueError, match="lengths"):
        substyle_confusion(model, x, styles[:3], subs, 3)


def test_matched_purity_known_answers():
    perfect = torch.tensor([[[0, 5, 0], [0, 0, 4], [3, 0, 0]]])  # a permutation of a diagonal table
    assert matched_purity(perfect) == 1.0
    mixed = torch.tensor([[[2, 2], [1, 3]], [[4, 0], [0, 0]]])  # best: 2 + 3 of 8, then 4 of 4
    assert matched_purity(mixed) == pytest.approx(9 / 12)
