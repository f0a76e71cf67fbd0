"""A network camera's stream that drops and comes back: an HTTP MJPEG stream (multipart/x-mixed-replace, as IP
cameras serve it) read through OpenCV's FFmpeg back end, the server stopped and started again on the same port."""

from __future__ import annotations

import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import cv2
import numpy as np
import pytest

from calib_core.connectors.registry import open_camera
from calib_core.connectors.frame import FrameTimeout, VideoSourceError


class MjpegCamera:
    """An IP camera's MJPEG stream at ``url``: frames of one grey level at about 20 fps until :meth:`stop`."""

    def __init__(self, port: int, level: int):
        self.level = level
        self.stopped = threading.Event()
        camera = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args):
                pass

            def do_GET(self):
                self.send_response(200)
                self.send_header("Content-Type", "multipart/x-mixed-replace; boundary=frame")
                self.end_headers()
                jpeg = cv2.imencode(".jpg", np.full((120, 160, 3), camera.level, np.uint8))[1].tobytes()
                try:
                    while not camera.stopped.wait(0.05):
                        self.wfile.write(
                            b"--frame\r\nContent-Type: image/jpeg\r\nContent-Length: "
                            + str(len(jpeg)).encode()
                            + b"\r\n\r\n"
                            + jpeg
                            + b"\r\n"
                        )
                        self.wfile.flush()
                except OSError:
                    pass

        ThreadingHTTPServer.allow_reuse_address = True
        self.server = ThreadingHTTPServer(("127.0.0.1", port), Handler)
        self.server.daemon_threads = True
        self.port = self.server.server_address[1]
        self.url = f"http://127.0.0.1:{self.port}/stream.mjpg"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def stop(self):
        self.stopped.set()
        self.server.shutdown()
        self.server.server_close()


def _next_frame(source, tries: int = 200):
    """The next frame, reading through the waits (FrameTimeout) as the camera's reader thread does."""
    waits = 0
    for _ in range(tries):
        try:
            return source.read(), waits
        except FrameTimeout:
            waits += 1
    raise AssertionError(f"no frame after {tries} reads")


def test_a_stream_that_drops_is_waited_for_and_read_again_when_it_is_back():
    camera = MjpegCamera(0, level=60)
    source = open_camera(camera.url, {"timeout_s": 2.0, "reopen_every_s": 0.2})
    try:
        frame, _ = _next_frame(source)
        assert frame.image.shape == (120, 160, 3) and abs(float(frame.image.mean()) - 60) < 3
        camera.stop()  # the camera restarts: its stream ends
        with pytest.raises(FrameTimeout):
            for _ in range(100):  # the frames already on the way, then the drop
                source.read()
        with pytest.raises(FrameTimeout, match="opening it again"):
            source.read()  # still gone: said, not ended
        camera = MjpegCamera(camera.port, level=180)  # back, at the same URL
        frame, waits = _next_frame(source)
        assert abs(float(frame.image.mean()) - 180) < 3 and source.reconnects == 1
    finally:
        source.close()
        camera.stop()


def test_a_stream_nobody_serves_and_a_bad_option_are_errors_at_once():
    free = MjpegCamera(0, level=0)
    url = free.url
    free.stop()
    with pytest.raises(VideoSourceError, match="cannot open stream http://127.0.0.1"):
        open_camera(url, {"timeout_s": 1.0})
    with pytest.raises(VideoSourceError, match="reopen_every_s"):
        open_camera(url, {"reopen_every_s": "often"})
    with pytest.raises(VideoSourceError, match="unknown option"):
        open_camera(url, {"reopen_evry_s": 1})
