"""Stress measures engineers read: principal stresses (tension positive, sigma1 >= sigma2 >=
sigma3), the differential stress sigma1 - sigma3 and the von Mises stress."""
from __future__ import annotations

import numpy as np


def principal_stresses(stresses: np.ndarray) -> np.ndarray:
    """(n, 3) principal stresses sigma1 >= sigma2 >= sigma3 of (n, 3, 3) symmetric stresses."""
    return np.linalg.eigvalsh(stresses)[:, ::-1]


def principal_directions(stresses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(principal stresses (n, 3) descending, unit directions (n, 3, 3), column k for sigma_k+1)."""
    values, vectors = np.linalg.eigh(stresses)
    return values[:, ::-1], vectors[:, :, ::-1]


def von_mises(stresses: np.ndarray) -> np.ndarray:
    """sqrt(3/2 s:s) with s the deviatoric part, (n,)."""
    mean = np.trace(stresses, axis1=1, axis2=2) / 3.0
    deviator = stresses - mean[:, None, None] * np.eye(3)
    return np.sqrt(1.5 * np.einsum("nij,nij->n", deviator, deviator))
