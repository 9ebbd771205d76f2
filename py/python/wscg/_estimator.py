"""The scikit-learn estimator protocol shared by every wscg estimator (py/API.md, "Verbs").

wscg does not depend on scikit-learn. :class:`Estimator` implements the protocol that
``sklearn.base.BaseEstimator`` implements, in the same way: the hyper-parameters are the
arguments of ``__init__`` (read from its signature), stored under their own names, returned
by ``get_params`` and changed by ``set_params`` (``name__sub`` reaches a nested estimator);
what ``fit`` learns ends in ``_``. ``sklearn.base.clone``, ``Pipeline`` and ``GridSearchCV``
therefore take wscg estimators. The tags that scikit-learn's checks read
(``__sklearn_tags__``) import scikit-learn only when scikit-learn asks for them.

Input validation follows scikit-learn's ``check_array``: ``X`` is a 2-D numeric array (a
list, a pandas frame, a read-only or Fortran-ordered array, an object array of numbers);
1-D input, complex values, NaN or infinity, sparse matrices, empty arrays and a number of
columns other than the one seen by ``fit`` raise ``ValueError`` (``TypeError`` for
sparse input and for objects that are not numbers) naming the argument.
"""

from __future__ import annotations

import inspect
import sys
import warnings
from collections import defaultdict
from typing import Dict, List, Optional, Tuple

import numpy as np

from ._checks import integer_ranges

__all__ = ["Estimator", "NotFittedError", "DataConversionWarning"]


class NotFittedError(ValueError, AttributeError):
    """A method that needs a fitted estimator was called before ``fit``.

    A ``ValueError`` and an ``AttributeError``, as scikit-learn's
    ``sklearn.exceptions.NotFittedError``. When scikit-learn is imported, the error raised is
    also an instance of scikit-learn's class, so ``except
    sklearn.exceptions.NotFittedError`` catches it too (wscg does not import scikit-learn
    itself: code that names scikit-learn's class has imported it).
    """


class DataConversionWarning(UserWarning):
    """A column vector ``y`` of shape ``(n, 1)`` was given where labels of shape ``(n,)``
    are expected; it is used raveled. Also an instance of scikit-learn's
    ``sklearn.exceptions.DataConversionWarning`` when scikit-learn is imported."""


# (wscg class, scikit-learn class) -> their common subclass, made on first use.
_BOTH: Dict[Tuple[type, type], type] = {}


def _with_sklearn_base(cls: type) -> type:
    """``cls``, or a subclass of ``cls`` and of scikit-learn's class of the same name when
    ``sklearn.exceptions`` is imported (checked at every call: importing scikit-learn later
    is seen)."""
    mod = sys.modules.get("sklearn.exceptions")
    base = getattr(mod, cls.__name__, None) if mod is not None else None
    if not isinstance(base, type) or issubclass(cls, base):
        return cls
    both = _BOTH.get((cls, base))
    if both is None:
        both = type(cls.__name__, (cls, base), {
            "__module__": cls.__module__,
            "__doc__": cls.__doc__,
            # Pickled by its wscg class: the process that loads it may not import sklearn.
            "__reduce__": lambda self: (_rebuild, (cls, self.args)),
        })
        _BOTH[(cls, base)] = both
    return both


def _rebuild(cls: type, args: tuple) -> BaseException:
    return _with_sklearn_base(cls)(*args)


def not_fitted_error(estimator) -> NotFittedError:
    """The :class:`NotFittedError` raised by ``estimator`` before ``fit``."""
    name = type(estimator).__name__
    return _with_sklearn_base(NotFittedError)(
        f"this {name} instance is not fitted yet: call fit before using it"
    )


def _same(a, b) -> bool:
    """Whether a parameter value equals its default (arrays and mixed types: no)."""
    try:
        return a is b or (type(a) is type(b) and bool(a == b))
    except (TypeError, ValueError):
        return False


class Estimator:
    """Base of every wscg estimator: the scikit-learn protocol (see the module docstring).

    Subclasses set ``_estimator_type`` (``"classifier"`` or ``None``), ``_requires_y``,
    ``_matrix_input`` (``False`` where ``X`` is not an ``(n_samples, n_features)`` matrix,
    e.g. skeleton sequences or images) and ``_fitted_attr``, the attribute that ``fit``
    sets, which :meth:`__sklearn_is_fitted__` looks for.
    """

    _estimator_type: Optional[str] = None
    _requires_y = False
    _matrix_input = True
    _fitted_attr = "n_features_in_"

    # -- parameters
    @classmethod
    def _get_param_names(cls) -> List[str]:
        """The arguments of ``__init__``, in signature order."""
        init = cls.__init__
        if init is object.__init__:
            return []
        names = []
        for p in inspect.signature(init).parameters.values():
            if p.name == "self":
                continue
            if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
                raise TypeError(f"{cls.__name__}.__init__ must name every parameter, "
                                f"got *{p.name}")
            names.append(p.name)
        return names

    def get_params(self, deep: bool = True) -> dict:
        """The hyper-parameters, as given to ``__init__`` or :meth:`set_params`.

        Parameters
        ----------
        deep : bool, default True
            Also return the parameters of nested estimators as ``name__sub``.
        """
        out = {}
        for k in self._get_param_names():
            v = getattr(self, k)
            if deep and hasattr(v, "get_params") and not isinstance(v, type):
                out.update((f"{k}__{kk}", vv) for kk, vv in v.get_params(deep=True).items())
            out[k] = v
        return out

    def set_params(self, **params):
        """Sets hyper-parameters (``name__sub`` for a nested estimator's) and returns
        ``self``. Values are checked by ``fit``, as in scikit-learn.

        Raises
        ------
        ValueError
            A name that is not a parameter.
        """
        if not params:
            return self
        valid = self.get_params(deep=True)
        nested: Dict[str, dict] = defaultdict(dict)
        for key, value in params.items():
            head, delim, sub = key.partition("__")
            if head not in valid:
                raise ValueError(
                    f"invalid parameter {head!r} for {type(self).__name__}; valid parameters "
                    f"are {self._get_param_names()}"
                )
            if delim:
                nested[head][sub] = value
            else:
                setattr(self, head, value)
                valid[head] = value
        for head, sub_params in nested.items():
            valid[head].set_params(**sub_params)
        return self

    def __repr__(self) -> str:
        """The class and the parameters that differ from their defaults."""
        sig = inspect.signature(type(self).__init__).parameters
        changed = []
        for k in self._get_param_names():
            v = getattr(self, k, None)
            default = sig[k].default
            if default is inspect.Parameter.empty or not _same(v, default):
                changed.append(f"{k}={v!r}")
        return f"{type(self).__name__}({', '.join(changed)})"

    # -- fitted state
    def __sklearn_is_fitted__(self) -> bool:
        return hasattr(self, self._fitted_attr)

    def _check_fitted(self) -> None:
        if not self.__sklearn_is_fitted__():
            raise not_fitted_error(self)

    # -- scikit-learn tags (read by scikit-learn >= 1.6 only, so sklearn is importable)
    def __sklearn_tags__(self):
        from sklearn.utils import ClassifierTags, InputTags, Tags, TargetTags, TransformerTags

        classifier = self._estimator_type == "classifier"
        return Tags(
            estimator_type=self._estimator_type,
            target_tags=TargetTags(required=self._requires_y),
            transformer_tags=TransformerTags() if hasattr(self, "transform") else None,
            classifier_tags=ClassifierTags() if classifier else None,
            input_tags=InputTags(two_d_array=self._matrix_input),
        )

    # -- input validation
    def _validate_X(self, X, *, reset: bool, name: str = "X", min_samples: int = 1,
                    allow_images: bool = False) -> np.ndarray:
        """``X`` as a C-contiguous float64 ``(n, d)`` matrix, validated as scikit-learn's
        ``check_array`` does. With ``reset`` (in ``fit``, which sets ``n_features_in_`` once
        it succeeded) any width is taken; otherwise the estimator must be fitted and the
        width must equal ``n_features_in_``. ``allow_images`` accepts an ``(n, h, w)``
        stack, flattened row-major."""
        a = as_matrix(X, name=name, min_samples=min_samples, allow_images=allow_images)
        if not reset:
            self._check_fitted()
            expected = self.n_features_in_
            if a.shape[1] != expected:
                raise ValueError(f"{name} has {a.shape[1]} features, but {type(self).__name__} "
                                 f"is expecting {expected} features as input")
        return a

    def _validate_y(self, y, n: int) -> np.ndarray:
        """Labels ``y`` as a 1-D array of ``n`` values (a column vector is raveled with a
        :class:`DataConversionWarning`). A classifier refuses NaN, infinity and continuous
        (non-integer float) labels."""
        if y is None:
            raise ValueError(f"{type(self).__name__} requires y to be passed, but the target "
                             "y is None")
        y = np.asarray(y)
        if y.ndim == 2 and y.shape[1] == 1:
            warnings.warn(
                "A column-vector y was passed when a 1d array was expected: `y` of shape "
                f"{y.shape} is used as ({y.shape[0]},); use y.ravel()",
                _with_sklearn_base(DataConversionWarning), stacklevel=3)
            y = y.ravel()
        if y.ndim != 1:
            raise ValueError(f"`y` must be 1-D (one label per row), got shape {y.shape}")
        if y.shape[0] != n:
            raise ValueError(f"`y` has {y.shape[0]} labels for {n} rows of `X`")
        if self._estimator_type == "classifier" and y.dtype.kind in "fc":
            if not np.all(np.isfinite(y)):
                raise ValueError("`y` contains NaN or infinity")
            if np.iscomplexobj(y) or np.any(y != np.round(y)):
                raise ValueError("Unknown label type: `y` holds continuous values; a "
                                 "classifier takes class labels (integers or strings)")
        return y


def as_matrix(X, name: str = "X", min_samples: int = 1,
              allow_images: bool = False) -> np.ndarray:
    """``X`` as a C-contiguous float64 ``(n, d)`` matrix (see :meth:`Estimator._validate_X`)."""
    sparse = sys.modules.get("scipy.sparse")
    if sparse is not None and sparse.issparse(X):
        raise TypeError(f"`{name}` is a sparse matrix; wscg estimators take dense arrays "
                        "(sparse input is not supported: use X.toarray())")
    a = np.asarray(X)
    if a.dtype == object:
        # Numbers stored as objects convert; anything else raises TypeError or ValueError.
        a = a.astype(np.float64)
    if np.iscomplexobj(a):
        raise ValueError(f"`{name}` must be real-valued (Complex data not supported), "
                         f"got dtype {a.dtype}")
    if not (np.issubdtype(a.dtype, np.number) or a.dtype == np.bool_):
        raise ValueError(f"`{name}` must be a numeric array, got dtype {a.dtype}")
    if a.ndim == 3 and allow_images:
        a = a.reshape(a.shape[0], -1)
    elif a.ndim != 2:
        shapes = "an (n, d) matrix or an (n, h, w) image stack" if allow_images else \
            "an (n_samples, n_features) matrix"
        hint = (": Reshape your data either using X.reshape(-1, 1) if it has a single "
                "feature or X.reshape(1, -1) if it is a single sample") if a.ndim < 2 else ""
        raise ValueError(f"`{name}` must be {shapes}, got a {a.ndim}-D array of shape "
                         f"{a.shape}{hint}")
    if a.shape[0] < min_samples:
        raise ValueError(f"`{name}` has {a.shape[0]} sample(s) (shape={a.shape}) while a "
                         f"minimum of {min_samples} is required")
    if a.shape[1] < 1:
        raise ValueError(f"`{name}` has 0 feature(s) (shape={a.shape}) while a minimum of 1 "
                         "is required.")
    a = np.ascontiguousarray(a, dtype=np.float64)
    if not np.isfinite(a).all():
        what = "NaN" if np.isnan(a).any() else "infinity"
        raise ValueError(f"`{name}` contains {what}")
    return a


# The public methods carry the package's translation of OverflowError (as every module's).
integer_ranges(globals())
