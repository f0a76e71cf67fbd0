"""How far from where the model puts it Find points looks for the target (the robot's error it allows)."""

REACH_MM = 20.0
"""How far the camera's centre may be from where the model puts it: a typical robot's error (8 mm), twice, and some."""
REACH_DEG = 1.5
"""How far the camera may be turned from where the model puts it: a typical robot's error (0.7 deg), twice."""
