"""videocal's core: everything but the window. Never imports Qt; only ``render`` imports VTK."""

__version__ = "0.1.0"
