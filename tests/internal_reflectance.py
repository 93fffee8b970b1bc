"""Two independent sums of the internal hemispherical reflectance of a dielectric (the ``subsurface`` term's recycled
share): SCATMECH's 0.2 deg grid, and Walton's closed form."""

import numpy as np


def scatmech_grid(n):
    """As SCATMECH's Diffuse_Subsurface_BRDF_Model sums it: the unpolarized Fresnel reflectance from inside (1 beyond
    the critical angle), cosine-weighted, 0 to 90 deg in 0.2 deg steps. Shape of ``n``."""
    n = np.asarray(n, float)[..., None]
    theta = np.linspace(0.0, 0.5 * np.pi, 451)
    sin_t = n * np.sin(theta)
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin_t**2))
    c = np.cos(theta)
    r_s = ((n * c - cos_t) / (n * c + cos_t)) ** 2
    r_p = ((c - n * cos_t) / (c + n * cos_t)) ** 2
    r = np.where(sin_t >= 1.0, 1.0, 0.5 * (r_s + r_p))
    weights = np.sin(2.0 * theta)
    return np.sum(r * weights, axis=-1) / np.sum(weights)


def walton(n):
    """1 - (1 - r_e) / n^2, with r_e the external cosine-weighted hemispherical reflectance of a dielectric of index
    n > 1 in closed form (Walton, Proc. R. Soc. A 1917; Stern, Appl. Opt. 3, 111 (1964))."""
    n = np.asarray(n, float)
    r_e = (0.5 + (n - 1) * (3 * n + 1) / (6 * (n + 1) ** 2)
           + n**2 * (n**2 - 1) ** 2 / (n**2 + 1) ** 3 * np.log((n - 1) / (n + 1))
           - 2 * n**3 * (n**2 + 2 * n - 1) / ((n**2 + 1) * (n**4 - 1))
           + 8 * n**4 * (n**4 + 1) / ((n**2 + 1) * (n**4 - 1) ** 2) * np.log(n))
    return 1.0 - (1.0 - r_e) / n**2
