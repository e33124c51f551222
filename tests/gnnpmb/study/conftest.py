"""Tiny data for study tests (one demo scene cut to a few keyframes; both cut: ``two_scene_dataroot`` in
``tests/conftest.py``) and one Ray session per module."""

from __future__ import annotations

import json
from collections.abc import Iterator, Sequence
from pathlib import Path

import pytest

TINY_SCENE = "scene-0103"
TINY_FRAMES = 6


def _cut(records: list[dict], keep: set[str], links: tuple[str, ...] = ("prev", "next")) -> list[dict]:
    kept = [dict(r) for r in records if r["token"] in keep]
    for r in kept:
        for link in links:
            if r.get(link) and r[link] not in keep:
                r[link] = ""
    return kept


def cut_dataset(src: Path, dst: Path, scene_names: Sequence[str], n_frames: int) -> Path:
    """A copy of the dataset at ``src`` with only the first ``n_frames`` keyframes of each of ``scene_names`` (the
    devkit loads and evaluates it as a normal dataset; LiDAR files are shared by a symlink)."""
    version = "v1.0-mini"
    tables = {p.stem: json.loads(p.read_text()) for p in (src / version).glob("*.json")}
    by_token = {s["token"]: s for s in tables["sample"]}
    scenes, keep_samples = [], set()
    for scene in (s for s in tables["scene"] if s["name"] in scene_names):
        samples, token = [], scene["first_sample_token"]
        while token and len(samples) < n_frames:
            samples.append(token)
            token = by_token[token]["next"]
        keep_samples.update(samples)
        scenes.append({**scene, "nbr_samples": len(samples), "last_sample_token": samples[-1]})
    tables["scene"] = scenes
    tables["sample"] = _cut(tables["sample"], keep_samples)
    tables["sample_data"] = _cut(
        tables["sample_data"], {d["token"] for d in tables["sample_data"] if d["sample_token"] in keep_samples}
    )
    annotations = _cut(
        tables["sample_annotation"],
        {a["token"] for a in tables["sample_annotation"] if a["sample_token"] in keep_samples},
    )
    tables["sample_annotation"] = annotations
    per_instance: dict[str, list[dict]] = {}
    for a in annotations:
        per_instance.setdefault(a["instance_token"], []).append(a)
    instances = []
    for inst in tables["instance"]:
        anns = per_instance.get(inst["token"])
        if anns:
            first = next(a for a in anns if not a["prev"])
            last = next(a for a in anns if not a["next"])
            instances.append(
                {
                    **inst,
                    "nbr_annotations": len(anns),
                    "first_annotation_token": first["token"],
                    "last_annotation_token": last["token"],
                }
            )
    tables["instance"] = instances
    (dst / version).mkdir(parents=True)
    for name, table in tables.items():
        (dst / version / f"{name}.json").write_text(json.dumps(table))
    for folder in ("samples", "maps"):
        if (src / folder).exists():
            (dst / folder).symlink_to((src / folder).resolve())
    return dst


@pytest.fixture(scope="session")
def tiny_dataroot(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The demo's scene-0103 cut to 6 keyframes: split mini_val holds just this scene."""
    return cut_dataset(demo_dataroot, tmp_path_factory.mktemp("tiny") / "nuscenes", [TINY_SCENE], TINY_FRAMES)


@pytest.fixture(scope="module")
def ray_local() -> Iterator[None]:
    """One local Ray instance (2 CPUs) for a test module; the commands reuse it instead of starting their own."""
    import logging

    from gnnpmb.study.runner import import_ray

    ray = import_ray()
    ray.init(num_cpus=2, include_dashboard=False, logging_level=logging.ERROR, log_to_driver=False)
    try:
        yield
    finally:
        ray.shutdown()
