"""A sweep stopped by Ctrl-C keeps what finished and resumes from the cache (``gnnpmb.study.sweep``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from gnnpmb.config import ModelParams
from gnnpmb.data.nuscenes import resolve_dataroot
from gnnpmb.eval.result_cache import ResultCache
from gnnpmb.study.data import resolve_study_data
from gnnpmb.study.grid import parse_param
from gnnpmb.study.runner import Execution
from gnnpmb.study.sweep import plan_sweep, run_sweep


def test_interrupted_sweep_keeps_finished_rows_and_resumes(tiny_dataroot: Path, tmp_path: Path) -> None:
    location = resolve_dataroot(tiny_dataroot, None)
    data = resolve_study_data(location, "mini_val", None, "centerpoint", 0)
    plan = plan_sweep("gnnpmb", data, {}, [parse_param("pmb.birth_weight=0.05,0.1")], one_at_a_time_mode=False)
    cache = ResultCache(tmp_path / "cache")

    def stop(row: dict[str, Any], from_cache: bool) -> None:
        raise KeyboardInterrupt

    first = run_sweep(plan, cache, Execution(workers=1), stop)
    assert first.interrupted and [r["config"] for r in first.rows] == [0]
    assert len(list(cache.folder.glob("*.json"))) == 1

    seen: list[bool] = []
    second = run_sweep(plan, cache, Execution(workers=1), lambda row, cached: seen.append(cached))
    assert not second.interrupted and second.from_cache == 1 and seen == [True, False]
    assert second.rows[0]["amota"] == first.rows[0]["amota"]
    assert [r["pmb.birth_weight"] for r in second.rows] == [0.05, 0.1]


def test_one_at_a_time_plan_starts_with_the_base(tiny_dataroot: Path) -> None:
    data = resolve_study_data(resolve_dataroot(tiny_dataroot, None), "mini_val", None, "centerpoint", 0)
    plan = plan_sweep(
        "gnnpmb", data, {}, [parse_param("pmb.birth_weight=0.05"), parse_param("preprocess.nms_iou_3d=0.2")], True
    )
    assert plan.assignments == ((), (("pmb.birth_weight", 0.05),), (("preprocess.nms_iou_3d", 0.2),))
    assert plan.base_values == {"pmb.birth_weight": ModelParams().birth_weight, "preprocess.nms_iou_3d": 0.1}
    with pytest.raises(Exception, match="unknown parameter"):
        plan_sweep("gnnpmb", data, {}, [parse_param("pmb.nope=1")], True)


def test_a_configuration_that_tracks_nothing_scores_zero_without_the_devkit(tiny_dataroot: Path) -> None:
    from gnnpmb.study.evaluate import ConfigJob, score_config
    from gnnpmb.study.grid import build_config, config_toml

    data = resolve_study_data(resolve_dataroot(tiny_dataroot, None), "mini_val", None, "centerpoint", 0)
    assignment = (("pmb.birth_weight", 1e-6),)
    row = score_config(ConfigJob(0, assignment, build_config(config_toml({}, assignment)), "gnnpmb", data))
    assert row["amota"] == 0.0 and row["tp"] == 0 and row["fp"] == 0 and row["eval_time_s"] == 0.0
    assert row["mota"] is None and row["amota_car"] is None
