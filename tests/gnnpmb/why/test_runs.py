"""``why.runs``: which values of a sentence may differ within a run, and which are claims that never may."""

from __future__ import annotations

from gnnpmb.why.runs import Slot, cut, ids_text, split_comparisons


def test_only_the_findings_own_frame_and_measured_values_are_cut_out() -> None:
    sentence = (
        "at frame 7 detection m6 (score 0.69) lay 0.1 m from bicycle GT bdb19c and went to track 41 "
        "(1,043 LiDAR and radar points); from frames 6 and 8, last at frame 5, within 2 m, 40 m range"
    )
    c = cut(sentence, 7)
    assert c.slots == (Slot.FRAME, Slot.DETECTION, Slot.SCORE, Slot.DISTANCE, Slot.POINTS)
    assert c.values == ("7", "m6", "0.69", "0.1", "1,043")
    assert "GT bdb19c and went to track 41" in c.texts[4]  # ids are never values
    assert c.texts[5] == " LiDAR and radar points); from frames 6 and 8, last at frame 5, within 2 m, 40 m range"
    assert c.text() == sentence


def test_no_points_is_a_claim_not_a_value() -> None:
    c = cut("at frame 3 (0 LiDAR and 4 radar points in its box)", 3)
    assert c.values == ("3", "4") and "(0 LiDAR and " in c.texts[1]


def test_comparisons_are_split_off_only_when_the_sentence_ends_in_them() -> None:
    why = "Why (gnnpmb, the tracker's doing): at frame 7 it was lost; immortal on the same detections failed here too."
    assert split_comparisons(why, ("immortal",)) == ("immortal on the same detections failed here too",)
    assert split_comparisons(why, ("pmbm",)) == ()
    assert split_comparisons("Why (gnnpmb, x): immortal on the same detections failed here too.", ("immortal",)) == ()


def test_ids_read_as_ranges() -> None:
    assert ids_text(["miss:12", "miss:13", "miss:14"]) == "miss:12-14"
    assert ids_text(["false_track:2", "false_track:5", "false_track:6"]) == "false_track:2, 5-6"
