"""Trackers that filter the whole 3D box: the AB3DMOT family of the GNN-PMB paper's model-based baselines.

``overlap`` (IoU and GIoU of upright boxes, BEV and 3D), ``kalman`` (the 10-D constant-velocity box filter),
``noise`` (its per-class noise learned from a training split), ``cost`` (association costs and their meaning),
``life`` (hits / misses life cycle), ``tracker`` (``BoxTracker``, the ``skeleton.ClassFilter`` they share) and
one small module per published tracker: ``ab3dmot``, ``prob3dmot``, ``simpletrack`` (SimpleTrack and
ImmortalTracker).
"""
