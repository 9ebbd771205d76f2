from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
F64 = npt.NDArray[np.float64]
F32 = npt.NDArray[np.float32]
I64 = npt.NDArray[np.int64]

__all__: list[str]

class _Subspace:
    n_components_: int
    n_features_in_: int
    image_shape_: Optional[Tuple[int, int]]
    classes_: Optional[np.ndarray]
    metric: str
    def get_params(self, deep: bool = True) -> dict[str, Any]: ...
    def set_params(self, **params: Any) -> "_Subspace": ...
    def fit(self, X: ArrayLike, y: Optional[ArrayLike] = None) -> "_Subspace": ...
    def transform(self, X: ArrayLike) -> F64: ...
    def fit_transform(self, X: ArrayLike, y: Optional[ArrayLike] = None) -> F64: ...
    def truncated(self, n_components: int) -> "_Subspace": ...
    def kneighbors(self, X: ArrayLike) -> Tuple[F64, I64]: ...
    def predict(self, X: ArrayLike) -> np.ndarray: ...
    def score(self, X: ArrayLike, y: ArrayLike) -> float: ...
    def to_json(self) -> str: ...

class _Linear(_Subspace):
    mean_: F64
    components_: F64
    def inverse_transform(self, Z: ArrayLike) -> F64: ...
    def axis_images(self, k: Optional[int] = None,
                    shape: Optional[Tuple[int, int]] = None) -> F32: ...

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
    eigenvalues_: F64
    entropy_: F64
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
    variances_: F64
    def __init__(self, n_components: Optional[int] = None, whiten: bool = False,
                 metric: str = "euclidean") -> None: ...

class _SampleKernel(_Subspace):
    eigenvalues_: F64
    eigenvectors_: F64
    embedding_: F64
    sigma_: Optional[float]
    gamma_: Optional[float]
    def __init__(self, n_components: Optional[int] = None, kernel: str = "rbf",
                 sigma: Union[float, str, None] = None, sigma_scale: float = 1.0,
                 degree: int = 2, gamma: Union[float, str, None] = None, coef0: float = 1.0,
                 metric: str = "euclidean") -> None: ...

class KernelPCA(_SampleKernel): ...

class KECA(_SampleKernel):
    entropy_: F64
    renyi_entropy_: float

def nn_classify(Z_train: ArrayLike, y_train: ArrayLike, Z_test: ArrayLike,
                metric: str = "euclidean") -> np.ndarray: ...
def accuracy_curve(model: _Subspace, X_train: ArrayLike, y_train: ArrayLike,
                   X_test: ArrayLike, y_test: ArrayLike,
                   dims: Optional[Sequence[int]] = None,
                   metric: Optional[str] = None) -> F64: ...
def best_dimension(curve: ArrayLike) -> Tuple[int, float]: ...
def select_dimension_cv(model: _Subspace, X: ArrayLike, y: ArrayLike,
                        dims: Optional[Sequence[int]] = None, folds: int = 5,
                        seed: int = 0) -> Tuple[int, F64]: ...
def feature_kernel(X: ArrayLike, kernel: str = "rbf", sigma: Union[float, str, None] = None,
                   sigma_scale: float = 1.0, degree: int = 2,
                   gamma: Union[float, str, None] = None, coef0: float = 1.0,
                   center: bool = True) -> Tuple[F64, dict[str, Any]]: ...
def make_finger_veins(subjects: int = 200, samples: int = 10,
                      size: Tuple[int, int] = (10, 20), canvas: Tuple[int, int] = (40, 80),
                      max_shift: float = 3.5, max_rotation_deg: float = 3.0,
                      noise: float = 0.03, blur: float = 1.0,
                      seed: int = 0) -> Tuple[F64, I64]: ...
def split_per_subject(labels: ArrayLike, train_per_subject: int,
                      seed: int = 0) -> Tuple[I64, I64]: ...
