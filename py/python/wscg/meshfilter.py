"""Joint bilateral mesh denoising with colour and local anti-shrinking: paper 04 of WSCG
vol. 23 (Wasenmüller, Bleser and Stricker).

Every vertex moves along its (area-weighted) normal by a bilateral mean of its
``n_neighbors`` (the paper's ``k``) nearest neighbours' offsets to its tangent plane,
weighted by distance (``sigma_d``), offset (``sigma_o``) and vertex colour difference
(``sigma_c``, 0-255 RGB); a second pass removes the local shrinkage, and ``sigma_o`` is
multiplied by ``lam`` after every iteration.
Baselines: bilateral mesh denoising (Fleishman et al. 2003, with or without volume
preservation), uniform Laplacian, Taubin and HC-Laplacian smoothing.

Vertices are ``(n, 3)`` float arrays ``(x, y, z)``, faces ``(m, 3)`` integer arrays, colours
``(n, 3)`` RGB in 0..255 (uint8 or float). Every filter runs ``n_iter`` iterations (a fixed
count). Boundary vertices stay in place. Bad input raises ``ValueError``.
"""

from ._native.meshfilter import (add_noise, bilateral, cad_labels, hc_laplacian, jbmd,
                                 laplacian, make_mesh, mean_error, mvd, surface_error, taubin)

__all__ = ["jbmd", "bilateral", "laplacian", "taubin", "hc_laplacian", "mean_error",
           "surface_error", "mvd", "make_mesh", "cad_labels", "add_noise"]
