"""The GenICam camera connector: ``aravis://DEVICE`` (an Aravis device id: ``Vendor-Model-Serial``, an IP
address for a GigE Vision camera, or ``Fake_1``, Aravis's own fake camera once its interface is enabled).

Options (``?exposure_us=8000&gain_db=2&pixel_format=RGB8&width=1280&height=960``, or the ``site:`` section's
``camera_options``): set on the camera when it opens and set again after a reconnect; a camera that refuses one
is an error naming it. Frames carry the camera's own timestamp (``t_device_ns``: the device's clock, ns) and the
host's time at the frame (``t_host_s``, from Aravis's system timestamp). A camera that stops sending gives
:class:`~calib_core.connectors.frame.FrameTimeout`; after ``reopen_after_s`` of silence the device is opened again
(a GigE camera that was unplugged or rebooted comes back without restarting videocal).
"""

from __future__ import annotations

import ipaddress
import time
from urllib.parse import parse_qs, unquote

from calib_core.gige.aravis_lib import aravis
from calib_core.gige.pixel_formats import to_rgb
from calib_core.connectors.urls import split_url
from calib_core.connectors.frame import Frame, FrameSource, FrameTimeout, VideoSourceError

_OPTIONS = {"exposure_us", "gain_db", "pixel_format", "width", "height", "timeout_s", "reopen_after_s", "fake"}
_BUFFERS = 8


def _is_address(device: str) -> bool:
    try:
        ipaddress.ip_address(device)
        return True
    except ValueError:
        return False


def _device_id(spec: str) -> str:
    parts = split_url(spec, VideoSourceError)
    device = unquote(parts.netloc + parts.path).strip("/")
    if not device:
        raise VideoSourceError(
            f"{spec!r}: name the camera: aravis://DEVICE-ID (see `arv-tool-0.8`), an IP address, or Fake_1"
        )
    return device


class AravisSource(FrameSource):
    def __init__(self, spec: str, options: dict | None = None):
        merged = dict(options or {})
        merged.update({k: v[-1] for k, v in parse_qs(split_url(spec, VideoSourceError).query).items()})
        unknown = set(merged) - _OPTIONS
        if unknown:
            raise VideoSourceError(
                f"{spec!r}: unknown option(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(_OPTIONS))}"
            )
        self.device = _device_id(spec.split("?", 1)[0])
        self.options = merged
        try:
            self.timeout_s = float(merged.get("timeout_s", 2.0))
            self.reopen_after_s = float(merged.get("reopen_after_s", 3.0))
        except ValueError as exc:
            raise VideoSourceError(f"{spec!r}: {exc}") from None
        self.description = f"GenICam camera {self.device}"
        self.reopened = 0
        self.skipped = 0
        """Frames passed over because a newer one had arrived (the pane shows the newest, never a queue)."""
        self._index = 0
        self._camera = self._stream = None
        self._last_frame_s = time.monotonic()
        self._Aravis = aravis()
        if str(merged.get("fake", "")).lower() in ("1", "true", "yes") or self.device.startswith("Fake_"):
            self._Aravis.enable_interface("Fake")  # Aravis's own fake camera, for trying it without hardware
        self._open()

    # --- the device ----------------------------------------------------------------------------
    def _open(self) -> None:
        Aravis = self._Aravis
        self._find_device()
        try:
            camera = Aravis.Camera.new(self.device)
        except Exception as exc:  # GLib.Error: the device is not there (yet)
            raise VideoSourceError(f"{self.description}: cannot open it: {getattr(exc, 'message', exc)}") from None
        self._configure(camera)
        stream = camera.create_stream(None, None)
        if stream is None:
            raise VideoSourceError(f"{self.description}: Aravis could not open its stream")
        payload = camera.get_payload()
        for _ in range(_BUFFERS):
            stream.push_buffer(Aravis.Buffer.new_allocate(payload))
        camera.set_acquisition_mode(Aravis.AcquisitionMode.CONTINUOUS)
        camera.start_acquisition()
        self._camera, self._stream = camera, stream
        self.model = f"{camera.get_vendor_name()} {camera.get_model_name()}"
        self.pixel_format = camera.get_pixel_format_as_string()
        self.exposure_us = camera.get_exposure_time() if camera.is_exposure_time_available() else None
        self.gain_db = camera.get_gain() if camera.is_gain_available() else None

    def _find_device(self) -> None:
        """Look the camera up on every interface first: a camera named by its device id is found only in Aravis's
        device list (opened without it, a GigE Vision camera answered but never streamed). A name on no list is an
        error that says which cameras are there."""
        if _is_address(self.device):
            return  # a GigE Vision camera by its IP address is reached directly
        Aravis = self._Aravis
        Aravis.update_device_list()
        found = [Aravis.get_device_id(i) for i in range(Aravis.get_n_devices())]
        if self.device not in found:
            seen = (
                ", ".join(
                    f"{d} ({Aravis.get_device_address(i) or Aravis.get_device_protocol(i)})"
                    for i, d in enumerate(found)
                )
                or "none"
            )
            raise VideoSourceError(
                f"{self.description}: no camera with that id; cameras found: {seen} (an id is Vendor-Model-Serial, as "
                "`arv-tool-0.8` lists them)"
            )

    def _configure(self, camera) -> None:
        """The options, each checked against the range the camera offers, set, and read back: a refusal, or a value
        the camera clamped or rounded, is an error naming the setting, the value asked and what the camera offers."""
        o = self.options

        def number(name: str) -> float:
            try:
                value = float(o[name])
            except (TypeError, ValueError):
                raise VideoSourceError(f"{self.description}: {name}={o[name]!r} is not a number") from None
            if value != value or value in (float("inf"), float("-inf")):
                raise VideoSourceError(f"{self.description}: {name}={o[name]!r} is not a finite number")
            return value

        def setting(name: str, apply) -> None:
            try:
                apply()
            except Exception as exc:
                if _timed_out(exc, self._Aravis):  # no answer is no refusal: the camera or the network is busy
                    why = getattr(exc, "message", exc)
                    raise VideoSourceError(
                        f"{self.description}: no answer while setting {name}={o[name]!r} ({why}): is another "
                        "application controlling the camera, or is the network dropping packets?"
                    ) from None
                raise VideoSourceError(
                    f"{self.description}: it refuses {name}={o[name]!r}: {getattr(exc, 'message', exc)}"
                ) from None

        def within(name: str, value: float, bounds, unit: str) -> None:
            low, high = float(bounds[0]), float(bounds[1])
            if not low <= value <= high:
                raise VideoSourceError(
                    f"{self.description}: it refuses {name}={o[name]!r}: it offers {low:.10g}-{high:.10g} {unit}"
                )

        def read_back(name: str, asked: float, got: float, tolerance: float, unit: str) -> None:
            if abs(got - asked) > tolerance:
                raise VideoSourceError(
                    f"{self.description}: {name}={o[name]!r} was not taken: the camera reports {got:g} {unit}"
                )

        if "pixel_format" in o:
            allowed = list(camera.dup_available_pixel_formats_as_strings() or [])
            if o["pixel_format"] not in allowed:
                raise VideoSourceError(
                    f"{self.description}: it refuses pixel_format={o['pixel_format']!r}; it offers {', '.join(allowed)}"
                )
            setting("pixel_format", lambda: camera.set_pixel_format_from_string(str(o["pixel_format"])))
            got = camera.get_pixel_format_as_string()
            if got != o["pixel_format"]:
                raise VideoSourceError(
                    f"{self.description}: pixel_format={o['pixel_format']!r} was not taken: the camera reports {got}"
                )
        if "width" in o or "height" in o:
            x, y, w, h = camera.get_region()
            width = number("width") if "width" in o else float(w)
            height = number("height") if "height" in o else float(h)
            if "width" in o:
                within("width", width, camera.get_width_bounds(), "px")
            if "height" in o:
                within("height", height, camera.get_height_bounds(), "px")
            setting("width" if "width" in o else "height", lambda: camera.set_region(0, 0, int(width), int(height)))
            _, _, w, h = camera.get_region()
            if "width" in o:
                read_back("width", int(width), w, 0, "px (its width step?)")
            if "height" in o:
                read_back("height", int(height), h, 0, "px (its height step?)")
        if "exposure_us" in o:
            exposure = number("exposure_us")
            if camera.is_exposure_time_available():
                within("exposure_us", exposure, camera.get_exposure_time_bounds(), "us")
            setting("exposure_us", lambda: camera.set_exposure_time(exposure))
            read_back("exposure_us", exposure, camera.get_exposure_time(), max(1.0, 0.01 * exposure), "us")
        if "gain_db" in o:
            gain = number("gain_db")
            if camera.is_gain_available():
                within("gain_db", gain, camera.get_gain_bounds(), "dB")
            setting("gain_db", lambda: camera.set_gain(gain))
            read_back("gain_db", gain, camera.get_gain(), 0.05, "dB")

    def _close_device(self) -> None:
        if self._camera is not None:
            try:
                self._camera.stop_acquisition()
            except Exception:  # a vanished camera cannot be told to stop: nothing to do
                pass
        self._camera = self._stream = None

    # --- frames --------------------------------------------------------------------------------
    @property
    def fps(self) -> float:
        try:
            return float(self._camera.get_frame_rate()) if self._camera is not None else 0.0
        except Exception:
            return 0.0

    def read(self) -> Frame:
        Aravis = self._Aravis
        deadline = time.monotonic() + self.timeout_s
        while True:
            if self._stream is None:
                self._reopen()
            buffer = (
                self._stream.timeout_pop_buffer(int(max(deadline - time.monotonic(), 0.01) * 1e6))
                if self._stream is not None
                else None
            )
            while buffer is not None:  # frames queued while the caller was busy are old: keep only the newest
                newer = self._stream.try_pop_buffer()
                if newer is None:
                    break
                self._stream.push_buffer(buffer)
                self.skipped += 1
                buffer = newer
            if buffer is not None:
                status = buffer.get_status()
                if status == Aravis.BufferStatus.SUCCESS:
                    frame = self._frame(buffer)
                    self._stream.push_buffer(buffer)
                    return frame
                self._stream.push_buffer(buffer)  # a damaged frame (lost packets): the next one
            now = time.monotonic()
            if now - self._last_frame_s > self.reopen_after_s and self._stream is not None:
                self._close_device()  # gone quiet for long: open it afresh on the next read
            if now >= deadline:
                raise FrameTimeout(
                    f"{self.description}: no frame for {now - self._last_frame_s:.1f} s (waiting; reconnecting after "
                    f"{self.reopen_after_s:g} s)"
                )

    def _reopen(self) -> None:
        try:
            self._open()
            self.reopened += 1
        except VideoSourceError:
            time.sleep(0.2)  # not back yet

    def _frame(self, buffer) -> Frame:
        data = buffer.get_data()
        rgb = to_rgb(
            data, buffer.get_image_width(), buffer.get_image_height(), buffer.get_image_pixel_format(), self.description
        )
        received_ns = buffer.get_system_timestamp()  # the host's realtime clock at the frame
        age_s = (time.time_ns() - received_ns) / 1e9 if received_ns else 0.0
        now = time.monotonic()
        self._last_frame_s = now
        # However old the frame, its stamp dates it (a late frame must never pass for a new one); only a stamp
        # ahead of the host's clock cannot, and then its arrival does.
        frame = Frame(rgb, self._index, now - age_s if age_s >= 0.0 else now, None, int(buffer.get_timestamp()) or None)
        self._index += 1
        return frame

    def close(self) -> None:
        self._close_device()


def open_aravis(spec: str, options: dict) -> AravisSource:
    """Entry point of ``videocal.cameras`` for ``aravis://``."""
    return AravisSource(spec, options)


def _timed_out(exc: Exception, Aravis) -> bool:
    """Whether ``exc`` is Aravis's timeout (a GLib error of its device domain): the camera did not answer."""
    matches = getattr(exc, "matches", None)
    try:
        return bool(matches and matches(Aravis.device_error_quark(), int(Aravis.DeviceError.TIMEOUT)))
    except TypeError:
        return False
