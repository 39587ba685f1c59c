"""The cached, voxelised point cloud of CSIRO's frontier generation (Section III-A1).

Each voxel of size d_vox keeps the count n_i, mean mu_i and covariance Sigma_i of the LiDAR points
that fell in it, and the ray (p - a) of the latest one (point p seen from agent position a), which
fixes the sign of the voxel's normal. :meth:`PointCache.cloud` gives the observed part of the set P
of equation 2: voxel means within d_max of the agent, nine sub-sampled points per voxel within
eta_subsample (equation 1), and voxels whose surface faces away from the agent left out.
"""
from __future__ import annotations

import numpy as np

from .params import CsiroFrontierParams

#: Voxel indices are packed into one int64 key, 21 bits per axis, offset to be non-negative.
_BITS = 21
_OFFSET = 1 << (_BITS - 1)
#: A voxel needs three points for a plane, hence a normal and the in-plane axes of equation 1.
MIN_POINTS_FOR_NORMAL = 3
#: The offsets (k, l) in {-1, 0, 1}^2 of equation 1.
_KL = np.array([(k, l) for k in (-1, 0, 1) for l in (-1, 0, 1)], dtype=float)


def _pack(ijk: np.ndarray) -> np.ndarray:
    u = ijk + _OFFSET
    return (u[:, 0] << (2 * _BITS)) | (u[:, 1] << _BITS) | u[:, 2]


def _unpack(keys: np.ndarray) -> np.ndarray:
    mask = (1 << _BITS) - 1
    return np.stack([keys >> (2 * _BITS), (keys >> _BITS) & mask, keys & mask], axis=1) - _OFFSET


class PointCache:
    """Per-voxel point statistics (count, sums of offsets from the voxel centre and of their outer
    products, latest ray), kept sorted by voxel key so that every query is deterministic.

    The statistics are sums rather than the paper's point-by-point recursion: the same mean and
    covariance, but a whole scan is added with numpy in one go. Offsets from the voxel centre keep
    the sums small, so the covariance does not lose precision far from the origin.
    """

    #: The per-voxel arrays, in the order of the voxel keys.
    _COLUMNS = ("_keys", "_n", "_s1", "_s2", "_ray", "_lam", "_xi", "_stale")

    def __init__(self, d_vox_m: float) -> None:
        if not d_vox_m > 0:
            raise ValueError(f"d_vox_m must be > 0, got {d_vox_m}")
        self.d_vox_m = float(d_vox_m)
        self._keys = np.zeros(0, dtype=np.int64)
        self._n = np.zeros(0, dtype=np.int64)
        self._s1 = np.zeros((0, 3))
        self._s2 = np.zeros((0, 3, 3))
        self._ray = np.zeros((0, 3))
        #: Each voxel's eigen-decomposition of its covariance, kept between calls of
        #: :meth:`cloud` and made again only where points came in since (``_stale``):
        #: numpy decomposes a stack of 3x3 matrices one LAPACK call at a time.
        self._lam = np.zeros((0, 3))
        self._xi = np.zeros((0, 3, 3))
        self._stale = np.zeros(0, dtype=bool)

    def __len__(self) -> int:
        return len(self._keys)

    def insert(self, points: np.ndarray, sensor: np.ndarray) -> None:
        """Add LiDAR ``points`` (N, 3) returned to a sensor at ``sensor`` (3,); a voxel's latest ray
        comes from the last of its points in ``points``."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        if len(points) == 0:
            return
        ijk = np.floor(points / self.d_vox_m).astype(np.int64)
        keys, inv = np.unique(_pack(ijk), return_inverse=True)
        off = points - (ijk + 0.5) * self.d_vox_m
        m = len(keys)
        n = np.bincount(inv, minlength=m)
        s1 = np.stack([np.bincount(inv, off[:, a], m) for a in range(3)], axis=1)
        outer = (off[:, :, None] * off[:, None, :]).reshape(-1, 9)
        s2 = np.stack([np.bincount(inv, outer[:, c], m) for c in range(9)], axis=1).reshape(m, 3, 3)
        last = np.zeros(m, dtype=np.int64)
        np.maximum.at(last, inv, np.arange(len(points)))
        ray = points[last] - np.asarray(sensor, dtype=float)

        pos = np.searchsorted(self._keys, keys)
        old = pos < len(self._keys)
        old[old] = self._keys[pos[old]] == keys[old]
        at = pos[old]
        self._n[at] += n[old]
        self._s1[at] += s1[old]
        self._s2[at] += s2[old]
        self._ray[at] = ray[old]
        self._stale[at] = True
        new = ~old
        if new.any():
            k = int(new.sum())
            added = {"_keys": keys[new], "_n": n[new], "_s1": s1[new], "_s2": s2[new], "_ray": ray[new],
                     "_lam": np.zeros((k, 3)), "_xi": np.zeros((k, 3, 3)), "_stale": np.ones(k, dtype=bool)}
            order = np.argsort(np.concatenate([self._keys, keys[new]]), kind="stable")
            for name in self._COLUMNS:
                setattr(self, name, np.concatenate([getattr(self, name), added[name]])[order])

    def prune(self, agent: np.ndarray, radius_m: float) -> None:
        """Forget the voxels whose mean lies farther than ``radius_m`` from ``agent`` (the cache is
        limited in range)."""
        keep = np.linalg.norm(self.means() - np.asarray(agent, float), axis=1) <= radius_m
        for name in self._COLUMNS:
            setattr(self, name, getattr(self, name)[keep])

    def counts(self) -> np.ndarray:
        """(M,) points per voxel, by voxel key."""
        return self._n.copy()

    def means(self) -> np.ndarray:
        """(M, 3) voxel means mu_i."""
        centres = (_unpack(self._keys) + 0.5) * self.d_vox_m
        return centres + self._s1 / self._n[:, None]

    def covariances(self, which: np.ndarray | None = None) -> np.ndarray:
        """(M, 3, 3) voxel covariances Sigma_i (population), of all voxels or of those ``which``
        selects."""
        sel = slice(None) if which is None else which
        n = self._n[sel][:, None, None]
        mo = self._s1[sel][:, :, None] / n
        return self._s2[sel] / n - mo * np.swapaxes(mo, 1, 2)

    def cloud(self, agent: np.ndarray, params: CsiroFrontierParams) -> np.ndarray:
        """The observed points of P (equation 2) for an agent at ``agent``: the mean of every voxel
        in C_dmax minus C_eta_subsample, and the nine points mu_{i,k,l} (equation 1) of every voxel
        in C_eta_subsample. C_r holds the voxels with ||mu_i - a|| <= r whose normal xi_1 (the
        eigenvector of the smallest eigenvalue, signed towards the sensor of the latest point)
        does not face away from a. Voxels of fewer than three points have no normal: they stay,
        represented by their mean. Returns (N, 3), deterministic order."""
        a = np.asarray(agent, dtype=float)
        if len(self) == 0:
            return np.zeros((0, 3))
        mu = self.means()
        idx = np.flatnonzero(np.linalg.norm(mu - a, axis=1) <= params.d_max_m)
        mu = mu[idx]
        lam, xi = self._eigen(idx)   # ascending eigenvalues
        normal = xi[:, :, 0]
        normal *= np.where(np.einsum("ij,ij->i", normal, self._ray[idx]) > 0, -1.0, 1.0)[:, None]
        has_normal = self._n[idx] >= MIN_POINTS_FOR_NORMAL
        facing = ~has_normal | (np.einsum("ij,ij->i", normal, mu - a) <= 0)
        near = facing & has_normal & (np.linalg.norm(mu - a, axis=1) <= params.eta_subsample_m)
        far = facing & ~near
        # equation 1: mu + k sqrt(lambda_2)/2 xi_2 + l sqrt(lambda_3)/2 xi_3, the two largest axes
        half = np.sqrt(np.maximum(lam[near][:, 1:], 0.0)) / 2.0
        axes = xi[near][:, :, 1:] * half[:, None, :]          # (n, 3, 2) scaled in-plane axes
        sub = mu[near][:, None, :] + np.einsum("kc,ndc->nkd", _KL, axes)
        return np.concatenate([mu[far], sub.reshape(-1, 3)])

    def _eigen(self, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``np.linalg.eigh`` of the covariances of the voxels ``idx``, from the kept ones where
        no point came in since they were made."""
        redo = idx[self._stale[idx]]
        if len(redo):
            self._lam[redo], self._xi[redo] = np.linalg.eigh(self.covariances(redo))
            self._stale[redo] = False
        return self._lam[idx], self._xi[idx]


__all__ = ["MIN_POINTS_FOR_NORMAL", "PointCache"]
