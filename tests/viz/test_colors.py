from __future__ import annotations

import numpy as np

from gnnpmb.types import TRACKING_CLASSES
from viz import colors
from viz.colors import (
    CLASS_COLORS,
    CLASS_IDS,
    annotation_context,
    class_colors,
    class_ids,
    pack_rgba,
    packed_track_colors,
    readable_text,
    track_color,
    track_colors,
)


def hue_of(rgb: np.ndarray) -> np.ndarray:
    """(N,) hue in [0, 1) of (N, 3) RGB colours (0-255); 0 for greys."""
    c = np.asarray(rgb, dtype=np.float64).reshape(-1, 3) / 255.0
    mx, mn = c.max(axis=1), c.min(axis=1)
    d = np.where(mx > mn, mx - mn, 1.0)
    r, g, b = c.T
    h = np.where(mx == r, np.mod((g - b) / d, 6.0), np.where(mx == g, (b - r) / d + 2.0, (r - g) / d + 4.0))
    return np.where(mx > mn, h / 6.0, 0.0)


def test_every_class_has_a_distinct_id_and_colour() -> None:
    assert set(CLASS_IDS) == set(CLASS_COLORS) == set(TRACKING_CLASSES)
    assert sorted(CLASS_IDS.values()) == list(range(1, 8))
    assert len(set(CLASS_COLORS.values())) == 7
    np.testing.assert_array_equal(class_ids(np.array(["car", "bus", "tree"], dtype=object)), [3, 2, 0])
    rgba = class_colors(np.array(["car", "tree"], dtype=object), alpha=70)
    np.testing.assert_array_equal(rgba, [[0, 130, 200, 70], [128, 128, 128, 70]])


def test_annotation_context_lists_the_seven_classes() -> None:
    batch = annotation_context().context.as_arrow_array().to_pylist()[0]
    infos = [c["class_description"]["info"] for c in batch]
    assert sorted((i["id"], i["label"]) for i in infos) == sorted((i, n) for n, i in CLASS_IDS.items())
    car = next(i for i in infos if i["label"] == "car")
    assert car["color"] == (0 << 24) | (130 << 16) | (200 << 8) | 255


def test_track_colours_are_a_pure_function_of_the_id() -> None:
    ids = np.arange(1, 200)
    a = track_colors(ids)
    np.testing.assert_array_equal(a, track_colors(ids))
    np.testing.assert_array_equal(track_colors(ids[::-1]), a[::-1])
    assert track_color(42) == tuple(int(v) for v in a[41])
    some = (-7, 0, 42, 5000)  # one id's colour (the packed table's) is the id's own, negative ids too
    assert [track_color(i) for i in some] == [tuple(int(v) for v in track_colors(np.array([i]))[0]) for i in some]
    assert a.dtype == np.uint8 and a.shape == (199, 3)


def test_consecutive_ids_are_well_separated() -> None:
    a = track_colors(np.arange(1, 500)).astype(float)
    gap = np.linalg.norm(np.diff(a, axis=0), axis=1)
    assert gap.min() > 60.0
    assert len({tuple(c) for c in a[:50].astype(int)}) == 50


def test_faded_colours_are_opaque_and_move_towards_the_background() -> None:
    from viz.colors import FADE_TO, faded, pack_rgba

    red = pack_rgba(np.array([[200, 0, 0]], dtype=np.uint8))
    assert int(faded(red, 1.0)[0]) == int(red[0])
    pale = int(faded(red, 0.3)[0])
    assert pale & 0xFF == 255
    rgb = np.array([(pale >> 24) & 0xFF, (pale >> 16) & 0xFF, (pale >> 8) & 0xFF])
    np.testing.assert_array_equal(rgb, np.rint(0.3 * np.array([200, 0, 0]) + 0.7 * FADE_TO))


def test_packed_colours_of_negative_ids_are_their_own_not_a_wrapped_table_entry() -> None:
    """GM-PHD's provisional labels are negative: they get ``track_colors`` of themselves, also as the first ids
    ever asked (an empty table), and the table's entries for the others."""
    colors._PACKED[0] = np.zeros(0, dtype=np.uint32)  # as in a fresh process
    np.testing.assert_array_equal(packed_track_colors(np.array([-16])), pack_rgba(track_colors(np.array([-16]))))
    ids = np.array([-16, 3, -1, 2000])  # the table now grows; -16 must not wrap around to one of its entries
    np.testing.assert_array_equal(packed_track_colors(ids), pack_rgba(track_colors(ids)))


def test_involved_tracks_get_distinct_palette_colours_no_marker_uses() -> None:
    from viz.colors import INVOLVED_PALETTE, TRACK_HUE_BANDS, involved_track_colors

    assert involved_track_colors([212, 26, 123]) == {
        26: INVOLVED_PALETTE[0],
        123: INVOLVED_PALETTE[1],
        212: INVOLVED_PALETTE[2],
    }
    palette = np.array(INVOLVED_PALETTE, dtype=float)
    gaps = np.linalg.norm(palette[:, None] - palette[None], axis=2)[np.triu_indices(len(palette), 1)]
    assert gaps.min() > 60.0  # no two look alike, unlike hash colours of nearby hues
    chromatic = np.ptp(palette, axis=1) > 30
    assert (palette[~chromatic].max(axis=1) < 60).all()  # the grey one is black, no marker's grey
    hues = hue_of(palette[chromatic])  # no marker's hue either
    assert all(any(a - 0.01 <= h <= b + 0.01 for a, b in TRACK_HUE_BANDS) for h in hues.tolist())
    car = involved_track_colors([26, 123], avoid=CLASS_COLORS["car"])  # not the blue of car detections
    assert car == {26: INVOLVED_PALETTE[1], 123: INVOLVED_PALETTE[2]}
    beyond = involved_track_colors(range(1, len(INVOLVED_PALETTE) + 2))
    assert beyond[len(INVOLVED_PALETTE) + 1] == track_color(len(INVOLVED_PALETTE) + 1)


def test_label_text_is_darkened_to_be_read_on_a_pale_pill_keeping_its_hue() -> None:
    orange = (255, 140, 0)
    dark = readable_text(orange)
    assert colors.luminance(dark) <= colors.TEXT_LUMINANCE_MAX < colors.luminance(orange)
    assert dark[0] > dark[1] > dark[2] == 0 and abs(dark[1] / dark[0] - 140 / 255) < 0.01  # still orange
    assert readable_text((0, 0, 200)) == (0, 0, 200)  # dark blue already reads
