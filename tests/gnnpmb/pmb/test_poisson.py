import numpy as np

from gnnpmb.config import paper_config
from gnnpmb.models import birth_covariance, measurement_birth
from gnnpmb.pmb.core import VelocityMeasurements
from gnnpmb.pmb.poisson import birth_update, new_track_hypotheses
from tests.gnnpmb.pmb.helpers import make_measurements

CFG = paper_config()
CAR = CFG.for_class("car")


def test_shared_birth_update_gives_the_same_bits():
    """The update every birth component shares gives every new-track hypothesis bit for bit as a Kalman update
    of each of the M components, for both measurement spaces (z = [x, y] and [x, y, vx, vy]), signed zeros
    included."""
    xy = [(1.0, 2.0), (-0.0, 0.25), (10.0, -7.0)]
    xy_meas = make_measurements(xy, [0.9, 0.4, 0.65], velocity=[(1.0, -2.0), (-0.0, 0.0), (0.0, -0.0)])
    v_meas = VelocityMeasurements(xy_meas.boxes, xy_meas.source_index)
    birth = measurement_birth(xy_meas, CFG.models)
    for meas, R in ((xy_meas, np.diag([CAR.r_x, CAR.r_y])), (v_meas, np.diag([CAR.r_x, CAR.r_y, 0.5, 0.5]))):
        one = birth_update(birth_covariance(CFG.models), R)
        each = new_track_hypotheses(birth, meas, R, CFG.models.clutter_intensity)
        shared = new_track_hypotheses(birth, meas, R, CFG.models.clutter_intensity, one)
        for name in ("log_likelihood", "existence", "mean", "cov"):
            assert getattr(each, name).tobytes() == getattr(shared, name).tobytes(), name
        assert len(new_track_hypotheses(birth, make_measurements([]), R, 0.1, one).existence) == 0
