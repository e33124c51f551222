"""The files written from the parameter declarations (``gnnpmb.param``, ``gnnpmb.config``): the table
``docs/parameters.md``, the editable defaults ``gnnpmb/default_params.toml`` and the paper's values
``gnnpmb/params/paper.toml``. ``python -m gnnpmb.param_docs`` rewrites them; a test checks the committed copies
equal what this module renders.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

from gnnpmb.atomic import write_text
from gnnpmb.config import (
    _SECTIONS,
    DEFAULT_CLASS_PARAMS,
    PAPER_CLASS_PARAMS,
    BoxNoise,
    ClassParams,
    TrackerConfig,
    dump_config,
)
from gnnpmb.param import Declared, declared

_PACKAGE = Path(__file__).resolve().parent

_DEFAULTS_HEADER = """\
# gnnpmb-viz tracker parameters: the GNN-PMB paper defaults (Liu et al., IEEE T-IV 2023, sec. V-B, Table II)
# and the per-class noise of the authors' code, except [models] p_survive, birth_weight and [pmb]
# extraction_threshold, miss_p_detect_max, chosen on the demo mini_train split, and [pmb] measure_velocity,
# clutter_velocity_density, the miss_p_detect_online cap, [pmbm] n_hypotheses and the two-wheelers' q_x, q_y,
# chosen on the mini_train splits of the demo and the dev set (see gnnpmb/config.py; gnnpmb/params/paper.toml has
# the paper's). [models] holds what every tracker shares; these keys are also accepted under [pmb], where they
# were before.
# Copy this file, edit it and pass it with --params FILE. Any subset of keys may be given; unknown keys are an
# error. [classes.<class>] may also override any key of the shared sections for that class, e.g.
# [classes.pedestrian] birth_weight = 0.1 (p_detect, in two sections, goes in [classes.<class>.phd] or .vector).
# [ab3dmot], [prob3dmot], [simpletrack], [immortal], [cbmot] and [box_noise.<class>] hold the model-based
# baselines' published nuScenes settings (gnnpmb/config.py); min_hits and max_misses, in several of them, go in
# a sub-table per class, e.g. [classes.car.ab3dmot] min_hits = 2.
# Written by `python -m gnnpmb.param_docs` from the declarations in gnnpmb/config.py; docs/parameters.md says
# what each key means, its unit and its allowed range.

"""

_BOX_NOISE_NOTE = """\
# 10-D box Kalman filter noise per class (prob3dmot): Probabilistic 3D MOT's nuScenes train statistics,
# velocities in m/s (gnnpmb/config.py BoxNoise); gnnpmb/params/box_noise_mini_train.toml has the demo mini_train ones.
"""

_PAPER_HEADER = """\
# The GNN-PMB paper's own values (Liu et al., IEEE T-IV 2023, sec. V-B, Table II) where the defaults differ:
# pass with --params to run the tracker exactly as published (constant velocity, the centre alone measured,
# no overlap gate, a missed track's score not decayed, the authors' process noise of two-wheelers).
"""

_DOCS_HEADER = """\
# Tracker parameters

Every key of a `--params FILE.toml` (and of `gnnpmb sweep --param KEY=V1,V2`), as declared in
`gnnpmb/config.py`; written by `python -m gnnpmb.param_docs`, do not edit by hand. *Allowed* is checked when a
file is read (the error names the key, the value and this range); an upper bound marked † is where the model's
float64 arithmetic would overflow (`gnnpmb/param.py`). *Paper* is the GNN-PMB paper's value where it differs
from the default (`gnnpmb/params/paper.toml`). Any shared key may also be set per class in
`[classes.<class>]` (see `docs/architecture.md`).
"""


def _row(section: str, d: Declared, default: str) -> str:
    allowed = d.spec.allowed + (" †" if d.spec.limit is not None else "")
    paper = "" if d.spec.paper is None else repr(d.type(d.spec.paper))
    cells = (f"`{section}`", f"`{d.name}`", d.type.__name__, d.spec.unit, default, allowed, paper, d.spec.doc)
    return "| " + " | ".join(cells) + " |"


def parameters_markdown() -> str:
    """``docs/parameters.md``: one row per declared parameter, then the per-class defaults."""
    lines = [_DOCS_HEADER, "| section | key | type | unit | default | allowed | paper | meaning |"]
    lines.append("|---|---|---|---|---|---|---|---|")
    for section, kind in _SECTIONS.items():
        lines.extend(_row(f"[{section}]", d, repr(d.default)) for d in declared(kind))
    lines.extend(_row("[classes.<class>]", d, "per class") for d in declared(ClassParams))
    lines.extend(_row("[box_noise.<class>]", d, "per class") for d in declared(BoxNoise))
    names = [d.name for d in declared(ClassParams)]
    lines += ["", "## Per-class defaults (`[classes.<class>]`)", "", "| class | " + " | ".join(names) + " |"]
    lines.append("|---" * (len(names) + 1) + "|")
    for cls, p in PAPER_CLASS_PARAMS.items():
        lines.append(f"| {cls} | " + " | ".join(repr(getattr(p, n)) for n in names) + " |")
    lines += ["", "The `[box_noise.<class>]` defaults are in `gnnpmb/default_params.toml`.", ""]
    return "\n".join(lines)


def default_toml() -> str:
    """``gnnpmb/default_params.toml``: every default in the TOML layout ``load_config`` reads."""
    body = dump_config(TrackerConfig())
    at = body.index("[box_noise.")
    return _DEFAULTS_HEADER + body[:at] + _BOX_NOISE_NOTE + body[at:]


def paper_toml() -> str:
    """``gnnpmb/params/paper.toml``: the paper's values where they differ from the defaults."""
    lines = [_PAPER_HEADER]
    for section, kind in _SECTIONS.items():
        values = [d for d in declared(kind) if d.spec.paper is not None]
        if values:
            lines.append(f"[{section}]")
            lines.extend(f"{d.name} = {d.type(d.spec.paper)!r}" for d in values)
            lines.append("")
    for name, paper in PAPER_CLASS_PARAMS.items():
        differ = [
            d.name
            for d in declared(ClassParams)
            if getattr(paper, d.name) != getattr(DEFAULT_CLASS_PARAMS[name], d.name)
        ]
        if differ:
            lines.append(f"[classes.{name}]")
            lines.extend(f"{key} = {getattr(paper, key)!r}" for key in differ)
            lines.append("")
    return "\n".join(lines)


GENERATED: dict[Path, Callable[[], str]] = {
    _PACKAGE.parent / "docs" / "parameters.md": parameters_markdown,
    _PACKAGE / "default_params.toml": default_toml,
    _PACKAGE / "params" / "paper.toml": paper_toml,
}
"""Each generated file and the function that renders it."""


def main() -> int:
    """Rewrite every generated file; print the ones that changed."""
    for path, render in GENERATED.items():
        text = render()
        if not path.exists() or path.read_text(encoding="utf-8") != text:
            write_text(path, text)
            print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
