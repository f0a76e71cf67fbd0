"""Fault injection on the simulator's outgoing bytes: garbage, corrupted and dropped sentences."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class FaultInjector:
    """Per-sentence probabilities: ``noise_rate`` random garbage bytes before it, ``corrupt_rate``
    one byte flipped in it, ``drop_rate`` not sent at all. Deterministic for a seed."""

    noise_rate: float = 0.0
    corrupt_rate: float = 0.0
    drop_rate: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("noise_rate", "corrupt_rate", "drop_rate"):
            v = getattr(self, name)
            if not 0.0 <= v <= 1.0:
                raise ValueError(f"--{name.replace('_', '-')} must lie in [0, 1], got {v}")
        self._rng = np.random.default_rng(self.seed)
        self.dropped = 0
        self.corrupted = 0
        self.noise_bursts = 0

    def apply(self, sentence: bytes) -> bytes:
        rng = self._rng
        out = b""
        if self.noise_rate and rng.random() < self.noise_rate:
            out += rng.integers(0, 256, int(rng.integers(1, 24)), dtype=np.uint8).tobytes()
            self.noise_bursts += 1
        if self.drop_rate and rng.random() < self.drop_rate:
            self.dropped += 1
            return out
        if self.corrupt_rate and rng.random() < self.corrupt_rate:
            b = bytearray(sentence)
            i = int(rng.integers(0, len(b)))
            b[i] ^= int(rng.integers(1, 256))
            sentence = bytes(b)
            self.corrupted += 1
        return out + sentence
