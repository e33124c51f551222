from pathlib import Path

import pytest

import gnnpmb
from gnnpmb.config import PAPER_CLASS_PARAMS, ConfigError, TrackerConfig, dump_config, load_config

DEFAULT_FILE = Path(gnnpmb.__file__).parent / "default_params.toml"


def test_shipped_parameter_file_equals_paper_defaults():
    assert load_config(DEFAULT_FILE) == TrackerConfig()


def test_dump_load_round_trip(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text(dump_config(TrackerConfig()))
    assert load_config(path) == TrackerConfig()


def test_partial_override(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text("[pmb]\np_survive = 0.9\n[classes.car]\nq_x = 0.5\n[pmbm]\nn_hypotheses = 10\n")
    cfg = load_config(path)
    assert cfg.pmb.p_survive == 0.9 and cfg.pmb.gate_chi2 == 40.0
    assert cfg.classes["car"].q_x == 0.5 and cfg.classes["car"].r_x == PAPER_CLASS_PARAMS["car"].r_x
    assert cfg.pmbm.n_hypotheses == 10 and isinstance(cfg.pmbm.n_hypotheses, int)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[pmb]\np_surive = 0.9\n", "unknown parameter 'p_surive'"),
        ("[classes.boat]\nq_x = 1\n", "unknown class"),
        ("[pmb]\np_survive = 'high'\n", "expected a number"),
        ("[pmbm]\nn_hypotheses = 2.5\n", "expected an integer"),
        ("[nonsense]\n", "unknown section"),
        ("[pmb\n", "not valid TOML"),
    ],
)
def test_bad_parameter_files_name_the_problem(tmp_path, text, message):
    path = tmp_path / "p.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=message):
        load_config(path)


def test_missing_parameter_file(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        load_config(tmp_path / "nope.toml")
