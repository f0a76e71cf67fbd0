"""Where a view's frame came from is a flag of its stamp, kept through files, never read from a name."""

from calib_core.calibration.view_stamp import ViewStamp


def test_a_recorded_stamp_named_live_stays_recorded_through_its_file_form():
    stamp = ViewStamp(3, 1.5, (0.0, 10.0), 0.01, "1.500 s into live", "live", recorded=True)
    again = ViewStamp.from_dict(stamp.to_dict())
    assert again.recorded and again.source == "live" and again == stamp


def test_stamps_written_before_the_flag_are_read_by_their_name_as_they_were():
    live = ViewStamp.from_dict({"frame_index": 1, "t_capture_s": 0.0, "joints_deg": [1.0], "source": "live"})
    recorded = ViewStamp.from_dict({"frame_index": 1, "t_capture_s": 0.0, "joints_deg": [1.0], "source": "s.mcap"})
    assert not live.recorded and recorded.recorded
