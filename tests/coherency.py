"""The Cloude coherency matrix of Mueller matrices, the test of physical realizability used by the effects' tests."""

import numpy as np

# Stokes-basis Pauli matrices: the Cloude coherency matrix H = 1/4 sum_ij M_ij sigma_i (x) conj(sigma_j)
PAULI = [np.eye(2), np.diag([1.0, -1.0]), np.array([[0.0, 1.0], [1.0, 0.0]]), np.array([[0.0, -1j], [1j, 0.0]])]
_BASIS = np.array([[np.kron(a, b.conj()) for b in PAULI] for a in PAULI])


def coherency_eigenvalues(mueller):
    """Eigenvalues of the Cloude coherency matrix of Mueller matrices (..., 4, 4), ascending: all >= 0 exactly when
    the matrix is a sum of non-depolarizing ones (physically realizable)."""
    return np.linalg.eigvalsh(np.einsum("...ij,ijab->...ab", mueller, _BASIS) / 4)


def jones_to_mueller(jones):
    """The Mueller matrix of a Jones matrix (2 x 2, complex): M = A (J (x) J*) A^-1 with A the Stokes map
    (Azzam and Bashara, Ellipsometry and Polarized Light, 1977, eq 2.114)."""
    a = np.array([[1, 0, 0, 1], [1, 0, 0, -1], [0, 1, 1, 0], [0, 1j, -1j, 0]])
    return np.real(a @ np.kron(jones, np.conj(jones)) @ np.linalg.inv(a))
