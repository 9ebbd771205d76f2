"""Image-based biometrics: paper 01 of WSCG vol. 23, FDKECA (feature-dependent kernel entropy
component analysis, Damavandinejadmonfared and Varadharajan) with the baselines it is
compared against, PCA, kernel PCA and KECA, and the 1-NN recognition pipeline of its
section 5.

Every model is a scikit-learn estimator: ``fit(X, y=None)`` returns the estimator,
``transform``, ``fit_transform``, ``inverse_transform`` (FDKECA, PCA), and, when fitted with
labels, ``predict``, ``score`` and ``kneighbors`` (nearest gallery sample in the subspace).
Hyper-parameters are the arguments of ``__init__`` (``get_params`` / ``set_params``), what
``fit`` learns ends in ``_``; ``sklearn.base.clone``, ``Pipeline`` and ``GridSearchCV`` take
them, each passes ``sklearn.utils.estimator_checks.check_estimator``, and fitted or not they
pickle and deep-copy. A method called before ``fit`` raises :class:`wscg.NotFittedError`.

Data: one sample per row, ``X`` of shape ``(n, d)``, or a stack of images ``(n, h, w)``
that is flattened row-major (the image shape is remembered for :meth:`FDKECA.axis_images`).
Labels may be any hashable numpy values (ints, strings).

FDKECA builds a ``d x d`` kernel between the *feature vectors* (pixel ``t`` across all
training images), orders its eigenvectors by their Renyi-entropy contribution
``psi_i = lambda_i (1' e_i)^2`` and projects linearly, so its cost does not grow with the
number of images beyond one ``O(n d^2)`` product. KPCA and KECA build ``n x n`` kernels.

Paper 05 (Tewari et al., slow feature analysis for hand-pose classification):
:class:`PerClassSFA` (the paper's class-wise SFA with its variance rule), :class:`GlobalSFA`
(SFA fitted once on all classes, Berkes 2005), :class:`TemporalSFA`, :class:`KNN` and
:func:`confusion_matrix` and :class:`Isomap` for the baselines of its Tables 3-6; the synthetic
hand-pose data (:func:`make_hand_poses`), the physical features (:func:`physical_features`),
the paper's split (:func:`hand_pose_split`) and the whole comparison
(:func:`hand_pose_comparison`).

Paper 14 (Sultana et al., occlusion detection and index-based ear recognition) is the
submodule :mod:`wscg.biometrics.ear` (also :mod:`wscg.ear`).

Paper 17 (Ahmed et al., Kinect gait recognition with joint relative angles and a DTW kernel)
is the submodule :mod:`wscg.biometrics.gait` (also :mod:`wscg.gait`).

Bad arguments raise ``ValueError`` naming the problem; the GIL is released while Rust works.
"""

from __future__ import annotations

import os
import warnings
from typing import Dict, Optional, Sequence, Tuple, Union

import numpy as np

from ._native import biometrics as _b
from ._native.biometrics import (downscale_mask, hand_pose_rotated_test, make_finger_veins,
                                 physical_features, rotate_mask)
from ._checks import integer_ranges as _integer_ranges
from ._results import from_mapping as _from_mapping, result as _result
from ._estimator import Estimator, as_matrix

__all__ = [
    "FDKECA", "PCA", "KernelPCA", "KECA",
    "nn_classify", "accuracy_curve", "best_dimension", "select_dimension_cv",
    "feature_kernel", "make_finger_veins", "split_per_subject",
    "PerClassSFA", "GlobalSFA", "TemporalSFA", "KNN", "confusion_matrix", "Isomap",
    "HAND_POSE_CLASSES", "hand_pose_jitter", "make_hand_poses", "physical_features",
    "rotate_mask", "downscale_mask", "hand_pose_split", "hand_pose_comparison",
    "hand_pose_rotated_test", "ResolvedKernel", "HandPoseSplit", "ClassifierRun",
    "HandPoseComparison",
]

_METRICS = ("euclidean", "cosine")


@_result
class ResolvedKernel:
    """The kernel :func:`feature_kernel` used, with the values it resolved from the data
    (eq. 10 of paper 01). Parameters a kernel does not have are ``None``.

    Attributes
    ----------
    kernel : str
        ``"rbf"``, ``"poly"`` or ``"linear"``.
    sigma : float or None
        Gaussian width ``sigma`` of ``exp(-|a - b|^2 / (2 sigma^2))``, in the units of ``X``
        (``rbf``; the median feature distance times ``sigma_scale`` unless given).
    degree : int or None
        Polynomial degree (``poly``).
    gamma : float or None
        Polynomial scale of ``(gamma a.b + coef0)^degree`` (``poly``; ``1 / n`` unless
        given).
    coef0 : float or None
        Polynomial offset (``poly``).
    """

    kernel: str
    sigma: Optional[float] = None
    degree: Optional[int] = None
    gamma: Optional[float] = None
    coef0: Optional[float] = None


def _matrix(X, name: str = "X") -> Tuple[np.ndarray, Optional[Tuple[int, int]]]:
    """``X`` as a C-contiguous float64 ``(n, d)`` matrix plus the image shape when ``X``
    was a ``(n, h, w)`` stack."""
    a = np.asarray(X)
    if a.dtype == object or not (np.issubdtype(a.dtype, np.number) or a.dtype == np.bool_):
        raise ValueError(f"`{name}` must be a numeric array, got dtype {a.dtype}")
    if np.iscomplexobj(a):
        raise ValueError(f"`{name}` must be real-valued, got dtype {a.dtype}")
    shape = None
    if a.ndim == 3:
        shape = (a.shape[1], a.shape[2])
        a = a.reshape(a.shape[0], -1)
    elif a.ndim != 2:
        raise ValueError(
            f"`{name}` must be a 2-D (n, d) matrix or a 3-D (n, h, w) image stack, "
            f"got shape {a.shape}"
        )
    return np.ascontiguousarray(a, dtype=np.float64), shape


def _encode_labels(y, n: int, name: str = "y") -> Tuple[np.ndarray, np.ndarray]:
    """Labels as codes ``0..k`` (int64) plus the sorted distinct values."""
    y = np.asarray(y)
    if y.ndim != 1:
        raise ValueError(f"`{name}` must be 1-D, got shape {y.shape}")
    if y.shape[0] != n:
        raise ValueError(f"`{name}` has {y.shape[0]} labels for {n} rows")
    classes, codes = np.unique(y, return_inverse=True)
    return classes, np.ascontiguousarray(codes.reshape(-1), dtype=np.int64)


def _check_metric(metric: str) -> str:
    if metric not in _METRICS:
        raise ValueError(f"`metric` must be 'euclidean' or 'cosine', got {metric!r}")
    return metric


def _kernel_spec(kernel, sigma, sigma_scale, degree, gamma, coef0) -> dict:
    if kernel not in ("rbf", "poly", "linear"):
        raise ValueError(f"`kernel` must be 'rbf', 'poly' or 'linear', got {kernel!r}")
    if isinstance(sigma, str):
        if sigma != "median":
            raise ValueError(f"`sigma` must be a positive number or 'median', got {sigma!r}")
        sigma = None
    if isinstance(gamma, str):
        if gamma != "inv_dim":
            raise ValueError(f"`gamma` must be a positive number or 'inv_dim', got {gamma!r}")
        gamma = None
    # Read and checked by name by the native functions.
    return {"kernel": kernel, "sigma": sigma, "sigma_scale": sigma_scale, "degree": degree,
            "gamma": gamma, "coef0": coef0}


class _Subspace(Estimator):
    """Shared estimator machinery; subclasses set ``_method`` and define ``_spec()``, the
    parameters passed to the native ``fit``."""

    _method = ""

    # -- fitting
    def fit(self, X, y=None):
        """Fits the model to the rows of ``X``; with labels ``y`` the projected training
        set becomes the gallery of :meth:`predict`.

        Parameters
        ----------
        X : array_like, shape (n, d) or (n, h, w)
            Training samples (images are flattened row-major).
        y : array_like, shape (n,), optional
            Labels (any values); enables ``predict``, ``score`` and ``kneighbors``.

        Returns
        -------
        self

        Raises
        ------
        ValueError
            Fewer than 2 rows, ``d = 0``, NaN/inf, bad parameters, ``n_components`` 0 or
            more than available, labels of the wrong length.
        """
        _check_metric(self.metric)
        if not hasattr(X, "tocsr"):  # sparse input is refused by _validate_X
            X = np.asarray(X)
        shape = X.shape[1:] if getattr(X, "ndim", 0) == 3 else None
        Xm = self._validate_X(X, reset=True, min_samples=2, allow_images=True)
        if y is not None:
            classes, codes = _encode_labels(self._validate_y(y, Xm.shape[0]), Xm.shape[0])
        self._model = _b.fit(Xm, self._spec())
        self.image_shape_ = shape
        self.n_features_in_ = Xm.shape[1]
        self._set_attributes(self._model.info())
        if y is not None:
            self.classes_ = classes
            # Kernel methods already hold the training projections (E D^1/2); linear ones
            # project in one product.
            embedding = getattr(self, "embedding_", None)
            self._gallery = (np.ascontiguousarray(embedding) if embedding is not None
                             else self._model.transform(Xm))
            self._gallery_codes = codes
        else:
            self.classes_ = None
            self._gallery = None
            self._gallery_codes = None
        return self

    def _set_attributes(self, info: dict) -> None:
        self.n_components_ = self._model.n_components

    def _fitted(self):
        self._check_fitted()
        return self._model

    def transform(self, X) -> np.ndarray:
        """Projects the rows of ``X`` (``(n, d)``, or an ``(n, h, w)`` image stack) to
        ``(n, n_components_)``.

        Raises
        ------
        NotFittedError
            Before ``fit``.
        ValueError
            Wrong width, NaN/inf.
        """
        Xm = self._validate_X(X, reset=False, allow_images=True)
        return self._model.transform(Xm)

    def fit_transform(self, X, y=None) -> np.ndarray:
        """``fit(X, y)`` then ``transform(X)``."""
        return self.fit(X, y).transform(X)

    def truncated(self, n_components: int):
        """A copy keeping only the first ``n_components`` components (no refit; the
        gallery, if any, is re-projected)."""
        import copy

        out = copy.copy(self)
        out._model = self._fitted().truncated(n_components)
        out._set_attributes(out._model.info())
        if self._gallery is not None:
            out._gallery = np.ascontiguousarray(self._gallery[:, : out._model.n_components])
        return out

    # -- recognition (section 5)
    def _gallery_or_raise(self):
        self._fitted()
        if self._gallery is None:
            raise ValueError(
                f"this {type(self).__name__} was fitted without labels; call fit(X, y) to "
                "use it as a classifier"
            )
        return self._gallery

    def kneighbors(self, X) -> Tuple[np.ndarray, np.ndarray]:
        """Nearest training sample of every row of ``X`` in the subspace.

        Returns
        -------
        distance : ndarray, shape (m,)
            Euclidean distance (or cosine distance ``1 - cos``).
        index : ndarray of int64, shape (m,)
            Row of the nearest training sample.
        """
        gallery = self._gallery_or_raise()
        idx, dist = _b.nearest(gallery, self.transform(X), self.metric)
        return dist, idx

    def predict(self, X) -> np.ndarray:
        """Label of the nearest training sample in the subspace (1-NN, the paper's
        section 5)."""
        _, idx = self.kneighbors(X)
        return self.classes_[self._gallery_codes[idx]]

    def score(self, X, y) -> float:
        """Fraction of rows of ``X`` whose predicted label equals ``y``."""
        y = np.asarray(y)
        pred = self.predict(X)
        if y.shape != pred.shape:
            raise ValueError(f"`y` has shape {y.shape}, expected {pred.shape}")
        return float(np.mean(pred == y))

    # -- persistence
    def to_json(self) -> str:
        """The fitted model (without the gallery) as JSON."""
        return self._fitted().to_json()

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        model = state.pop("_model", None)
        state["_model_json"] = None if model is None else model.to_json()
        return state

    def __setstate__(self, state: dict) -> None:
        state = dict(state)
        js = state.pop("_model_json", None)
        self.__dict__.update(state)
        self._model = None if js is None else _b.Model.from_json(js)


class _KernelParams:
    """Kernel parameters shared by FDKECA, KernelPCA and KECA."""

    def _init_kernel(self, kernel, sigma, sigma_scale, degree, gamma, coef0) -> None:
        self.kernel = kernel
        self.sigma = sigma
        self.sigma_scale = sigma_scale
        self.degree = degree
        self.gamma = gamma
        self.coef0 = coef0

    def _kernel_spec(self, **extra) -> dict:
        spec = _kernel_spec(self.kernel, self.sigma, self.sigma_scale, self.degree,
                            self.gamma, self.coef0)
        spec.update(method=self._method, n_components=self.n_components, **extra)
        return spec


class _Linear(_Subspace):
    """Models with image-space axes: reconstruction and eigen-images."""

    def _set_attributes(self, info: dict) -> None:
        super()._set_attributes(info)
        self.mean_ = info["mean"]
        self.components_ = info["components"]

    def inverse_transform(self, Z) -> np.ndarray:
        """Reconstructs samples from projections ``Z`` of shape ``(m, n_components_)``:
        ``mean_ + Z @ components_`` (exact at ``n_components_ = d``)."""
        model = self._fitted()
        Zm = as_matrix(Z, "Z")
        if Zm.shape[1] != self.n_components_:
            raise ValueError(f"`Z` has {Zm.shape[1]} columns, but this {type(self).__name__} "
                             f"has {self.n_components_} components")
        return model.inverse_transform(Zm)

    def axis_images(self, n_components: Optional[int] = None,
                    shape: Optional[Tuple[int, int]] = None):
        """The first ``n_components`` axes (default all kept) as images
        ``(n_components, h, w)``, each min-max scaled to ``[0, 1]`` (the paper's eigenface
        view, section 4). ``shape`` defaults to the shape of the image stack given to
        ``fit``."""
        model = self._fitted()
        shape = shape or self.image_shape_
        if shape is None:
            raise ValueError("`shape` is required when the model was fitted on a 2-D matrix")
        n = model.n_components if n_components is None else n_components
        return _b.axis_images(model, n, shape)


class FDKECA(_Linear, _KernelParams):
    """Feature-dependent kernel entropy component analysis (paper 01, section 3).

    Parameters
    ----------
    n_components : int, optional
        Axes kept (default all ``d``).
    kernel : {"rbf", "poly", "linear"}, default "rbf"
        Kernel between feature vectors: Gaussian ``exp(-|a-b|^2 / (2 sigma^2))`` (the
        recognition experiments), polynomial ``(gamma a.b + coef0)^degree`` (the eigenface
        analysis, degree 2) or linear.
    sigma : float or "median", optional
        Gaussian bandwidth; default ``sigma_scale`` times the median distance between
        feature vectors (the paper gives no value).
    sigma_scale : float, default 1.0
    degree : int, default 2
    gamma : float or "inv_dim", optional
        Polynomial scale; default ``1 / n`` (so ``gamma a.b`` is a covariance).
    coef0 : float, default 1.0
    ordering : {"entropy", "eigenvalue"}, default "entropy"
        Rank eigenvectors by entropy contribution (the paper) or eigenvalue.
    center : bool, default True
        Subtract the mean image first (section 4).
    metric : {"euclidean", "cosine"}, default "euclidean"
        Distance of the nearest-neighbour classifier.

    Attributes
    ----------
    components_ : ndarray (n_components_, d)
        The axes (eigen-images), in ranking order; orthonormal rows.
    mean_ : ndarray (d,)
    eigenvalues_ : ndarray
        Kernel eigenvalues ``lambda`` of the kept axes.
    entropy_ : ndarray
        Entropy terms ``psi = lambda (1' e)^2`` of the kept axes.
    kernel_sum_ : float
        ``1' K 1`` (equals the sum of ``psi`` over all ``d`` axes).
    renyi_entropy_ : float
        The estimate ``V = 1'K1 / d^2`` (the entropy is ``-log V``).
    sigma_, gamma_ : float or None
        The kernel parameters used.

    Examples
    --------
    >>> X, y = make_finger_veins(n_subjects=20, n_per_subject=6)
    >>> m = FDKECA(n_components=40).fit(X[::2], y[::2])
    >>> m.score(X[1::2], y[1::2]) > 0.8
    True
    """

    _method = "fdkeca"

    def __init__(self, n_components: Optional[int] = None, kernel: str = "rbf",
                 sigma: Union[float, str, None] = None, sigma_scale: float = 1.0,
                 degree: int = 2, gamma: Union[float, str, None] = None, coef0: float = 1.0,
                 ordering: str = "entropy", center: bool = True, metric: str = "euclidean"):
        self.n_components = n_components
        self._init_kernel(kernel, sigma, sigma_scale, degree, gamma, coef0)
        self.ordering = ordering
        self.center = center
        self.metric = metric

    def _spec(self) -> dict:
        return self._kernel_spec(ordering=self.ordering, center=bool(self.center))

    def _set_attributes(self, info: dict) -> None:
        super()._set_attributes(info)
        self.eigenvalues_ = info["eigenvalues"]
        self.entropy_ = info["entropy_terms"]
        self.kernel_sum_ = info["kernel_sum"]
        self.renyi_entropy_ = info["renyi_entropy_estimate"]
        self.sigma_ = info.get("sigma")
        self.gamma_ = info.get("gamma")


class PCA(_Linear):
    """Principal component analysis (the paper's section 2.1 baseline).

    Parameters
    ----------
    n_components : int, optional
        Axes kept (default ``min(n, d)``).
    whiten : bool, default False
        Divide projections by the square root of the variances (the paper's formula);
        off by default, as in classic eigenfaces.
    metric : {"euclidean", "cosine"}, default "euclidean"

    Attributes
    ----------
    components_ : ndarray (n_components_, d)
    mean_ : ndarray (d,)
    variances_ : ndarray
        Eigenvalues of ``Xc' Xc / n`` (the paper divides by ``n``; scikit-learn's
        ``explained_variance_`` divides by ``n - 1``).
    """

    _method = "pca"

    def __init__(self, n_components: Optional[int] = None, whiten: bool = False,
                 metric: str = "euclidean"):
        self.n_components = n_components
        self.whiten = whiten
        self.metric = metric

    def _spec(self) -> dict:
        return {"method": "pca", "n_components": self.n_components, "whiten": bool(self.whiten)}

    def _set_attributes(self, info: dict) -> None:
        super()._set_attributes(info)
        self.variances_ = info["variances"]


class _SampleKernel(_Subspace, _KernelParams):

    def __init__(self, n_components: Optional[int] = None, kernel: str = "rbf",
                 sigma: Union[float, str, None] = None, sigma_scale: float = 1.0,
                 degree: int = 2, gamma: Union[float, str, None] = None, coef0: float = 1.0,
                 metric: str = "euclidean"):
        self.n_components = n_components
        self._init_kernel(kernel, sigma, sigma_scale, degree, gamma, coef0)
        self.metric = metric

    def _spec(self) -> dict:
        return self._kernel_spec()

    def _set_attributes(self, info: dict) -> None:
        super()._set_attributes(info)
        self.eigenvalues_ = info["eigenvalues"]
        self.eigenvectors_ = info["eigenvectors"].T
        self.embedding_ = info["embedding"]
        self.sigma_ = info.get("sigma")
        self.gamma_ = info.get("gamma")


class KernelPCA(_SampleKernel):
    """Kernel PCA (Schoelkopf et al. 1998; the paper's section 2.2 baseline).

    The ``n x n`` kernel between samples is centred; out-of-sample projection centres the
    new kernel rows against the training kernel, which equals scikit-learn's
    ``KernelPCA(eigen_solver="dense").transform`` up to the sign of each component.
    Parameters as :class:`FDKECA` (the Gaussian ``sigma`` relates to scikit-learn's
    ``gamma`` by ``gamma = 1 / (2 sigma^2)``; the median heuristic is over sample
    distances; polynomial ``gamma`` defaults to ``1 / d``). ``n_components`` defaults to
    the numerical rank of the centred kernel.

    Attributes
    ----------
    eigenvalues_ : ndarray
        Eigenvalues of the centred kernel, descending.
    eigenvectors_ : ndarray (n, n_components_)
    embedding_ : ndarray (n, n_components_)
        Training projections ``E D^{1/2}``.
    """

    _method = "kpca"


class KECA(_SampleKernel):
    """Kernel entropy component analysis (Jenssen 2010; the paper's section 2.3 baseline).

    The **uncentred** ``n x n`` kernel is decomposed and all eigenpairs are ranked by
    their entropy terms ``psi = lambda (1' e)^2``. New samples map to
    ``D^{-1/2} E' k_x``. ``n_components`` defaults to the components with a positive
    entropy term. Parameters as :class:`KernelPCA`.

    Attributes
    ----------
    eigenvalues_, eigenvectors_, embedding_ : as :class:`KernelPCA`, in entropy order.
    entropy_ : ndarray
        Entropy terms of the kept components.
    renyi_entropy_ : float
        ``V = 1'K1 / n^2``.
    """

    _method = "keca"

    def _set_attributes(self, info: dict) -> None:
        super()._set_attributes(info)
        self.entropy_ = info["entropy_terms"]
        self.renyi_entropy_ = info["renyi_entropy_estimate"]


def nn_classify(Z_train, y_train, Z_test, metric: str = "euclidean") -> np.ndarray:
    """1-NN labels of the rows of ``Z_test`` against the labelled rows of ``Z_train``
    (same width). Ties go to the lowest training row.

    Raises
    ------
    ValueError
        Width mismatch, label count, empty training set, NaN.
    """
    Ztr, _ = _matrix(Z_train, "Z_train")
    Zte, _ = _matrix(Z_test, "Z_test")
    classes, codes = _encode_labels(y_train, Ztr.shape[0], "y_train")
    idx, _ = _b.nearest(Ztr, Zte, _check_metric(metric))
    return classes[codes[idx]]


def accuracy_curve(model, X_train, y_train, X_test, y_test,
                   dims: Optional[Sequence[int]] = None,
                   metric: Optional[str] = None) -> np.ndarray:
    """The paper's evaluation (section 6): 1-NN accuracy using the first ``l`` components
    of ``model`` for every ``l`` in ``dims``, with ``model`` fitted once on ``X_train``.

    Parameters
    ----------
    model : FDKECA, PCA, KernelPCA or KECA
        An unfitted or fitted estimator; it is (re)fitted on ``X_train``.
    dims : sequence of int, optional
        Dimensions to evaluate; default ``1 .. n_components_``.
    metric : str, optional
        Defaults to the model's metric.

    Returns
    -------
    ndarray, shape (k, 2)
        Rows ``(l, accuracy)`` sorted by ``l``. ``best_dimension`` picks Table 1's columns.
    """
    Xtr, _ = _matrix(X_train, "X_train")
    Xte, _ = _matrix(X_test, "X_test")
    model.fit(Xtr)
    Ztr, Zte = model.transform(Xtr), model.transform(Xte)
    classes, ytr = _encode_labels(y_train, Xtr.shape[0], "y_train")
    y_test = np.asarray(y_test)
    if y_test.ndim != 1 or y_test.shape[0] != Xte.shape[0]:
        raise ValueError(f"`y_test` has shape {y_test.shape} for {Xte.shape[0]} rows")
    pos = np.searchsorted(classes, y_test)
    known = (pos < len(classes)) & (classes[np.minimum(pos, len(classes) - 1)] == y_test)
    # Test labels absent from training can never be predicted: give them an unused code.
    yte = np.where(known, pos, len(classes)).astype(np.int64)
    return _b.accuracy_curve(Ztr, ytr, Zte, yte, dims, _check_metric(metric or model.metric))


def best_dimension(curve) -> Tuple[int, float]:
    """The maximum accuracy of an ``accuracy_curve`` and the smallest ``l`` reaching it."""
    c = np.asarray(curve, dtype=np.float64)
    if c.ndim != 2 or c.shape[1] != 2 or c.shape[0] == 0:
        raise ValueError(f"`curve` must be a non-empty (k, 2) array, got shape {c.shape}")
    i = int(np.argmax(c[:, 1]))
    return int(c[i, 0]), float(c[i, 1])


def select_dimension_cv(model, X, y, dims: Optional[Sequence[int]] = None, n_folds: int = 5,
                        seed: int = 0) -> Tuple[int, np.ndarray]:
    """The validated protocol: choose the number of components by ``n_folds``-fold
    cross-validation inside the training set (refitting ``model``'s method on each fold).

    Returns
    -------
    l : int
        The dimension with the best mean validation accuracy.
    curve : ndarray (k, 2)
        Mean validation accuracy per dimension.
    """
    Xm, _ = _matrix(X)
    _, codes = _encode_labels(y, Xm.shape[0])
    return _b.select_dimension_cv(Xm, codes, model._spec(), dims, n_folds, seed, model.metric)


def feature_kernel(X, kernel: str = "rbf", sigma=None, sigma_scale: float = 1.0,
                   degree: int = 2, gamma=None, coef0: float = 1.0,
                   center: bool = True) -> Tuple[np.ndarray, ResolvedKernel]:
    """FDKECA's ``d x d`` kernel between the feature vectors (columns of the centred
    ``X``), eq. 10 of the paper, and the kernel parameters used (a
    :class:`ResolvedKernel`).

    Equals ``sklearn.metrics.pairwise.rbf_kernel(Xc.T, gamma=1/(2 sigma^2))`` or
    ``polynomial_kernel(Xc.T, degree, gamma, coef0)``.
    """
    Xm, _ = _matrix(X)
    spec = _kernel_spec(kernel, sigma, sigma_scale, degree, gamma, coef0)
    spec["center"] = bool(center)
    K, info = _b.feature_kernel(Xm, spec)
    return K, _from_mapping(ResolvedKernel, info)


def split_per_subject(labels, n_train_per_subject: int, seed: int = 0
                      ) -> Tuple[np.ndarray, np.ndarray]:
    """Row indices ``(train, test)``: for every subject, ``n_train_per_subject`` random
    samples train and the rest test (the paper's 5/5 and 9/1 protocols)."""
    _, codes = _encode_labels(labels, len(np.asarray(labels)), "labels")
    return _b.split_per_subject(codes, n_train_per_subject, seed)


# ---------------------------------------------------------------------------------------
# Paper 05: slow feature analysis for hand-pose (and digit) classification.
# ---------------------------------------------------------------------------------------

_OBJECTIVES = ("within_minus_out", "within")


class _JsonPickled:
    """Pickling of estimators whose native model (``_model``) has ``to_json`` and a
    ``_model_from_json`` counterpart."""

    def __getstate__(self):
        state = self.__dict__.copy()
        if state.get("_model") is not None:
            state["_model"] = state["_model"].to_json()
        return state

    def __setstate__(self, state):
        if isinstance(state.get("_model"), str):
            state["_model"] = self._model_from_json(state["_model"])
        self.__dict__.update(state)


class _SFAClassifier(Estimator, _JsonPickled):
    """Shared plumbing of :class:`PerClassSFA` and :class:`GlobalSFA`."""

    _estimator_type = "classifier"
    _requires_y = True
    _global = False

    def _fit(self, X, y, m: int, gamma, rule):
        X = self._validate_X(X, reset=True, min_samples=2, allow_images=True)
        classes, codes = _encode_labels(self._validate_y(y, X.shape[0]), X.shape[0])
        if self.degree not in (1, 2):
            raise ValueError(f"`degree` must be 1 or 2, got {self.degree}")
        self._model = _b.sfa_fit(X, codes, self.pca_n_components, m, self.degree,
                                 self.include_linear, gamma, self.shrinkage, self.rank_tol, rule)
        self.classes_ = classes
        self.n_features_in_ = X.shape[1]
        self.eigenvalues_, self.rank_ = self._model.eigenvalues()
        return self

    def _fitted(self):
        self._check_fitted()
        return self._model

    def class_scores(self, X) -> np.ndarray:
        """``(n, n_classes)`` scores of the paper, columns in ``classes_`` order; **smaller
        is better**: the energy ``Var_C`` of eq. 16 (:class:`PerClassSFA`, and
        :class:`GlobalSFA` with ``rule="variance"``) or the negative Gaussian log-likelihood
        (``rule="gaussian"``). :meth:`predict` picks the smallest (eq. 17)."""
        X = self._validate_X(X, reset=False, allow_images=True)
        return self._model.decision_scores(X)

    def decision_function(self, X) -> np.ndarray:
        """Confidence scores as scikit-learn defines them, **larger is better**: the
        negated :meth:`class_scores`, ``(n, n_classes)``; with two classes the ``(n,)``
        difference ``class_scores[:, 0] - class_scores[:, 1]``, positive for
        ``classes_[1]``."""
        s = self.class_scores(X)
        return s[:, 0] - s[:, 1] if s.shape[1] == 2 else -s

    def predict(self, X) -> np.ndarray:
        """The class of smallest score for every row (eq. 17), ties to the first class."""
        X = self._validate_X(X, reset=False, allow_images=True)
        return self.classes_[self._model.predict(X)]

    def score(self, X, y) -> float:
        """Mean accuracy."""
        return float(np.mean(self.predict(X) == np.asarray(y)))

    def save(self, path) -> None:
        """Writes the fitted model (JSON), atomically: a failed write raises ``OSError`` and
        leaves any previous file."""
        import json

        from ._native import math as _m

        model = self._fitted()
        text = json.dumps({"params": self.get_params(), "classes": self.classes_.tolist(),
                           "n_features_in": self.n_features_in_,
                           "model": model.to_json()})
        _m.write_file(os.fspath(path), text.encode())

    @classmethod
    def load(cls, path):
        """Reads a model written by :meth:`save`."""
        import json

        with open(path) as f:
            d = json.load(f)
        # Files written before the 1.0 rename keep loading.
        obj = cls(**{_SAVED_PARAM_RENAMES.get(k, k): v for k, v in d["params"].items()})
        obj._model = _b.SfaModel.from_json(d["model"], cls._global)
        obj.classes_ = np.asarray(d["classes"])
        obj.n_features_in_ = d["n_features_in"]
        obj.eigenvalues_, obj.rank_ = obj._model.eigenvalues()
        return obj

    def _model_from_json(self, text):
        return _b.SfaModel.from_json(text, self._global)


#: Hyper-parameter names in model files written before the 1.0 rename -> today's names.
_SAVED_PARAM_RENAMES = {"pca_dims": "pca_n_components"}


class PerClassSFA(_SFAClassifier):
    """Class-wise slow feature analysis (paper 05, Tewari et al.): PCA to
    ``pca_n_components``, quadratic expansion, and per class ``m`` functions minimising the
    within-class differences minus ``gamma`` times the differences to the other classes
    (eq. 14, in the closed forms ``2 S_C`` and ``S_C + S_not + d d'``), under unit variance
    over all training rows; a sample goes to the class whose centred responses have the
    least energy.

    ``degree=2`` with ``include_linear=True`` expands ``d`` inputs to ``d + d(d+1)/2``
    (665 for 35); ``include_linear=False`` gives the paper's literal 630. ``objective=
    "within"`` drops the out-of-class term. ``shrinkage`` regularises the within-class
    scatter (use 1e-3 or more when classes have fewer rows than expanded dimensions).
    Directions of the expanded covariance below ``rank_tol`` times its largest eigenvalue
    are dropped (``rank_`` reports how many remain).

    Labels may be any values; ``predict`` returns them as given. Continuous (non-integer
    float) labels raise ``ValueError``.
    """

    def __init__(self, pca_n_components: int = 35, m: int = 10, degree: int = 2,
                 include_linear: bool = True, objective: str = "within_minus_out",
                 gamma: float = 1.0, shrinkage: float = 1e-6, rank_tol: float = 1e-10):
        self.pca_n_components, self.m, self.degree = pca_n_components, m, degree
        self.include_linear, self.objective, self.gamma = include_linear, objective, gamma
        self.shrinkage, self.rank_tol = shrinkage, rank_tol

    def fit(self, X, y):
        """Fits to rows ``X`` (``(n, d)`` or an ``(n, h, w)`` image stack) and labels ``y``;
        returns ``self``."""
        if self.objective not in _OBJECTIVES:
            raise ValueError(f"`objective` must be one of {_OBJECTIVES}, got {self.objective!r}")
        gamma = self.gamma if self.objective == "within_minus_out" else None
        return self._fit(X, y, self.m, gamma, None)

    def responses(self, X, cls) -> np.ndarray:
        """The centred responses ``r_C = W_C'(z - mu_C)`` (``(n, m)``) of class ``cls``."""
        X = self._validate_X(X, reset=False, allow_images=True)
        idx = np.flatnonzero(self.classes_ == cls)
        if len(idx) == 0:
            raise ValueError(f"{cls!r} is not a trained class")
        return self._model.responses(X, int(idx[0]))


class GlobalSFA(_SFAClassifier):
    """SFA fitted once on all classes (the "Full dataset" row of paper 05's Table 1;
    Berkes 2005): ``n_components`` shared functions minimising the class-weighted objective.
    ``rule="variance"`` classifies by the nearest class mean in the paper's variance sense,
    ``rule="gaussian"`` by class-conditional Gaussians on the outputs (Berkes). ``gamma=0``
    is Berkes' SFA, equivalent to Fisher discriminant analysis."""

    _global = True

    def __init__(self, pca_n_components: int = 35, n_components: int = 10, degree: int = 2,
                 include_linear: bool = True, gamma: float = 1.0, shrinkage: float = 1e-6,
                 rank_tol: float = 1e-10, rule: str = "variance"):
        self.pca_n_components, self.n_components, self.degree = (
            pca_n_components, n_components, degree)
        self.include_linear, self.gamma, self.shrinkage = include_linear, gamma, shrinkage
        self.rank_tol, self.rule = rank_tol, rule

    def fit(self, X, y):
        """Fits to rows ``X`` and labels ``y``; returns ``self``."""
        if self.rule not in ("variance", "gaussian"):
            raise ValueError(f"`rule` must be 'variance' or 'gaussian', got {self.rule!r}")
        return self._fit(X, y, self.n_components, self.gamma, self.rule)

    def transform(self, X) -> np.ndarray:
        """The shared outputs ``W'z`` (``(n, n_components)``)."""
        X = self._validate_X(X, reset=False, allow_images=True)
        return self._model.responses(X, 0)

    def fit_transform(self, X, y) -> np.ndarray:
        """``fit(X, y)`` then ``transform(X)``."""
        return self.fit(X, y).transform(X)


class _NativeTransform:
    """``transform(X)`` through the fitted native model ``_model`` (for Isomap: the
    embedding of new rows, sklearn's ``Isomap.transform`` semantics)."""

    def transform(self, X) -> np.ndarray:
        """The fitted mapping applied to the rows of ``X``, ``(n, n_components)``."""
        X = self._validate_X(X, reset=False)
        return self._model.transform(X)


class TemporalSFA(Estimator, _NativeTransform, _JsonPickled):
    """Temporal slow feature analysis (Wiskott and Sejnowski 2002; paper 05, section 2.1):
    the ``n_components`` slowest, decorrelated, unit-variance functions of the (quadratically
    expanded, ``degree=2``) signal ``X`` with one time step per row (at least 3).
    ``delta_values_`` are the slowness values, ascending."""

    def __init__(self, n_components: int = 2, degree: int = 2, include_linear: bool = True,
                 rank_tol: float = 1e-10):
        self.n_components, self.degree = n_components, degree
        self.include_linear, self.rank_tol = include_linear, rank_tol

    def fit(self, X, y=None):
        """Fits to the time series ``X`` (``(T, d)``, rows in time order); ``y`` is ignored.
        Returns ``self``."""
        X = self._validate_X(X, reset=True, min_samples=3)
        self._model = _b.temporal_sfa_fit(X, self.n_components, self.degree,
                                          self.include_linear, self.rank_tol)
        self.n_features_in_ = X.shape[1]
        self.delta_values_ = np.asarray(self._model.delta_values())
        self.rank_ = self._model.rank()
        return self

    def fit_transform(self, X, y=None) -> np.ndarray:
        """``fit(X)`` then ``transform(X)``."""
        return self.fit(X).transform(X)

    def _model_from_json(self, text):
        return _b.TemporalSfaModel.from_json(text)


class KNN(Estimator):
    """k-nearest-neighbour classifier (Euclidean, majority vote of the ``n_neighbors``
    nearest training rows) of paper 05's baselines. Ties of the vote go to the class with the
    nearest member (``tie="nearest"``) or to the smallest label (``tie="smallest"``, as
    scikit-learn's ``KNeighborsClassifier``)."""

    _estimator_type = "classifier"
    _requires_y = True

    def __init__(self, n_neighbors: int = 5, tie: str = "nearest"):
        self.n_neighbors, self.tie = n_neighbors, tie

    def fit(self, X, y):
        """Stores the training rows ``X`` and labels ``y``; returns ``self``."""
        X = self._validate_X(X, reset=True)
        self.classes_, self._codes = _encode_labels(self._validate_y(y, X.shape[0]), X.shape[0])
        self._X = X
        self.n_features_in_ = X.shape[1]
        return self

    def predict(self, X) -> np.ndarray:
        """The majority label of the ``n_neighbors`` nearest training rows of every row."""
        X = self._validate_X(X, reset=False)
        return self.classes_[_b.knn_predict(self._X, self._codes, X,
                                            self.n_neighbors,
                                            self.tie)]

    def score(self, X, y) -> float:
        """Mean accuracy."""
        return float(np.mean(self.predict(X) == np.asarray(y)))


def confusion_matrix(y_true, y_pred, classes=None) -> Tuple[np.ndarray, np.ndarray]:
    """Row-normalised confusion matrix in percent (row = true class, column = predicted),
    the layout of paper 05's Tables 3-6, and the class order used."""
    y_true, y_pred = np.asarray(y_true), np.asarray(y_pred)
    classes = np.unique(np.concatenate([y_true, y_pred])) if classes is None else np.asarray(classes)
    lookup = {c: i for i, c in enumerate(classes.tolist())}
    try:
        t = np.array([lookup[v] for v in y_true.tolist()], dtype=np.int64)
        p = np.array([lookup[v] for v in y_pred.tolist()], dtype=np.int64)
    except KeyError as e:
        raise ValueError(f"label {e.args[0]!r} is not among the classes") from None
    return _b.confusion_matrix(t, p, len(classes)), classes


class Isomap(Estimator, _NativeTransform, _JsonPickled):
    """Isomap (Tenenbaum et al. 2000): the "KNN on 9-D Isomap" baseline of paper 05
    (Table 6). Exact Isomap follows scikit-learn's ``Isomap`` step by step (brute-force
    neighbourhood graph, Dijkstra geodesics, kernel PCA of ``-D^2/2``, ``transform`` of new
    points through their nearest training points), so ``embedding_`` equals sklearn's up to
    the sign of each component. With ``n_landmarks`` it is Landmark Isomap (de Silva and
    Tenenbaum 2003; geodesic MaxMin landmarks), for more than 5000 points.

    A disconnected neighbourhood graph raises ``ValueError`` (use a larger
    ``n_neighbors``)."""

    def __init__(self, n_neighbors: int = 8, n_components: int = 9,
                 n_landmarks: Optional[int] = None):
        self.n_neighbors, self.n_components, self.n_landmarks = (
            n_neighbors, n_components, n_landmarks)

    def fit(self, X, y=None):
        """Fits to the rows of ``X``; ``y`` is ignored. Returns ``self``."""
        X = self._validate_X(X, reset=True, min_samples=2)
        self._model = _b.isomap_fit(X, self.n_neighbors, self.n_components, self.n_landmarks)
        self.n_features_in_ = X.shape[1]
        self.embedding_ = self._model.embedding()
        self.eigenvalues_ = np.asarray(self._model.eigenvalues())
        lm = self._model.landmarks()
        self.landmarks_ = None if lm is None else np.asarray(lm)
        return self

    def fit_transform(self, X, y=None) -> np.ndarray:
        """``fit(X)``, returning ``embedding_``."""
        return self.fit(X).embedding_

    def _model_from_json(self, text):
        return _b.IsomapModel.from_json(text)


HAND_POSE_CLASSES = ("FIST", "FLAT", "INDEX", "OPEN", "GRAB")
_JITTER_KEYS = ("extension", "finger_angle_deg", "spread", "rotation_deg", "scale",
                "translation_px")


@_result
class HandPoseSplit:
    """Paper 05's protocol applied by :func:`hand_pose_split`: rows are masks downscaled by
    3 and flattened (values in ``[0, 1]``, the fraction of hand in each 3 x 3 cell).

    Attributes
    ----------
    X_train : float64 array (n_train, h * w)
        Training rows, the rotated copies appended after the original frames.
    y_train : array (n_train,)
        Their labels (as given).
    X_test : float64 array (n_test, h * w)
        Test rows.
    y_test : array (n_test,)
        Their labels.
    train_index : int64 array (n_train,)
        Source frame of each training row.
    test_index : int64 array (n_test,)
        Source frame of each test row.
    train_rotation : float64 array (n_train,)
        Rotation of each training row in degrees (0 for the original frames).
    shape : (int, int)
        ``(h, w)`` of the downscaled masks.
    """

    X_train: np.ndarray
    y_train: np.ndarray
    X_test: np.ndarray
    y_test: np.ndarray
    train_index: np.ndarray
    test_index: np.ndarray
    train_rotation: np.ndarray
    shape: Tuple[int, int]


@_result
class ClassifierRun:
    """One method of :func:`hand_pose_comparison` on the test rows.

    Attributes
    ----------
    confusion : float64 array (n_classes, n_classes)
        Row-normalised confusion matrix in percent (row = true class, column = predicted).
    predictions : array (n_test,)
        Predicted label of each test row.
    accuracy : float
        Mean of the confusion diagonal, percent.
    fit_seconds, predict_seconds : float
        Wall time of fitting and of predicting the test rows, seconds.
    """

    confusion: np.ndarray
    predictions: np.ndarray
    accuracy: float
    fit_seconds: float
    predict_seconds: float


@_result
class HandPoseComparison:
    """Paper 05's comparison (Tables 3-6) run by :func:`hand_pose_comparison`.

    Attributes
    ----------
    classes : array (n_classes,)
        Class order of the confusion matrices.
    y_test : array (n_test,)
        True label of each test row.
    results : dict mapping str to ClassifierRun
        One entry per method run, by name (``"sfa"``, ``"physical"``, ``"pca"``,
        ``"isomap"``, ``"global"``).
    """

    classes: np.ndarray
    y_test: np.ndarray
    results: Dict[str, ClassifierRun]


def hand_pose_jitter(preset: str = "default") -> dict:
    """Per-frame variation amplitudes of :func:`make_hand_poses`: ``"default"`` (the tight
    amplitudes with the hand translated by +-25 px, which makes FLAT/OPEN and FIST/GRAB
    confusable) or ``"tight"`` (translation +-8 px: every class far apart). ``"spec"`` is a
    deprecated alias of ``"tight"``."""
    if preset == "spec":
        warnings.warn("hand_pose_jitter('spec') is deprecated; use 'tight'",
                      DeprecationWarning, stacklevel=2)
        preset = "tight"
    default, tight = _b.jitter_presets()
    if preset not in ("default", "tight"):
        raise ValueError(f"`preset` must be 'default' or 'tight', got {preset!r}")
    return dict(zip(_JITTER_KEYS, default if preset == "default" else tight))


def make_hand_poses(n_per_class: int = 3000, n_subjects: int = 3, seed: int = 0,
                    size: Tuple[int, int] = (165, 120), jitter: Optional[dict] = None):
    """Synthetic time-of-flight hand poses standing in for paper 05's private recordings
    (5 poses ``HAND_POSE_CLASSES``, frames stored class by class): returns ``(masks,
    depth, labels, subjects)`` with ``masks`` uint8 ``(n, h, w)`` (0/1, segmented from a
    simulated amplitude image as the paper does), ``depth`` float32 in mm (0 off the hand),
    ``labels`` 0..4 and the subject of each frame. ``jitter`` overrides entries of
    :func:`hand_pose_jitter`. Deterministic given ``seed``; **synthetic data**."""
    amp = hand_pose_jitter()
    for k, v in (jitter or {}).items():
        if k not in amp:
            raise ValueError(f"unknown jitter key {k!r}; expected one of {_JITTER_KEYS}")
        amp[k] = float(v)
    return _b.hand_poses(n_per_class, n_subjects, seed, size, [amp[k] for k in _JITTER_KEYS])


def _n_frames(masks) -> int:
    """The number of frames of a mask stack ``(n, h, w)``, 1 for one ``(h, w)`` mask."""
    shape = np.shape(masks)
    return shape[0] if len(shape) == 3 else 1


def hand_pose_split(masks, labels, n_test_per_class: int = 300,
                    n_augment_per_class: int = 1000, seed: int = 0) -> HandPoseSplit:
    """The paper's protocol on a mask stack: per class ``n_test_per_class`` random test
    frames, the rest train; then ``n_augment_per_class`` training frames per class rotated by
    +-U(10, 20) degrees and appended. Rows are the masks downscaled by 3, flattened.
    Returns a :class:`HandPoseSplit` with ``X_train``, ``y_train``, ``X_test``, ``y_test``,
    ``train_index``, ``test_index`` (source frames), ``train_rotation`` (degrees) and
    ``shape``."""
    classes, codes = _encode_labels(labels, _n_frames(masks), "labels")
    d = _b.hand_pose_split(masks, codes, n_test_per_class, n_augment_per_class, seed)
    return _from_mapping(HandPoseSplit, d, y_train=classes[d["y_train"]],
                         y_test=classes[d["y_test"]], shape=tuple(d["shape"]))


def hand_pose_comparison(masks, labels, depth=None, methods=("sfa", "physical", "pca",
                         "isomap", "global"), n_test_per_class: int = 300,
                         n_augment_per_class: int = 1000, seed: int = 0,
                         pca_n_components: int = 35, m: int = 10, gamma: float = 1.0,
                         shrinkage: float = 1e-6, knn_n_neighbors: int = 5,
                         physical_n_per_class: int = 1500, isomap_n_neighbors: int = 8,
                         isomap_n_components: int = 9, isomap_n_per_class: Optional[int] = None,
                         isomap_n_landmarks: int = 2000,
                         global_rule: str = "variance") -> HandPoseComparison:
    """Paper 05's comparison (Tables 3-6) on a mask stack: the split of
    :func:`hand_pose_split`, then class-wise SFA (``"sfa"``; ``pca_n_components``, ``m``,
    ``gamma`` and ``shrinkage`` as in :class:`PerClassSFA`), KNN (``knn_n_neighbors``
    neighbours) on physical features (``"physical"``, z-scored, ``physical_n_per_class``
    original training frames per class), on PCA-35 (``"pca"``) and on Isomap (``"isomap"``;
    ``isomap_n_neighbors``, ``isomap_n_components``, ``isomap_n_per_class`` training frames
    per class (default all); Landmark Isomap with ``isomap_n_landmarks`` landmarks above 5000
    rows) and full-data-set SFA (``"global"``, ``global_rule`` as :class:`GlobalSFA`'s
    ``rule``). Returns a :class:`HandPoseComparison`: ``classes``, ``y_test`` and
    ``results[name]``, a :class:`ClassifierRun` (``confusion`` in % per true class,
    ``predictions``, ``accuracy``: mean of the diagonal in %, ``fit_seconds``,
    ``predict_seconds``)."""
    classes, codes = _encode_labels(labels, _n_frames(masks), "labels")
    cls, y_test, res = _b.hand_pose_comparison(
        masks, depth, codes, [str(x) for x in methods], n_test_per_class, n_augment_per_class,
        seed, (pca_n_components, m, gamma, shrinkage), knn_n_neighbors, physical_n_per_class,
        (isomap_n_neighbors, isomap_n_components, isomap_n_per_class, isomap_n_landmarks),
        global_rule)
    runs = {name: ClassifierRun(confusion=conf, predictions=classes[pred],
                                accuracy=float(np.mean(np.diag(conf))), fit_seconds=tf,
                                predict_seconds=tp)
            for name, conf, pred, tf, tp in res}
    return HandPoseComparison(classes=classes[np.asarray(cls)], y_test=classes[y_test],
                              results=runs)


# Paper 14 (occlusion detection and index-based ear recognition) lives in its own module,
# reachable as ``wscg.biometrics.ear`` and ``wscg.ear``.
from . import ear  # noqa: E402

# Paper 17 (Kinect gait recognition, JRA sequences + DTW kernel), reachable as
# ``wscg.biometrics.gait`` and ``wscg.gait``.
from . import gait  # noqa: E402

# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
