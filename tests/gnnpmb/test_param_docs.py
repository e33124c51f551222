"""The files written from the parameter declarations are the committed ones, and the declarations agree with
the reader (``gnnpmb.param_docs``, ``gnnpmb.param``)."""

from __future__ import annotations

import pytest

from gnnpmb.config import _SECTIONS, BoxNoise, ClassParams, ConfigError, TrackerConfig, load_config, paper_config
from gnnpmb.param import declared
from gnnpmb.param_docs import GENERATED


@pytest.mark.parametrize("path", list(GENERATED), ids=lambda p: p.name)
def test_committed_file_equals_the_one_rendered_from_the_declarations(path):
    assert path.read_text(encoding="utf-8") == GENERATED[path](), f"run: uv run python -m gnnpmb.param_docs ({path})"


def test_the_rendered_parameter_files_load_to_the_defaults_and_the_paper():
    by_name = {p.name: p for p in GENERATED}
    assert load_config(by_name["default_params.toml"]) == TrackerConfig()
    paper = load_config(by_name["paper.toml"])
    assert paper == paper_config() and paper.models.p_survive == 0.7 and paper.pmbm.n_hypotheses == 100


def test_every_declared_default_and_paper_value_is_inside_its_declared_range():
    assert all(name == kind.SECTION for name, kind in _SECTIONS.items())  # the name errors give it
    for kind in (*_SECTIONS.values(), ClassParams, BoxNoise):
        for d in declared(kind):
            assert d.spec.doc and d.type in (int, float), (kind.SECTION, d.name)
            for value in (d.default, d.spec.paper):
                if isinstance(value, int | float):
                    d.spec.check(d.name, value, f"[{kind.SECTION}]")


def test_a_value_past_the_models_limit_names_key_value_and_range(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text("[classes.car]\nq_x = 1e100\n")
    with pytest.raises(
        ConfigError, match=r"\[classes.car\] q_x must be in \[0, 1.15792e\+77\] \(.*float64.*\), got 1e\+100"
    ):
        load_config(path)
    path.write_text("[models]\nbirth_pos_std_m = inf\n")
    with pytest.raises(ConfigError, match=r"birth_pos_std_m must be in \(0, 3.40282e\+38\] .*got inf"):
        load_config(path)
