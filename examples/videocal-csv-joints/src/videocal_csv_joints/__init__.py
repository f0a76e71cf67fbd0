"""An example videocal controller connector (see ``connector.py``)."""
