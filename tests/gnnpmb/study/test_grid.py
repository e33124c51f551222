"""Parameter keys, values and grids (``gnnpmb.study.grid``)."""

from __future__ import annotations

import pytest

from gnnpmb.config import ModelParams, TrackerConfig
from gnnpmb.study.grid import (
    StudyError,
    base_value,
    build_config,
    check_assignments,
    config_toml,
    full_grid,
    one_at_a_time,
    parse_param,
    toml_paths,
)
from gnnpmb.types import TRACKING_CLASSES


def test_keys_expand_to_toml_paths() -> None:
    assert toml_paths("pmb.gate_chi2") == (("pmb", "gate_chi2"),)
    assert toml_paths("car.birth_weight") == (("classes", "car", "birth_weight"),)
    assert toml_paths("classes.bus.q_x") == (("classes", "bus", "q_x"),)
    assert toml_paths("*.extraction_threshold") == tuple(
        ("classes", c, "extraction_threshold") for c in TRACKING_CLASSES
    )
    for bad in ("gate_chi2", "pmb.", "a.b.c", "classes.boat.q_x", "car.q x"):
        with pytest.raises(StudyError):
            toml_paths(bad)


def test_values_are_toml_scalars_in_order() -> None:
    p = parse_param("pmb.gate_chi2=40, 1e1 ,20")
    assert p.key == "pmb.gate_chi2" and p.values == (40, 10.0, 20)
    assert parse_param("x.flag=true,false").values == (True, False)
    for bad in ("pmb.gate_chi2", "=1", "pmb.gate_chi2=,", "pmb.gate_chi2=inf", "pmb.gate_chi2=[1]"):
        with pytest.raises(StudyError):
            parse_param(bad)


def test_full_grid_and_one_at_a_time() -> None:
    a, b = parse_param("pmb.gate_chi2=20,40"), parse_param("car.q_x=0.1,0.2,0.3")
    grid = full_grid([a, b])
    assert len(grid) == 6
    assert grid[0] == (("pmb.gate_chi2", 20), ("car.q_x", 0.1))
    assert grid[5] == (("pmb.gate_chi2", 40), ("car.q_x", 0.3))
    assert one_at_a_time([a, b]) == [
        (),
        (("pmb.gate_chi2", 20),),
        (("pmb.gate_chi2", 40),),
        (("car.q_x", 0.1),),
        (("car.q_x", 0.2),),
        (("car.q_x", 0.3),),
    ]
    with pytest.raises(StudyError, match="empty grid"):
        full_grid([])
    with pytest.raises(StudyError, match="both set classes.car.q_x"):
        full_grid([b, parse_param("*.q_x=1")])


def test_configurations_go_through_the_config_loader() -> None:
    base = {"pmb": {"p_survive": 0.8}, "classes": {"car": {"r_x": 0.5}}}
    toml = config_toml(base, (("pmb.gate_chi2", 20), ("*.q_x", 0.3)))
    config = build_config(toml)
    assert config.models.gate_chi2 == 20.0 and config.models.p_survive == 0.8
    assert {config.classes[c].q_x for c in TRACKING_CLASSES} == {0.3}
    assert config.classes["car"].r_x == 0.5 and config.classes["bus"].r_x == TrackerConfig().classes["bus"].r_x
    assert base == {"pmb": {"p_survive": 0.8}, "classes": {"car": {"r_x": 0.5}}}
    with pytest.raises(StudyError, match=r"pmb.gate_chi3=1: \[pmb\]: unknown parameter 'gate_chi3'"):
        check_assignments({}, [(("pmb.gate_chi3", 1),)])
    with pytest.raises(StudyError, match="expected a number"):
        check_assignments({}, [(("pmb.gate_chi2", "wide"),)])


def test_base_values() -> None:
    config = TrackerConfig()
    assert base_value(config, "pmb.birth_weight") == ModelParams().birth_weight
    assert base_value(config, "car.q_x") == 0.1589
    assert base_value(config, "*.q_x") is None  # differs between classes
    assert base_value(config, "pmb.no_such_key") is None
