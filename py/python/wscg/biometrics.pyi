from dataclasses import dataclass
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import ear as ear
from . import gait as gait
from ._estimator import Estimator

_ArrayLike = npt.ArrayLike
_F64 = npt.NDArray[np.float64]
_F32 = npt.NDArray[np.float32]
_I64 = npt.NDArray[np.int64]

__all__ = ["FDKECA", "PCA", "KernelPCA", "KECA", "nn_classify", "accuracy_curve",
           "best_dimension", "select_dimension_cv", "feature_kernel", "make_finger_veins",
           "split_per_subject", "PerClassSFA", "GlobalSFA", "TemporalSFA", "KNN",
           "confusion_matrix", "Isomap", "HAND_POSE_CLASSES", "hand_pose_jitter",
           "make_hand_poses", "physical_features", "rotate_mask", "downscale_mask",
           "hand_pose_split", "hand_pose_comparison", "hand_pose_rotated_test",
           "ResolvedKernel", "HandPoseSplit", "ClassifierRun", "HandPoseComparison"]

@dataclass(frozen=True)
class ResolvedKernel:
    kernel: str
    sigma: Optional[float] = ...
    degree: Optional[int] = ...
    gamma: Optional[float] = ...
    coef0: Optional[float] = ...

@dataclass(frozen=True)
class HandPoseSplit:
    X_train: _F64
    y_train: np.ndarray
    X_test: _F64
    y_test: np.ndarray
    train_index: _I64
    test_index: _I64
    train_rotation: _F64
    shape: Tuple[int, int]

@dataclass(frozen=True)
class ClassifierRun:
    confusion: _F64
    predictions: np.ndarray
    accuracy: float
    fit_seconds: float
    predict_seconds: float

@dataclass(frozen=True)
class HandPoseComparison:
    classes: np.ndarray
    y_test: np.ndarray
    results: Dict[str, ClassifierRun]

class _Subspace(Estimator):
    n_components_: int
    n_features_in_: int
    image_shape_: Optional[Tuple[int, int]]
    classes_: Optional[np.ndarray]
    metric: str
    def fit(self, X: _ArrayLike, y: Optional[_ArrayLike] = None) -> "_Subspace": ...
    def transform(self, X: _ArrayLike) -> _F64: ...
    def fit_transform(self, X: _ArrayLike, y: Optional[_ArrayLike] = None) -> _F64: ...
    def truncated(self, n_components: int) -> "_Subspace": ...
    def kneighbors(self, X: _ArrayLike) -> Tuple[_F64, _I64]: ...
    def predict(self, X: _ArrayLike) -> np.ndarray: ...
    def score(self, X: _ArrayLike, y: _ArrayLike) -> float: ...
    def to_json(self) -> str: ...

class _Linear(_Subspace):
    mean_: _F64
    components_: _F64
    def inverse_transform(self, Z: _ArrayLike) -> _F64: ...
    def axis_images(self, n_components: Optional[int] = None,
                    shape: Optional[Tuple[int, int]] = None) -> _F32: ...

class FDKECA(_Linear):
    n_components: Optional[int]
    kernel: str
    sigma: Union[float, str, None]
    sigma_scale: float
    degree: int
    gamma: Union[float, str, None]
    coef0: float
    ordering: str
    center: bool
    eigenvalues_: _F64
    entropy_: _F64
    kernel_sum_: float
    renyi_entropy_: float
    sigma_: Optional[float]
    gamma_: Optional[float]
    def __init__(self, n_components: Optional[int] = None, kernel: str = "rbf",
                 sigma: Union[float, str, None] = None, sigma_scale: float = 1.0,
                 degree: int = 2, gamma: Union[float, str, None] = None, coef0: float = 1.0,
                 ordering: str = "entropy", center: bool = True,
                 metric: str = "euclidean") -> None: ...

class PCA(_Linear):
    n_components: Optional[int]
    whiten: bool
    variances_: _F64
    def __init__(self, n_components: Optional[int] = None, whiten: bool = False,
                 metric: str = "euclidean") -> None: ...

class _SampleKernel(_Subspace):
    eigenvalues_: _F64
    eigenvectors_: _F64
    embedding_: _F64
    sigma_: Optional[float]
    gamma_: Optional[float]
    def __init__(self, n_components: Optional[int] = None, kernel: str = "rbf",
                 sigma: Union[float, str, None] = None, sigma_scale: float = 1.0,
                 degree: int = 2, gamma: Union[float, str, None] = None, coef0: float = 1.0,
                 metric: str = "euclidean") -> None: ...

class KernelPCA(_SampleKernel): ...

class KECA(_SampleKernel):
    entropy_: _F64
    renyi_entropy_: float

def nn_classify(Z_train: _ArrayLike, y_train: _ArrayLike, Z_test: _ArrayLike,
                metric: str = "euclidean") -> np.ndarray: ...
def accuracy_curve(model: _Subspace, X_train: _ArrayLike, y_train: _ArrayLike,
                   X_test: _ArrayLike, y_test: _ArrayLike,
                   dims: Optional[Sequence[int]] = None,
                   metric: Optional[str] = None) -> _F64: ...
def best_dimension(curve: _ArrayLike) -> Tuple[int, float]: ...
def select_dimension_cv(model: _Subspace, X: _ArrayLike, y: _ArrayLike,
                        dims: Optional[Sequence[int]] = None, n_folds: int = 5,
                        seed: int = 0) -> Tuple[int, _F64]: ...
def feature_kernel(X: _ArrayLike, kernel: str = "rbf", sigma: Union[float, str, None] = None,
                   sigma_scale: float = 1.0, degree: int = 2,
                   gamma: Union[float, str, None] = None, coef0: float = 1.0,
                   center: bool = True) -> Tuple[_F64, ResolvedKernel]: ...
def make_finger_veins(n_subjects: int = 200, n_per_subject: int = 10,
                      size: Tuple[int, int] = (10, 20), canvas: Tuple[int, int] = (40, 80),
                      max_shift: float = 3.5, max_rotation_deg: float = 3.0,
                      noise: float = 0.03, blur: float = 1.0,
                      seed: int = 0) -> Tuple[_F64, _I64]: ...
def split_per_subject(labels: _ArrayLike, n_train_per_subject: int,
                      seed: int = 0) -> Tuple[_I64, _I64]: ...

class PerClassSFA(Estimator):
    classes_: np.ndarray
    n_features_in_: int
    eigenvalues_: list
    rank_: int
    pca_n_components: int
    m: int
    degree: int
    include_linear: bool
    objective: str
    gamma: float
    shrinkage: float
    rank_tol: float
    def __init__(self, pca_n_components: int = 35, m: int = 10, degree: int = 2,
                 include_linear: bool = True, objective: str = "within_minus_out",
                 gamma: float = 1.0, shrinkage: float = 1e-6, rank_tol: float = 1e-10) -> None: ...
    def fit(self, X: npt.ArrayLike, y: npt.ArrayLike) -> "PerClassSFA": ...
    def predict(self, X: npt.ArrayLike) -> np.ndarray: ...
    def class_scores(self, X: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def decision_function(self, X: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def responses(self, X: npt.ArrayLike, cls: object) -> npt.NDArray[np.float64]: ...
    def score(self, X: npt.ArrayLike, y: npt.ArrayLike) -> float: ...
    def save(self, path: str) -> None: ...
    @classmethod
    def load(cls, path: str) -> "PerClassSFA": ...

class GlobalSFA(Estimator):
    classes_: np.ndarray
    n_features_in_: int
    eigenvalues_: list
    rank_: int
    pca_n_components: int
    n_components: int
    degree: int
    include_linear: bool
    gamma: float
    shrinkage: float
    rank_tol: float
    rule: str
    def __init__(self, pca_n_components: int = 35, n_components: int = 10, degree: int = 2,
                 include_linear: bool = True, gamma: float = 1.0, shrinkage: float = 1e-6,
                 rank_tol: float = 1e-10, rule: str = "variance") -> None: ...
    def fit(self, X: npt.ArrayLike, y: npt.ArrayLike) -> "GlobalSFA": ...
    def predict(self, X: npt.ArrayLike) -> np.ndarray: ...
    def class_scores(self, X: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def decision_function(self, X: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def transform(self, X: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def fit_transform(self, X: npt.ArrayLike, y: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def score(self, X: npt.ArrayLike, y: npt.ArrayLike) -> float: ...
    def save(self, path: str) -> None: ...
    @classmethod
    def load(cls, path: str) -> "GlobalSFA": ...

class TemporalSFA(Estimator):
    n_features_in_: int
    delta_values_: npt.NDArray[np.float64]
    rank_: int
    n_components: int
    degree: int
    include_linear: bool
    rank_tol: float
    def __init__(self, n_components: int = 2, degree: int = 2, include_linear: bool = True,
                 rank_tol: float = 1e-10) -> None: ...
    def fit(self, X: npt.ArrayLike, y: object = None) -> "TemporalSFA": ...
    def transform(self, X: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def fit_transform(self, X: npt.ArrayLike, y: object = None) -> npt.NDArray[np.float64]: ...

class KNN(Estimator):
    classes_: np.ndarray
    n_features_in_: int
    n_neighbors: int
    tie: str
    def __init__(self, n_neighbors: int = 5, tie: str = "nearest") -> None: ...
    def fit(self, X: npt.ArrayLike, y: npt.ArrayLike) -> "KNN": ...
    def predict(self, X: npt.ArrayLike) -> np.ndarray: ...
    def score(self, X: npt.ArrayLike, y: npt.ArrayLike) -> float: ...

def confusion_matrix(y_true: npt.ArrayLike, y_pred: npt.ArrayLike,
                     classes: Optional[npt.ArrayLike] = ...) -> Tuple[npt.NDArray[np.float64], np.ndarray]: ...

class Isomap(Estimator):
    n_features_in_: int
    n_neighbors: int
    n_components: int
    n_landmarks: Optional[int]
    embedding_: npt.NDArray[np.float64]
    eigenvalues_: npt.NDArray[np.float64]
    landmarks_: Optional[np.ndarray]
    def __init__(self, n_neighbors: int = 8, n_components: int = 9,
                 n_landmarks: Optional[int] = None) -> None: ...
    def fit(self, X: npt.ArrayLike, y: object = None) -> "Isomap": ...
    def transform(self, X: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def fit_transform(self, X: npt.ArrayLike, y: object = None) -> npt.NDArray[np.float64]: ...

HAND_POSE_CLASSES: Tuple[str, str, str, str, str]

def hand_pose_jitter(preset: str = "default") -> dict: ...
def make_hand_poses(n_per_class: int = 3000, n_subjects: int = 3, seed: int = 0,
                    size: Tuple[int, int] = (165, 120), jitter: Optional[dict] = None
                    ) -> Tuple[npt.NDArray[np.uint8], npt.NDArray[np.float32],
                               npt.NDArray[np.int64], npt.NDArray[np.int64]]: ...
def physical_features(masks: npt.ArrayLike, depth: Optional[npt.ArrayLike] = None
                      ) -> npt.NDArray[np.float64]: ...
def rotate_mask(mask: npt.ArrayLike, degrees: float) -> npt.NDArray[np.uint8]: ...
def downscale_mask(mask: npt.ArrayLike, factor: int = 3) -> npt.NDArray[np.float64]: ...
def hand_pose_split(masks: npt.ArrayLike, labels: npt.ArrayLike, n_test_per_class: int = 300,
                    n_augment_per_class: int = 1000, seed: int = 0) -> HandPoseSplit: ...
def hand_pose_comparison(masks: npt.ArrayLike, labels: npt.ArrayLike,
                         depth: Optional[npt.ArrayLike] = None,
                         methods: Sequence[str] = ..., n_test_per_class: int = 300,
                         n_augment_per_class: int = 1000, seed: int = 0,
                         pca_n_components: int = 35, m: int = 10, gamma: float = 1.0,
                         shrinkage: float = 1e-6, knn_n_neighbors: int = 5,
                         physical_n_per_class: int = 1500, isomap_n_neighbors: int = 8,
                         isomap_n_components: int = 9, isomap_n_per_class: Optional[int] = None,
                         isomap_n_landmarks: int = 2000,
                         global_rule: str = "variance") -> HandPoseComparison: ...
def hand_pose_rotated_test(masks: npt.ArrayLike, test_index: npt.ArrayLike,
                           angles: Tuple[float, float] = ..., seed: int = 1
                           ) -> npt.NDArray[np.float64]: ...
