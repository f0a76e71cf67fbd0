"""Recording a session to one MCAP file (crash safe), reading it back, recovering a cut file,
and replaying its solves. Frames use Foxglove's ``foxglove.CompressedImage`` schema, so the
file opens in Foxglove Studio; everything else is JSON with the schemas in ``schemas.py``."""
