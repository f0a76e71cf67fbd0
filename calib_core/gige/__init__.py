"""GenICam cameras (GigE Vision, USB3 Vision) through Aravis, with its GObject binding (PyGObject)."""
