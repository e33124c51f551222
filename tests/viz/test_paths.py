from __future__ import annotations

import pytest

from viz import paths


def test_spatial_entities_follow_the_transform_tree() -> None:
    assert paths.EGO == "world/ego_vehicle"
    assert paths.LIDAR == "world/ego_vehicle/LIDAR_TOP"
    assert paths.DETECTIONS_KEPT == "world/detections/kept"
    assert paths.DETECTIONS_SUPPRESSED == "world/detections/suppressed"
    assert paths.tracks("gnnpmb", "car") == "world/trackers/gnnpmb/tracks/car"
    assert paths.track("gnnpmb", "car", 802) == "world/trackers/gnnpmb/tracks/car/802"
    assert paths.associations("gnnpmb", "car") == "world/trackers/gnnpmb/associations/car"
    assert paths.candidates_world("gnnpmb", "car") == "world/trackers/gnnpmb/candidates/car"
    assert paths.gates("pmbm", "bus") == "world/trackers/pmbm/gates/bus"
    assert paths.failures_world("gnn", "id_switch") == "world/trackers/gnn/failures/id_switch"


def test_non_spatial_entities_live_under_the_tracker() -> None:
    assert paths.decisions("gnnpmb") == "trackers/gnnpmb/decisions"
    assert paths.nis("gnnpmb", "car", 17) == "trackers/gnnpmb/nis/car/17"
    assert paths.hypothesis_weights("pmbm", "car") == "trackers/pmbm/hypotheses/car"
    assert paths.existence("gnnpmb", "car", 17) == "trackers/gnnpmb/existence/car/17"
    assert paths.events("jpda", "truck") == "trackers/jpda/events/truck"
    assert paths.cardinality_pmf("cphd", "car").startswith(paths.cardinality_pmf.root("cphd") + "/")
    assert paths.intensity_total("phd", "car").startswith(paths.intensity_total.root("phd") + "/")


def test_every_tracker_entity_sits_in_its_own_subtree() -> None:
    """Two trackers never share an entity, so both fit in one recording."""
    makers = [
        paths.tracks, paths.predicted, paths.gates, paths.associations, paths.gated_pairs, paths.candidates_world,
        paths.events, paths.marginals, paths.candidate_count, paths.hypothesis_weights,
        paths.cardinality_pmf, paths.cardinality_mean, paths.intensity_weights, paths.intensity_total,
    ]  # fmt: skip
    a = {m("gnnpmb", "car") for m in makers}
    b = {m("pmbm", "car") for m in makers}
    assert len(a) == len(makers) and not a & b
    for p in a:
        assert p.startswith((paths.tracker_world("gnnpmb") + "/", paths.tracker_root("gnnpmb") + "/"))


@pytest.mark.parametrize("bad", ["", "a/b", " car"])
def test_bad_segments_are_rejected(bad: str) -> None:
    with pytest.raises(ValueError, match="segment"):
        paths.tracks("gnnpmb", bad)
