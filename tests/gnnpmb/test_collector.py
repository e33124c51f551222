"""The ``gnnpmb-viz`` script's garbage collector (``gnnpmb.stages.inputs.collect_rarely``): on while it loads, so
a reference cycle made then (an import's caught exception holds its frames, and they hold their callers' locals)
is freed instead of staying until the process ends."""

from __future__ import annotations

import gc
import weakref

from gnnpmb.stages.inputs import YOUNG_COLLECTION_THRESHOLD, collect_rarely, freeze_loaded


class _Big:
    """Stands for what a leaked frame would hold (a cold run's tables)."""


def test_a_cycle_made_while_loading_is_collected_and_the_loaded_objects_are_frozen() -> None:
    thresholds, was_enabled = gc.get_threshold(), gc.isenabled()
    try:
        collect_rarely()
        assert gc.isenabled() and gc.get_threshold()[0] == YOUNG_COLLECTION_THRESHOLD
        big = _Big()
        cycle: list[object] = [big]
        cycle.append(cycle)
        alive = weakref.ref(big)
        del big, cycle
        churn = [[] for _ in range(3 * YOUNG_COLLECTION_THRESHOLD)]  # containers enough for young collections
        del churn
        assert alive() is None
        kept = _Big()
        freeze_loaded()
        assert gc.get_freeze_count() > 0 and gc.isenabled()
        assert gc.get_threshold() == (YOUNG_COLLECTION_THRESHOLD, 10, 10) and kept is not None
    finally:
        gc.unfreeze()
        gc.set_threshold(*thresholds)
        (gc.enable if was_enabled else gc.disable)()
