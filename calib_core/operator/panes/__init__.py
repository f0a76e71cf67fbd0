"""What each pane of the window shows and does: one model a pane, composed by the window's assembly from the
operator's parts (:mod:`calib_core.operator.core`), exposing just the events the pane subscribes to, the values it
reads and the actions it asks for. A pane is given its model and nothing else of the core, so what a pane can touch is
read in one file, and a part can change behind its models without a widget noticing.

The models hold no state of their own and make no copies: their events are the parts' own signals, their values read
through to the parts."""
