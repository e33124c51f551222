from pathlib import Path

import pytest

import gnnpmb
from gnnpmb.config import (
    PAPER_CLASS_PARAMS,
    ConfigError,
    TrackerConfig,
    dump_config,
    get_param,
    load_config,
    paper_config,
    with_params,
)

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
    assert cfg.models.p_survive == 0.9 and cfg.models.gate_chi2 == 40.0
    assert cfg.classes["car"].q_x == 0.5 and cfg.classes["car"].r_x == PAPER_CLASS_PARAMS["car"].r_x
    assert cfg.pmbm.n_hypotheses == 10 and isinstance(cfg.pmbm.n_hypotheses, int)


BAD_FILES = [
    ("[pmb]\np_surive = 0.9\n", "unknown parameter 'p_surive'; did you mean 'p_survive'\\?"),
    ("[pmb]\nmiss_p_detect_neighbor_m = 2\n", "did you mean 'miss_p_detect_neighbour_m'\\?"),
    ("[pmb]\nspeed = 2\n", r"unknown parameter 'speed' \(known: "),
    ("[classes.boat]\nq_x = 1\n", "unknown class"),
    ("[pmb]\np_survive = 'high'\n", "expected a number"),
    ("[pmbm]\nn_hypotheses = 2.5\n", "expected an integer"),
    ("[nonsense]\n", "unknown section"),
    ("[pmb\n", "not valid TOML"),
]
"""Parameter files and the error each gives."""


def test_missing_parameter_file(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        load_config(tmp_path / "nope.toml")


OUT_OF_RANGE = [
    ("[classes]\ncar = 5\n", r"\[classes.car\] must be a table"),
    ("[classes.car]\nq_x = -0.1\n", r"\[classes.car\] q_x must be >= 0, got -0.1"),
    ("[classes.car]\nr_y = 0\n", r"\[classes.car\] r_y must be > 0, got 0.0"),
    ("[pmb]\np_survive = 1.5\n", r"\[pmb\] p_survive must be in \(0, 1\], got 1.5"),
    ("[pmb]\ngate_chi2 = nan\n", r"\[pmb\] gate_chi2 must be > 0, got nan"),
    ("[pmb]\ngate_chi2 = -4\n", r"\[pmb\] gate_chi2 must be > 0, got -4.0"),
    ("[pmb]\nextraction_threshold = 1.2\n", r"extraction_threshold must be in \[0, 1\], got 1.2"),
    ("[pmb]\nbirth_weight = 0\n", r"birth_weight must be > 0, got 0.0"),
    ("[preprocess]\nscore_threshold = -0.1\n", r"\[preprocess\] score_threshold must be in \[0, 1\]"),
    ("[classes.pedestrian]\nbirth_weight = -1\n", r"\[classes.pedestrian\] birth_weight must be > 0, got -1"),
    ("[classes.car]\np_detect = 0.8\n", r"several sections \(phd, vector\); set it in a sub-table"),
    ("[classes.car.vector]\np_detect = 1.0\n", r"\[classes.car.vector\] p_detect must be in \(0, 1\)"),
    ("[classes.car]\nbirth_wieght = 1\n", "unknown parameter 'birth_wieght'; did you mean 'birth_weight'\\?"),
    ("[classes.car.vector]\nconfirm_m = 5\n", "confirm_m <= confirm_n"),
    ("[greedy]\nmax_age = 0\n", r"\[greedy\] max_age must be >= 1, got 0"),
]
"""Every value is range-checked: the error names the key, the value and the range."""


def test_a_folder_as_parameter_file_is_a_config_error(tmp_path):
    with pytest.raises(ConfigError, match="is a folder"):
        load_config(tmp_path)


def test_per_class_overrides_fall_back_to_the_section_values(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text(
        "[pmb]\nbirth_weight = 0.2\n[classes.pedestrian]\nbirth_weight = 0.05\nscore_threshold = 0.3\n"
        "[classes.car.vector]\np_detect = 0.8\n"
    )
    cfg = load_config(path)
    ped, car, bus = cfg.resolved("pedestrian"), cfg.resolved("car"), cfg.resolved("bus")
    assert ped.models.birth_weight == 0.05 and car.models.birth_weight == 0.2 and bus.models.birth_weight == 0.2
    assert ped.preprocess.score_threshold == 0.3 and car.preprocess.score_threshold == 0.1
    assert car.vector.p_detect == 0.8 and ped.vector.p_detect == 0.9 and car.phd.p_detect == 0.9
    assert cfg.preprocess_by_class()["pedestrian"].score_threshold == 0.3
    assert ped.class_overrides == {} and ped.classes == cfg.classes
    again = tmp_path / "again.toml"
    again.write_text(dump_config(cfg))
    assert load_config(again) == cfg


def test_dotted_names_get_and_set_parameters():
    cfg = with_params(TrackerConfig(), {"pmb.gate_chi2": 30, "classes.car.birth_weight": 0.2})
    assert get_param(cfg, "pmb.gate_chi2") == 30.0 and get_param(cfg, "classes.car.birth_weight") == 0.2
    assert get_param(cfg, "classes.bus.birth_weight") == 0.3 and get_param(cfg, "classes.car.q_x") == 0.1589
    cfg = with_params(cfg, {"classes.car.vector.p_detect": 0.7})
    assert get_param(cfg, "classes.car.vector.p_detect") == 0.7
    with pytest.raises(ConfigError, match="unknown parameter"):
        get_param(cfg, "pmb.nope")
    with pytest.raises(ConfigError, match="not a parameter name"):
        with_params(cfg, {"gate_chi2": 3})


def test_every_tracker_of_a_class_sees_its_overrides():
    from gnnpmb.registry import make_class_tracker
    from gnnpmb.types import IdAllocator

    cfg = with_params(TrackerConfig(), {"classes.pedestrian.gate_chi2": 9.0, "classes.pedestrian.max_age": 5})
    assert make_class_tracker("gnnpmb", "pedestrian", cfg, IdAllocator()).models.gate_chi2 == 9.0
    assert make_class_tracker("gnnpmb", "car", cfg, IdAllocator()).models.gate_chi2 == 40.0
    assert make_class_tracker("gnn", "pedestrian", cfg, IdAllocator()).gate_chi2 == 9.0
    assert make_class_tracker("greedy", "pedestrian", cfg, IdAllocator()).max_age == 5


def test_paper_parameter_file_is_the_paper_config():
    assert load_config(DEFAULT_FILE.parent / "params" / "paper.toml") == paper_config()
    assert paper_config().models.p_survive == 0.7 and paper_config().pmb.extraction_threshold == 0.9


def test_model_keys_given_in_their_former_pmb_section_still_work(tmp_path):
    path = tmp_path / "old.toml"
    path.write_text("[pmb]\np_survive = 0.8\nextraction_threshold = 0.5\n[classes.car.pmb]\ngate_chi2 = 12.0\n")
    cfg = load_config(path)
    assert cfg.models.p_survive == 0.8 and cfg.pmb.extraction_threshold == 0.5
    assert cfg.resolved("car").models.gate_chi2 == 12.0 and cfg.resolved("bus").models.gate_chi2 == 40.0
    assert get_param(cfg, "pmb.p_survive") == 0.8 and get_param(cfg, "classes.car.pmb.gate_chi2") == 12.0
    assert with_params(TrackerConfig(), {"pmb.birth_weight": 0.2}).models.birth_weight == 0.2


def test_a_model_key_given_in_both_sections_is_an_error_naming_it(tmp_path):
    path = tmp_path / "both.toml"
    path.write_text("[models]\np_survive = 0.8\n[pmb]\np_survive = 0.9\n")
    with pytest.raises(ConfigError, match=r"\[pmb\] p_survive and \[models\] p_survive are the same parameter"):
        load_config(path)
    path.write_text("[models]\np_survive = 1.5\n")
    with pytest.raises(ConfigError, match=r"\[models\] p_survive must be in \(0, 1\], got 1.5"):
        load_config(path)


def test_box_noise_tables_read_check_and_round_trip(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text("[box_noise.car]\nr_yaw = 0.25\nq_size = 0.0\n")
    cfg = load_config(path)
    assert cfg.box_noise["car"].r_yaw == 0.25 and cfg.box_noise["bus"] == TrackerConfig().box_noise["bus"]
    assert get_param(cfg, "box_noise.car.r_yaw") == 0.25
    assert get_param(with_params(cfg, {"box_noise.truck.p_vx": 2.0}), "box_noise.truck.p_vx") == 2.0
    again = tmp_path / "again.toml"
    again.write_text(dump_config(cfg))
    assert load_config(again) == cfg


BAD_BASELINE_PARAMETERS = [
    ("[box_noise.boat]\nr_x = 1\n", r"\[box_noise.boat\]: unknown class"),
    ("[box_noise.car]\nr_x = 0\n", r"\[box_noise.car\] r_x must be > 0, got 0"),
    ("[box_noise.car]\nr_xx = 1\n", "unknown parameter 'r_xx'"),
    ("[ab3dmot]\niou_threshold = 1.0\n", r"\[ab3dmot\] iou_threshold must be in \[0, 1\), got 1.0"),
    ("[simpletrack]\ndetector_velocity = 2\n", r"\[simpletrack\] detector_velocity must be in \[0, 1\], got 2"),
    ("[classes.car]\nmin_hits = 2\n", r"'min_hits' is a parameter of several sections"),
]
"""The baseline trackers' sections and the box-noise tables: one clear error each."""


@pytest.mark.parametrize(("text", "message"), [*BAD_FILES, *OUT_OF_RANGE, *BAD_BASELINE_PARAMETERS])
def test_bad_parameter_files_name_the_problem(tmp_path, text, message):
    path = tmp_path / "p.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=message):
        load_config(path)


def test_a_baseline_key_per_class_goes_in_its_section_sub_table(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text("[classes.pedestrian.ab3dmot]\nmin_hits = 1\n")
    cfg = load_config(path)
    assert cfg.resolved("pedestrian").ab3dmot.min_hits == 1 and cfg.resolved("car").ab3dmot.min_hits == 3


def test_shipped_box_noise_file_is_a_parameter_file():
    cfg = load_config(DEFAULT_FILE.parent / "params" / "box_noise_mini_train.toml")
    assert cfg.box_noise != TrackerConfig().box_noise and cfg.classes == TrackerConfig().classes
