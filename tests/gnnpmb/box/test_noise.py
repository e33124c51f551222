"""Learning the box Kalman noise from annotations and detections: a synthetic scene with known statistics."""

from pathlib import Path

import numpy as np
import pytest

from gnnpmb.box.noise import MIN_SAMPLES, collect_samples, noise_from_samples
from gnnpmb.config import NUSCENES_BOX_NOISE
from gnnpmb.data.boxes3d import quat_wxyz_from_yaw
from gnnpmb.data.scene import Keyframe, Pose, SceneData
from gnnpmb.types import Boxes

N_FRAMES = 30


def _boxes(xyz: np.ndarray, yaw: np.ndarray, ids: list[str], score: float) -> Boxes:
    n = len(ids)
    return Boxes(
        translation_m=xyz,
        size_wlh_m=np.tile([2.0, 4.5, 1.6], (n, 1)),
        quat_wxyz=quat_wxyz_from_yaw(yaw),
        velocity_mps=np.zeros((n, 2)),
        score=np.full(n, score),
        class_name=np.array(["car"] * n, dtype=object),
        instance_id=np.array(ids, dtype=object),
    )


def _scene(rng: np.random.Generator) -> tuple[SceneData, dict[str, Boxes], np.ndarray, np.ndarray]:
    """Two cars, 0.5 s keyframes: car a accelerates by a random step each frame, car b moves at constant
    velocity; detections are the annotations plus known errors (every 5th detection flipped by pi)."""
    pose = Pose(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
    v = np.array([[5.0, 0.0, 0.0], [0.0, 3.0, 0.0]])
    p = np.array([[0.0, 0.0, 1.0], [50.0, 0.0, 1.0]])
    keyframes, dets, errors, accel = [], {}, [], []
    for i in range(N_FRAMES):
        yaw = np.array([0.1 * i, 1.0])
        gt = _boxes(p.copy(), yaw, ["a", "b"], 1.0)
        token = f"s{i}"
        keyframes.append(Keyframe(i, token, 1_000_000 + 500_000 * i, pose, pose, Path("none"), gt, np.ones(2)))
        err = rng.normal(scale=0.2, size=(2, 3))
        errors.append(err)
        det_yaw = yaw + (np.pi if i % 5 == 0 else 0.0)
        dets[token] = _boxes(p + err, det_yaw, ["", ""], 0.9)
        a = rng.normal(scale=0.4, size=3)
        accel.append(a)
        v[0] += a
        p = p + 0.5 * v
    scene = SceneData("scene-x", "tok", "SYNTHETIC", Path("."), "v1.0-mini", True, tuple(keyframes))
    return scene, dets, np.array(errors), np.array(accel)


def test_learned_noise_is_the_variance_of_the_right_differences():
    scene, dets, errors, accel = _scene(np.random.default_rng(0))
    samples = collect_samples([scene], [dets], ["car"])["car"]
    # R: detection minus annotation, x y z, yaw modulo pi (the flips vanish), sizes exact
    assert samples.residual.shape == (2 * N_FRAMES, 7)
    np.testing.assert_allclose(np.sort(samples.residual[:, 0]), np.sort(errors[:, :, 0].ravel()), atol=1e-9)
    assert np.abs(samples.residual[:, 3]).max() < 1e-9 and np.abs(samples.residual[:, 4:]).max() < 1e-9
    # Q: second differences; car a's are its velocity steps x 0.5 s, car b's are 0
    assert samples.d2p.shape == (2 * (N_FRAMES - 2), 4)
    np.testing.assert_allclose(
        np.sort(samples.d2p[:, 0]),
        np.sort(np.concatenate([0.5 * accel[1 : N_FRAMES - 1, 0], np.zeros(N_FRAMES - 2)])),
        atol=1e-9,
    )
    np.testing.assert_allclose(np.sort(samples.dv[:, 0]), np.sort(samples.d2p[:, 0] / 0.5), atol=1e-9)
    # initial velocity variance: the change of the detection error over 0.5 s
    assert samples.error_velocity.shape == (2 * (N_FRAMES - 1), 3)
    expected = np.diff(errors, axis=0).reshape(-1, 3)[:, 0] / 0.5
    np.testing.assert_allclose(np.sort(samples.error_velocity[:, 0]), np.sort(expected), atol=1e-9)
    noise = noise_from_samples(samples, NUSCENES_BOX_NOISE["car"])
    assert noise.r_x == pytest.approx(np.var(samples.residual[:, 0]))
    assert noise.q_x == pytest.approx(np.var(samples.d2p[:, 0]))
    assert noise.q_vx == pytest.approx(np.var(samples.dv[:, 0]))
    assert noise.p_vx == pytest.approx(np.var(samples.error_velocity[:, 0]))
    assert noise.r_l == pytest.approx(1e-6) and noise.q_size == 0.0 and noise.p_scale == 1.0


def test_too_few_samples_keep_the_fallback():
    scene, dets, _, _ = _scene(np.random.default_rng(1))
    short = SceneData(
        scene.name, scene.token, scene.description, scene.dataroot, scene.version, True, scene.keyframes[:3]
    )
    samples = collect_samples([short], [dets], ["car"])["car"]
    assert len(samples.d2p) < MIN_SAMPLES
    noise = noise_from_samples(samples, NUSCENES_BOX_NOISE["car"])
    assert noise.q_x == NUSCENES_BOX_NOISE["car"].q_x and noise.r_x == NUSCENES_BOX_NOISE["car"].r_x
