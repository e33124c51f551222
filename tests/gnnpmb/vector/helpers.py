"""Hand computations shared by the vector-tracker tests: the car model and Kalman steps written out."""

from __future__ import annotations

import numpy as np

from gnnpmb.config import paper_config

CFG = paper_config()  # hand computations use the paper's values (sec. V-B)
V, P = CFG.vector, CFG.models
CAR = CFG.for_class("car")
R = np.diag([CAR.r_x, CAR.r_y])
Q = np.diag([CAR.q_x, CAR.q_y, CAR.q_x, CAR.q_y])
H = np.eye(2, 4)


def cv(dt: float) -> np.ndarray:
    F = np.eye(4)
    F[0, 2] = F[1, 3] = dt
    return F


def joseph(P_: np.ndarray, K: np.ndarray) -> np.ndarray:
    A = np.eye(4) - K @ H
    return A @ P_ @ A.T + K @ R @ K.T


def birth_cov() -> np.ndarray:
    Pb = np.diag([P.birth_pos_std_m**2] * 2 + [P.birth_vel_std_mps**2] * 2)
    return joseph(Pb, Pb[:, :2] @ np.linalg.inv(Pb[:2, :2] + R))


def gauss2(nu: np.ndarray, S: np.ndarray) -> float:
    return float(np.exp(-0.5 * nu @ np.linalg.solve(S, nu)) / (2 * np.pi * np.sqrt(np.linalg.det(S))))
