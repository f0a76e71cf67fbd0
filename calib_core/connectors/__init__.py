"""Connectors: how videocal reaches a cell's controller and camera.

A *controller connector* gives joint samples (stamped by the controller's clock), moves, Stop and its
liveness (:mod:`calib_core.connectors.controller`); a *camera connector* gives frames
(:class:`~calib_core.connectors.frame.FrameSource`). Both are found by entry points (``videocal.controllers``,
``videocal.cameras``) under the scheme of the URL that names them (:mod:`calib_core.connectors.registry`),
so a user's connector is a package of theirs. videocal's own protocol is one controller connector among
the others; ``docs/connectors.md`` says how to write one.
"""
