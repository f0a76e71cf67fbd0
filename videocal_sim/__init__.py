"""videocal's simulated cell, a plug-in outside the core: a true robot that differs from the model,
a camera on it, the controller simulator's process, the cold cell, the simulated views for hand-eye
and robot calibration, and the demo's scripted operator and scoring.

It is the only code that reads the truth. It registers itself by entry points (``videocal.sites``:
``sim``; ``videocal.commands``: ``demo``); ``calib_core`` and ``app`` never import it, so deleting
this package leaves a videocal that drives real cells only.
"""
