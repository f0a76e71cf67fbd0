"""A simulated GigE Vision camera: Aravis's own fake GigE Vision camera (``ArvGvFakeCamera``, the GVCP/GVSP
protocols on a network interface) sending the images of a videocal frame source instead of its test pattern,
so a GenICam client (videocal's ``aravis://`` connector, ``arv-viewer``, any GigE Vision software) receives them
over the wire.

The fake camera calls its fill function from its own thread for every frame; that function is set through the
C API (``arv_fake_camera_set_fill_pattern``, via ctypes): PyGObject frees a callback given to it after the call,
and the fake camera keeps calling it. The fake camera stamps the buffer just before it calls the fill, so the fill
takes its image *then* (a simulated camera renders the robot where it stands at that moment): the stamp is the
exposure, as a real camera's is. The image is resized to the region the client chose and written in the pixel
format it chose (RGB8, Mono8) into the buffer Aravis hands it.

One simulated camera serves on an interface at a time on this machine: a GigE Vision device owns its address's
control port (GVCP, UDP 3956), and two fake cameras bound to the loopback's both answered discovery, a client's
register writes reaching the one another client controlled (a write timed out while two test suites ran). A camera
made while another serves waits for it to close (:data:`WAIT_FOR_INTERFACE_S`), holding a lock file of the
interface's that the system releases when its process ends, however it ends.
"""

from __future__ import annotations

import ctypes
import fcntl
import os
import tempfile
import time

import cv2
import numpy as np

from calib_core.gige.aravis_lib import aravis
from calib_core.gige.pixel_formats import MONO8, RGB8

WAIT_FOR_INTERFACE_S = 300.0
"""How long a simulated camera waits for another to leave its interface, s (a whole demo serves for a minute)."""

_FILL = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_uint32)


def _library():
    lib = ctypes.CDLL("libaravis-0.8.so.0")
    lib.arv_buffer_get_data.restype = ctypes.c_void_p
    lib.arv_buffer_get_data.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_size_t)]
    for name in ("arv_buffer_get_image_width", "arv_buffer_get_image_height"):
        getattr(lib, name).restype = ctypes.c_int
        getattr(lib, name).argtypes = [ctypes.c_void_p]
    lib.arv_fake_camera_set_fill_pattern.argtypes = [ctypes.c_void_p, _FILL, ctypes.c_void_p]
    return lib


def _gpointer(obj) -> int:
    """The C pointer of a PyGObject wrapper (its ``__gpointer__`` capsule)."""
    api = ctypes.pythonapi
    api.PyCapsule_GetName.restype, api.PyCapsule_GetName.argtypes = ctypes.c_char_p, [ctypes.py_object]
    api.PyCapsule_GetPointer.restype, api.PyCapsule_GetPointer.argtypes = (
        ctypes.c_void_p,
        [ctypes.py_object, ctypes.c_char_p],
    )
    capsule = obj.__gpointer__
    return api.PyCapsule_GetPointer(capsule, api.PyCapsule_GetName(capsule))


class SimulatedGigECamera:
    """Serves ``images()`` (a function returning an RGB image taken when it is called, or None) as GigE Vision
    camera ``serial`` on ``interface`` (``lo``: reachable as ``aravis://127.0.0.1``) until :meth:`close`."""

    def __init__(self, images, *, interface: str = "lo", serial: str = "VIDEOCAL01"):
        Aravis = aravis()
        self.images = images
        self.frames_sent = 0
        self._lib = _library()
        self._hold = _hold_interface(interface)
        self._gv = Aravis.GvFakeCamera.new(interface, serial)
        if not self._gv.is_running():
            self._release()
            raise RuntimeError(f"the fake GigE Vision camera could not serve on {interface} (another one there?)")
        self._fill_c = _FILL(self._fill)  # kept: the fake camera calls it for as long as it runs
        self._lib.arv_fake_camera_set_fill_pattern(_gpointer(self._gv.get_fake_camera()), self._fill_c, None)

    def _fill(self, buffer, _data, _exposure_us, _gain, pixel_format) -> None:
        try:
            image = self.images()
            if image is None:
                return
            w, h = self._lib.arv_buffer_get_image_width(buffer), self._lib.arv_buffer_get_image_height(buffer)
            if image.shape[1] != w or image.shape[0] != h:
                image = cv2.resize(image, (w, h), interpolation=cv2.INTER_AREA)
            if pixel_format == RGB8:
                data = np.ascontiguousarray(image, dtype=np.uint8).tobytes()
            elif pixel_format == MONO8:
                data = cv2.cvtColor(image, cv2.COLOR_RGB2GRAY).tobytes()
            else:
                return  # a format this camera does not simulate: the fake camera's own pattern stays
            size = ctypes.c_size_t()
            target = self._lib.arv_buffer_get_data(buffer, ctypes.byref(size))
            if target:
                ctypes.memmove(target, data, len(data))
                self.frames_sent += 1
        except Exception:  # never into Aravis's thread: the frame keeps the fake pattern
            pass

    def close(self) -> None:
        """Stop serving (the camera vanishes from the network, as an unplugged one does)."""
        self._gv = None
        import gc

        gc.collect()
        self._release()

    def _release(self) -> None:
        if self._hold is not None:
            os.close(self._hold)  # (closing the file releases its lock)
            self._hold = None


def _hold_interface(interface: str) -> int:
    """An open lock file (its descriptor) of ``interface``'s GigE Vision port, held by this process; waits up to
    :data:`WAIT_FOR_INTERFACE_S` for another simulated camera to close, then raises :class:`RuntimeError`."""
    path = os.path.join(tempfile.gettempdir(), f"videocal-gige-{interface}.lock")
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    deadline = time.monotonic() + WAIT_FOR_INTERFACE_S
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return fd
        except BlockingIOError:
            if time.monotonic() > deadline:
                os.close(fd)
                raise RuntimeError(
                    f"another simulated GigE Vision camera has served on {interface} for over "
                    f"{WAIT_FOR_INTERFACE_S:g} s ({path} is held)"
                ) from None
            time.sleep(0.05)  # another process's camera: nothing here to wait on but its lock
