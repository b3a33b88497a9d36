"""A small learned text encoder for captions — a pluggable slot: anything with
`encode_text(list[str]) -> (B, D)` can replace it (e.g. a real sentence encoder).

API (stable):
    tok = Tokenizer.from_captions(captions)      # word vocabulary of the captions; "<pad>" 0, "<unk>" 1
    ids, mask = tok(["a person walks", ...])     # (B, L) long, (B, L) bool; unknown words → <unk>
    enc = TextEncoder(tok.vocab, TextConfig())   # embeddings + positions + a small transformer, mean-pooled
    emb = enc.encode_text(["an old person walks forward"])   # (B, D), L2-normalised
    enc = load_text_encoder(path=None)           # the text tower of the packaged style_extractor checkpoint
It is trained jointly with paper B's style extractor (CLIP-style, mslib.models.common.style_extractor) on
the style corpus's captions; `python -m mslib train style_extractor --preset course` writes both.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import ClassVar

import torch
from torch import nn

from ...checkpoints import course_path, read_checkpoint
from .config import Config
from .layers import PositionalEncoding, transformer_encoder

PAD, UNK = "<pad>", "<unk>"
_WORD = re.compile(r"[a-z]+")


def words(text: str) -> list:
    """Lower-case alphabetic words of a caption."""
    if not isinstance(text, str):
        raise ValueError(f"text: expected a string, got {type(text).__name__}")
    return _WORD.findall(text.lower())


class Tokenizer:
    """Word-level tokenizer over a fixed vocabulary; index 0 pads, 1 stands for any unknown word."""

    def __init__(self, vocab: list, max_words: int = 16):
        vocab = list(vocab)
        if vocab[:2] != [PAD, UNK]:
            raise ValueError(f"vocab: must start with {PAD!r}, {UNK!r}; got {vocab[:2]}")
        self.vocab, self.max_words = vocab, int(max_words)
        self.index = {w: i for i, w in enumerate(vocab)}

    @classmethod
    def from_captions(cls, captions, max_words: int = 16) -> "Tokenizer":
        """The sorted word set of `captions` after <pad>, <unk>."""
        found = sorted({w for c in captions for w in words(c)})
        if not found:
            raise ValueError("captions: no words found to build a vocabulary")
        return cls([PAD, UNK] + found, max_words)

    def __call__(self, texts) -> tuple:
        if isinstance(texts, str) or not len(texts):
            raise ValueError("texts: expected a non-empty list of strings")
        rows = [[self.index.get(w, 1) for w in words(t)][: self.max_words] or [1] for t in texts]
        L = max(len(r) for r in rows)
        ids = torch.zeros(len(rows), L, dtype=torch.long)
        for i, r in enumerate(rows):
            ids[i, : len(r)] = torch.tensor(r)
        return ids, ids != 0


@dataclass
class TextConfig(Config):
    """Sizes of the text tower (a small one: neither B nor D fixes it; the course uses its PRESETS)."""

    dim: int = 128
    out_dim: int = 128
    heads: int = 4
    layers: int = 1
    max_words: int = 16

    STORED_BESIDE: ClassVar[tuple] = ("vocab",)  # a checkpoint keeps the tokenizer's vocabulary with the sizes


class TextEncoder(nn.Module):
    """Word embeddings + positions → transformer → masked mean → linear → L2-normalised (B, out_dim)."""

    def __init__(self, vocab: list, cfg: TextConfig | None = None):
        super().__init__()
        cfg = cfg or TextConfig()
        self.cfg, self.tokenizer = cfg, Tokenizer(vocab, cfg.max_words)
        self.config = {"vocab": list(vocab), **cfg.to_dict()}
        self.embed = nn.Embedding(len(vocab), cfg.dim, padding_idx=0)
        self.pos = PositionalEncoding(cfg.dim, max_len=cfg.max_words)
        self.body = transformer_encoder(cfg.dim, cfg.heads, cfg.layers, 2, 0.0)
        self.proj = nn.Linear(cfg.dim, cfg.out_dim)

    def forward(self, ids: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """(B, L) ids, (B, L) mask → (B, out_dim) unit vectors."""
        h = self.body(self.pos(self.embed(ids)), src_key_padding_mask=~mask)  # (B, L, D)
        w = mask.unsqueeze(-1).to(h.dtype)
        pooled = (h * w).sum(1) / w.sum(1).clamp_min(1.0)
        return nn.functional.normalize(self.proj(pooled), dim=-1)

    def encode_text(self, texts) -> torch.Tensor:
        """A list of captions → (B, out_dim) embeddings on this module's device."""
        ids, mask = self.tokenizer(texts)
        dev = self.embed.weight.device
        return self(ids.to(dev), mask.to(dev))


def load_text_encoder(path=None, device="cpu") -> TextEncoder:
    """The text tower ("text." weights) of a style_extractor checkpoint (default: the packaged one)."""
    path = course_path("style_extractor") if path is None else path
    blob = read_checkpoint(path, "style_extractor")
    tcfg = blob["config"].get("text")
    if not tcfg:
        raise ValueError(f"checkpoint {path}: has no text encoder config")
    enc = TextEncoder(tcfg["vocab"], TextConfig.from_dict(tcfg))
    state = {k[len("text."):]: v for k, v in blob["state_dict"].items() if k.startswith("text.")}
    enc.load_state_dict(state)
    return enc.to(device).eval()
