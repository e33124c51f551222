import numpy as np

from gnnpmb.config import paper_config
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.models import measurement_birth
from gnnpmb.pmb.bernoulli import Bernoullis
from gnnpmb.pmb.cost import local_hypotheses
from gnnpmb.pmb.poisson import new_track_hypotheses
from tests.gnnpmb.pmb.helpers import make_measurements

CFG = paper_config()
CAR = CFG.for_class("car")
R = np.diag([CAR.r_x, CAR.r_y])


def bernoullis(xy: list[tuple[float, float]]) -> Bernoullis:
    k = len(xy)
    return Bernoullis(
        track_id=np.arange(1, k + 1),
        local_key=np.arange(k),
        existence=np.linspace(0.5, 0.95, k),
        mean=np.column_stack([np.asarray(xy, dtype=float).reshape(k, 2), np.zeros((k, 2))]),
        cov=np.broadcast_to(np.eye(4), (k, 4, 4)).copy(),
        det=DetectionFields(np.full(k, 0.8), np.zeros(k), np.ones((k, 3)), np.zeros((k, 4)), np.full(k, -1)),
    )


def test_cost_matrix_entries():
    """C[j, k] = -(log l_kj - log l_k0) (inf outside the gate), C[j, K + j] = -log l_j, inf elsewhere."""
    for tracks, points in (([(0.0, 0.0), (5.0, 0.0), (60.0, 0.0)], [(0.2, 0.1), (5.5, -0.3)]), ([], [(1.0, 1.0)])):
        for xy in (points, []):
            meas = make_measurements(xy, 0.7)
            new = new_track_hypotheses(measurement_birth(meas, CFG.models), meas, R, CFG.models.clutter_intensity)
            local = local_hypotheses(bernoullis(tracks), meas, new, R, CFG.models.gate_chi2)
            k, m = len(tracks), len(xy)
            expected = np.full((m, k + m), np.inf)
            for j in range(m):
                for i in range(k):
                    expected[j, i] = -(local.det_log_lik[i, j] - local.miss_log_lik[i])
                expected[j, k + j] = -new.log_likelihood[j]
            cost = local.cost_matrix()
            assert cost.shape == (m, k + m) and cost.tobytes() == expected.tobytes()
            assert k == 0 or m == 0 or np.isinf(cost[:, 2]).all()  # the track 60 m away gates nothing
