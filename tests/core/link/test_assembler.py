"""The sentence assembler on dirty lines: resynchronisation, rejection, nothing lost or invented."""

import re

import numpy as np
from hypothesis import assume, given, settings, strategies as st

from calib_core.link.assembler import SentenceAssembler
from calib_core.link.protocol import MAX_SENTENCE_BYTES, JointSample, encode

_VALID = re.compile(rb"\$([^$*\r\n]{3,})\*([0-9A-F]{2})\r\n")


def _sample(seq):
    return JointSample(seq, seq * 10, tuple(float(seq % 7 + k) for k in range(6))).body()


def _contains_valid_sentence(data: bytes) -> bool:
    from calib_core.link.protocol import checksum

    return any(int(m.group(2), 16) == checksum(m.group(1)) for m in _VALID.finditer(data))


def test_clean_stream_in_odd_chunks():
    bodies = [_sample(i) for i in range(50)]
    stream = b"".join(encode(b) for b in bodies)
    a = SentenceAssembler()
    out = []
    for i in range(0, len(stream), 7):
        out += a.feed(stream[i : i + 7])
    assert out == bodies
    assert a.counts.sentences == 50 and a.counts.garbage_bytes == 0


def test_each_kind_of_damage_is_rejected_and_counted():
    good = encode(_sample(1))
    bad_sum = good[:-4] + b"00\r\n" if good[-4:-2] != b"00" else good[:-4] + b"11\r\n"
    too_long = b"$" + b"A" * (MAX_SENTENCE_BYTES + 10) + b"\r\n"
    no_cr = good[:-2] + b"\n"
    fragment = good[:20]
    a = SentenceAssembler()
    out = a.feed(b"noise" + bad_sum + too_long + no_cr + fragment + good)
    assert out == [_sample(1)]
    c = a.counts
    assert c.bad_checksum == 1 and c.too_long == 1 and c.malformed == 2
    assert c.garbage_bytes > 5  # "noise" and the tail of the over-long sentence


@settings(max_examples=200, deadline=None)
@given(
    garbage=st.lists(st.binary(min_size=0, max_size=40), min_size=1, max_size=30),
    cuts=st.lists(st.integers(1, 64), min_size=1, max_size=40),
)
def test_valid_sentences_survive_garbage_exactly_once_in_order(garbage, cuts):
    assume(not any(_contains_valid_sentence(g) for g in garbage))
    bodies = [_sample(i) for i in range(len(garbage))]
    stream = b"".join(g + encode(b) for g, b in zip(garbage, bodies))
    a = SentenceAssembler()
    out = []
    pos = 0
    for cut in cuts * (len(stream) // max(sum(cuts), 1) + 1):
        if pos >= len(stream):
            break
        out += a.feed(stream[pos : pos + cut])
        pos += cut
    out += a.feed(stream[pos:])
    assert out == bodies


def test_fuzz_100k_chunks_of_random_garbage():
    rng = np.random.default_rng(1)
    a = SentenceAssembler()
    bodies, out = [], []
    chunks = []
    for i in range(100_000):
        g = rng.integers(0, 256, int(rng.integers(0, 12)), dtype=np.uint8).tobytes()
        chunks.append(g)
        if i % 10 == 0:
            body = _sample(i)
            bodies.append(body)
            chunks.append(encode(body))
    stream = b"".join(chunks)
    for start in range(0, len(stream), 509):
        out += a.feed(stream[start : start + 509])
    # Every valid sentence exactly once and in order; any extra would be a sentence invented from garbage.
    assert out == bodies
