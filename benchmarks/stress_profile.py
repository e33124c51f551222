"""Where a PMBM step goes on the dense stress frame: per-class strategy time and the cProfile top entries.

Usage: uv run python benchmarks/stress_profile.py [--n-hypotheses 100] [--stress-n 320] [--repeat 5] [--top 25]

Runs ``pmbm`` on the 4 stress frames of ``tracker_speed.py`` (the 4th is the one timed there) ``--repeat``
times and prints, for the 4th frame, the fastest step time and per class the fastest ``KBest.update`` time
(wall clock) with the number of prior and posterior hypotheses; then one cProfile run of that frame, sorted by
internal time and by cumulative time. Run it on an otherwise idle machine; cProfile's own overhead inflates
its times (compare them with each other, not with the step time).
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time
from collections.abc import Sequence

from tracker_speed import stress_frames

from gnnpmb.config import PmbmParams, TrackerConfig
from gnnpmb.data.preprocess import preprocess
from gnnpmb.events import NullSink
from gnnpmb.pmb import pmbm
from gnnpmb.pmb.core import GlobalHypothesis, UpdateContext
from gnnpmb.pmb.cost import LocalHypotheses
from gnnpmb.tracker import MultiClassTracker
from gnnpmb.types import TRACKING_CLASSES, FrameDetections


def warmed_tracker(frames: Sequence[FrameDetections], config: TrackerConfig) -> MultiClassTracker:
    """A ``pmbm`` tracker that has stepped through every frame but the last (0.5 s apart)."""
    mot = MultiClassTracker("pmbm", config)
    for i, frame in enumerate(frames[:-1]):
        mot.step(frame, 0.5 if i else 0.0, NullSink())
    return mot


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n-hypotheses", type=int, default=100)
    parser.add_argument("--stress-n", type=int, default=320)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--top", type=int, default=25)
    args = parser.parse_args()
    config = TrackerConfig().replace(pmbm=PmbmParams(n_hypotheses=args.n_hypotheses))
    frames = [preprocess(b, config.preprocess, TRACKING_CLASSES) for b in stress_frames(args.stress_n, 4)]
    per_class: dict[str, list[float]] = {}
    counts: dict[str, tuple[int, int]] = {}
    update = pmbm.KBest.update

    def timed(
        self: pmbm.KBest, priors: list[GlobalHypothesis], locals_: Sequence[LocalHypotheses], ctx: UpdateContext
    ) -> list[GlobalHypothesis]:
        start = time.perf_counter()
        out = update(self, priors, locals_, ctx)
        per_class.setdefault(ctx.class_name, []).append(time.perf_counter() - start)
        counts[ctx.class_name] = (len(priors), len(out))
        return out

    step_s = []
    for _ in range(args.repeat):
        mot = warmed_tracker(frames, config)
        pmbm.KBest.update = timed
        start = time.perf_counter()
        mot.step(frames[-1], 0.5, NullSink())
        step_s.append(time.perf_counter() - start)
        pmbm.KBest.update = update
    print(
        f"stress frame ({int(frames[-1].kept.sum())} detections), N_h = {args.n_hypotheses}: fastest step "
        f"{min(step_s) * 1e3:.1f} ms of {args.repeat}"
    )
    print(f"{'class':12s} {'KBest.update ms':>16s} {'prior hyps':>11s} {'posterior hyps':>15s}")
    for name, times in per_class.items():
        print(f"{name:12s} {min(times) * 1e3:16.2f} {counts[name][0]:11d} {counts[name][1]:15d}")
    mot = warmed_tracker(frames, config)
    profile = cProfile.Profile()
    profile.enable()
    mot.step(frames[-1], 0.5, NullSink())
    profile.disable()
    for key in ("tottime", "cumulative"):
        pstats.Stats(profile).strip_dirs().sort_stats(key).print_stats(args.top)


if __name__ == "__main__":
    main()
