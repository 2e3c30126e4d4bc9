"""LQR design in the paper's convention V = +K x (section 3, eq. 13), with the
controllable-subsystem reduction of section 4.2 for the dynamic friction model.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..physics.params import Field, FrictionParams, PlantParams
from .linearize import jacobian

__all__ = ['STATE_WEIGHT', 'CONTROL_WEIGHT', 'controllability_matrix', 'design']

#: bounds of the LQR weights: Q on (x, theta, x', theta') and R on the voltage
STATE_WEIGHT = Field('', 0.0, 1e12, 'LQR state weight')
CONTROL_WEIGHT = Field('', 0.0, 1e12, 'LQR control weight', lo_open=True)

def controllability_matrix(A, B) -> np.ndarray:
    """[B, AB, ..., A^(n-1) B]."""
    A, B = np.asarray(A, float), np.asarray(B, float)
    cols = [B]
    for _ in range(A.shape[0] - 1):
        cols.append(A @ cols[-1])
    return np.hstack(cols)


def controllable_basis(A, B, rtol: float = 1e-9):
    """(U, r): orthogonal U (rows) whose first r rows span the controllable subspace.

    s = U x splits the state into controllable s_c = U[:r] x and uncontrollable
    s_u = U[r:] x, the staircase form (24) that Matlab's ``minreal`` produces. The
    Krylov space of (A, B) is built with orthonormalization at every step (Arnoldi),
    which stays accurate where the raw controllability matrix is ill-conditioned.
    """
    A, B = np.asarray(A, float), np.asarray(B, float)
    n = A.shape[0]
    basis: list[np.ndarray] = []
    block = B
    for _ in range(n):
        new: list[np.ndarray] = []
        for v in block.T:
            scale = np.linalg.norm(v)
            for q in basis + new:
                v = v - (q @ v) * q
            for q in basis + new:  # second pass for numerical orthogonality
                v = v - (q @ v) * q
            if scale > 0 and np.linalg.norm(v) > rtol * scale:
                new.append(v / np.linalg.norm(v))
        if not new:
            break
        basis += new
        block = A @ np.array(new).T
    r = len(basis)
    Q, _ = np.linalg.qr(np.column_stack(basis + [np.eye(n)[:, k] for k in range(n)]))
    return Q.T, r


def lqr_gain(A, B, Q, R) -> np.ndarray:
    """K (1 x n) minimizing int x'Qx + R V^2 dt, returned for V = +K x."""
    # python-control is imported here only: importing it takes seconds (scipy.signal, matplotlib), and every
    # ROS node imports this module (its scenario's LQR weights)
    import control
    K, _, _ = control.lqr(np.asarray(A, float), np.asarray(B, float), np.asarray(Q, float),
                          np.atleast_2d(R))
    return -np.asarray(K, float).ravel()


@dataclass
class Design:
    """Result of :func:`design`.

    gain : gain applied to the measured state (x, theta, x', theta') [V/m, V/rad, ...];
        for the dynamic model a 5th entry 0 for z, as printed in the paper's (25).
    full_gain : K' U, the feedback on the whole state including z (equals ``gain``
        for 4-state models).
    reduced_gain : K' of the controllable subsystem (dynamic model), else None.
    basis : U of the reduction, else None.
    A, B : linearization the design used.
    """

    gain: np.ndarray
    full_gain: np.ndarray
    reduced_gain: np.ndarray | None
    basis: np.ndarray | None
    A: np.ndarray
    B: np.ndarray

    def closed_loop_eigenvalues(self) -> np.ndarray:
        """Eigenvalues of A + B K with the measured-state gain (z not fed back)."""
        return np.linalg.eigvals(self.A + self.B @ self.gain[None, :])


def design(plant: PlantParams, friction: FrictionParams, Q, R: float = 1.0) -> Design:
    """LQR gain designed on the linearization of ``friction`` (paper sections 3-4).

    Q weights (x, theta, x', theta'). For the dynamic model the 5-state linearization is
    not stabilizable (z - x is an uncontrollable integrator, lambda = 0); following
    section 4.2 the design is done on the controllable subsystem s_c = U_c x with
    Q' = U_c diag(Q, 0) U_c^T, and K = K' U_c. The paper's printed gain (25) keeps
    K's entries on the measured states and sets the z entry to 0 (z is not measured);
    ``gain`` follows that convention, ``full_gain`` keeps the z entry.
    """
    A, B = jacobian(plant, friction)
    Q = np.diag(np.asarray(Q, float)) if np.ndim(Q) == 1 else np.asarray(Q, float)
    n = A.shape[0]
    if n == 4:
        K = lqr_gain(A, B, Q, R)
        return Design(K, K, None, None, A, B)
    U, r = controllable_basis(A, B)
    Uc = U[:r]
    Q5 = np.zeros((n, n))
    Q5[:4, :4] = Q
    Qr = Uc @ Q5 @ Uc.T
    Kr = lqr_gain(Uc @ A @ Uc.T, Uc @ B, 0.5 * (Qr + Qr.T), R)
    full = Kr @ Uc
    gain = full.copy()
    gain[4:] = 0.0
    return Design(gain, full, Kr, U, A, B)
