"""CSIRO 3D frontier exploration (Williams et al., issue 14): pure planning core.

Frontiers straight from LiDAR points by direct visibility (Section III-A), their
sequential update (Section III-B, Algorithm 2), observer planning, sharing and selection.
"""
