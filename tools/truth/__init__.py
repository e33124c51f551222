"""An independent checker of the explainer (``gnnpmb.why``): what a rendered finding says, checked against the
devkit's own per-frame bookkeeping, the tracker's raw events and re-solved cost matrices. It imports nothing of
``gnnpmb.why`` or ``gnnpmb.eval`` to decide a fact (``__main__`` uses them only to produce what is checked)."""
