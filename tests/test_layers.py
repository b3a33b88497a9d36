"""Shared model blocks: AdaIN statistics (A Eq. 2), masks, residual blocks, positions."""
import torch

from mslib.models.common.layers import PositionalEncoding, ResBlock1d, adain, channel_stats, sinusoid


def test_adain_output_has_style_statistics():
    torch.manual_seed(0)
    c = torch.randn(3, 40, 8) * 2 + 1
    s = torch.randn(3, 25, 8) * 0.5 - 3
    mu_s, sig_s = channel_stats(s)
    out = adain(c, mu_s, sig_s)
    mu_o, sig_o = channel_stats(out)
    assert torch.allclose(mu_o, mu_s, atol=1e-5) and torch.allclose(sig_o, sig_s, atol=1e-3)


def test_adain_switches_keep_the_other_statistic():
    torch.manual_seed(1)
    c, s = torch.randn(2, 30, 4) * 3 + 2, torch.randn(2, 30, 4) * 0.2 - 1
    mu_c, sig_c = channel_stats(c)
    mu_s, sig_s = channel_stats(s)
    mean_only = adain(c, mu_s, sig_s, use_std=False)
    var_only = adain(c, mu_s, sig_s, use_mean=False)
    m, sg = channel_stats(mean_only)
    assert torch.allclose(m, mu_s, atol=1e-5) and torch.allclose(sg, sig_c, atol=1e-4)
    m, sg = channel_stats(var_only)
    assert torch.allclose(m, mu_c, atol=1e-5) and torch.allclose(sg, sig_s, atol=1e-3)


def test_masked_stats_ignore_padding():
    x = torch.randn(1, 10, 3)
    padded = torch.cat([x, 100 * torch.ones(1, 5, 3)], 1)
    mask = torch.arange(15)[None] < 10
    for a, b in zip(channel_stats(padded, mask), channel_stats(x)):
        assert torch.allclose(a, b, atol=1e-5)


def test_resblock_and_positions_shapes():
    assert ResBlock1d(6)(torch.randn(2, 6, 11)).shape == (2, 6, 11)
    emb = sinusoid(torch.arange(5), 7)
    assert emb.shape == (5, 7) and torch.allclose(emb[0, :3], torch.ones(3))
    pe = PositionalEncoding(8, max_len=16)
    assert pe(torch.zeros(2, 16, 8)).shape == (2, 16, 8)
    try:
        pe(torch.zeros(1, 17, 8))
    except ValueError as e:
        assert "max_len" in str(e)
    else:
        raise AssertionError("expected a ValueError")
