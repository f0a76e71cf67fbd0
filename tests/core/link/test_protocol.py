"""Sentences: known checksums, round trips of every message, specific errors for bad fields."""

import pytest

from calib_core.link.protocol import (
    Ack,
    Done,
    ErrorReply,
    JointSample,
    MoveJoints,
    ProtocolError,
    RequestJoints,
    RequestState,
    StateReport,
    Stream,
    checksum,
    encode,
    parse_body,
)


def test_known_checksums():
    # XOR of 'R', 'Q', 'J' = 0x52 ^ 0x51 ^ 0x4A = 0x49
    assert encode("RQJ") == b"$RQJ*49\r\n"
    # The classic NMEA example sentence.
    assert checksum(b"GPGLL,5057.970,N,00146.110,E,142451,A") == 0x27


@pytest.mark.parametrize(
    "message",
    [
        JointSample(4294967295, 123456, (1.5, -20.25, 33.0, 0.0001, -179.9999, 90.0)),
        Ack("MVJ", "m12"),
        Done("m12"),
        StateReport("IDLE", "stream 50 Hz"),
        ErrorReply("LIMIT", "move m3: joint 2 target 200.00 deg outside [-85.0; 155.0]"),
        RequestJoints(),
        Stream(125.0),
        MoveJoints("m7", (10.0, 20.0, -30.0, 0.0, 45.5, -90.0)),
        RequestState(),
    ],
)
def test_round_trip(message):
    sentence = encode(message.body())
    assert sentence.startswith(b"$") and sentence.endswith(b"\r\n") and len(sentence) <= 128
    assert parse_body(sentence[1:-5].decode()) == message


@pytest.mark.parametrize(
    "body, kind, text",
    [
        ("JNT,1,2,3", "malformed", "JNT needs 9 fields"),
        ("JNT,1,2,0,0,0,0,0,abc", "malformed", "q6: not a number"),
        ("JNT,1,2,0,0,nan,0,0,0", "non_finite", "q3: not finite"),
        ("JNT,1,2,0,0,0,inf,0,0", "non_finite", "q4"),
        ("JNT,-1,2,0,0,0,0,0,0", "malformed", "seq"),
        ("JNT,4294967296,2,0,0,0,0,0,0", "malformed", "exceeds"),
        ("XYZ,1", "unknown", "unknown sentence type"),
        ("STR,-5", "malformed", ">= 0"),
        ("MVJ,m1,1,2,3", "malformed", "MVJ needs 8 fields"),
        ("ACK,MVJ", "malformed", "ACK with 1 fields"),
    ],
)
def test_bad_fields(body, kind, text):
    with pytest.raises(ProtocolError, match=text) as info:
        parse_body(body)
    assert info.value.kind == kind


def test_bodies_that_cannot_be_sent():
    with pytest.raises(ValueError, match="may not contain"):
        encode("STA,IDLE,a*b")
    with pytest.raises(ValueError, match="exceeds 128"):
        encode("STA,IDLE," + "x" * 130)
