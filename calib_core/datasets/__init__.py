"""Public pose data sets read as their authors wrote them, and the field's pose errors for scoring against them."""
