"""PySide6 must not lose references to Python's ``True`` when a signal is emitted.

PySide6 6.12.0 did (one Py_DECREF(Py_True) per ``Signal.emit``): the window, which emits a
signal per joint sample and per camera frame, aborted after a minute with "bool_dealloc".
"""

import gc
import sys
import threading

from PySide6.QtCore import QObject, Signal


class _Emitter(QObject):
    sample = Signal(object)
    text = Signal(str)


def _true_refs() -> int:
    gc.collect()
    return sys.getrefcount(True)


def test_emitting_signals_keeps_the_reference_count_of_true(qapp):
    emitter = _Emitter()
    received = []
    emitter.sample.connect(received.append)
    emitter.text.connect(received.append)
    before = _true_refs()
    for k in range(500):
        emitter.sample.emit(k)
        emitter.text.emit("x")
    worker = threading.Thread(target=lambda: [emitter.sample.emit(k) for k in range(500)])
    worker.start()
    worker.join()
    qapp.processEvents()
    assert len(received) == 1500
    # A few references come and go with the interpreter's own state; 1500 lost ones would not.
    assert abs(_true_refs() - before) < 50
