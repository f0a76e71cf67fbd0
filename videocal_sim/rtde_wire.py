"""Universal Robots' RTDE protocol (the *Real-Time Data Exchange* guide), the controller's side: packages,
their types, and the variables' types, as the simulated UR controller answers ``ur_rtde``.

A package is a big-endian ``uint16`` size (the whole package, header included), a ``uint8`` type and the
payload. Protocol version 2: setup packages carry a recipe id, data packages start with it.
"""

from __future__ import annotations

import struct

REQUEST_PROTOCOL_VERSION = ord("V")
GET_URCONTROL_VERSION = ord("v")
TEXT_MESSAGE = ord("M")
DATA_PACKAGE = ord("U")
CONTROL_PACKAGE_SETUP_OUTPUTS = ord("O")
CONTROL_PACKAGE_SETUP_INPUTS = ord("I")
CONTROL_PACKAGE_START = ord("S")
CONTROL_PACKAGE_PAUSE = ord("P")

# The guide's type names and their packing (big endian).
FORMATS = {
    "BOOL": "?",
    "UINT8": "B",
    "UINT32": "I",
    "UINT64": "Q",
    "INT32": "i",
    "DOUBLE": "d",
    "VECTOR3D": "3d",
    "VECTOR6D": "6d",
    "VECTOR6INT32": "6i",
    "VECTOR6UINT32": "6I",
}

# Output variables the simulated controller offers, with the guide's types.
OUTPUTS = {
    "timestamp": "DOUBLE",
    "target_q": "VECTOR6D",
    "target_qd": "VECTOR6D",
    "target_qdd": "VECTOR6D",
    "actual_q": "VECTOR6D",
    "actual_qd": "VECTOR6D",
    "actual_TCP_pose": "VECTOR6D",
    "target_TCP_pose": "VECTOR6D",
    "actual_execution_time": "DOUBLE",
    "robot_mode": "INT32",
    "joint_mode": "VECTOR6INT32",
    "safety_mode": "INT32",
    "safety_status": "INT32",
    "speed_scaling": "DOUBLE",
    "target_speed_fraction": "DOUBLE",
    "runtime_state": "UINT32",
    "robot_status_bits": "UINT32",
    "safety_status_bits": "UINT32",
    "actual_digital_input_bits": "UINT64",
    "actual_digital_output_bits": "UINT64",
    "output_bit_registers0_to_31": "UINT32",
    "output_bit_registers32_to_63": "UINT32",
    "payload": "DOUBLE",
    **{f"output_int_register_{i}": "INT32" for i in range(48)},
    **{f"output_double_register_{i}": "DOUBLE" for i in range(48)},
}

ROBOT_MODE_RUNNING = 7
SAFETY_MODE_NORMAL, SAFETY_MODE_PROTECTIVE_STOP = 1, 3
RUNTIME_STATE_STOPPED, RUNTIME_STATE_PLAYING = 1, 2
# robot_status_bits: 0 power on, 1 program running, 2 teach button pressed, 3 power button pressed.
# safety_status_bits: 0 normal mode, 1 reduced, 2 protective stopped, ... 7 emergency stopped.


def package(kind: int, payload: bytes = b"") -> bytes:
    return struct.pack(">HB", 3 + len(payload), kind) + payload


def read_package(sock) -> tuple[int, bytes] | None:
    """``(type, payload)`` of the next package, or None when the client hung up."""
    header = _read_exact(sock, 3)
    if header is None:
        return None
    size, kind = struct.unpack(">HB", header)
    payload = _read_exact(sock, size - 3) if size > 3 else b""
    return None if payload is None else (kind, payload)


def _read_exact(sock, n: int) -> bytes | None:
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            return None
        data += chunk
    return data


def pack_values(types: list[str], values: list) -> bytes:
    out = b""
    for kind, value in zip(types, values):
        fmt = FORMATS[kind]
        out += struct.pack(">" + fmt, *(value if fmt[0].isdigit() else [value]))
    return out
