"""The controller link: the wire protocol, a serial driver that survives faults, and a
controller simulator that speaks the same protocol (see ``docs/controller-protocol.md``)."""
