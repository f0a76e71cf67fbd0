"""Assembling sentences from a byte stream that may be dirty.

Resynchronises on ``$`` after garbage; rejects and counts bad checksums, over-long sentences
and anything that is not ``$body*HH\\r\\n``. A read that timed out may end mid-sentence: the
partial sentence is kept until its terminator arrives. Never delivers a sentence twice and
never invents one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from calib_core.link.protocol import MAX_SENTENCE_BYTES, checksum

_HEX = b"0123456789ABCDEF"


@dataclass
class AssemblerCounts:
    """What the assembler threw away: ``garbage_bytes`` outside any sentence, ``bad_checksum``,
    ``too_long`` (no terminator within MAX_SENTENCE_BYTES), ``malformed`` (bad framing: a ``$`` inside,
    missing ``*HH``, a lone CR or LF)."""

    sentences: int = 0
    garbage_bytes: int = 0
    bad_checksum: int = 0
    too_long: int = 0
    malformed: int = 0


@dataclass
class SentenceAssembler:
    """Feed bytes in any chunks; get verified sentence bodies (ASCII ``str``) out, in order."""

    counts: AssemblerCounts = field(default_factory=AssemblerCounts)
    _buffer: bytearray = field(default_factory=bytearray)
    _in_sentence: bool = False

    def feed(self, data: bytes) -> list[str]:
        bodies: list[str] = []
        buf = self._buffer
        for byte in data:
            if not self._in_sentence:
                if byte == 0x24:  # '$'
                    self._in_sentence = True
                    buf.clear()
                    buf.append(byte)
                else:
                    self.counts.garbage_bytes += 1
                continue
            if byte == 0x24:  # a new sentence starts before this one ended: drop the fragment
                self.counts.malformed += 1
                buf.clear()
                buf.append(byte)
                continue
            buf.append(byte)
            if byte == 0x0A:  # LF ends a sentence
                body = self._verify(bytes(buf))
                if body is not None:
                    bodies.append(body)
                self._in_sentence = False
                buf.clear()
            elif len(buf) >= MAX_SENTENCE_BYTES:
                self.counts.too_long += 1
                self._in_sentence = False
                buf.clear()
        return bodies

    def _verify(self, sentence: bytes) -> str | None:
        # $ body * H H CR LF, the body at least a sentence type
        if len(sentence) < 9 or sentence[-2] != 0x0D or sentence[-5] != 0x2A:
            self.counts.malformed += 1
            return None
        body = sentence[1:-5]
        hh = sentence[-4:-2]
        if hh[0] not in _HEX or hh[1] not in _HEX or b"*" in body or b"\r" in body or b"\n" in body:
            self.counts.malformed += 1
            return None
        if int(hh, 16) != checksum(body):
            self.counts.bad_checksum += 1
            return None
        try:
            text = body.decode("ascii")
        except UnicodeDecodeError:
            self.counts.malformed += 1
            return None
        if not text.isprintable():
            self.counts.malformed += 1
            return None
        self.counts.sentences += 1
        return text

    def reset(self) -> None:
        """Forget a partial sentence (after a reconnect the stream starts afresh)."""
        self._buffer.clear()
        self._in_sentence = False
