"""``python -m tools.truth``: the independent checker over a dev-set matrix of trackers × scenes × presets.

Per cell it runs the tracker once (a ``ListSink`` beside the fact sink), finds and explains its failures
(``gnnpmb.why``), renders each finding as ``gnnpmb failures --why`` prints it, and checks every checkable sentence
(``tools.truth.sentences``) and every typed field of the finding (``tools.truth.fields``) against the devkit's own
matching (``tools.truth.devkit``), the raw events (``tools.truth.rawevents``), the files and replays
(``tools.truth.replay``). ``--demo``: the demo world instead of the dev set. Prints contradictions per tracker and
per class and the counterfactual replays checked / refuted; exit 1 when any contradiction is found.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from collections import defaultdict
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from tools.truth import fields, lost, otherruns
from tools.truth.sentences import CLASSES, Context, Contradiction, Tally, check_choice_lines, check_text

DEVSET = next(
    (p for p in (Path(__file__).resolve().parents[3] / "shared" / "devset", Path("/work/shared/devset")) if p.is_dir()),
    Path("../shared/devset"),
)
"""The dev set beside the checkout (``../shared/devset``, as CI lays it out), else where the developers' machines
keep it."""
MINI_VAL = ("scene-0103", "scene-0916")
MINI_TRAIN = tuple(f"scene-{n}" for n in ("0061", "0553", "0655", "0757", "0796", "1077", "1094", "1100"))
PRESETS = ("centerpoint", "megvii", "pointpillars")


def split_of_scene(scene: str) -> str:
    return "mini_val" if scene in MINI_VAL else "mini_train"


def run_cell(
    tracker: str,
    scene: str,
    preset: str,
    dataroot: Path = DEVSET,
    version: str = "v1.0-mini",
    where: list[tuple[str, Contradiction]] | None = None,
    other: str | None = None,
) -> tuple[Tally, int]:
    """Check every finding of ``tracker`` on ``scene`` with ``preset``'s detection file; (tally, findings).
    where: gets ("tracker scene preset failure-id", contradiction) for each contradiction; other: a second tracker
    run on the same detections, whose outcome the findings state ("pmbm on the same detections ...") and which is
    checked against its own devkit bookkeeping."""
    return run_scene(scene, preset, {tracker: other}, dataroot, version, where)[tracker]


def run_scene(
    scene: str,
    preset: str,
    trackers: Mapping[str, str | None],
    dataroot: Path = DEVSET,
    version: str = "v1.0-mini",
    where: list[tuple[str, Contradiction]] | None = None,
    results: Mapping[str, Path] | None = None,
    detections: Path | None = None,
    focus: bool = False,
    seen: Callable[[object, fields.Sources], None] | None = None,
) -> dict[str, tuple[Tally, int]]:
    """``run_cell`` for several trackers on one scene and preset (tracker -> the run its findings compare with, or
    None), each tracker run and evaluated once: the cells of a row of the matrix share their other run. results:
    name -> a results file of a tracker outside the project, made on the same detections (its findings checked
    against the file: it has no events); a name of ``trackers`` may be one of them. detections: the detection file
    (default: the dev set's of ``preset`` and the scene's split). focus: also render each finding's focus document
    (``gnnpmb-viz --focus``'s summary, the run beside it included) and check it for a ``?`` placeholder. seen: called
    with each finding and the sources its fields were checked against."""
    where = [] if where is None else where
    from gnnpmb.data.nuscenes import open_nuscenes
    from gnnpmb.eval.submission import run_results
    from gnnpmb.registry import tracker_keeps_detection_box
    from gnnpmb.stages.evaluation import find_reports
    from gnnpmb.stages.findings import evidence_of
    from gnnpmb.stages.inputs import load_inputs
    from gnnpmb.stages.request import check_request
    from gnnpmb.stages.runs import run_all
    from gnnpmb.why.findings import FRAMES_BEFORE
    from gnnpmb.why.reason import explain_failure
    from gnnpmb.why.words import plain, why_lines
    from tools.truth.devkit import eval_facts
    from tools.truth.rawevents import RawEvents
    from tools.truth.scene import SceneTruth

    detections = detections or dataroot / "detections" / f"{preset}_{split_of_scene(scene)}.json"
    results = dict(results or {})
    names = list(dict.fromkeys([*trackers, *(o for o in trackers.values() if o is not None)]))
    files = [f"{n}={p}" for n, p in results.items() if n in names]
    request = load_inputs(
        check_request(
            scene,
            [n for n in names if n not in results],
            results=files,
            dataroot=dataroot,
            version=version,
            detections_file=detections,
        )
    )
    runs = dict(zip(request.trackers, run_all(request, record=True), strict=True))
    reports, _ = find_reports(request, list(runs.values()))
    evidence = {n: evidence_of(request, reports[n], r) for n, r in runs.items()}
    nusc = open_nuscenes(request.location)
    facts: dict[str, object] = {}

    def ev_of(name: str):
        if name not in facts:
            facts[name] = eval_facts(nusc, scene, run_results(runs[name].tracking))
        return facts[name]

    truth = SceneTruth.read(nusc, scene, detections)
    keeps = {n: n in results or tracker_keeps_detection_box(str(request.spec(n).tracker)) for n in trackers}

    def found(tally: Tally):
        return lambda kind, sentence, why: tally.found.append(Contradiction(kind, sentence, why))

    out = {}
    for tracker, other in trackers.items():
        rest = [other] if other is not None and other != tracker else []
        raw = None if tracker in results else RawEvents.of(list(runs[tracker].events))
        ev = ev_of(tracker)
        others = {n: ev_of(n) for n in rest}
        tally = Tally()
        report = reports[tracker]
        raws = (
            {n: None if n in results else RawEvents.of(list(runs[n].events)) for n in [tracker, *rest]} if focus else {}
        )
        for fid, failure in zip(report.ids(), report.failures, strict=True):
            start = max(request.frame_range.start, failure.frame_index - FRAMES_BEFORE)
            f = explain_failure(fid, evidence[tracker], request.scene, [evidence[n] for n in rest], first_frame=start)
            text = "\n".join(plain(line) for line in why_lines(f))
            ctx = Context(
                f.class_name,
                f.frame,
                f.gt_id,
                tuple(f.covered),
                f.taker.false_frames if f.taker is not None else (),
                f.taker.track_id if f.taker is not None else None,
                f.kind.value,
                f.lost.track_id if f.lost is not None else None,
                f.false_output.track_id if f.false_output is not None else None,
            )
            one = check_text(text, ctx, raw, ev, tracker, truth, others)
            sources = fields.Sources(truth, raw, ev, others, keeps[tracker])
            fields.check_fields(f, sources, one, found(one))
            if focus:
                raws = {
                    n: raw if n == tracker else None if n in results else RawEvents.of(list(runs[n].events))
                    for n in [tracker, *rest]
                }
                subs = {n: ev_of(n).submitted for n in [tracker, *rest]}
                _check_focus(fid, f, request, {n: reports[n] for n in [tracker, *rest]}, evidence, one, raws, subs)
            if seen is not None:
                seen(f, sources)
            tally.add(one)
            where.extend((f"{tracker} {scene} {preset} {fid}", c) for c in one.found)
        out[tracker] = (tally, len(report.failures))
    return out


def _check_focus(
    fid: str,
    finding,
    request,
    reports: Mapping,
    evidence: Mapping,
    out: Tally,
    raws: Mapping | None = None,
    submitted: Mapping | None = None,
) -> None:
    """The focus document of failure ``fid`` (its summary, as ``gnnpmb-viz --focus`` shows it with the runs of
    ``reports``) holds no ``?`` placeholder, and each run's story lines (``lost.check_story``) hold against that
    run's raw events (``raws``: by run name, None for a results file) and its submission (``submitted``: by run
    name, frame -> the track ids it has a box of)."""
    from gnnpmb.focus import resolve_focus
    from gnnpmb.why.story import Storyteller
    from viz.focus_summary import TrackerView, focus_markdown

    estimates = {n: [fr.estimates for fr in evidence[n].run.frames] for n in reports}
    target = resolve_focus(fid, request.scene, reports, estimates, request.frame_range)
    views = {}
    for name in reports:
        ev = evidence[name]
        teller = Storyteller(ev.facts, involved=frozenset(target.track_ids.get(name, ())))  # as the viewer tells it
        story = tuple(line for x in ev.facts.frame_indices for line in teller.frame_lines(x))
        views[name] = TrackerView(ev, request.capabilities(name).has_gates, story, frozenset(teller.shown_ever))
    doc = focus_markdown(target, finding, views, target.window(request.frame_range), request.scene)
    otherruns.check_involved(doc, target.track_ids, out, lambda *a: out.found.append(Contradiction(*a)))
    otherruns.check_parting(
        doc, target.frame_index, target.class_name, raws or {}, out, lambda *a: out.found.append(Contradiction(*a))
    )
    for name, raw in (raws or {}).items():
        section = doc.split(f"\n## {name}\n", 1)[1].split("\n## ", 1)[0] if f"\n## {name}\n" in doc else ""
        lost.check_story(
            section,
            finding.class_name,
            raw,
            out,
            lambda *a: out.found.append(Contradiction(*a)),
            (submitted or {}).get(name),
        )
        lost.check_track_tables(section, finding.class_name, raw, out, lambda *a: out.found.append(Contradiction(*a)))
        header = f"**Key decisions of {name}**"
        key = doc.split(header, 1)[1].split("\n\n")[1] if header in doc else ""
        check_choice_lines(
            key + "\n" + section, finding.class_name, raw, out, lambda *a: out.found.append(Contradiction(*a))
        )
    out.checked["misleading"] += 1
    doc = doc.replace("?url=", "")
    if "?" in doc:
        at = doc.index("?")
        out.found.append(Contradiction("misleading", doc[max(0, at - 60) : at + 1], "a placeholder in the focus doc"))


def demo_detections(dataroot: Path, scene: str, preset: str, folder: Path) -> Path:
    """The demo world's simulated detector (``preset``, seed 0) on ``scene`` written as a detection file in
    ``folder``: the boxes the tracker gets with ``--detector preset``, and the file the checker reads them from."""
    from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
    from gnnpmb.data.simdet import to_submission
    from gnnpmb.eval.submission import write_json
    from gnnpmb.pipeline import get_detections

    data = load_scene(resolve_dataroot(dataroot, None, (scene,)), scene)
    path = folder / f"{preset}_{scene}.json"
    write_json(path, to_submission(get_detections(data, None, preset, 0)))
    return path


def other_of(tracker: str, other: str) -> str:
    """The run a tracker's findings are compared with: ``other``, or gnnpmb for ``other`` itself."""
    return "gnnpmb" if tracker == other else other


def cells(scenes: Sequence[str], presets: Sequence[str], trackers: Sequence[str], square: bool):
    """(scene, preset, tracker) in order; square: each tracker once, walking scenes and presets in turn (a Latin
    square over the first ``len(trackers)`` cells of scenes × presets)."""
    if not square:
        return [(s, p, t) for s in scenes for p in presets for t in trackers]
    return [
        (scenes[i % len(scenes)], presets[(i // len(scenes) + i) % len(presets)], t) for i, t in enumerate(trackers)
    ]


def main(argv: Sequence[str] | None = None) -> int:
    from gnnpmb.registry import TRACKER_NAMES

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", action="append", help="dev-set scenes (default: the two mini_val scenes)")
    parser.add_argument("--all-scenes", action="store_true", help="all ten: mini_val and mini_train")
    parser.add_argument("--detector", action="append", help="presets (default: all three)")
    parser.add_argument("--tracker", action="append", help="trackers (default: all)")
    parser.add_argument("--dataroot", type=Path, default=None, help="default: the dev set (the demo with --demo)")
    parser.add_argument(
        "--demo", action="store_true", help="the demo world (its val and staged scenes, simulated detector presets)"
    )
    parser.add_argument("--other", default="pmbm", help="the run findings compare with ('none': no other run)")
    parser.add_argument("--square", action="store_true", help="each tracker once over the scenes and presets")
    parser.add_argument(
        "--focus", action="store_true", help="also check each finding's focus document (on by default with --demo)"
    )
    parser.add_argument(
        "--results",
        action="append",
        default=[],
        metavar="NAME=FILE.json",
        help="check a results file's findings (made on the preset's detections) instead of the trackers'",
    )
    args = parser.parse_args(argv)
    per: dict[str, Tally] = defaultdict(Tally)
    findings: dict[str, int] = defaultdict(int)
    where: list[tuple[str, Contradiction]] = []
    scenes = MINI_VAL + MINI_TRAIN if args.all_scenes else (args.scene or MINI_VAL)
    dataroot, folder = args.dataroot or DEVSET, None
    if args.demo:
        import tempfile

        from gnnpmb.data.demo import DEMO_SCENES, ensure_demo_dataset
        from gnnpmb.data.demo_staged import STAGED_SCENES

        scenes = tuple(args.scene or DEMO_SCENES + STAGED_SCENES)
        dataroot = args.dataroot or ensure_demo_dataset(DEMO_SCENES + STAGED_SCENES)
        folder = Path(tempfile.mkdtemp(prefix="truth-demo-"))
    try:
        files = {spec.split("=", 1)[0]: Path(spec.split("=", 1)[1]) for spec in args.results}
        todo = cells(scenes, args.detector or PRESETS, args.tracker or ([] if files else TRACKER_NAMES), args.square)
        todo += [(s, p, name) for s in scenes for p in args.detector or PRESETS for name in files]
        rows: dict[tuple[str, str], dict[str, str | None]] = defaultdict(dict)
        for scene, preset, tracker in todo:
            rows[(scene, preset)][tracker] = None if args.other == "none" else other_of(tracker, args.other)
        for (scene, preset), row in rows.items():
            here: list[tuple[str, Contradiction]] = []
            detections = demo_detections(dataroot, scene, preset, folder) if folder is not None else None
            focus = args.focus or args.demo
            done = run_scene(
                scene, preset, row, dataroot, where=here, results=files, detections=detections, focus=focus
            )
            for tracker, (tally, n) in done.items():
                per[tracker].add(tally)
                findings[tracker] += n
                line = " ".join(f"{k} {sum(c.kind == k for c in tally.found)}/{tally.checked[k]}" for k in CLASSES)
                print(
                    f"checked {tracker} {scene} {preset}: {n} findings; false/checked {line}; replays "
                    f"{tally.replays} refuted {tally.refuted}; clauses {tally.clauses - sum(tally.unchecked.values())}/"
                    f"{tally.clauses} read",
                    file=sys.stderr,
                    flush=True,
                )
            for place, c in here:
                print(f"  {place}: [{c.kind}] {c.sentence!r} -- {c.truth}", file=sys.stderr, flush=True)
            where += here
    finally:
        if folder is not None:  # the demo's detection files written for this run
            shutil.rmtree(folder, ignore_errors=True)
    head = " ".join(f"{k:>14}" for k in CLASSES)
    print(f"{'tracker':12} {'findings':>8} {head} {'replays':>8} {'refuted':>8}")
    total = Tally()
    for tracker, t in per.items():
        total.add(t)
        counts = defaultdict(int)
        for c in t.found:
            counts[c.kind] += 1
        cells_text = " ".join(f"{counts[k]:>6}/{t.checked[k]:<7}" for k in CLASSES)
        print(f"{tracker:12} {findings[tracker]:>8} {cells_text} {t.replays:>8} {t.refuted:>8}")
    print(f"contradictions: {len(total.found)} (false/checked per class above)")
    read = total.clauses - sum(total.unchecked.values())
    share = 100.0 * read / total.clauses if total.clauses else 0.0
    print(f"coverage: {read} of {total.clauses} printed clauses read by a checker pattern ({share:.1f} %)")
    print("clause kinds not checked (count):")
    for kind, n in total.unchecked.most_common():
        print(f"  {n:6} {kind}")
    for place, c in where:
        print(f"  {place}: [{c.kind}] {c.sentence!r} -- {c.truth}")
    return 1 if total.found else 0


if __name__ == "__main__":
    sys.exit(main())
