"""The workspace file: what an operator's work is saved as, and the correction exports."""
