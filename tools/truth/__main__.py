"""``python -m tools.truth``: the independent checker over a dev-set matrix of trackers × scenes × presets.

Per cell it runs the tracker once (a ``ListSink`` beside the fact sink), finds and explains its failures
(``gnnpmb.why``), renders each finding as ``gnnpmb failures --why`` prints it, and checks every checkable sentence
(``tools.truth.sentences``) against the devkit's own matching (``tools.truth.devkit``), the raw events
(``tools.truth.rawevents``) and replays (``tools.truth.replay``). Prints contradictions per tracker and per class
and the counterfactual replays checked / refuted; exit 1 when any contradiction is found.
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

from tools.truth.sentences import CLASSES, Context, Contradiction, Tally, check_text

DEVSET = next(
    (p for p in (Path(__file__).resolve().parents[3] / "shared" / "devset", Path("/work/shared/devset")) if p.is_dir()),
    Path("../shared/devset"),
)
"""The dev set beside the checkout (``../shared/devset``, as CI lays it out), else where the developers' machines
keep it."""
MINI_VAL = ("scene-0103", "scene-0916")
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
) -> tuple[Tally, int]:
    """Check every finding of ``tracker`` on ``scene`` with ``preset``'s detection file; (tally, findings).
    where: gets ("tracker scene preset failure-id", contradiction) for each contradiction."""
    where = [] if where is None else where
    from gnnpmb.data.nuscenes import open_nuscenes
    from gnnpmb.eval.submission import run_results
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

    detections = dataroot / "detections" / f"{preset}_{split_of_scene(scene)}.json"
    request = load_inputs(
        check_request(scene, [tracker], dataroot=dataroot, version=version, detections_file=detections)
    )
    name = request.trackers[0]
    (run,) = run_all(request, record=True)
    reports, _ = find_reports(request, [run])
    evidence = evidence_of(request, reports[name], run)
    raw = RawEvents.of(list(run.events))
    ev = eval_facts(open_nuscenes(request.location), scene, run_results(run.tracking))
    tally = Tally()
    report = reports[name]
    for fid, failure in zip(report.ids(), report.failures, strict=True):
        start = max(request.frame_range.start, failure.frame_index - FRAMES_BEFORE)
        f = explain_failure(fid, evidence, request.scene, [], first_frame=start)
        text = "\n".join(plain(line) for line in why_lines(f))
        ctx = Context(
            f.class_name,
            f.frame,
            f.gt_id,
            tuple(f.covered),
            f.taker.false_frames if f.taker is not None else (),
            f.taker.track_id if f.taker is not None else None,
        )
        one = check_text(text, ctx, raw, ev, tracker)
        tally.add(one)
        where.extend((f"{tracker} {scene} {preset} {fid}", c) for c in one.found)
    return tally, len(report.failures)


def main(argv: Sequence[str] | None = None) -> int:
    from gnnpmb.registry import TRACKER_NAMES

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", action="append", help="dev-set scenes (default: the two mini_val scenes)")
    parser.add_argument("--detector", action="append", help="presets (default: all three)")
    parser.add_argument("--tracker", action="append", help="trackers (default: all)")
    parser.add_argument("--dataroot", type=Path, default=DEVSET)
    args = parser.parse_args(argv)
    per: dict[str, Tally] = defaultdict(Tally)
    findings: dict[str, int] = defaultdict(int)
    where: list[tuple[str, Contradiction]] = []
    for scene in args.scene or MINI_VAL:
        for preset in args.detector or PRESETS:
            for tracker in args.tracker or TRACKER_NAMES:
                tally, n = run_cell(tracker, scene, preset, args.dataroot, where=where)
                per[tracker].add(tally)
                findings[tracker] += n
                line = " ".join(f"{k} {sum(c.kind == k for c in tally.found)}/{tally.checked[k]}" for k in CLASSES)
                print(
                    f"checked {tracker} {scene} {preset}: {n} findings; false/checked {line}; replays "
                    f"{tally.replays} refuted {tally.refuted}",
                    file=sys.stderr,
                    flush=True,
                )
    head = " ".join(f"{k:>14}" for k in CLASSES)
    print(f"{'tracker':12} {'findings':>8} {head} {'replays':>8} {'refuted':>8}")
    total = Tally()
    for tracker, t in per.items():
        total.add(t)
        counts = defaultdict(int)
        for c in t.found:
            counts[c.kind] += 1
        cells = " ".join(f"{counts[k]:>6}/{t.checked[k]:<7}" for k in CLASSES)
        print(f"{tracker:12} {findings[tracker]:>8} {cells} {t.replays:>8} {t.refuted:>8}")
    print(f"contradictions: {len(total.found)} (false/checked per class above)")
    for place, c in where:
        print(f"  {place}: [{c.kind}] {c.sentence!r} -- {c.truth}")
    return 1 if total.found else 0


if __name__ == "__main__":
    sys.exit(main())
