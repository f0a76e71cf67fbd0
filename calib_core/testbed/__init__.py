"""The simulated test bed: a true robot that differs from the model, and a camera on it."""
