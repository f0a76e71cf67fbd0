"""Sentences: known checksums, round trips of every message, specific errors for bad fields."""

import pytest

from calib_core.link.protocol import (
    MAX_SENTENCE_BYTES,
    PROTOCOL_VERSION,
    SEQ_MODULUS,
    Ack,
    Done,
    ErrorReply,
    JointSample,
    MoveJoints,
    ProtocolError,
    RequestJoints,
    RequestState,
    RequestVersion,
    StateReport,
    Stream,
    VersionReport,
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
    assert sentence.startswith(b"$") and sentence.endswith(b"\r\n") and len(sentence) <= MAX_SENTENCE_BYTES
    assert parse_body(sentence[1:-5].decode()) == message


@pytest.mark.parametrize(
    "body, kind, text",
    [
        ("JNT,1,2", "malformed", "JNT needs a sequence number, a time and 1 to 16 joint values"),
        ("JNT,1,2," + ",".join(["0"] * 17), "malformed", "1 to 16 joint values; got 20 fields"),
        ("JNT,1,2,0,0,0,0,0,abc", "malformed", "q6: not a number"),
        ("JNT,1,2,0,0,nan,0,0,0", "non_finite", "q3: not finite"),
        ("JNT,1,2,0,0,0,inf,0,0", "non_finite", "q4"),
        ("JNT,1,2,0,0,0,1e308,0,0", "non_finite", "q4: 1e308 is no joint's value"),
        ("JNT,-1,2,0,0,0,0,0,0", "malformed", "seq"),
        ("JNT,4294967296,2,0,0,0,0,0,0", "malformed", "exceeds"),
        ("XYZ,1", "unknown", "unknown sentence type"),
        ("STR,-5", "malformed", ">= 0"),
        ("MVJ,m1", "malformed", "MVJ needs an id and 1 to 16 joint values"),
        ("VER,two,7", "malformed", "VER version"),
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
    with pytest.raises(ValueError, match=f"exceeds {MAX_SENTENCE_BYTES}"):
        encode("STA,IDLE," + "x" * MAX_SENTENCE_BYTES)


@pytest.mark.parametrize("n", [1, 5, 6, 7, 16])
def test_any_joint_count_round_trips_within_one_sentence(n):
    # The widest values a joint can carry (prismatic mm or revolute deg with 4 decimals), the largest counters.
    sample = JointSample(SEQ_MODULUS - 1, 2**32 - 1, tuple([-12345.6789] * n))
    sentence = encode(sample.body())
    assert len(sentence) <= MAX_SENTENCE_BYTES
    assert parse_body(sentence[1:-5].decode()) == sample
    move = MoveJoints("m99999", tuple(float(v) for v in range(n)))
    assert parse_body(encode(move.body())[1:-5].decode()) == move


def test_version_report_round_trips():
    report = VersionReport(PROTOCOL_VERSION, 7)
    assert parse_body(encode(report.body())[1:-5].decode()) == report
    assert parse_body("VER") == RequestVersion()
