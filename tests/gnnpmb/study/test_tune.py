"""Search space, per-class choice and the written TOML (``gnnpmb.study.tune``, ``gnnpmb.config.dump_toml``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from gnnpmb.config import ConfigError, dump_toml, load_config
from gnnpmb.study.grid import StudyError
from gnnpmb.study.tune import (
    SearchDim,
    Trial,
    check_space,
    choose_best,
    default_space,
    parse_space,
    write_params,
)


def test_parse_space() -> None:
    assert parse_space("car.q_x=0.01:1:log") == SearchDim("car.q_x", 0.01, 1.0, True)
    assert parse_space("pmb.gate_chi2=10:60") == SearchDim("pmb.gate_chi2", 10.0, 60.0, False)
    for bad in ("car.q_x=1:0.1", "car.q_x=0:1:log", "car.q_x=a:b", "car.q_x", "car.q_x=1"):
        with pytest.raises(StudyError):
            parse_space(bad)


def test_default_space_keeps_only_keys_the_loader_accepts_per_class() -> None:
    dims = default_space(("car",), {})
    names = {d.key.split(".")[1] for d in dims}
    assert {"q_x", "q_y", "r_x", "r_y"} <= names
    check_space(dims, {})
    with pytest.raises(StudyError, match="unknown parameter 'nope'"):
        check_space([SearchDim("car.nope", 0.1, 1.0, False)], {})


def _trial(car_q: float, ped_q: float, car: float, ped: float) -> Trial:
    return Trial(
        (("car.q_x", car_q), ("pedestrian.q_x", ped_q)),
        {"amota": (car + ped) / 2, "amota_car": car, "amota_pedestrian": ped},
    )


def test_each_class_takes_the_trial_where_it_scored_best() -> None:
    dims = [SearchDim("car.q_x", 0.01, 1, True), SearchDim("pedestrian.q_x", 0.01, 1, True)]
    trials = [_trial(0.1, 0.2, 0.5, 0.9), _trial(0.3, 0.4, 0.8, 0.4), _trial(0.5, 0.6, 0.8, 0.1)]
    assert choose_best(dims, trials) == (("car.q_x", 0.3), ("pedestrian.q_x", 0.2))
    shared = [*dims, SearchDim("pmb.gate_chi2", 10, 60, False)]
    coupled = [Trial((*t.assignment, ("pmb.gate_chi2", 20.0)), t.row) for t in trials]
    assert choose_best(shared, coupled) == coupled[0].assignment  # best overall: (0.5 + 0.9) / 2 = 0.7
    with pytest.raises(StudyError, match="no trial finished"):
        choose_best(dims, [])


def test_written_params_load_back(tmp_path: Path) -> None:
    toml = {"pmb": {"gate_chi2": 30.0}, "classes": {"car": {"q_x": 0.25, "r_y": 0.125}}}
    text = dump_toml(toml, ["made by a test", "second line"])
    assert text.startswith("# made by a test\n# second line\n")
    path = tmp_path / "p.toml"
    write_params(path, toml, ["x"])
    config = load_config(path)
    assert config.models.gate_chi2 == 30.0 and config.classes["car"].q_x == 0.25 and config.classes["car"].r_y == 0.125
    with pytest.raises(ConfigError):
        dump_toml({"pmb": {"gate_chi2": [1, 2]}})
