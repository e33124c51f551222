"""``gnnpmb-viz --focus``: a small recording that opens at a failure, looking at it, with the failure explained."""

from __future__ import annotations

import functools
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from rerun.chunk import RrdReader

from gnnpmb.eval.failures import FailureKind, short_id
from gnnpmb.stages.findings import explain_all
from gnnpmb.why.facts import Ending
from gnnpmb.why.findings import Party, Rule
from gnnpmb.why.words import column_name, whose_text, why_lines
from tests.inprocess import run_script_with
from tests.pipeline import PMBM_ALL, PMBM_NO_NSCAN, POSITION_ONLY, evidence_of_all, focus_comparison_args, prepare
from tests.viz.rrd import read_rows
from tests.viz.test_blueprint import stored_views
from viz import compare, paths
from viz.blueprint import FOCUS_TIMELINE, focus_axis_frames, focus_doc, focus_world, reading_guide_doc
from viz.evaluated import evaluated_world
from viz.focus import predicted_ghosts
from viz.legend import LOW_EXISTENCE, PROBABILITY_RANGE, existence_range, place_legend

SCENE = "scene-0103"
ARGS = ["--detector", "pointpillars", "--params", str(POSITION_ONLY)]
PMBM = PMBM_NO_NSCAN


@functools.cache
def evidence_of(demo_dataroot: Path, trackers: tuple[str, ...], detector: str = "pointpillars") -> tuple:
    """The inputs of ``trackers`` on the scene and, per tracker, the evidence of its run (its failure report, its
    events): each set of arguments run once per worker (a module's tests share a worker), read-only."""
    request = prepare(SCENE, list(trackers), dataroot=demo_dataroot, detector=detector, params=POSITION_ONLY)
    evidence, _, _ = evidence_of_all(request)
    return request, evidence


@pytest.fixture(scope="module")
def gnnpmb_report(demo_dataroot: Path):
    """GNN-PMB's failures on the scene (the ids ``gnnpmb failures`` prints), from the run the findings below are
    made from."""
    _, evidence = evidence_of(demo_dataroot, ("gnnpmb",))
    return evidence["gnnpmb"].report


@pytest.fixture(scope="module")
def record(viz_recording):
    """``record(focus, trackers)``: ``gnnpmb-viz SCENE --focus FOCUS --save focus.rrd`` in-process, each command
    line run once in the session (tests that look at the same recording share it; read-only): the recording and
    what the command printed. GNN-PMB beside PMBM without N-scan pruning is the recording the browser check opens
    too (``focus_comparison_args``: without camera views)."""

    def run(focus: str, trackers: tuple[str, ...] = ("gnnpmb",)) -> tuple[Path, str]:
        if trackers == ("gnnpmb", PMBM):
            return viz_recording(focus_comparison_args(focus))
        return viz_recording([SCENE, *ARGS, "--focus", focus, *[a for t in trackers for a in ("--tracker", t)]])

    return run


def blueprint_rows(path: Path) -> list[tuple[str, dict]]:
    reader = RrdReader(path)
    (blueprint,) = reader.blueprints()
    return [(c.entity_path, row) for c in reader.stream(store=blueprint) for row in c.to_record_batch().to_pylist()]


def stored_legends(bp: list[tuple[str, dict]]) -> dict[str, tuple[int | None, list[float] | None]]:
    """View name -> (legend corner, y range) of every view whose legend the blueprint places."""
    names = {path: r["ViewBlueprint:display_name"][0] for path, r in bp if r.get("ViewBlueprint:display_name")}
    corners = {path.rsplit("/", 1)[0]: r["PlotLegend:corner"][0] for path, r in bp if r.get("PlotLegend:corner")}
    ranges = {path.rsplit("/", 1)[0]: r["ScalarAxis:range"][0] for path, r in bp if r.get("ScalarAxis:range")}
    return {names[v]: (corner, ranges.get(v)) for v, corner in corners.items()}


def test_focus_on_a_failure_id_opens_at_its_frame_looking_at_it(demo_dataroot: Path, record, gnnpmb_report) -> None:
    report = gnnpmb_report
    pick = next(i for i, f in zip(report.ids(), report.failures, strict=True) if f.gt_ids and f.track_ids)
    failure = report.by_id(pick)
    out, stdout = record(pick)
    assert f"focus: {pick} at frame {failure.frame_index} (gnnpmb): {failure.describe()}" in stdout
    rows = read_rows(out)
    # Only the frames around the failure are recorded; the focus timeline ends at the failure frame.
    frames = sorted({r["frame"] for r in rows[paths.EGO]})
    assert frames == list(range(max(0, failure.frame_index - 8), min(40, failure.frame_index + 5)))
    focus_times = [r["focus"] for r in rows[paths.EGO] if r.get("focus") is not None]
    assert max(focus_times) == failure.frame_index
    # The blueprint shows the focus timeline, following the newest data: the viewer opens at the failure.
    bp = blueprint_rows(out)
    panel = {k: v for _, r in bp for k, v in r.items() if k.startswith("TimePanelBlueprint:")}
    assert panel["TimePanelBlueprint:timeline"] == [FOCUS_TIMELINE]
    eyes = [r for path, r in bp if path.endswith("EyeControls3D")]
    center = np.mean([b.translation_m[:2] for b in failure.boxes if b.is_gt], axis=0)  # where the object is
    assert len(eyes) == 2  # bird's-eye and perspective, both looking at the place
    for eye in eyes:
        np.testing.assert_allclose(eye["EyeControls3D:look_target"][0][:2], center, atol=1e-3)
    top = next(e for e in eyes if e["EyeControls3D:eye_up"] == [[0.0, 1.0, 0.0]])
    np.testing.assert_allclose(top["EyeControls3D:position"][0][:2], center, atol=1e-3)  # straight down
    # The summary names the failure and tells each involved track's frames; the objects are highlighted.
    summary = rows[focus_doc()][0]["TextDocument:text"][0]
    assert summary.startswith(f"# {pick} at frame {failure.frame_index}")
    for t in failure.track_ids:
        assert f"Track {t}, frame by frame:" in summary
    # The object's table gives the tracking score of every track output on it and whether the evaluation counted
    # it; the involved tracks' existence is plotted whatever it is (a starved track is often the cause).
    assert "frame by frame (the evaluation counted " in summary and "tracks output on it (score)" in summary
    # "Counted" is the evaluation's: the track's score averaged over the whole track against the threshold.
    threshold = report.threshold_of(failure.class_name)
    listed = re.findall(r"(\d+) \((\d\.\d\d); track average (\d\.\d{3,4})(, not counted)?\)", summary)
    assert listed
    for track_id, _score, average, not_counted in listed:
        assert average == f"{report.track_scores[track_id]:.{len(average) - 2}f}"
        assert bool(not_counted) == (report.track_scores[track_id] < threshold)
    followed = [t for t in failure.track_ids if paths.existence("gnnpmb", failure.class_name, t) in rows]
    assert followed, f"no existence series for the involved tracks {failure.track_ids}"
    # The existence plot (fixed at [0, 1], or zoomed to tracks that all stay low) has its legend where it covers
    # least of the lines the recording shows up to the failure frame.
    involved = re.search(r"gnnpmb: tracks ([\d, ]+)", summary).group(1).split(", ")  # the plot's tracks
    shown = [paths.existence("gnnpmb", failure.class_name, int(t)) for t in involved]
    shown = [p for p in shown if p in rows]
    shown.append(paths.extraction_threshold("gnnpmb", failure.class_name))
    lines = [
        (np.array([r["focus"] for r in points]), np.array([r["Scalars:scalars"][0] for r in points]))
        for points in ([r for r in rows[p] if r.get("focus") is not None] for p in shown)
    ]
    expected = existence_range([v for _, v in lines[:-1]])  # the tracks' values, not the threshold line
    axis = focus_axis_frames(SimpleNamespace(frame_index=failure.frame_index))  # the plot's x axis on opening
    placed = place_legend(lines, len(shown), y_range=expected, x_range=axis)
    corner, y_range = stored_legends(bp)["gnnpmb existence"]
    assert corner == placed.corner.value
    assert y_range == pytest.approx(expected)
    # These tracks never came near being shown: the plot is zoomed to them, not flat on the floor of [0, 1].
    peak = max(float(v.max()) for _, v in lines[:-1] if len(v))
    assert peak < LOW_EXISTENCE and y_range[1] == pytest.approx(PROBABILITY_RANGE[1] * max(peak, 0.01))
    # The story opens on the lines that name an involved track (the class's whole story is the next tab).
    views = stored_views(out)
    assert views["gnnpmb story (involved tracks)"] == ("TextLog", paths.involved_story("gnnpmb"))
    assert views[f"gnnpmb story (every {failure.class_name})"][1] == paths.events("gnnpmb", failure.class_name)
    story = [r["TextLog:text"][0] for r in rows[paths.involved_story("gnnpmb")] if r.get("TextLog:text")]
    assert story and all(re.search(r"(?:track |→ )(" + "|".join(involved) + r")\b", line) for line in story)
    guide = rows[reading_guide_doc()][0]["TextDocument:text"][0]
    assert guide.startswith("# How to read the views") and "how to read the views" in summary
    highlighted = [r for r in rows[focus_world()] if r.get("frame") == failure.frame_index]
    assert any(label.startswith("GT ") for label in highlighted[0]["Boxes3D:labels"])
    # Their labels are in a column beside them (callouts), one row each, with a leader line to each object.
    callouts = [r for r in rows[paths.focus_callouts("gnnpmb")] if r.get("frame") == failure.frame_index][0]
    labels = callouts["Points3D:labels"]
    assert any(label.startswith("GT ") for label in labels)
    assert any(label.startswith(f"{failure.track_ids[0]} predicted r=") for label in labels)
    # Which detection each involved track was given, on the picture itself (here none: nothing in their gates).
    predicted = [label for label in labels if " predicted r=" in label]
    assert predicted and all(re.fullmatch(r"\d+ predicted r=[\d.]+(?: → m\d+|, missed)?", p) for p in predicted)
    assert callouts["Points3D:positions.len"] == len(labels)
    # A track kept but not output this frame is drawn at its prediction with its last box: the shape it expected.
    ghosts = [r for r in rows[predicted_ghosts("gnnpmb")] if r.get("frame") == failure.frame_index][0]
    assert f"{failure.track_ids[0]} (predicted)" in ghosts["Boxes3D:labels"], ghosts
    leaders = [r for r in rows[paths.focus_callouts("gnnpmb") + "/leaders"] if r.get("frame") == failure.frame_index]
    label_at = np.array([strip[1] for strip in leaders[0]["LineStrips3D:strips"]])  # each: object -> label
    assert len(label_at) == len(labels) and len(set(label_at[:, 0].tolist())) == 1
    assert len(set(np.round(label_at[:, 1], 6).tolist())) == len(labels)


def test_focus_on_a_track_and_on_a_ground_truth_prefix(record, gnnpmb_report) -> None:
    report = gnnpmb_report
    failure = next(f for f in report.failures if f.track_ids and f.gt_ids)
    out, stdout = record(f"track:{failure.track_ids[0]}")
    assert "focus: " in stdout and f"track {failure.track_ids[0]}" in stdout
    out2, stdout2 = record(f"gt:{failure.gt_ids[0][:8]}")
    assert "focus: " in stdout2
    summary = read_rows(out2)[focus_doc()][0]["TextDocument:text"][0]
    assert f"GT {failure.gt_ids[0][:6]}" in summary


def test_focus_in_a_comparison_highlights_each_trackers_tracks(record, gnnpmb_report) -> None:
    """On the comparison ``test_why_and_where_two_trackers_part_on_the_failure_frame`` records (one run shared)."""
    pick = next(i for i in gnnpmb_report.ids() if i.startswith("id_switch:"))
    out, _ = record(pick, ("gnnpmb", PMBM))
    rows = read_rows(out)
    summary = rows[focus_doc()][0]["TextDocument:text"][0]
    assert "\n## gnnpmb" in summary and f"\n## {PMBM_ALL}" in summary
    for tracker in ("gnnpmb", PMBM_ALL):
        assert paths.tracker_world(tracker) + "/focus" in rows


@pytest.mark.parametrize(
    ("focus", "message"),
    [
        ("switch", "bad --focus 'switch': use track:ID, gt:TOKEN, a failure id such as id_switch:1"),
        ("track:abc", "bad --focus 'track:abc': track:ID takes a track number"),
        ("id_switch:999", "--focus id_switch:999: no such failure of gnnpmb on scene-0103"),
        ("gt:zzzz", "--focus gt:zzzz: no ground-truth object of scene-0103 has an id starting so"),
    ],
)
def test_bad_focus_is_one_line_and_exit_2(
    demo_dataroot: Path,
    tmp_path: Path,
    focus: str,
    message: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """In-process (``tests.inprocess``): the installed script's own error path runs in real processes in
    ``tests/cli/test_user_errors.py``; what is checked here is the focus's message. A failure id or an object is
    looked up in the tracked frames: three of them (``--frames 0:3``) are enough to find that there is none."""
    out = tmp_path / "x.rrd"
    argv = ["gnnpmb-viz", SCENE, "--dataroot", str(demo_dataroot), *ARGS, "--frames", "0:3", "--focus", focus]
    proc = run_script_with(
        [*argv, "--save", str(out)],
        {"PATH": "/usr/bin:/bin", "NO_COLOR": "1", "HOME": str(tmp_path)},
        tmp_path,
        monkeypatch,
        capsys,
    )
    assert proc.returncode == 2, proc.stderr
    errors = [line for line in proc.stderr.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and message in errors[0], proc.stderr
    assert "Traceback" not in proc.stderr
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir() if p.suffix == ".rrd") == []


def test_the_summary_opens_with_the_decisions_that_made_the_switch(demo_dataroot: Path, record, gnnpmb_report) -> None:
    report = gnnpmb_report
    switch = report.by_id("id_switch:1")
    old, new = switch.track_ids
    out, _ = record("id_switch:1")
    summary = read_rows(out)[focus_doc()][0]["TextDocument:text"][0]
    head = summary.split("Opened at frame")[0]
    assert "**Key decisions of gnnpmb**" in head
    # The detection that started the new track, with the old track as the choice the solver passed over.
    line = next(x for x in head.splitlines() if x.startswith("- ") and f"**new track {new}**" in x)
    assert line.startswith(f"- frame {switch.frame_index}: m") and "over track " in line and "margin " in line


def test_each_assignment_is_labelled_once(record) -> None:
    """A detection's label says which track it went to ("m11 0.39 → track 6"); that track's label at its predicted
    position then gives its existence only ("6 predicted r=0.95"), not "→ m11" again: each pair is read once
    (fragmentation:2, whose track takes detections in most frames of the window)."""
    out, _ = record("fragmentation:2")
    exercised = 0
    for row in read_rows(out)[paths.focus_callouts("gnnpmb")]:
        labels = row.get("Points3D:labels") or []
        told = {g.groups() for x in labels if (g := re.fullmatch(r"m(\d+) [\d.]+ → track (\d+)", x))}
        for x in labels:
            g = re.fullmatch(r"(\d+) predicted r=[\d.]+(?: → m(\d+)|, missed)?", x)
            if g is None:
                continue
            track, meas = g.groups()
            assert (meas, track) not in told, (row.get("frame"), labels)
            exercised += any(t == track for _, t in told)
    assert exercised  # some frame labels a detection that went to an involved track with a predicted label


@functools.cache
def findings_of(demo_dataroot: Path, trackers: tuple[str, ...], detector: str = "pointpillars") -> dict:
    """Per tracker, failure id -> its ``Finding`` (the data every sentence of the focus document is made from);
    made once per worker for each set of arguments (read-only: findings are frozen)."""
    request, evidence = evidence_of(demo_dataroot, trackers, detector)
    found = explain_all(request, evidence)
    return {t: dict(zip(evidence[t].report.ids(), fs, strict=True)) for t, fs in found.items()}


def test_a_failure_at_an_interpolated_gt_box_is_explained(demo_dataroot: Path, record, gnnpmb_report) -> None:
    report = gnnpmb_report
    scene = evidence_of(demo_dataroot, ("gnnpmb",))[0].scene
    # The devkit's boxes are flagged interpolated exactly where the annotated object has no points.
    for f in report.failures:
        for b in (b for b in f.boxes if b.is_gt):
            gt = scene.keyframes[f.frame_index].gt
            hit = np.flatnonzero(gt.instance_id.astype(str) == b.object_id)
            assert b.interpolated == (scene.keyframes[f.frame_index].gt_num_pts[hit[0]] == 0)
    pick, failure = next(
        (i, f)
        for i, f in zip(report.ids(), report.failures, strict=True)
        if f.kind is FailureKind.FRAGMENTATION and f.gt_interpolated
    )
    finding = findings_of(demo_dataroot, ("gnnpmb",))["gnnpmb"][pick]
    assert finding.parties[0] is Party.EVALUATION and finding.reach is not None
    g = report.gt_frame(failure.gt_ids[0], failure.frame_index)
    assert finding.reach.offset_m == pytest.approx(g.offset_m) and g.offset_m >= 0.5
    out, _ = record(pick)
    rows = read_rows(out)
    summary = rows[focus_doc()][0]["TextDocument:text"][0]
    gt = short_id(failure.gt_ids[0])
    # Right below the headline: where the evaluation put the object, how far from the annotation, and why.
    paragraphs = summary.split("\n\n")[1:3]
    if finding.reach.near_annotated and not finding.reach.near_evaluated:
        # a verdict that names the evaluation alone only when the Why blames nobody else
        lead = "**Verdict: the evaluation's doing.**" if len(finding.parties) == 1 else "**The evaluation's part:**"
        assert paragraphs[0].startswith(f"{lead} gnnpmb track")
        note = paragraphs[1]
    else:
        note = paragraphs[0]
    assert note.startswith(f"**GT {gt} as evaluated**: at frame {failure.frame_index} its annotated box was dropped")
    assert " m** from the annotated one" in note
    # The frame table says which frames the evaluation did not score as annotated.
    assert f"| {failure.frame_index} | 0: interpolated by the evaluation ({g.offset_m:.1f} m off) |" in summary
    callouts = [r for r in rows[paths.focus_callouts("gnnpmb")] if r.get("frame") == failure.frame_index][0]
    assert any(label.startswith(f"GT {gt} as evaluated (") for label in callouts["Points3D:labels"])
    # The evaluated box is drawn at the failure frame with the 2 m match circle, and cleared at the others.
    drawn = {r["frame"]: r for r in rows[evaluated_world()] if r.get("frame") is not None and "Boxes3D:centers" in r}
    assert drawn[failure.frame_index]["Boxes3D:labels"] == [f"GT {gt} as evaluated"]
    gt_box = next(b for b in failure.boxes if b.is_gt)
    np.testing.assert_allclose(drawn[failure.frame_index]["Boxes3D:centers"][0][:2], gt_box.translation_m[:2])
    assert all(not r["Boxes3D:centers"] for f, r in drawn.items() if f != failure.frame_index)


def test_why_and_where_two_trackers_part_on_the_failure_frame(demo_dataroot: Path, record, gnnpmb_report) -> None:
    pmbm = PMBM
    report = gnnpmb_report
    pick = next(i for i in report.ids() if i.startswith("id_switch:"))
    failure = report.by_id(pick)
    old, new = (int(t) for t in failure.track_ids)
    finding = findings_of(demo_dataroot, ("gnnpmb", pmbm))["gnnpmb"][pick]
    # The data: the lost and the new track, the choice that started the new one, the other tracker as evidence.
    assert finding.lost.track_id == old and finding.taker.track_id == new
    d = finding.decision
    assert d is not None and d.went == new and d.born and d.frame <= failure.frame_index
    assert d.choice.alternative is not None and d.choice.alternative_terms is not None
    (other,) = finding.others
    assert other.tracker == PMBM_ALL
    out, _ = record(pick, ("gnnpmb", pmbm))
    summary = read_rows(out)[focus_doc()][0]["TextDocument:text"][0]
    why, because = summary.split("\n\n")[1:3]
    assert why.startswith(f"**Why** (gnnpmb, {whose_text(finding)}): ")
    assert f"→ **new track {new}** (cost {d.choice.chosen_cost:.2f}) over {column_name(d.choice.alternative)}" in why
    # Then the decisive choice's costs taken apart; the parts add up to the cost the decision table shows.
    assert because.startswith(f"**Because** (frame {d.frame}): m{d.choice.meas.ref} went to new track {new} (cost ")
    lost = re.search(
        r"Track (\d+)'s ([-\d.]+) = (.*?)(?:\. (?:With a predicted existence above|No predicted existence)|\.$)",
        because,
    )
    assert lost, because
    parts = [float(p.split(" for ")[0]) for p in lost.group(3).split(" + ")]
    assert sum(parts) == pytest.approx(float(lost.group(2)), abs=0.005)
    # The track that had the object, when it was not the next best, gets its own cost (or: out of its gate).
    if d.lost is not None:
        assert (d.lost_in_gate and f"Track {old}, which had the object, would have cost " in because) or (
            not d.lost_in_gate and f"Track {old}, which had the object, could not take m" in because
        )
    # The disagreement log opens on the focused class's lines (the whole log is the next tab).
    rows = read_rows(out)
    assert stored_views(out)[f"disagreements ({failure.class_name})"] == ("TextLog", compare.focus_log_path())
    about = [r["TextLog:text"][0] for r in rows[compare.focus_log_path()] if r.get("TextLog:text")]
    everything = [r["TextLog:text"][0] for r in rows[compare.log_path()] if r.get("TextLog:text")]
    assert about and all(f": {failure.class_name} " in line for line in about)
    assert about == [line for line in everything if f": {failure.class_name} " in line] and len(everything) > len(about)
    # The picture says it too: the detection's label names where it went, in each tracker's view.
    for tracker in ("gnnpmb", PMBM_ALL):
        callouts = [r for r in rows[paths.focus_callouts(tracker)] if r.get("frame") == failure.frame_index]
        went = [label.split(" → ")[1] for label in callouts[0]["Points3D:labels"] if re.match(r"m\d+ ", label)]
        assert went and all(re.fullmatch(r"(?:new )?track \d+", w) for w in went)
        if tracker == "gnnpmb":
            assert f"new track {new}" in went
    # The decision view of that frame takes the same choice apart under its table.
    doc = next(r for r in rows[paths.decisions("gnnpmb")] if r.get("frame") == d.frame)
    assert f"- m{d.choice.meas.ref} went to a new track (cost " in doc["TextDocument:text"][0]
    head, _, rest = summary.partition(f"**Where the trackers part** at frame {failure.frame_index}")
    assert rest, "the two trackers sent a detection on the object to different places; the summary says where"
    assert "## gnnpmb" not in head  # it comes before the per-tracker sections
    lines = [line for line in rest.split("\n\n")[1].splitlines() if line.startswith("- ")]
    assert any("gnnpmb: m" in line and f"new track {new}" in line and f" · {PMBM_ALL}: m" in line for line in lines)
    for line in lines:
        gnnpmb, pmbm = line[2:].split(" · ")
        assert gnnpmb.split("→")[1].split("(")[0] != pmbm.split("→")[1].split("(")[0]  # different destinations
        # two new tracks are one place numbered twice, not where the runs part (dev set scene-0655 megvii)
        assert not ("**new track" in gnnpmb and "**new track" in pmbm)


def test_a_false_track_says_what_it_was_output_on_and_why_it_counted(
    demo_dataroot: Path, record, gnnpmb_report
) -> None:
    report = gnnpmb_report
    findings = findings_of(demo_dataroot, ("gnnpmb",))["gnnpmb"]
    checked = 0
    for pick, failure in zip(report.ids(), report.failures, strict=True):
        if failure.kind is not FailureKind.FALSE_TRACK:
            continue
        finding = findings[pick]
        out = finding.false_output
        assert out is not None and out.track_id == int(failure.track_ids[0])
        # What it was output on is what the tracker output: the detection its box carries (or none).
        box = next(b for b in failure.boxes if b.role == "false track")
        assert out.output_xy_m == pytest.approx(box.translation_m[:2])
        # The evaluation counted the track: the score it averaged over the frames it kept reaches the threshold.
        assert out.evaluated.averaged_score == report.track_scores[failure.track_ids[0]]
        assert out.evaluated.averaged_score >= report.threshold_of(failure.class_name)
        rules = [b.rule for b in finding.blame]
        if out.nearest_own is not None:  # two tracks on one object may be the detector's doing too: two boxes of it
            assert rules in (
                [Rule.NO_EVAL_BOX],
                [Rule.INTERPOLATED],
                [Rule.TWO_TRACKS],
                [Rule.TWO_DETECTIONS, Rule.TWO_TRACKS],
            )
        else:
            assert len(rules) == 1 and rules[0] in (Rule.OTHER_CLASS, Rule.DETECTION_OF_NOTHING, Rule.COASTED)
        checked += 1
    assert checked
    pick = next(i for i, f in zip(report.ids(), report.failures, strict=True) if f.kind is FailureKind.FALSE_TRACK)
    rec, _ = record(pick)
    why = read_rows(rec)[focus_doc()][0]["TextDocument:text"][0].split("\n\n")[1]
    assert why == why_lines(findings[pick])[0]  # the document says what the finding holds


def test_a_miss_says_whether_the_detector_or_the_tracker_missed_it(demo_dataroot: Path, record, gnnpmb_report) -> None:
    report = gnnpmb_report
    pick, failure = next(
        (i, f)
        for i, f in zip(report.ids(), report.failures, strict=True)
        if f.kind is FailureKind.MISS and not f.gt_interpolated and f.frame_index > 0
    )
    finding = findings_of(demo_dataroot, ("gnnpmb",))["gnnpmb"][pick]
    s = finding.sighting(failure.frame_index)
    rules = {b.rule for b in finding.blame}
    # The detector's test holds exactly when no detection of any class lay within 2 m of a visible object.
    assert (Rule.NO_DETECTION in rules) == (s.nearest_any is None and s.points > 0)
    for o in s.on_it:  # tracks on it were not counted: their averaged score is below the class threshold
        assert not o.counted and o.evaluated.averaged_score < report.threshold_of(failure.class_name)
    assert (Rule.NOT_COUNTED in rules) == any(not o.counted for o in s.on_it)
    out, _ = record(pick)
    why = read_rows(out)[focus_doc()][0]["TextDocument:text"][0].split("\n\n")[1]
    assert why == why_lines(finding)[0] and why.startswith(f"**Why** (gnnpmb, {whose_text(finding)}): ")


def test_an_id_switch_without_a_close_call_says_where_the_new_track_came_from(demo_dataroot: Path, record) -> None:
    """GNN on pointpillars: the old track ended while the object had no points; the new one was started later."""
    findings = findings_of(demo_dataroot, ("gnn",))["gnn"]
    pick = next(i for i in findings if i.startswith("id_switch:"))
    finding = findings[pick]
    ended = [s for s in finding.lost.steps if s.ended is not None]
    assert ended and ended[0].ended.ending is Ending.DELETED and ended[0].ended.hits >= 0
    assert finding.decision is None and finding.taker.meas >= 0  # no close call: where the new track came from
    out, _ = record(pick, ("gnn",))
    why = read_rows(out)[focus_doc()][0]["TextDocument:text"][0].split("\n\n")[1]
    assert why.startswith("**Why** (gnn, ") and "existence" not in why  # GNN's tracks have none
    e = ended[0]
    hits = f"{e.ended.hits} of {e.ended.window} hits" if e.ended.hits else f"no hit in its last {e.ended.window} frames"
    assert f"its track logic deleted it at frame {e.frame} ({hits})" in why
    o = finding.taker
    assert f"track {o.track_id} had been started at frame {o.frame} by m{o.meas}" in why


def test_every_object_and_detection_the_why_names_is_labelled_at_the_failure_frame(
    demo_dataroot: Path, record, gnnpmb_report
) -> None:
    """A Why that points at another object ("no detection of its own within 2 m (truck m7, 1.2 m away, lay 1.0 m
    from truck GT 9da03c)") labels that object in the view at the failure's frame, as it labels the failure's own
    (dev set scene-0916 centerpoint miss:20: the neighbour the sentence named had no label, so a reader could not
    find it); at the other frames only the failure's objects are labelled."""
    report = gnnpmb_report
    scene = evidence_of(demo_dataroot, ("gnnpmb",))[0].scene
    findings = findings_of(demo_dataroot, ("gnnpmb",))["gnnpmb"]

    def others(fid: str) -> set[str]:
        failure = report.by_id(fid)
        text = " ".join(why_lines(findings[fid]))
        here = {short_id(str(t)) for t in scene.keyframes[failure.frame_index].gt.instance_id}
        return set(re.findall(r"\bGT ([0-9a-f]{6})\b", text)) & here - {short_id(g) for g in failure.gt_ids}

    pick = next(i for i in report.ids() if report.by_id(i).gt_ids and others(i))
    failure = report.by_id(pick)
    out, _ = record(pick)
    rows = read_rows(out)
    labels = {r["frame"]: set(r["Points3D:labels"] or []) for r in rows[paths.focus_callouts("gnnpmb")]}
    named = {f"GT {g}" for g in others(pick)}
    assert named <= labels[failure.frame_index], (pick, labels[failure.frame_index])
    assert all(not named & seen for frame, seen in labels.items() if frame != failure.frame_index)
    boxes = next(r for r in rows[focus_world()] if r.get("frame") == failure.frame_index)
    assert named <= set(boxes["Boxes3D:labels"])
    # The detections it names near the object at that frame too ("truck m7, 1.2 m away"), by their own labels.
    s = findings[pick].sighting(failure.frame_index)
    near = {n.meas for n in (s.nearest_any, s.nearest_own, s.neighbours_own, s.off, s.in_box) if n is not None}
    said = near & {int(m) for m in re.findall(r"\bm(\d+)\b", " ".join(why_lines(findings[pick])))}
    assert said, pick
    for m in said:
        assert any(x.startswith(f"m{m} ") for x in labels[failure.frame_index]), (m, labels[failure.frame_index])
        assert any(x.startswith(f"m{m} ") for x in boxes["Boxes3D:labels"])
