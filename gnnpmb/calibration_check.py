"""Which of its learnt values ``gnnpmb calibrate`` writes, per class: a k-fold cross-validation by scenes on the
split it learns from, scored with the official evaluation.

The learnt values are this detector's statistics fed into models cruder than the data; the defaults are values
tuned together. Out of sample the statistics can lose to the defaults (issue 32, Round 13 in
``docs/results.md``: on both worlds' ``mini_train`` the pedestrians' learnt clutter, the box likelihood and the
fixed P_D cap each lost AMOTA on some detector). So calibrate checks what it learnt on the user's own split:

- the split's scenes are cut into ``k`` folds (every k-th scene in sorted order);
- for each fold, the values are learnt again on the other folds (``calibration.calibrate``), and the check's
  tracker (``CHECK_TRACKER``, the default tracker) tracks the fold's scenes with each candidate: the defaults
  (nothing learnt that it reads), everything learnt, and everything learnt but one group (``GROUPS``);
- each candidate is scored per class with the official evaluation on the fold (``gnnpmb.study.evaluate``); a
  class's score is its AMOTA averaged over the folds where it has annotations.

A class takes the candidate with the highest score if that beats the defaults by at least ``MARGIN_AMOTA``, else
the defaults. Classes can choose apart because they are tracked apart: a class's boxes depend only on its own
parameters (the trackers share only the counter that numbers the tracks, which the evaluation does not read).
Values the check's tracker does not read (PHD/CPHD and JPDA/GNN detection probabilities, ``prob3dmot``'s box
noise) are written as learnt: they are not checked.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from gnnpmb.calibration import Learnt, calibrate
from gnnpmb.config import TrackerConfig, config_from_dict
from gnnpmb.data.scene import SceneData
from gnnpmb.study.data import SceneInputs, StudyData, track_scene
from gnnpmb.study.runner import Execution, run_tasks
from gnnpmb.types import TRACKING_CLASSES, Boxes

CHECK_TRACKER = "gnnpmb"
"""The tracker the candidates are scored with."""
MARGIN_AMOTA = 0.01
"""A class keeps the defaults unless a candidate's mean AMOTA over the folds is at least this much higher."""
GROUPS: dict[str, frozenset[str]] = {
    "box likelihood": frozenset({"heading_std_rad", "size_log_std", "box_outlier_prob", "size_log_spread"}),
    "velocity noise": frozenset({"r_vx", "r_vy"}),
    "clutter": frozenset({"clutter_intensity", "clutter_velocity_density"}),
    "P_D cap": frozenset({"miss_p_detect_max", "miss_p_detect_online"}),
}
"""The groups of learnt keys a candidate leaves out one at a time (the four that Round 13 found losing somewhere)."""
DEFAULTS = "defaults"
LEARNT = "learnt"
_UNCHECKED_TABLES = ("phd", "vector")
"""Per-class tables the check's tracker does not read: written as learnt."""


def candidates() -> tuple[str, ...]:
    """The candidates' names, the defaults first (ties go to the earlier one)."""
    return (DEFAULTS, LEARNT, *(f"without {group}" for group in GROUPS))


def _checked(item: Learnt) -> bool:
    """Whether the check's tracker reads ``item`` (a value of ``classes.<c>`` or ``classes.<c>.pmb``)."""
    return item.table.rsplit(".", 1)[-1] not in _UNCHECKED_TABLES


def unchecked_note(learnt: Sequence[Learnt]) -> str | None:
    """The file's line for one class's values the check's tracker does not read, or None when there are none:
    written as learnt whatever the check chose, which a reader of "the defaults kept" must be told."""
    tables = sorted({v.table.rsplit(".", 1)[-1] for v in learnt if not _checked(v)})
    if not tables:
        return None
    where = " and ".join(f"[{t}]" for t in tables)
    return f"{where} written as learnt: read by the PHD/CPHD and JPDA/GNN trackers, which the check does not run"


def candidate_values(name: str, learnt: Sequence[Learnt]) -> list[Learnt]:
    """The values of one class's ``learnt`` that candidate ``name`` writes."""
    if name == LEARNT:
        return list(learnt)
    if name == DEFAULTS:
        return [v for v in learnt if not _checked(v)]
    group = GROUPS[name.removeprefix("without ")]
    return [v for v in learnt if not (_checked(v) and v.key in group)]


def as_params(learnt: Mapping[str, Sequence[Learnt]]) -> dict[str, Any]:
    """The learnt values as the parameter file's nested tables (``{"classes": {"car": {"pmb": {...}}}}``)."""
    out: dict[str, Any] = {}
    for items in learnt.values():
        for item in items:
            table = out
            for part in item.table.split("."):
                table = table.setdefault(part, {})
            table[item.key] = item.value
    return out


def fold_scenes(scene_names: Sequence[str], k: int) -> list[tuple[str, ...]]:
    """The scenes in ``k`` folds: every k-th scene in sorted order."""
    ordered = sorted(scene_names)
    return [tuple(ordered[i::k]) for i in range(k)]


@dataclass(frozen=True, slots=True)
class FoldJob:
    """One candidate tracked on one fold's scenes and scored there."""

    fold: int
    candidate: str
    config: TrackerConfig
    data: StudyData


def score_fold(job: FoldJob) -> dict[str, float | None]:
    """Per class, the official AMOTA of ``job``'s candidate on its fold (None: no annotations of the class there);
    runs in a Ray worker or here."""
    from gnnpmb.study.evaluate import official_scores

    parts = [track_scene(job.data, name, CHECK_TRACKER, job.config).results for name in job.data.scene_names]
    if not any(boxes for part in parts for boxes in part.values()):  # the devkit refuses an empty submission
        return dict.fromkeys(TRACKING_CLASSES, 0.0)
    scores = official_scores(job.data, parts)
    amota = {c: scores.per_class.get(c, {}).get("amota", math.nan) for c in TRACKING_CLASSES}
    return {c: None if math.isnan(v) else v for c, v in amota.items()}


@dataclass(frozen=True, slots=True)
class CheckResult:
    """The cross-validation: per candidate and class, the mean AMOTA over the folds with annotations of the class
    (None: none); per class the chosen candidate; the folds' scenes."""

    amota: dict[str, dict[str, float | None]]
    chosen: dict[str, str]
    folds: tuple[tuple[str, ...], ...]

    def reason(self, cls: str) -> str:
        """One line saying what the check chose for ``cls`` and why."""
        k, scores = len(self.folds), self.amota
        base = scores[DEFAULTS][cls]
        if base is None:
            return "the defaults kept: no annotations of the class in any fold"
        pick = self.chosen[cls]
        if pick != DEFAULTS:
            group = pick.removeprefix("without ")
            what = "everything learnt" if pick == LEARNT else f"everything learnt but the {group}"
            return f"{what} written: {k}-fold AMOTA {scores[pick][cls]:.3f} against the defaults' {base:.3f}"
        best = _best(scores, cls)
        if best == DEFAULTS:
            return f"the defaults kept: they scored highest ({k}-fold AMOTA {base:.3f})"
        return (
            f"the defaults kept: no candidate beat them by {MARGIN_AMOTA:g} ({k}-fold AMOTA {base:.3f}; best, "
            f"{best}, {scores[best][cls]:.3f})"
        )


def _best(amota: Mapping[str, Mapping[str, float | None]], cls: str) -> str:
    """The candidate with the highest mean AMOTA for ``cls``, the earlier one on a tie (None counts lowest)."""
    return max(candidates(), key=lambda n: -math.inf if amota[n][cls] is None else amota[n][cls])


def choose(amota: Mapping[str, Mapping[str, float | None]]) -> dict[str, str]:
    """Per class: the candidate with the highest mean AMOTA (the earlier one on a tie) if it beats the defaults
    by ``MARGIN_AMOTA``, else the defaults."""
    out = {}
    for c in TRACKING_CLASSES:
        base = amota[DEFAULTS][c]
        best = _best(amota, c)
        beats = base is not None and amota[best][c] is not None and amota[best][c] >= base + MARGIN_AMOTA
        out[c] = best if beats else DEFAULTS
    return out


def cross_validate(
    scenes: Sequence[SceneData],
    detections: Sequence[Mapping[str, Boxes]],
    data: StudyData,
    base: TrackerConfig,
    class_range_m: Mapping[str, float],
    match_distance_m: float,
    k: int,
    run: Execution,
    on_done: Callable[[], None] = lambda: None,
) -> CheckResult:
    """The check (module docstring) of the values learnt from ``scenes`` (the split of ``data``) and their
    ``detections``, in ``k`` folds, the candidates scored as ``run`` says (call inside its session)."""
    from gnnpmb.data.eval_subset import eval_location
    from gnnpmb.data.nuscenes import sample_tokens

    folds = fold_scenes([s.name for s in scenes], k)
    by_name = {s.name: (s, d) for s, d in zip(scenes, detections, strict=True)}
    inputs: Any = {name: SceneInputs(s, dict(d)) for name, (s, d) in by_name.items()}
    if run.uses_ray:
        from gnnpmb.study.runner import import_ray

        inputs = import_ray().put(inputs)
    jobs = []
    for f, fold in enumerate(folds):
        rest = [by_name[n] for n in sorted(by_name) if n not in fold]
        learnt, _, _ = calibrate([s for s, _ in rest], [d for _, d in rest], base, class_range_m, match_distance_m)
        fold_data = dataclasses.replace(
            data,
            scene_names=fold,
            sample_tokens=tuple(sample_tokens(data.location, fold)),
            inputs=inputs,
            evaluation=eval_location(data.location, fold),
        )
        for name in candidates():
            chosen = {c: candidate_values(name, learnt[c]) for c in TRACKING_CLASSES}
            jobs.append(FoldJob(f, name, config_from_dict(as_params(chosen), base), fold_data))
    per_job: dict[int, dict[str, float | None]] = {}
    for i, scores in run_tasks(score_fold, jobs, run):
        per_job[i] = scores
        on_done()
    amota: dict[str, dict[str, float | None]] = {}
    for name in candidates():
        mine = [per_job[i] for i, job in enumerate(jobs) if job.candidate == name]
        amota[name] = {}
        for c in TRACKING_CLASSES:
            values = [s[c] for s in mine if s[c] is not None]
            amota[name][c] = sum(values) / len(values) if values else None
    return CheckResult(amota=amota, chosen=choose(amota), folds=tuple(folds))


def check_jobs(n_folds: int) -> int:
    """How many candidate scorings a check of ``n_folds`` folds runs (for a progress bar)."""
    return n_folds * len(candidates())
