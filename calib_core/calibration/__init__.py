"""The calibration workflow without a window: point pairs, undoable edits, the solve, the
end-effector displacement and the correction table. The window only shows and edits these."""
