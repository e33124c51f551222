"""Run spellings (``gnnpmb.runs``): trackers, trackers with their own parameters, results files; one-line errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from gnnpmb.errors import GnnpmbError, UnknownNameError
from gnnpmb.runs import OUTPUT_ONLY, RunSpec, capabilities, check_runs, parse_results, parse_run, parse_runs

PAPER = Path("gnnpmb/params/paper.toml")


def test_spellings_and_their_names(tmp_path: Path) -> None:
    results = tmp_path / "mine.json"
    results.write_text("{}")
    assert parse_run("pmbm") == RunSpec("pmbm", tracker="pmbm")
    assert parse_run(f"gnnpmb:{PAPER}") == RunSpec("gnnpmb-paper", tracker="gnnpmb", params=PAPER)
    assert parse_run(f"pub=gnnpmb:{PAPER}").name == "pub"
    assert parse_run(f"mine={results}") == RunSpec("mine", results=results)
    assert parse_results(f"mine={results}") == RunSpec("mine", results=results)
    for spec in (parse_run("pmbm"), parse_run(f"gnnpmb:{PAPER}"), parse_run(f"pub=gnnpmb:{PAPER}")):
        assert parse_run(spec.text()) == spec  # printed back as it is read
    assert parse_runs([], [f"mine={results}"]) == (RunSpec("mine", results=results),)  # no default tracker
    assert [s.name for s in parse_runs(["gnnpmb"], [f"mine={results}"])] == ["mine", "gnnpmb"]
    assert [s.name for s in parse_runs([], [], default="gnnpmb")] == ["gnnpmb"]
    assert capabilities(parse_run(f"mine={results}")) == OUTPUT_ONLY
    assert capabilities(parse_run("greedy")).has_gates is False


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("gnnpmb=x.json", "results name 'gnnpmb' is a built-in tracker's"),
        ("x.json", "a results file needs a name"),
        ("mine=missing.json", "results file not found: missing.json"),
        ("mine=gnnpmb/params", "a results file is NAME=FILE.json"),
        ("nope:paper.toml", "unknown tracker 'nope'"),
        ("gnnpmb:missing.toml", "parameter file not found"),
        ("gnnpmb:gnnpmb/params/paper.txt", "must be a .toml file"),
        ("bad name=gnnpmb", "bad run name 'bad name'"),
        ("pmbm=gnnpmb", "run name 'pmbm' is a built-in tracker's"),
    ],
)
def test_bad_spellings_are_one_line(text: str, message: str) -> None:
    with pytest.raises(GnnpmbError) as raised:
        parse_run(text)
    assert message in str(raised.value) and "\n" not in str(raised.value)


def test_names_are_unique() -> None:
    assert check_runs([RunSpec("gnnpmb", tracker="gnnpmb")] * 2) == (RunSpec("gnnpmb", tracker="gnnpmb"),)
    with pytest.raises(GnnpmbError, match="two runs are named 'x'"):
        check_runs([RunSpec("x", tracker="gnnpmb"), RunSpec("x", tracker="pmbm")])
    with pytest.raises(UnknownNameError, match="^unknown tracker 'nope'; choose one of"):
        parse_run("nope")
    with pytest.raises(GnnpmbError, match="NAME=FILE.json"):
        parse_results("mine")
    with pytest.raises(GnnpmbError, match="must be a .json tracking submission"):
        parse_results("mine=gnnpmb/params")
